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
the reason (docs/surface-fit.md §6).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import check_range
from holofold.mechanics.folding import fold_pattern

__all__ = ["FoldCheck", "check_fold", "aligned_deviation", "FOLD_TOLERANCE"]

#: the largest vertex distance (relative to the target's size) between the simulated and the
#: fitted folded state for a fit to count as folded
FOLD_TOLERANCE = 1e-3


@dataclass(frozen=True, eq=False)
class FoldCheck:
    """Outcome of folding a fitted pattern from flat by simulation.

    ``reached`` is True when the solver converged at every increment and the simulated shape
    lies within ``tolerance`` (m) of the fitted one everywhere. ``deviation_rms`` and
    ``deviation_max`` are vertex distances after the best rigid alignment (m); ``coords``
    (nv, 3) the simulated vertices so aligned; ``reason`` says why a check failed, ``verdict``
    is :func:`~holofold.mechanics.folding.fold_pattern`'s, ``steps`` its actuation steps.
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
    max_step_deg: float = 3.0,
) -> FoldCheck:
    """Fold ``fit`` (a :class:`~holofold.fitting.SurfaceFit`) from flat by simulation.

    Thicknesses and crease width (m) default to fractions of the mean panel edge h: panels
    h / 20, creases a quarter of that, crease width h / 10 (stiff panels, soft creases: only
    the ratios matter to the shape, the fitted state being stress free). ``tolerance`` is
    relative to the target's size. ``max_step_deg`` is the largest rest-angle change per
    actuation step (a step that does not converge is retried at half the size).
    """
    t0 = time.perf_counter()
    tolerance = check_range("tolerance", tolerance, 0.0, None, low_open=True)
    pattern = fit.pattern
    h = float(np.mean(pattern.flat_edge_lengths))
    tp = h / 20 if panel_thickness is None else panel_thickness
    tc = tp / 4 if crease_thickness is None else crease_thickness
    W = h / 10 if crease_width is None else crease_width
    res = fold_pattern(pattern, 1.0, panel_thickness=tp, crease_thickness=tc, crease_width=W,
                       E=E, max_iter=max_iter, max_step_deg=max_step_deg)  # fmt: skip
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
    if res.fractions[-1] < 1.0 or not res.status.converged:
        reason = (f"the simulation reached {100 * res.fractions[-1]:.3g} % of the fold: "
                  f"{res.verdict} ({res.note}; {res.status})")  # fmt: skip
    elif mx > tol_m:
        reason = (f"the simulated shape ends {mx:.3g} m ({mx / size:.3g} of the target's size) "
                  f"from the fitted one, more than the tolerance {tolerance:g} ({res.verdict}: "
                  f"{res.note})")  # fmt: skip
    else:
        reason = ""
    return FoldCheck(not reason, rms, mx, tol_m, reason, f"{res.verdict}: {res.note}", steps,
                     time.perf_counter() - t0, aligned)  # fmt: skip
