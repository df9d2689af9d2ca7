"""Scenario 1 of the paper: axial stiffness of a single Miura-ori unit cell (data0).

docs/scenarios.md §2: a 2 x 2 Miura cell of size L = 0.04 m (b = L/2, a = (L - b cot gamma)/2),
concentrated-hinge model (E = 2 GPa, nu = 0.3, panel springs scaled by the crease width), one
stress-free model per extension Ext = 0.3, 0.6, 0.9. The nodes at x = 0 are fixed; the nodes at
x = max carry +x forces of 1 N per increment in total; Newton-Raphson, 3 increments, tol 1e-7 m;
``axialstiffXX = 3 N / mean |U_x|`` of the loaded nodes.

This is the sheet kind (:mod:`~holofold.design.scenarios.sheet`) with the setting
:data:`SETTING`: pattern, m and n fixed, the sector angle the feature ``gama``; the shipped
``single-miura.toml`` says the same.
"""

from __future__ import annotations

from holofold.design.scenarios.base import paper_scenario
from holofold.design.scenarios.sheet import (
    MIURA,
    SheetLoad,
    SheetSetting,
    check_sheet,
    sheet_features,
    sheet_models,
    sheet_scenario,
)
from holofold.mechanics.compat import PAPER

__all__ = [
    "SCENARIO",
    "SETTING",
    "evaluate",
    "check",
    "cell_models",
    "EXTENSIONS",
    "SIZE",
    "E",
    "NU",
]

SIZE = 0.04  #: cell size L, m
E = 2e9  #: Young's modulus of panels and creases, Pa
NU = 0.3
EXTENSIONS = (0.3, 0.6, 0.9)
INCREMENTS = 3
TOL = 1e-7

#: the paper's cell as a sheet setting: a fixed 2 x 2 Miura sheet, 3 N in +x (axial)
SETTING = SheetSetting(
    size_x=SIZE,
    size_y=SIZE,
    gamma=None,
    extensions=EXTENSIONS,
    loads=(SheetLoad("axial", (1.0, 0.0, 0.0), 3.0, INCREMENTS),),
    E=E,
    nu=NU,
    pattern=MIURA,
    m=2,
    n=2,
    tol=TOL,
)
#: tcrease, tpanel, W (m) and gama (rad, 50 to 80 deg)
FEATURES = sheet_features(SETTING, moduli=False)
_SHEET = sheet_scenario("single-miura", "", SETTING, FEATURES, extras=False)
#: axialstiff30, axialstiff60, axialstiff90 (N/m)
PERFORMANCE = _SHEET.performance
#: axial stiffness at the three extensions (N/m) and a status
evaluate = _SHEET.evaluate


def check(row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    return check_sheet(SETTING, row)


def cell_models(tcrease, tpanel, W, gama, *, profile=PAPER, extensions=EXTENSIONS):
    """The stress-free concentrated-hinge models of the cell with supports, one per extension.

    Returns
    -------
    list of (Structure, LoadGroup)
    """
    row = {"tcrease": tcrease, "tpanel": tpanel, "W": W, "gama": gama}
    models = sheet_models(SETTING, row, profile=profile, extensions=extensions)
    return [(s, groups[0]) for s, groups in models]


SCENARIO = paper_scenario(
    _SHEET,
    name="single-miura",
    description=(
        "Single Miura-ori cell (L = 0.04 m): axial secant stiffness under 3 N at extensions "
        "0.3, 0.6, 0.9 (Zhu & Filipov 2022, data0)."
    ),
    check=check,
)
