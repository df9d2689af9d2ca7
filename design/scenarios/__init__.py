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

#: command-line name -> module (its ``SCENARIO``) or ``module:ATTRIBUTE``
_MODULES = {
    "single-miura": "holofold.design.scenarios.single_miura",
    "canopy": "holofold.design.scenarios.canopy",
    "arch": "holofold.design.scenarios.arch",
    "gripper": "holofold.design.scenarios.gripper",
    "gripper-converged": "holofold.design.scenarios.gripper:SCENARIO_CONVERGED",
}
SCENARIO_NAMES = tuple(_MODULES)


def get_scenario(name: str) -> Scenario:
    """The :class:`Scenario` called ``name`` (one of :data:`SCENARIO_NAMES`)."""
    import importlib

    key = str(name).strip().lower().replace("_", "-")
    if key not in _MODULES:
        raise ValueError(
            f"unknown scenario {name!r}; allowed: {', '.join(SCENARIO_NAMES)} "
            "or a scenario file (.toml)"
        )
    module, _, attr = _MODULES[key].partition(":")
    return getattr(importlib.import_module(module), attr or "SCENARIO")
