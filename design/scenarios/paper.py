"""The paper's design scenarios by command-line name: ``single-miura``, ``canopy``, ``arch``,
``gripper`` and ``gripper-converged``, each a module's ``SCENARIO`` imported when asked for."""

from __future__ import annotations

import importlib

from holofold.design.scenarios.base import Scenario

__all__ = ["SCENARIO_NAMES", "get_scenario"]

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
    key = str(name).strip().lower().replace("_", "-")
    if key not in _MODULES:
        raise ValueError(
            f"unknown scenario {name!r}; allowed: {', '.join(SCENARIO_NAMES)} "
            "or a scenario file (.toml)"
        )
    module, _, attr = _MODULES[key].partition(":")
    return getattr(importlib.import_module(module), attr or "SCENARIO")
