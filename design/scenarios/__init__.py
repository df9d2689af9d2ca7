"""The paper's design scenarios (single Miura, canopy, arch, gripper), by command-line name,
and scenario files (:mod:`~holofold.design.scenarios.files`): a designer's own problem in TOML.

Each module defines ``SCENARIO`` (:class:`holofold.design.scenarios.base.Scenario`): feature and
performance columns with units and the paper's sampling ranges, a validity check and an
``evaluate(row) -> dict`` that reproduces the published rows.
"""

from __future__ import annotations

from holofold.design.scenarios.base import DISPLAY_UNITS, Column, Scenario, format_value
from holofold.design.scenarios.config import ScenarioFileError
from holofold.design.scenarios.files import (
    load_scenario,
    read_scenario,
    shipped_scenarios,
    shipped_text,
)
from holofold.design.scenarios.kinds import (
    KINDS,
    ScenarioKind,
    get_kind,
    kind_names,
    register_kind,
    scenario_kinds,
)
from holofold.design.scenarios.paper import SCENARIO_NAMES, get_scenario

__all__ = [
    "Column",
    "Scenario",
    "format_value",
    "DISPLAY_UNITS",
    "SCENARIO_NAMES",
    "get_scenario",
    "load_scenario",
    "read_scenario",
    "shipped_scenarios",
    "shipped_text",
    "ScenarioFileError",
    "ScenarioKind",
    "get_kind",
    "kind_names",
    "register_kind",
    "KINDS",
    "scenario_kinds",
]
