"""Nonlinear static solvers (each returns a path and a status as a :class:`SolveResult`)."""

from mechanics.solvers.displacement import solve_displacement
from mechanics.solvers.mgdcm import solve_mgdcm
from mechanics.solvers.newton import solve_newton
from mechanics.solvers.result import SolveResult
from mechanics.solvers.selffold import solve_selffold

__all__ = ["SolveResult", "solve_newton", "solve_mgdcm", "solve_displacement", "solve_selffold"]
