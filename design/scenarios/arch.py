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

from holofold.design.scenarios.base import paper_scenario
from holofold.design.scenarios.strip import (
    STRIP_FEATURES,
    StripLoad,
    StripSetting,
    check_strip,
    strip_model,
    strip_scenario,
)
from holofold.fitting import builtin_curve
from holofold.mechanics.compat import PAPER

__all__ = ["SCENARIO", "SETTING", "evaluate", "check", "arch_model", "SNAP_DISPLACEMENT"]

E = 2e9
NU = 0.3
INCREMENTS = 5
TOL = 1e-7
RADIUS = 2.0  #: radius of the target half circle, m
SNAP_DISPLACEMENT = 1.0  #: |U_z| above which the paper flags a snap, m

#: the paper's arch as a strip setting (the shipped ``arch.toml`` says the same)
SETTING = StripSetting(
    curve=builtin_curve("half-circle", radius=RADIUS),
    loads=(
        StripLoad("Z", 0.5, (0.0, 0.0, -1.0), 5.0, INCREMENTS, SNAP_DISPLACEMENT),
        StripLoad("X", 0.5, (1.0, 0.0, 0.0), 5.0, INCREMENTS),
    ),
    E=E,
    nu=NU,
    tol=TOL,
    # a self-overlapping strip is a failed row (it gave a 'converged' stiffness 200-3000x the
    # normal one); none of the 3000 published rows overlaps, so every published number holds
    curve_label="half circle, radius 2 m",
)
FEATURES = STRIP_FEATURES


def check(row) -> list[str]:
    """Physical validity of one design (empty if valid): the strip's, and an even m."""
    errs = check_strip(SETTING, row)
    if not errs and int(row["m"]) % 2:
        errs.append(f"m = {row['m']:g} must be even (the apex must be a centre-line vertex)")
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
    s, g, err = strip_model(SETTING, row, profile=profile)
    return s, g.apex, err


_STRIP = strip_scenario("arch", "", SETTING, FEATURES, extras=False)
#: Zstiff, Zsnap, Xstiff (N/m), error (m) and a status
evaluate = _STRIP.evaluate

SCENARIO = paper_scenario(
    _STRIP,  # its write_files: the same seven files as the shipped arch.toml
    name="arch",
    description=(
        "Miura-like arch fitted to a half circle of radius 2 m: apex stiffness in z and x under "
        "5 N, snap flag and fitting error (Zhu & Filipov 2022, data3)."
    ),
    check=check,
    categorical=("m",),
)
