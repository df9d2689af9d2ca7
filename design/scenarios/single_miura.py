"""Scenario 1 of the paper: axial stiffness of a single Miura-ori unit cell (data0).

docs/scenarios.md §2: a 2 x 2 Miura cell of size L = 0.04 m (b = L/2, a = (L - b cot gamma)/2),
concentrated-hinge model (E = 2 GPa, nu = 0.3, panel springs scaled by the crease width), one
stress-free model per extension Ext = 0.3, 0.6, 0.9. The nodes at x = 0 are fixed; the nodes at
x = max carry +x forces of 1 N per increment in total; Newton-Raphson, 3 increments, tol 1e-7 m;
``axialstiffXX = 3 N / mean |U_x|`` of the loaded nodes.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from holofold.design.scenarios.base import Column, Scenario, positive, single_thread
from holofold.geometry.miura import miura_faces, miura_nodes
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.analyses import load_group, secant_stiffness
from holofold.mechanics.compat import PAPER
from holofold.mechanics.hinges import build_concentrated
from holofold.mechanics.status import Outcome, Status

__all__ = ["SCENARIO", "evaluate", "check", "cell_models", "EXTENSIONS", "SIZE", "E", "NU"]

SIZE = 0.04  #: cell size L, m
E = 2e9  #: Young's modulus of panels and creases, Pa
NU = 0.3
EXTENSIONS = (0.3, 0.6, 0.9)
INCREMENTS = 3
TOL = 1e-7

FEATURES = (
    Column("tcrease", "m", "crease thickness", 0.5e-3, 1.0e-3),
    Column("tpanel", "m", "panel thickness", 1e-3, 6e-3),
    Column("W", "m", "crease width", 1e-3, 4e-3),
    Column("gama", "rad", "Miura sector angle gamma", math.radians(50), math.radians(80)),
)
PERFORMANCE = (
    Column("axialstiff30", "N/m", "axial secant stiffness at Ext = 0.3"),
    Column("axialstiff60", "N/m", "axial secant stiffness at Ext = 0.6"),
    Column("axialstiff90", "N/m", "axial secant stiffness at Ext = 0.9"),
)


@lru_cache(maxsize=4)
def _topology(m: int, n: int) -> CreasePattern:
    """A Miura pattern with the right faces (its coordinates are replaced per design)."""
    X = miura_nodes(m, n, 1.0, 1.0, 1.0, 0.5)
    return CreasePattern.from_faces(X, miura_faces(m, n), fold_angle=np.zeros(2 * m * n + m + n))


def check(row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    errs = positive(row, ("tcrease", "tpanel", "W", "gama"))
    g = row.get("gama")
    if g is not None and math.isfinite(g) and not 0 < g < math.pi / 2:
        errs.append(f"gama = {g!r} rad must lie in (0, pi/2)")
    elif g is not None and math.isfinite(g) and 0 < g and 2 * math.tan(g) <= 1:
        errs.append(f"gama = {g!r} rad is too small: the cell needs 2 tan(gama) > 1 (a > 0)")
    return errs


def cell_models(tcrease, tpanel, W, gama, *, profile=PAPER, extensions=EXTENSIONS):
    """The stress-free concentrated-hinge models of the cell with supports, one per extension.

    Returns
    -------
    list of (Structure, LoadGroup)
    """
    m = n = 2
    b = SIZE / m
    a = (SIZE - b / math.tan(gama)) / n
    pattern = _topology(m, n)
    out = []
    for ext in extensions:
        X = miura_nodes(m, n, a, b, gama, ext)
        x = X[:, 0]
        s = build_concentrated(
            pattern,
            coords=X,
            crease_width=W,
            crease_thickness=tcrease,
            panel_thickness=tpanel,
            E_panel=E,
            E_crease=E,
            nu_panel=NU,
            nu_crease=NU,
            profile=profile,
        ).fixed(np.flatnonzero(x == 0.0))  # vertex v is node v
        out.append((s, load_group(np.flatnonzero(x == x.max()), "+x")))
    return out


def evaluate(row) -> dict:
    """Axial stiffness at the three extensions (N/m) and a status."""
    out, cases = {}, {}
    models = cell_models(row["tcrease"], row["tpanel"], row["W"], row["gama"])
    for col, ext, (s, grp) in zip(PERFORMANCE, EXTENSIONS, models, strict=True):
        with single_thread():
            r = secant_stiffness(s, grp, increments=INCREMENTS, tol=TOL)
        out[col.name] = r.stiffness
        cases[f"Ext {ext}"] = r.result.status
    out["status"] = Status.gather(cases, worst=Outcome.NOT_CONVERGED)
    return out


SCENARIO = Scenario(
    name="single-miura",
    description=(
        "Single Miura-ori cell (L = 0.04 m): axial secant stiffness under 3 N at extensions "
        "0.3, 0.6, 0.9 (Zhu & Filipov 2022, data0)."
    ),
    features=FEATURES,
    performance=PERFORMANCE,
    check=check,
    evaluate=evaluate,
)
