"""Displacement control (docs/bar-and-hinge.md §6.3).

The load ``F0 + lambda * load`` is scaled so that one chosen DOF ``d*`` follows the path; the
corrector keeps ``d*`` fixed (``d_lambda = -u_r[d*] / u_p[d*]``), so the path passes load limit
points as long as ``d*`` itself increases monotonically.

Two predictors:

* ``step`` given (the default use): the controlled DOF moves by exactly ``step`` metres per
  increment (``d_lambda = step / u_p1[d*]``), so after ``n`` increments it has moved by
  ``n * step``;
* ``step=None``: the reference predictor (MGDCM's ``lambda_bar * sqrt(|GSP|)`` with the sign rule,
  no step adaptation); the predictor is then sized in load-factor terms, not in metres.
"""

from __future__ import annotations

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
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

__all__ = ["solve_displacement"]


@single_threaded
def solve_displacement(
    structure: Structure,
    load,
    control: tuple[int, int],
    *,
    increments: int = 50,
    step: float | None = None,
    lambda_bar: float = 1.0,
    tol: float = 1e-5,
    max_iter: int = 30,
    U0=None,
    F0=None,
    lambda0: float = 0.0,
    assembler: Assembler | None = None,
) -> SolveResult:
    """Displacement-controlled loading along ``load``.

    Parameters
    ----------
    structure : Structure
        The model; supports from ``structure.supports``.
    load : (nn, 3) float
        Reference load pattern F_ref, N (applied load ``F0 + lambda * load``).
    control : (node, direction)
        The controlled DOF: node id (0-based) and direction 0, 1, 2 (x, y, z). Must be free.
    increments : int
        Number of increments (>= 1).
    step : float, optional
        Displacement of the controlled DOF per increment, m (non-zero). None: reference
        predictor sized by ``lambda_bar``.
    lambda_bar : float
        Load-factor step of the reference predictor (used when ``step`` is None).
    tol : float
        Convergence tolerance on ``||dU||_2``, m.
    max_iter : int
        Iteration cap per increment, predictor included.
    U0, F0 : (nn, 3) float, optional
        Starting displacement (m) and previously applied force (N); default 0.
    lambda0 : float
        Load factor at the start (0; the reference uses 1).
    assembler : Assembler, optional
        A prebuilt ``Assembler(structure)``.

    Returns
    -------
    SolveResult
        ``load_factor`` is lambda after each increment.
    """
    asm = get_assembler(structure, assembler)
    increments, tol, max_iter = check_controls(increments, tol, max_iter)
    nn = structure.n_nodes
    try:
        node, direction = (int(c) for c in control)
    except (TypeError, ValueError):
        raise ParameterError(f"control must be a (node, direction) pair, got {control!r}") from None
    if not 0 <= node < nn:
        raise ParameterError(f"control node {node} is outside the allowed range [0, {nn - 1}]")
    if direction not in (0, 1, 2):
        raise ParameterError(f"control direction {direction} is outside the allowed range [0, 2]")
    dof = 3 * node + direction
    free = asm.free_dofs
    pos = int(np.searchsorted(free, dof))
    if pos >= free.size or free[pos] != dof:
        raise ParameterError(f"control DOF (node {node}, direction {direction}) is supported")
    if step is not None:
        step = check_range("step", step)
        if step == 0.0:
            raise ParameterError("step must be non-zero")
    lambda_bar = check_range("lambda_bar", lambda_bar, 0.0, None, low_open=True)
    return follow_path(
        asm,
        nodal_array("load", load, nn),
        increments=increments,
        tol=tol,
        max_iter=max_iter,
        U0=nodal_array("U0", U0, nn),
        F0=nodal_array("F0", F0, nn),
        lambda0=check_range("lambda0", lambda0),
        lambda_bar=lambda_bar,
        adapt=False,
        control_dof=pos,
        control_step=step,
        solver="solve_displacement",
    )
