"""Modified generalised displacement control, MGDCM (docs/bar-and-hinge.md §6.4).

Path following that passes load limit points (snap-through). Each increment:

1. step adaptation: ``lambda_bar`` doubles if the previous increment needed at most 3 solves
   (predictor + 2 correctors) and halves if it needed 14 or more;
2. predictor from the current state (assumed in equilibrium): ``u_p1 = K^-1 F_ref``;
   ``GSP = (u_p1(1) . u_p1(1)) / (u_p1(i) . u_p1(i))`` and the sign rule
   ``sig <- sig * sign(u_p1(i-1) . u_p1(i))``; ``d_lambda = sig * lambda_bar * sqrt(|GSP|)``;
3. corrector (at most ``max_iter - 2`` iterations, until ``||dU||_2 <= tol``):
   ``u_p = K^-1 F_ref``, ``u_r = K^-1 r`` (one factorisation),
   ``d_lambda = -(u_p1(i) . u_r) / (u_p1(i) . u_p)``, ``dU = d_lambda u_p + u_r``.

When the path passes a limit point the tangent loses definiteness, the new predictor turns
against the previous one and ``sig`` flips: the load factor then decreases while the
displacement goes on. The reference starts at ``lambda = 1`` with ``P = F_ref`` (spec quirk 2);
here the default is ``lambda0 = 0`` (the stage starts from equilibrium under ``F0``); pass
``lambda0=1`` to mimic the reference.
"""

from __future__ import annotations

from holofold.geometry.errors import check_range
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.solvers._common import (
    check_controls,
    follow_path,
    get_assembler,
    nodal_array,
)
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.structure import Structure
from holofold.mechanics.threads import single_threaded

__all__ = ["solve_mgdcm"]


@single_threaded
def solve_mgdcm(
    structure: Structure,
    load,
    *,
    increments: int = 50,
    lambda_bar: float = 1.0,
    tol: float = 1e-5,
    max_iter: int = 30,
    U0=None,
    F0=None,
    lambda0: float = 0.0,
    adapt_step: bool = True,
    assembler: Assembler | None = None,
) -> SolveResult:
    """Follow the equilibrium path of ``F0 + lambda * load`` through limit points.

    Parameters
    ----------
    structure : Structure
        The model; supports from ``structure.supports``.
    load : (nn, 3) float
        Reference load F_ref, N (the applied load is ``F0 + lambda * load``).
    increments : int
        Number of path increments (>= 1).
    lambda_bar : float
        Initial load-factor step (> 0); the first increment moves lambda by ``lambda_bar``.
    tol : float
        Convergence tolerance on ``||dU||_2``, m.
    max_iter : int
        Iteration cap per increment, predictor included (at most ``max_iter - 1`` solves).
    U0, F0 : (nn, 3) float, optional
        Starting displacement (m) and previously applied force (N); default 0.
    lambda0 : float
        Load factor at the start (0; the reference uses 1).
    adapt_step : bool
        Double/halve ``lambda_bar`` from the previous increment's iteration count (reference).
    assembler : Assembler, optional
        A prebuilt ``Assembler(structure)``.

    Returns
    -------
    SolveResult
        ``load_factor`` is lambda after each increment.
    """
    asm = get_assembler(structure, assembler)
    increments, tol, max_iter = check_controls(increments, tol, max_iter)
    lambda_bar = check_range("lambda_bar", lambda_bar, 0.0, None, low_open=True)
    lambda0 = check_range("lambda0", lambda0)
    nn = structure.n_nodes
    return follow_path(
        asm,
        nodal_array("load", load, nn),
        increments=increments,
        tol=tol,
        max_iter=max_iter,
        U0=nodal_array("U0", U0, nn),
        F0=nodal_array("F0", F0, nn),
        lambda0=lambda0,
        lambda_bar=lambda_bar,
        adapt=bool(adapt_step),
        control_dof=None,
        control_step=None,
        solver="solve_mgdcm",
    )
