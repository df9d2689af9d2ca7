"""The paper's design scenarios (single Miura, canopy, arch, gripper), by command-line name.

Each module defines ``SCENARIO`` (:class:`holofold.design.scenarios.base.Scenario`): feature and
performance columns with units and the paper's sampling ranges, a validity check and an
``evaluate(row) -> dict`` that reproduces the published rows.
"""

from __future__ import annotations

from holofold.design.scenarios.base import Column, Scenario

__all__ = ["Column", "Scenario", "SCENARIO_NAMES", "get_scenario"]

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
        raise ValueError(f"unknown scenario {name!r}; allowed: {', '.join(SCENARIO_NAMES)}")
    module, _, attr = _MODULES[key].partition(":")
    return getattr(importlib.import_module(module), attr or "SCENARIO")
