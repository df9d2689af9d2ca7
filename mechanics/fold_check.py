"""The honest fold: a fitted surface pattern folded from flat by the bar-and-hinge simulator.

:func:`check_fold` builds the concentrated-hinge model (docs/bar-and-hinge.md §3) of the fit's
*flat* crease pattern, stress free when flat, fixes the four corners of its central panel and
drives every spring's rest angle linearly from flat to the dihedral angle it has in the fitted
folded state (:func:`~holofold.mechanics.solvers.solve_selffold`). The fitted state is stress
free for those rest angles only if its quads are planar and its flat pattern is its exact
development, so the simulation reaches it only if the fit is a true rigidly foldable pattern and
the simulator can follow the fold from flat. The simulated shape is aligned to the fitted one
(rotation and translation, Kabsch) and their largest vertex distance is compared with a stated
tolerance; a fold that does not converge, stops, or ends farther away is reported as failed with
the reason, and one that runs over its time budget as not verified (docs/surface-fit.md §4).

The rigid-folding path is smooth, so the fold takes steps of up to :data:`FOLD_STEP_DEG` of
rest angle, each started from the secant extrapolation of the last two states (``fold_pattern``'s
``extrapolate``): 7 steps of about 4-5 Newton iterations instead of 45 steps of 9-10 at 3 deg
(docs/surface-fit.md §6 has the times).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import check_range
from holofold.mechanics.folding import fold_pattern

__all__ = [
    "FoldCheck",
    "check_fold",
    "aligned_deviation",
    "FOLD_TOLERANCE",
    "FOLD_STEP_DEG",
    "FOLD_TIME_LIMIT",
]

#: the largest vertex distance (relative to the target's size) between the simulated and the
#: fitted folded state for a fit to count as folded
FOLD_TOLERANCE = 1e-3
#: the largest rest-angle change per actuation step of the check, degrees (a step that does not
#: converge is retried at half the size, down to 1/16)
FOLD_STEP_DEG = 20.0
#: wall seconds the check's fold may take before it stops and reports the fit not verified
FOLD_TIME_LIMIT = 600.0


@dataclass(frozen=True, eq=False)
class FoldCheck:
    """Outcome of folding a fitted pattern from flat by simulation.

    ``reached`` is True when the solver converged at every increment and the simulated shape
    lies within ``tolerance`` (m) of the fitted one everywhere. ``deviation_rms`` and
    ``deviation_max`` are vertex distances after the best rigid alignment (m); ``coords``
    (nv, 3) the simulated vertices so aligned; ``reason`` says why a check failed, ``verdict``
    is :func:`~holofold.mechanics.folding.fold_pattern`'s, ``steps`` its actuation steps.
    ``timed_out`` is True when the fold ran over its time budget: the fit is then not verified
    (neither folded nor shown not to fold).
    """

    reached: bool
    deviation_rms: float
    deviation_max: float
    tolerance: float
    reason: str
    verdict: str
    steps: int
    seconds: float
    coords: np.ndarray
    timed_out: bool = False

    @property
    def summary(self) -> dict:
        return {
            "fold_reached": self.reached,
            "fold_deviation_rms": self.deviation_rms,
            "fold_deviation_max": self.deviation_max,
            "fold_tolerance": self.tolerance,
            "fold_reason": self.reason,
            "fold_verdict": self.verdict,
            "fold_seconds": self.seconds,
            "fold_timed_out": self.timed_out,
        }


def _kabsch(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """A (k, 3) moved by the rotation and translation that bring it closest to B."""
    ca, cb = A.mean(axis=0), B.mean(axis=0)
    U, _, Vt = np.linalg.svd((A - ca).T @ (B - cb))
    d = np.sign(np.linalg.det(U @ Vt))
    R = U @ np.diag([1.0, 1.0, d]) @ Vt
    return (A - ca) @ R + cb


def aligned_deviation(simulated, fitted) -> np.ndarray:
    """(nv,) distances (m) between the vertices ``simulated`` (nv, 3) moved by the rotation and
    translation that bring them closest to ``fitted`` (nv, 3), and ``fitted``."""
    A = np.asarray(simulated, float)
    B = np.asarray(fitted, float)
    return np.linalg.norm(_kabsch(A, B) - B, axis=1)


def check_fold(
    fit,
    *,
    tolerance: float = FOLD_TOLERANCE,
    panel_thickness: float | None = None,
    crease_thickness: float | None = None,
    crease_width: float | None = None,
    E: float = 2e9,
    max_iter: int = 30,
    max_step_deg: float = FOLD_STEP_DEG,
    extrapolate: bool = True,
    time_limit: float | None = FOLD_TIME_LIMIT,
) -> FoldCheck:
    """Fold ``fit`` (a :class:`~holofold.fitting.SurfaceFit`) from flat by simulation.

    Thicknesses and crease width (m) default to fractions of the mean panel edge h: panels
    h / 20, creases a quarter of that, crease width h / 10 (stiff panels, soft creases: only
    the ratios matter to the shape, the fitted state being stress free). ``tolerance`` is
    relative to the target's size. ``max_step_deg`` is the largest rest-angle change per
    actuation step (a step that does not converge is retried at half the size), ``extrapolate``
    starts each step from the secant extrapolation of the last two states. ``time_limit``
    (wall s, None: none) bounds the fold's steps: a fold still under way then is reported as
    not verified (``timed_out``), with how far it got.
    """
    t0 = time.perf_counter()
    tolerance = check_range("tolerance", tolerance, 0.0, None, low_open=True)
    pattern = fit.pattern
    h = float(np.mean(pattern.flat_edge_lengths))
    tp = h / 20 if panel_thickness is None else panel_thickness
    tc = tp / 4 if crease_thickness is None else crease_thickness
    W = h / 10 if crease_width is None else crease_width
    if time_limit is not None:
        time_limit = check_range("time_limit", time_limit, 0.0, None, low_open=True)
    t_fold = time.perf_counter()
    res = fold_pattern(pattern, 1.0, panel_thickness=tp, crease_thickness=tc, crease_width=W,
                       E=E, max_iter=max_iter, max_step_deg=max_step_deg,
                       extrapolate=extrapolate, time_limit=time_limit)  # fmt: skip
    size = fit.target.size
    tol_m = tolerance * size
    final = res.coords[-1]
    steps = len(res.fractions) - 1
    if not np.isfinite(final).all():
        return FoldCheck(False, np.inf, np.inf, tol_m, "the simulation diverged (non-finite "
                         "positions)", str(res.status), steps, time.perf_counter() - t0,
                         final)  # fmt: skip
    aligned = _kabsch(final, fit.coords)
    d = np.linalg.norm(aligned - fit.coords, axis=1)
    rms, mx = float(np.sqrt(np.mean(d**2))), float(d.max())
    timed_out = bool(
        time_limit is not None
        and res.fractions[-1] < 1.0
        and time.perf_counter() - t_fold >= time_limit
    )
    if timed_out:
        reason = (f"not verified: the fold ran over its time limit of {time_limit:g} s at "
                  f"{100 * res.fractions[-1]:.3g} % (a larger time_limit, or the optional "
                  "sparse Cholesky: pip install 'holofold[cholmod]')")  # fmt: skip
    elif res.fractions[-1] < 1.0 or not res.status.converged:
        reason = (f"the simulation reached {100 * res.fractions[-1]:.3g} % of the fold: "
                  f"{res.verdict} ({res.note}; {res.status})")  # fmt: skip
    elif mx > tol_m:
        reason = (f"the simulated shape ends {mx:.3g} m ({mx / size:.3g} of the target's size) "
                  f"from the fitted one, more than the tolerance {tolerance:g} ({res.verdict}: "
                  f"{res.note})")  # fmt: skip
    else:
        reason = ""
    return FoldCheck(not reason, rms, mx, tol_m, reason, f"{res.verdict}: {res.note}", steps,
                     time.perf_counter() - t0, aligned, timed_out)  # fmt: skip
