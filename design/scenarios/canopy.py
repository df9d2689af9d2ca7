"""Scenario 2 of the paper: bending and axial stiffness of Miura and TMP canopy sheets.

docs/scenarios.md §3 (data1, and data4 in §3.2): a 0.2 m x 0.2 m sheet, Miura-ori (pattern 1,
gamma = 70 deg, b = L/m, a = (L - b cot gamma)/n) or Tachi-Miura polyhedron (pattern 2, m even,
n a multiple of 3), concentrated-hinge model, one stress-free model per extension 0.3, 0.6,
0.9. The nodes at x = min are fixed; the nodes at x = max share 1 N per increment, in -z for
bending and +x for the axial case; Newton-Raphson, 3 increments, tol 1e-7 m; stiffness =
3 N / mean |U| of the loaded nodes. ``creaseE`` and ``panelE`` are optional columns (data4
variant); both default to 2 GPa.

This is the sheet kind (:mod:`~holofold.design.scenarios.sheet`) with the paper's setting
:data:`SETTING`; the shipped ``canopy.toml`` says the same.
"""

from __future__ import annotations

import math

from holofold.design.scenarios.base import ROW_TIMEOUTS, paper_scenario
from holofold.design.scenarios.sheet import MIURA as MIURA
from holofold.design.scenarios.sheet import TMP as TMP
from holofold.design.scenarios.sheet import (
    SheetLoad,
    SheetSetting,
    sheet_features,
    sheet_scenario,
)
from holofold.design.scenarios.sheet import sheet_models as _sheet_models
from holofold.mechanics.compat import PAPER

__all__ = [
    "SCENARIO",
    "SETTING",
    "evaluate",
    "check",
    "sheet_models",
    "SIZE",
    "GAMMA",
    "EXTENSIONS",
]

SIZE = 0.2  #: sheet size L, m
GAMMA = 70.0 / 180.0 * math.pi  #: Miura sector angle, rad
E_DEFAULT = 2e9
NU = 0.3
EXTENSIONS = (0.3, 0.6, 0.9)
INCREMENTS = 3
TOL = 1e-7

#: the paper's canopy as a sheet setting: 3 N in 3 increments, -z (bend) and +x (axial)
SETTING = SheetSetting(
    size_x=SIZE,
    size_y=SIZE,
    gamma=GAMMA,
    extensions=EXTENSIONS,
    loads=(
        SheetLoad("bend", (0.0, 0.0, -1.0), 3.0, INCREMENTS),
        SheetLoad("axial", (1.0, 0.0, 0.0), 3.0, INCREMENTS),
    ),
    E=E_DEFAULT,
    nu=NU,
    tol=TOL,
)
#: pattern, m, n, tcrease, tpanel, W and the optional creaseE, panelE
FEATURES = sheet_features(SETTING)
_SHEET = sheet_scenario("canopy", "", SETTING, FEATURES, extras=False)
#: bendstiff30, bendstiff60, bendstiff90, axialstiff30, axialstiff60, axialstiff90 (N/m)
PERFORMANCE = _SHEET.performance
#: physical validity of one design (empty list if valid)
check = _SHEET.check
#: bending and axial stiffness at the three extensions (N/m) and a status
evaluate = _SHEET.evaluate


def sheet_models(row, *, profile=PAPER, extensions=EXTENSIONS):
    """Stress-free models with supports, one per extension.

    Returns
    -------
    list of (Structure, bending LoadGroup, axial LoadGroup)
    """
    models = _sheet_models(SETTING, row, profile=profile, extensions=extensions)
    return [(s, *groups) for s, groups in models]


SCENARIO = paper_scenario(
    _SHEET,
    name="canopy",
    description=(
        "Miura-ori or TMP canopy sheet (0.2 m x 0.2 m): bending and axial secant stiffness "
        "under 3 N at extensions 0.3, 0.6, 0.9 (Zhu & Filipov 2022, data1; data4 with "
        "creaseE/panelE)."
    ),
    check=check,
    categorical=("pattern", "m", "n"),
    row_timeout=ROW_TIMEOUTS["sheet"],  # rows take 0.5-1.3 s warm
)
