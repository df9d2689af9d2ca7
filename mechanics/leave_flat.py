"""Pseudo-transient flow to an equilibrium: off flat along the folding force, or past a stall.

A flat crease pattern is a singular point of the rest-angle fold: every crease is at 180
degrees, the panels' out-of-plane stiffness is zero to first order, and Newton's method from
there lands on whichever of the exponentially many branches its first linear solve points to.
Origami Simulator never picks a branch either: its explicit dynamics simply follow the folding
force, which at flat pushes every crease towards its assigned side.

:func:`leave_flat` does the same with an implicit gradient flow (pseudo-transient continuation,
Kelley and Keyes 1998): from ``U`` it takes steps ``(K + D / dt) dU = -f`` with ``D`` the
diagonal of the tangent (a lumped "mass" that keeps the in-plane bar directions stiff) and a
pseudo time step ``dt`` that starts small (a short step along the force, the branch chosen by
the force and not by the sign of a singular tangent) and grows as the flow proceeds (switched
evolution relaxation), until the residual meets the tolerance, at which point the step is
Newton's. A step that raises both the energy and the residual is taken again with ``dt`` / 4.

Measured (docs/patterns.md, "Leaving flat"): from the flat crane and flapping bird this flow
reaches the same first equilibrium as Newton (the least-squares, first-order branch), with the
same creases on the wrong side, so :func:`fold_pattern` does not use it to leave flat; it is
the fallback of :func:`~holofold.mechanics.folding.fold_pattern` where Newton and the
Levenberg-Marquardt relaxation both stall (:func:`flow_to_equilibrium`).

All arrays are SI (m, N, rad); angles passed in and reported are degrees (FOLD sign).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["FlowResult", "flow_to_equilibrium", "on_assigned_side", "LEAVE_DEG"]

#: a driven crease has left flat on its side once it stands this far from flat, degrees
LEAVE_DEG = 0.05


@dataclass(frozen=True)
class FlowResult:
    """The end of a pseudo-transient flow.

    Attributes
    ----------
    U : (nn, 3) float
        Node displacements at the end, m.
    converged : bool
        The residual met the tolerance (an equilibrium).
    residual : float
        Its norm at the end, N.
    steps : int
        Linear solves taken.
    """

    U: np.ndarray
    converged: bool
    residual: float
    steps: int


def on_assigned_side(angles: np.ndarray, target: np.ndarray, min_deg: float = LEAVE_DEG):
    """(ne,) bool: driven creases (``target != 0``) that stand at least ``min_deg`` degrees on
    the side of their target (``angles``, ``target`` (ne,) degrees, FOLD sign); True for every
    other edge."""
    t = np.asarray(target, float)
    a = np.asarray(angles, float)
    return (t == 0) | (np.sign(a) == np.sign(t)) & (np.abs(a) >= min_deg)


def flow_to_equilibrium(
    asm,
    U,
    rest: np.ndarray,
    tol: float,
    *,
    dt0: float = 1e-3,
    max_steps: int = 400,
    time_limit: float | None = None,
    stop=None,
    max_dt: float = math.inf,
) -> FlowResult:
    """Pseudo-transient continuation from ``U`` (nn, 3) m to an equilibrium at spring rest
    angles ``rest`` (ns,) rad: ``(K + D / dt) dU = -f`` on the free DOFs, ``D`` the diagonal
    of the tangent at the start (floored at 1e-9 of its largest entry), ``dt`` starting at
    ``dt0`` (dimensionless: relative to ``D``), grown after a step that lowers the energy or
    the residual by ``|r_old| / |r_new|`` clipped to [2, 10], cut by 4 after one that does not.
    Stops when ``|r| <= tol`` (N), after ``max_steps`` solves or ``time_limit`` seconds."""
    import time

    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    started = time.perf_counter()
    free = asm.free_dofs
    U = np.asarray(U, float).copy().ravel()
    E, f, K = asm.evaluate_reduced(U, rest, dense=False)
    r = -f[free]
    d = np.abs(K.diagonal())
    D = np.maximum(d, 1e-9 * d.max(initial=1.0))
    dt = dt0
    norm = math.sqrt(r @ r)
    steps = 0
    while steps < max_steps:
        if norm <= tol:
            return FlowResult(U.reshape(-1, 3), True, norm, steps)
        if time_limit is not None and time.perf_counter() - started > time_limit:
            break
        steps += 1
        try:
            dU = splu((K + sp.diags(D / dt)).tocsc()).solve(r)
        except RuntimeError:  # singular: a shorter pseudo time step
            dt *= 0.25
            continue
        trial = U.copy()
        trial[free] += dU
        E_t, f_t, K_t = asm.evaluate_reduced(trial, rest, dense=False)
        r_t = -f_t[free]
        n_t = math.sqrt(r_t @ r_t)
        lower = E_t <= E + 1e-12 * abs(E) or n_t < norm  # energy or residual falls
        if np.isfinite(E_t) and np.isfinite(n_t) and lower:
            dt = min(max_dt, dt * min(10.0, max(norm / max(n_t, 1e-300), 2.0)))
            U, E, K, r, norm = trial, E_t, K_t, r_t, n_t
            if stop is not None and stop(U.reshape(-1, 3)):
                return FlowResult(U.reshape(-1, 3), norm <= tol, norm, steps)
        else:
            dt *= 0.25
            if dt < 1e-14:
                break
    return FlowResult(U.reshape(-1, 3), norm <= tol, norm, steps)
