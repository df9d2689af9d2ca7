"""Nonlinear static solvers (each returns a path and a status as a :class:`SolveResult`)."""

from holofold.mechanics.solvers.displacement import solve_displacement
from holofold.mechanics.solvers.mgdcm import solve_mgdcm
from holofold.mechanics.solvers.newton import solve_newton, solve_newton_batch
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.solvers.selffold import solve_selffold

__all__ = [
    "SolveResult",
    "solve_newton",
    "solve_newton_batch",
    "solve_mgdcm",
    "solve_displacement",
    "solve_selffold",
]
