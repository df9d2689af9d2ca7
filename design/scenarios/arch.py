"""Scenario 4 of the paper: a Miura-like arch fitted to a half circle (data3).

docs/scenarios.md §5: the strip of :mod:`~holofold.fitting.strip` (m units, offset l_o, side shift
W_s, half-width l_e) fitted to the half circle of radius 2 m, concentrated-hinge model (E = 2 GPa,
nu = 0.3). The two end nodes of each of the three lines are pinned (6 nodes, all DOFs); the apex
(node m) carries -1 N in z (Z case) or +1 N in x (X case) per increment; Newton-Raphson, 5
increments, tol 1e-7 m, at most 29 iterations per increment, the last iterate accepted as in the
reference. ``Zstiff = 5 / |U_z|``, ``Xstiff = 5 / |U_x|`` (N/m) and ``Zsnap = 1`` if ``|U_z| > 1
m``; ``error`` is the index-matched fitting error (m).

A snapping arch has no converged solution at 5 N: its Zstiff is the last (unconverged) iterate,
as in the published data, and ``status`` names the increments that did not converge.
"""

from __future__ import annotations

from functools import lru_cache

from holofold.design.scenarios.base import (
    Column,
    Scenario,
    integer,
    positive,
    single_thread,
)
from holofold.fitting import builtin_curve, index_matched_error, strip_geometry
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.analyses import load_group, secant_stiffness
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.compat import PAPER
from holofold.mechanics.hinges import build_concentrated
from holofold.mechanics.status import Outcome, Status

__all__ = ["SCENARIO", "evaluate", "check", "arch_model", "SNAP_DISPLACEMENT"]

E = 2e9
NU = 0.3
INCREMENTS = 5
TOL = 1e-7
RADIUS = 2.0  #: radius of the target half circle, m
SNAP_DISPLACEMENT = 1.0  #: |U_z| above which the paper flags a snap, m

FEATURES = (
    Column("m", "-", "number of Miura units (even)", choices=(8.0, 12.0, 16.0, 24.0)),
    Column("tcrease", "m", "crease thickness", 0.5e-3, 1.0e-3),
    Column("tpanel", "m", "panel thickness", 1e-3, 6e-3),
    Column("W", "m", "crease width", 1e-3, 4e-3),
    Column("offset", "m", "zigzag offset l_o of the middle vertices", 0.10, 0.30),
    Column("stripeWidth", "m", "side-line shift W_s", 0.01, 0.04),
    Column("extrude", "m", "half-width l_e of the strip", 0.05, 0.25),
)
PERFORMANCE = (
    Column("Zstiff", "N/m", "vertical secant stiffness at the apex under 5 N"),
    Column("Zsnap", "-", "1 if the apex moves more than 1 m under 5 N (snap-through)"),
    Column("Xstiff", "N/m", "horizontal secant stiffness at the apex under 5 N"),
    Column("error", "m", "mean index-matched distance of the centre line to the half circle"),
)


@lru_cache(maxsize=1)
def _curve():
    return builtin_curve("half-circle", radius=RADIUS)


@lru_cache(maxsize=16)
def _topology(m: int) -> CreasePattern:
    """A strip with the right faces, validated once per m (coordinates are replaced per design)."""
    g = strip_geometry(_curve(), m, 0.2, 0.02, 0.15)
    return CreasePattern.from_faces(g.nodes, list(g.faces))


def check(row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    errs = integer(row, "m", 2)
    if not errs and int(row["m"]) % 2:
        errs.append(f"m = {row['m']:g} must be even (the apex must be a centre-line vertex)")
    errs += positive(row, ("tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"))
    return errs


def arch_model(row, *, profile=PAPER):
    """The stress-free model with the arch supports, the apex node and the fitting error.

    Returns
    -------
    structure : Structure
    apex : int
        Loaded node: the strip's apex (node m).
    error : float
        Fitting error e, m.
    """
    m = int(row["m"])
    g = strip_geometry(
        _curve(), m, float(row["offset"]), float(row["stripeWidth"]), float(row["extrude"])
    )
    s = build_concentrated(
        _topology(m),
        coords=g.nodes,
        crease_width=row["W"],
        crease_thickness=row["tcrease"],
        panel_thickness=row["tpanel"],
        E_panel=E,
        E_crease=E,
        nu_panel=NU,
        nu_crease=NU,
        profile=profile,
    ).fixed(g.ends)
    return s, g.apex, index_matched_error(_curve(), g.centre_line, g.t)


def evaluate(row) -> dict:
    """Zstiff, Zsnap, Xstiff (N/m), error (m) and a status."""
    s, apex, err = arch_model(row)
    asm = Assembler(s)  # one sparse pattern and reduction for both load cases
    with single_thread():
        z = secant_stiffness(
            s, load_group([apex], "-z"), increments=INCREMENTS, tol=TOL, assembler=asm
        )
        x = secant_stiffness(
            s, load_group([apex], "+x"), increments=INCREMENTS, tol=TOL, assembler=asm
        )
    snap = z.displacement > SNAP_DISPLACEMENT
    z_case = "Z case (snap-through)" if snap else "Z case"
    cases = {z_case: z.result.status, "X case": x.result.status}
    return {
        "Zstiff": z.stiffness,
        "Zsnap": 1.0 if snap else 0.0,
        "Xstiff": x.stiffness,
        "error": err,
        "status": Status.gather(cases, worst=Outcome.NOT_CONVERGED),
    }


SCENARIO = Scenario(
    name="arch",
    description=(
        "Miura-like arch fitted to a half circle of radius 2 m: apex stiffness in z and x under "
        "5 N, snap flag and fitting error (Zhu & Filipov 2022, data3)."
    ),
    features=FEATURES,
    performance=PERFORMANCE,
    check=check,
    evaluate=evaluate,
    categorical=("m",),
)
