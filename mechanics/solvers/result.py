"""The result of a nonlinear static solve: the path, per-increment convergence and a status."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.mechanics.status import Status

__all__ = ["SolveResult"]


@dataclass(frozen=True, eq=False)
class SolveResult:
    """Load-displacement history of one solver stage.

    Attributes
    ----------
    U_history : (n_inc, nn, 3) float
        Total displacement after each increment (includes the starting ``U0``), m.
    load_factor : (n_inc,) float
        Load factor after each increment (Newton: the increment index; MGDCM/displacement
        control: lambda; self-folding: the fraction of the rest-angle change applied).
    converged : (n_inc,) bool
        Whether each increment met the tolerance.
    iterations : (n_inc,) int
        Linear solves made in each increment (MGDCM/DC count the predictor).
    residual : (n_inc,) float
        Last convergence measure of each increment (``||dU||_2`` in m for the loading solvers,
        ``||r||_2`` in N for self-folding).
    status : Status
        Converged; not converged, naming the increments that missed the tolerance; or failed
        (the stage stopped early on a singular or non-finite system: the histories then end at
        the failing increment).
    applied_force : (nn, 3) float
        Total external force at the end of the stage (start force + final load), N.
    spring_rest : (ns,) float
        Spring rest angles at the end of the stage, rad.

    A stage whose increments exceed the iteration cap is not an error: like the reference
    simulator it accepts the last iterate and goes on; ``converged``/``status`` record it.
    """

    U_history: np.ndarray
    load_factor: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    status: Status
    applied_force: np.ndarray
    spring_rest: np.ndarray

    @property
    def ok(self) -> bool:
        """True if every increment converged and nothing failed."""
        return self.status.converged

    @property
    def failed(self) -> bool:
        """True if the stage stopped early (singular or non-finite system)."""
        return self.status.is_failed

    @property
    def U(self) -> np.ndarray:
        """(nn, 3) float: displacement at the end of the stage, m."""
        return self.U_history[-1]

    @property
    def n_increments(self) -> int:
        return len(self.load_factor)
