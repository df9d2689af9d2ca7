"""Scenario 2 of the paper: bending and axial stiffness of Miura and TMP canopy sheets.

docs/scenarios.md §3 (data1, and data4 in §3.2): a 0.2 m x 0.2 m sheet, Miura-ori (pattern 1,
gamma = 70 deg, b = L/m, a = (L - b cot gamma)/n) or Tachi-Miura polyhedron (pattern 2, m even,
n a multiple of 3), concentrated-hinge model, one stress-free model per extension 0.3, 0.6,
0.9. The nodes at x = min are fixed; the nodes at x = max share 1 N per increment, in -z for
bending and +x for the axial case; Newton-Raphson, 3 increments, tol 1e-7 m; stiffness =
3 N / mean |U| of the loaded nodes. ``creaseE`` and ``panelE`` are optional columns (data4
variant); both default to 2 GPa.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from holofold.design.scenarios.base import (
    Column,
    Scenario,
    integer,
    positive,
    single_thread,
)
from holofold.geometry.miura import miura_faces, miura_nodes
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.tmp import tmp_faces, tmp_nodes
from holofold.mechanics.analyses import load_group, secant_stiffness
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.compat import PAPER
from holofold.mechanics.hinges import build_concentrated
from holofold.mechanics.status import Outcome, Status

__all__ = ["SCENARIO", "evaluate", "check", "sheet_models", "SIZE", "GAMMA", "EXTENSIONS"]

SIZE = 0.2  #: sheet size L, m
GAMMA = 70.0 / 180.0 * math.pi  #: Miura sector angle, rad
E_DEFAULT = 2e9
NU = 0.3
EXTENSIONS = (0.3, 0.6, 0.9)
INCREMENTS = 3
TOL = 1e-7
MIURA, TMP = 1, 2

FEATURES = (
    Column("pattern", "-", "1 = Miura-ori, 2 = TMP", choices=(1.0, 2.0)),
    Column("m", "-", "panels along x (TMP: even)", choices=(24.0, 30.0, 36.0)),
    Column("n", "-", "panels along y (TMP: multiple of 3)", choices=(6.0, 9.0, 12.0)),
    Column("tcrease", "m", "crease thickness", 0.5e-3, 1.0e-3),
    Column("tpanel", "m", "panel thickness", 1e-3, 6e-3),
    Column("W", "m", "crease width", 1e-3, 4e-3),
    Column(
        "creaseE",
        "Pa",
        "crease Young's modulus (data4)",
        1e9,
        5e9,
        required=False,
        default=E_DEFAULT,
    ),
    Column(
        "panelE",
        "Pa",
        "panel Young's modulus (data4)",
        1e9,
        5e9,
        required=False,
        default=E_DEFAULT,
    ),
)
PERFORMANCE = tuple(
    Column(f"{kind}stiff{int(round(100 * e))}", "N/m", f"{label} secant stiffness at Ext = {e}")
    for kind, label in (("bend", "bending (-z)"), ("axial", "axial (+x)"))
    for e in EXTENSIONS
)


@lru_cache(maxsize=32)
def _topology(pattern: int, m: int, n: int) -> CreasePattern:
    """A sheet with the right faces (coordinates are replaced per design)."""
    if pattern == MIURA:
        faces = miura_faces(m, n)
        X = miura_nodes(m, n, 1.0, 1.0, 1.0, 0.5)
    else:
        faces = tmp_faces(m, n)
        X = tmp_nodes(m, n, 1.0, 0.5)
    return CreasePattern.from_faces(X, faces)


def check(row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    errs = positive(row, ("tcrease", "tpanel", "W"))
    for opt in ("creaseE", "panelE"):
        v = row.get(opt)
        if v is not None and not (isinstance(v, float) and math.isnan(v)):
            errs += positive(row, (opt,))
    p = row.get("pattern")
    if p not in (MIURA, TMP):
        errs.append(f"pattern = {p!r} must be 1 (Miura) or 2 (TMP)")
    ok_m = not integer(row, "m", 1)
    errs += integer(row, "m", 1)
    errs += integer(row, "n", 1)
    if p == TMP and ok_m and row["m"] % 2:
        errs.append(f"m = {row['m']:g} must be even for a TMP sheet")
    if p == TMP and not integer(row, "n", 1) and row["n"] % 3:
        errs.append(f"n = {row['n']:g} must be a multiple of 3 for a TMP sheet")
    if p == MIURA and ok_m and not (row["m"] * math.tan(GAMMA) > 1):
        errs.append(f"m = {row['m']:g} is too small for the Miura sheet (m tan(70 deg) > 1)")
    return errs


def sheet_models(row, *, profile=PAPER, extensions=EXTENSIONS):
    """Stress-free models with supports, one per extension.

    Returns
    -------
    list of (Structure, bending LoadGroup, axial LoadGroup)
    """
    pat, m, n = int(row["pattern"]), int(row["m"]), int(row["n"])
    Ec = row.get("creaseE", E_DEFAULT)
    Ep = row.get("panelE", E_DEFAULT)
    Ec = E_DEFAULT if Ec is None or math.isnan(Ec) else Ec
    Ep = E_DEFAULT if Ep is None or math.isnan(Ep) else Ep
    topo = _topology(pat, m, n)
    out = []
    for ext in extensions:
        if pat == MIURA:
            b = SIZE / m
            a = (SIZE - b / math.tan(GAMMA)) / n
            X = miura_nodes(m, n, a, b, GAMMA, ext)
        else:
            X = tmp_nodes(m, n, SIZE, ext)
        x = X[:, 0]
        tip = np.flatnonzero(x == x.max())
        s = build_concentrated(
            topo,
            coords=X,
            crease_width=row["W"],
            crease_thickness=row["tcrease"],
            panel_thickness=row["tpanel"],
            E_panel=Ep,
            E_crease=Ec,
            nu_panel=NU,
            nu_crease=NU,
            profile=profile,
        ).fixed(np.flatnonzero(x == x.min()))  # vertex v is node v
        out.append((s, load_group(tip, "-z"), load_group(tip, "+x")))
    return out


def evaluate(row) -> dict:
    """Bending and axial stiffness at the three extensions (N/m) and a status."""
    out, cases = {}, {}
    models = sheet_models(row)
    for ext, (s, bend, axial) in zip(EXTENSIONS, models, strict=True):
        tag = int(round(100 * ext))
        asm = Assembler(s)  # one sparse pattern and reduction for both load cases
        for kind, grp in (("bend", bend), ("axial", axial)):
            with single_thread():
                r = secant_stiffness(s, grp, increments=INCREMENTS, tol=TOL, assembler=asm)
            out[f"{kind}stiff{tag}"] = r.stiffness
            cases[f"{kind} Ext {ext}"] = r.result.status
    out = {c.name: out[c.name] for c in PERFORMANCE}
    out["status"] = Status.gather(cases, worst=Outcome.NOT_CONVERGED)
    return out


SCENARIO = Scenario(
    name="canopy",
    description=(
        "Miura-ori or TMP canopy sheet (0.2 m x 0.2 m): bending and axial secant stiffness "
        "under 3 N at extensions 0.3, 0.6, 0.9 (Zhu & Filipov 2022, data1; data4 with "
        "creaseE/panelE)."
    ),
    features=FEATURES,
    performance=PERFORMANCE,
    check=check,
    evaluate=evaluate,
    categorical=("pattern", "m", "n"),
)
