"""Shared solver machinery: input checks, path following, status sentences."""

from __future__ import annotations

import logging

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.mechanics.assembly import Assembler, SingularSystemError
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.status import CONVERGED, Status
from holofold.mechanics.structure import Structure

logger = logging.getLogger("holofold.mechanics.solvers")

_MAX_LISTED = 6

#: the smallest displacement change of a loaded increment, as a fraction of the model's size,
#: that can count as converged: below it the displacement is at the round-off of the node
#: coordinates (eps x size = 9e-16 m for a 4 m arch) and a stiffness from it is noise. Measured
#: on an arch (m = 12, 4 m): Zstiff's relative error from round-off is about 10 eps size / |dU|:
#: 1.5e-5 at 1e-10 m, 3.6e-4 at 1e-11 m, 4 % at 1e-13 m, 94 % at 1e-15 m (a force of 1e-14 N,
#: or E = 1e25 Pa under 5 N: Zstiff 1.46e15 N/m whatever E); 1e-10 of the size per increment
#: keeps it under about 2e-5. An absolute tolerance on ||dU|| alone called all of them
#: converged.
RESOLUTION = 1e-10


def model_size(structure: Structure) -> float:
    """The largest extent of the model's nodes along x, y or z, m (> 0)."""
    nodes = np.asarray(structure.nodes, float)
    return float(max(np.ptp(nodes, axis=0).max(), np.abs(nodes).max(), 1e-300))


# ---------------------------------------------------------------------------------- inputs
def get_assembler(structure: Structure, assembler: Assembler | None) -> Assembler:
    if not isinstance(structure, Structure):
        raise TypeError(f"structure must be a mechanics.structure.Structure, got {type(structure)}")
    if assembler is None:
        return Assembler(structure)
    if assembler.structure is not structure:
        raise ParameterError(
            "assembler was built for another Structure; pass Assembler(structure) for this one"
        )
    return assembler


def check_count(name: str, value, low: int) -> int:
    if isinstance(value, bool) or int(value) != value:
        raise ParameterError(f"{name} must be an integer, got {value!r}")
    if int(value) < low:
        raise ParameterError(f"{name} = {value!r} is outside the allowed range [{low}, inf)")
    return int(value)


def check_controls(increments, tol, max_iter) -> tuple[int, float, int]:
    return (
        check_count("increments", increments, 1),
        check_range("tol", tol, 0.0, None, low_open=True),
        check_count("max_iter", max_iter, 2),
    )


def nodal_array(name: str, value, nn: int, default: float = 0.0) -> np.ndarray:
    """A (nn, 3) float array (copy) from ``value`` ((nn, 3), (3 nn,) or None)."""
    if value is None:
        return np.full((nn, 3), default)
    a = np.array(value, dtype=float)
    if a.shape == (3 * nn,):
        a = a.reshape(nn, 3)
    if a.shape != (nn, 3):
        raise ParameterError(f"{name} must have shape ({nn}, 3), got {a.shape}")
    if not np.isfinite(a).all():
        raise ParameterError(f"{name} contains non-finite values")
    return a


def spring_array(name: str, value, ns: int) -> np.ndarray:
    a = np.array(value, dtype=float)
    if a.shape == ():
        a = np.full(ns, float(a))
    if a.shape != (ns,):
        raise ParameterError(f"{name} must have shape ({ns},), got {a.shape}")
    if not np.isfinite(a).all():
        raise ParameterError(f"{name} contains non-finite values")
    return a


# ---------------------------------------------------------------------------------- results
def describe(
    converged, iterations, residual, tol, measure: str, failure: str | None, unresolved=None
) -> Status:
    """The :class:`Status` of a stage: failed (``failure``), not converged (the increments that
    missed ``tol``, up to six listed, and the increments whose displacement is below the
    round-off resolution, ``unresolved``: increment index -> (displacement, resolution), m) or
    converged."""
    unresolved = unresolved or {}
    conv = np.asarray(converged, bool).copy()
    conv[list(unresolved)] = True  # listed on their own below
    bad = np.flatnonzero(~conv)
    reasons = []
    if failure is not None:
        reasons.append(failure)
        bad = bad[:-1]  # the failing increment is described by the failure itself
    if bad.size:
        items = [
            f"increment {b + 1} ({iterations[b]} iterations, {measure} = {residual[b]:.3e} "
            f"> tol {tol:.1e})"
            for b in bad[:_MAX_LISTED]
        ]
        more = f" and {bad.size - _MAX_LISTED} more" if bad.size > _MAX_LISTED else ""
        reasons.append(
            f"{bad.size} of {len(converged)} increments above tol: " + ", ".join(items) + more
        )
    if unresolved:
        (first, (d, floor)), more = next(iter(unresolved.items())), len(unresolved) - 1
        reasons.append(
            f"{len(unresolved)} of {len(converged)} increments at round-off: increment "
            f"{first + 1} moved {d:.2e} m, below the resolution {floor:.1e} m of this model's "
            "size (a load or stiffness out of scale)" + (f" and {more} more" if more else "")
        )
    if failure is not None:
        return Status.failed(*reasons)
    return Status.not_converged(*reasons) if reasons else CONVERGED


class History:
    """Per-increment records collected by a solver loop."""

    def __init__(self, n: int, nn: int):
        self.U = np.empty((n, nn, 3))
        self.lam = np.empty(n)
        self.conv = np.zeros(n, bool)
        self.iters = np.zeros(n, np.int64)
        self.res = np.full(n, np.nan)
        self.count = 0
        self.failure: str | None = None
        self.unresolved: dict[int, tuple[float, float]] = {}

    def check_resolution(self, moved: float, floor: float) -> bool:
        """Whether the increment about to be recorded moved at least ``floor`` (m); if not,
        it is noted and will not count as converged."""
        if moved >= floor:
            return True
        self.unresolved[self.count] = (moved, floor)
        return False

    def record(self, U, lam, conv, iters, res):
        c = self.count
        self.U[c] = U.reshape(-1, 3)
        self.lam[c] = lam
        self.conv[c] = conv
        self.iters[c] = iters
        self.res[c] = res
        self.count += 1

    def result(self, tol, measure, applied_force, spring_rest, solver: str) -> SolveResult:
        c = self.count
        status = describe(
            self.conv[:c], self.iters[:c], self.res[:c], tol, measure, self.failure,
            self.unresolved,
        )  # fmt: skip
        if not status.converged:
            logger.info("%s: %s", solver, status)
        return SolveResult(
            U_history=self.U[:c].copy(),
            load_factor=self.lam[:c].copy(),
            converged=self.conv[:c].copy(),
            iterations=self.iters[:c].copy(),
            residual=self.res[:c].copy(),
            status=status,
            applied_force=np.asarray(applied_force, float).reshape(-1, 3).copy(),
            spring_rest=np.asarray(spring_rest, float).copy(),
        )


# ---------------------------------------------------------------------------------- path following
def follow_path(
    asm: Assembler,
    load: np.ndarray,
    *,
    increments: int,
    tol: float,
    max_iter: int,
    U0: np.ndarray,
    F0: np.ndarray,
    lambda0: float,
    lambda_bar: float,
    adapt: bool,
    control_dof: int | None,
    control_step: float | None,
    solver: str,
) -> SolveResult:
    """Generalised-displacement path following (MGDCM) or displacement control.

    ``control_dof is None``: MGDCM corrector (orthogonal to this increment's predictor).
    Otherwise the corrector keeps ``control_dof`` (an index into the free DOFs) fixed; with
    ``control_step`` the predictor prescribes that DOF's increment, else it is sized like MGDCM.
    """
    structure = asm.structure
    nn = structure.n_nodes
    free = asm.free_dofs
    U = U0.ravel().copy()
    F0v = F0.ravel()
    Fref = load.ravel()
    Fref_f = Fref[free]  # supported entries dropped (the reference zeroes them)
    lam = float(lambda0)
    hist = History(increments, nn)
    up_first = None
    up_prev = None
    sig = 1.0
    last_step = 10
    lbar = float(lambda_bar)
    for i in range(1, increments + 1):
        if adapt:
            if last_step <= 4:
                lbar *= 2.0
            elif last_step >= 15:
                lbar *= 0.5
        step = 1
        R = np.inf
        try:
            # ---- predictor (counts as iteration 1)
            _, _, solve = asm.evaluate_factorized(U)
            up1 = solve(Fref_f)
            if control_step is not None:
                if up1[control_dof] == 0.0:
                    raise SingularSystemError(
                        "the load does not move the controlled DOF (zero predictor component)"
                    )
                dlam = control_step / up1[control_dof]
            else:
                if up_first is None or not np.any(up_first):
                    gsp = 1.0
                    sig = 1.0
                else:
                    gsp = float(up_first @ up_first) / float(up1 @ up1)
                    sig = float(np.sign(up_prev @ up1)) * sig
                dlam = sig * lbar * np.sqrt(abs(gsp))
            if not np.isfinite(dlam):
                raise SingularSystemError("non-finite predictor load step")
            if up_first is None:
                up_first = up1
            up_prev = up1
            lam += dlam
            dU = dlam * up1
            U[free] += dU
            R = float(np.linalg.norm(dU))
            step = 2
            last_step = step
            # ---- corrector
            while step < max_iter and R > tol:
                _, f, solve = asm.evaluate_factorized(U)
                r = (F0v + lam * Fref - f)[free]
                sol = solve(np.column_stack([Fref_f, r]))
                up, ur = sol[:, 0], sol[:, 1]
                if control_dof is None:
                    dlam = -float(up1 @ ur) / float(up1 @ up)
                else:
                    dlam = -ur[control_dof] / up[control_dof]
                if not np.isfinite(dlam):
                    raise SingularSystemError("non-finite load-factor correction")
                lam += dlam
                dU = dlam * up + ur
                U[free] += dU
                R = float(np.linalg.norm(dU))
                step += 1
                last_step = step
        except SingularSystemError as exc:
            hist.failure = f"increment {i}, iteration {step}: {exc}"
            hist.record(U, lam, False, step - 1, R)
            break
        hist.record(U, lam, R <= tol, step - 1, R)
    applied = F0v + lam * Fref
    return hist.result(tol, "||dU||", applied, structure.spring_rest, solver)
