"""A generalised Miura-ori fitted to a target surface (docs/surface-fit.md).

:func:`fit_surface` lays an m x n Miura-ori over a chart of the target (the starting tiling: its
even rows of vertices on the surface, the odd rows offset along the normal by the Miura's
height), then solves for the folded vertex positions X (nv, 3):

    minimise   sum over the side vertices (n . (x - foot))^2 + w_f^2 |fairness|^2 + anchor
    subject to every quad planar, angle sum 2 pi and Kawasaki at every interior vertex

by Gauss-Newton sequential quadratic programming with analytic Jacobians: a restoration phase
(Newton steps onto the constraints from the tiling, which also take the distance's Gauss-Newton
model while the constraints are far from met) then feasible Gauss-Newton steps, each with
second-order corrections back onto the constraints, damped Levenberg-Marquardt style. Each
linear step is a saddle-point (KKT) system, solved by MINRES preconditioned with the augmented
Lagrangian block ``J_s^T J_s + mu I + rho J_c^T J_c`` (a banded Cholesky factorisation, reused
while it keeps MINRES short) and ``I / rho``. The result carries its flat crease pattern (the
exact development of the folded quads), a :class:`~holofold.geometry.pattern.CreasePattern` with
M/V assignments and fold angles, the distances of the fitted side to the target and every
constraint's residual.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from holofold.fitting.quadmesh import (
    QuadGrid,
    SparsePattern,
    constraints,
    develop,
    planarity_scale,
    quad_warp,
    sector_angles,
    vertex_conditions,
)
from holofold.fitting.spd_factor import SPDFactor
from holofold.fitting.surfaces import TargetSurface, load_surface
from holofold.geometry.errors import DegenerateGeometryError, ParameterError, check_range
from holofold.geometry.miura import check_count, miura_nodes
from holofold.geometry.pattern import MAX_PANELS, CreasePattern
from holofold.geometry.units import length_factor

__all__ = [
    "CONSTRAINT_TOL",
    "Placement",
    "SurfaceFit",
    "SurfaceFitError",
    "fit_surface",
    "starting_tiling",
]

#: constraint residual (rad, and relative warp) a fit must reach
CONSTRAINT_TOL = 1e-9
#: the smallest sector angle (and its supplement) a fitted panel may have, degrees
MIN_SECTOR_DEG = 5.0
#: restoration dampings tried in turn (the next only when the last cannot meet the constraints)
RESTORATION_DAMPING = (1e-2, 1.0, 100.0)
#: augmented-Lagrangian weight of the preconditioner (dimensionless units)
_RHO = 1e6
#: first Levenberg-Marquardt damping of the Gauss-Newton phase (the first step was never taken
#: at less than 1e-2 in the benchmark's 4 to 4096 panels: every smaller try cost a
#: factorisation in vain)
_MU_START = 1e-2
#: MINRES tolerances (relative): the Gauss-Newton step, and the Newton steps onto the
#: constraints (restoration and second-order corrections: each is checked on the constraints
#: themselves, and repeated while they exceed CONSTRAINT_TOL)
_TOL_STEP = 1e-9
_TOL_PROJECT = 1e-6
#: the restoration's Newton steps also take the Gauss-Newton model of the distance (SQP steps
#: from an infeasible point) while the largest constraint residual is above this (rad), then
#: only the constraints: at 4096 panels the restored cap's RMS falls from 1.56e-4 to 8.7e-5
#: (6 factorisations instead of 5), and the Gauss-Newton phase after it has little to do
_SQP_UNTIL = 1e-4
#: the restoration's aim once the constraints are met (CONSTRAINT_TOL), by chord steps only
_TOL_AIM = 1e-10


class SurfaceFitError(DegenerateGeometryError):
    """A fit that cannot be made (a placement off the chart, constraints that cannot be met)."""


@dataclass(frozen=True)
class Placement:
    """Where the pattern sits on the target's chart.

    ``centre`` (u, v) m, default the chart's centre; ``size`` (Lu, Lv) m, the folded footprint
    of the starting tiling along the pattern's i and j directions, default the chart's extent;
    ``angle`` rad, the i direction's angle from the chart's u axis.
    """

    centre: tuple[float, float] | None = None
    size: tuple[float, float] | None = None
    angle: float = 0.0

    def resolved(self, surface: TargetSurface) -> tuple[np.ndarray, np.ndarray, float]:
        u0, u1, v0, v1 = surface.domain
        c = np.array([(u0 + u1) / 2, (v0 + v1) / 2] if self.centre is None else self.centre, float)
        s = np.array([u1 - u0, v1 - v0] if self.size is None else self.size, float)
        if c.shape != (2,) or s.shape != (2,) or not np.isfinite(np.r_[c, s]).all():
            raise ParameterError(f"placement centre and size must be two finite numbers each, "
                                 f"got {self.centre!r}, {self.size!r}")  # fmt: skip
        if (s <= 0).any():
            raise ParameterError(f"placement size must be > 0, got {s.tolist()}")
        check_range("placement angle", self.angle, -2 * math.pi, 2 * math.pi)
        return c, s, float(self.angle)


@dataclass(frozen=True, eq=False, repr=False)
class SurfaceFit:
    """A generalised Miura-ori fitted to a target surface.

    Attributes
    ----------
    target : TargetSurface
    m, n : int
        Quads along i (the zig-zag direction) and along j.
    coords : (nv, 3) float
        Folded vertex positions, m.
    flat : (nv, 2) float
        The flat crease pattern, m (every quad counter-clockwise).
    side : (k,) int
        Vertex ids of the fitted side (rows j = 0, 2, ...).
    distance : (k,) float
        Signed distances of the side vertices to the target, m.
    residuals : dict
        Largest planarity warp (diagonal distance / mean diagonal), angle-sum and Kawasaki
        residuals (rad), development mismatch (largest relative edge-length difference
        between the flat and the folded pattern).
    ok : bool
        The constraints are met to :data:`CONSTRAINT_TOL`: the pattern is a generalised
        Miura-ori (planar quads, developable and flat-foldable vertices).
    message : str
        How the solve ended.
    iterations : int
    seconds : float
        Time to fit.
    options : dict
        The fit's inputs (gamma, ext, side, placement, fairness).
    """

    target: TargetSurface
    m: int
    n: int
    coords: np.ndarray
    flat: np.ndarray
    side: np.ndarray
    distance: np.ndarray
    residuals: dict
    ok: bool
    message: str
    iterations: int
    seconds: float
    options: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        return (f"SurfaceFit({self.target.name!r}, {self.m}x{self.n}, rms={self.rms:.4g} m, "
                f"max={self.max:.4g} m, ok={self.ok})")  # fmt: skip

    @property
    def grid(self) -> QuadGrid:
        return QuadGrid(self.m, self.n)

    @property
    def n_panels(self) -> int:
        return self.m * self.n

    @property
    def rms(self) -> float:
        """RMS distance of the fitted side to the target, m."""
        return float(np.sqrt(np.mean(self.distance**2)))

    @property
    def max(self) -> float:
        """Largest distance of the fitted side to the target, m."""
        return float(np.abs(self.distance).max())

    @property
    def flat_size(self) -> tuple[float, float]:
        """Width and height of the flat pattern's bounding box, m."""
        w, h = np.ptp(self.flat, axis=0)
        return float(w), float(h)

    @cached_property
    def pattern(self) -> CreasePattern:
        """The crease pattern: folded ``coords``, ``flat`` layout, M/V and fold angles (FOLD
        convention) measured on the folded state."""
        return CreasePattern.from_faces(
            self.coords,
            list(self.grid.quads),
            flat=self.flat,
            meta={
                "kind": "surface-fit",
                "generator": "holofold.fitting.fit_surface",
                "target": self.target.name,
                "target_params": _plain(self.target.params),
                "m": self.m,
                "n": self.n,
            },
        )

    @property
    def errors(self) -> dict[str, float]:
        """Distances (m, relative to the target's size, and in the target file's units), the
        constraint residuals and the flat pattern's size (m)."""
        size = self.target.size
        per = length_factor(self.target.units)
        w, h = self.flat_size
        return {
            "rms_error": self.rms,
            "max_error": self.max,
            "rms_error_rel": self.rms / size,
            "max_error_rel": self.max / size,
            f"rms_error_{self.target.units}": self.rms / per,
            f"max_error_{self.target.units}": self.max / per,
            "target_size": size,
            **self.residuals,
            "flat_width": w,
            "flat_height": h,
        }

    @property
    def summary(self) -> dict:
        """Inputs, errors and solve statistics as plain JSON-ready values."""
        return {
            "target": self.target.name,
            "target_params": _plain(self.target.params),
            "units": self.target.units,
            "m": self.m,
            "n": self.n,
            "panels": self.n_panels,
            **_plain(self.options),
            **self.errors,
            "ok": self.ok,
            "message": self.message,
            "iterations": self.iterations,
            "seconds": self.seconds,
        }


def _plain(d):
    if isinstance(d, dict):
        return {str(k): _plain(v) for k, v in d.items()}
    if isinstance(d, (list, tuple, np.ndarray)):
        return (
            [_plain(v) for v in np.asarray(d).tolist()]
            if isinstance(d, np.ndarray)
            else [_plain(v) for v in d]
        )
    if isinstance(d, (np.floating, np.integer)):
        return d.item()
    return d


# ---------------------------------------------------------------------------- tiling
def starting_tiling(target: TargetSurface, m: int, n: int, placement: Placement, gamma: float,
                    ext: float, side: str) -> np.ndarray:  # fmt: skip
    """The starting folded state (nv, 3) m: a uniform Miura-ori (sector angle ``gamma``,
    extension ``ext``) laid on the target's chart, even rows on the surface, odd rows offset
    along the normal by the Miura's height (``side`` "below" or "above" the target)."""
    c, s, angle = placement.resolved(target)
    theta = math.asin(ext * math.sin(gamma))
    beta = math.acos(min(1.0, max(-1.0, math.cos(gamma) / math.cos(theta))))
    b = s[0] / (m * math.sin(theta))
    a = (s[1] - b * math.cos(theta)) / (n * math.cos(beta))
    if not a > 0:
        raise ParameterError(
            f"placement size {s.tolist()} m is too short along j for {n} rows at gamma = "
            f"{math.degrees(gamma):.4g} deg, ext = {ext:g}: enlarge it or lower ext"
        )
    L = miura_nodes(m, n, a, b, gamma, ext)
    L[:, :2] -= 0.5 * (L[:, :2].min(axis=0) + L[:, :2].max(axis=0))
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    uv = c + L[:, :2] @ rot.T
    u0, u1, v0, v1 = target.domain
    tol = 1e-9 * max(u1 - u0, v1 - v0)
    out = (
        (uv[:, 0] < u0 - tol)
        | (uv[:, 0] > u1 + tol)
        | (uv[:, 1] < v0 - tol)
        | (uv[:, 1] > v1 + tol)
    )
    if out.any():
        raise ParameterError(
            f"the pattern ({np.ptp(uv[:, 0]):.4g} x {np.ptp(uv[:, 1]):.4g} m at centre "
            f"{c.tolist()}) leaves the target's chart [{u0:.4g}, {u1:.4g}] x [{v0:.4g}, {v1:.4g}] "
            f"m: a smaller placement size or another centre"
        )
    S, N = target.chart(uv[:, 0], uv[:, 1])
    sign = -1.0 if side == "below" else 1.0
    return S + sign * L[:, 2:3] * N


# ---------------------------------------------------------------------------- the solver
class _Problem:
    """Residuals and Jacobians of one fit in dimensionless units (lengths over ``h``)."""

    def __init__(self, grid: QuadGrid, target: TargetSurface, X0: np.ndarray, fairness: float):
        self.grid = grid
        self.target = target
        self.X0 = X0
        self.scale = planarity_scale(X0, grid.quads)
        P = X0[grid.quads]
        self.h = float(np.sqrt(np.mean(np.sum((P[:, 2] - P[:, 0]) ** 2, axis=1))))
        self.wf = float(fairness)
        nv, side = grid.nv, grid.side
        # anchor: the side vertex nearest the centre keeps its tangential place, a neighbour
        # along i keeps its bearing (removes the target's symmetries, fixes the placement)
        i, j = grid.ij
        centre = X0[side].mean(axis=0)
        a0 = side[np.argmin(np.linalg.norm(X0[side] - centre, axis=1))]
        a1 = a0 + (grid.n + 1) if i[a0] < grid.m else a0 - (grid.n + 1)
        self.anchor = np.array([a0, a1])
        _, nrm = target.closest(X0[self.anchor])
        t1 = X0[a1] - X0[a0]
        t1 -= (t1 @ nrm[0]) * nrm[0]
        t1 /= np.linalg.norm(t1)
        self.T = np.stack([t1, np.cross(nrm[0], t1), np.cross(nrm[0], t1)])
        # sparsity patterns: side rows, fairness rows, anchor rows
        ks = len(side)
        st = grid.fairness_stencils
        rows, cols = [np.repeat(np.arange(ks), 3)], [(3 * side[:, None] + np.arange(3)).ravel()]
        r0 = ks
        for ids, _ in st:
            nk, sz = ids.shape
            rr = r0 + 3 * np.arange(nk)[:, None, None] + np.arange(3)[None, None, :]
            rows.append(np.broadcast_to(rr, (nk, sz, 3)).ravel())
            cols.append((3 * ids[:, :, None] + np.arange(3)).ravel())
            r0 += 3 * nk
        self.n_fair = r0 - ks
        rows.append(r0 + np.repeat(np.arange(3), 3))
        cols.append(np.concatenate([3 * a0 + np.arange(3)] * 2 + [3 * a1 + np.arange(3)]))
        self.n_obj = r0 + 3
        self.obj_pattern = SparsePattern(np.concatenate(rows), np.concatenate(cols),
                                         (self.n_obj, 3 * nv))  # fmt: skip
        keep = np.ones(self.n_obj, bool)
        keep[ks : ks + self.n_fair] = False
        self.base_rows = np.flatnonzero(keep)  # side + anchor: the preconditioner's part

    def objective(self, X: np.ndarray):
        g = self.grid
        side = g.side
        foot, nrm = self.target.closest(X[side])
        rs = np.einsum("kd,kd->k", nrm, X[side] - foot) / self.h
        parts, vals = [rs], [nrm.ravel()]
        for ids, w in g.fairness_stencils:
            f = np.einsum("s,ksd->kd", w, X[ids]) / self.h
            parts.append(self.wf * f.ravel())
            nk = len(ids)
            vals.append(np.broadcast_to((self.wf * w)[None, :, None], (nk, len(w), 3)).ravel())
        e = X[self.anchor] - self.X0[self.anchor]
        parts.append(np.array([self.T[0] @ e[0], self.T[1] @ e[0], self.T[2] @ e[1]]) / self.h)
        vals.append(self.T.ravel())
        return np.concatenate(parts), self.obj_pattern.matrix(np.concatenate(vals))

    def constraints(self, X: np.ndarray, jacobian: bool = True):
        if not jacobian:
            return constraints(X, self.grid, self.scale, jacobian=False)
        c, J = constraints(X, self.grid, self.scale)
        J.data *= self.h  # a fresh matrix: scaled in place
        return c, J


class _Normal:
    """``J^T J + mu I`` as an operator (``H @ x``), not formed: two sparse products per
    MINRES iteration instead of a sparse matrix product and sum per step."""

    def __init__(self, J: sp.csr_matrix, mu: float):
        self.J, self.JT, self.mu = J, J.T, float(mu)

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        return self.JT @ (self.J @ x) + self.mu * x


class _KKT:
    """Saddle-point solves min 1/2 d^T H d + g^T d s.t. Jc d = -c by preconditioned MINRES."""

    def __init__(self, grid: QuadGrid, sparse: bool | None = None):
        self.block = SPDFactor(grid.band_order, grid.bandwidth, sparse=sparse)
        self.n_factor = 0
        self._jc = self._jct = None  # the last constraint Jacobian and its transpose
        self._pending = None  # (Jb, Jc, mu) of the next factorisation
        self.minres_its: list[int] = []

    def refactor(self, Jb: sp.csr_matrix, Jc: sp.csr_matrix, mu: float) -> None:
        """Plan a factorisation of the preconditioner block for ``Jb``, ``Jc`` and ``mu``; it is
        made at the next :meth:`solve` (a plan replaced before any solve costs nothing)."""
        self._pending = (Jb, Jc, mu)

    def _factor(self) -> None:
        Jb, Jc, mu = self._pending
        self._pending = None
        # J_s^T J_s + rho J_c^T J_c as one product of the stacked Jacobians (one sparse
        # product, the same pattern every time: SPDFactor plans its gather once). The damping
        # keeps the factorisation positive definite in floating point (SPDFactor raises it
        # from at least 1e-11 of the largest diagonal entry while Cholesky breaks down)
        B = sp.vstack([Jb, math.sqrt(_RHO) * Jc], format="csr")
        structure = None
        if self.block.sparse and self.n_factor == 0:  # the product's full pattern (no entry
            # cancels in a product of ones): one symbolic factorisation for the whole fit
            ones = B.copy()
            ones.data[:] = 1.0
            structure = ones.T.tocsr() @ ones
        try:  # B^T in CSR (one conversion), then a CSR product: no conversion of the result
            self.block.factor(B.T.tocsr() @ B, mu, structure)
        except np.linalg.LinAlgError:
            raise SurfaceFitError(
                "the fit's linear systems are singular (the pattern degenerated)"
            ) from None
        self.n_factor += 1

    def solve(self, H: _Normal, Jc: sp.csr_matrix, g: np.ndarray, c: np.ndarray,
              tol: float = _TOL_STEP) -> tuple[np.ndarray, int]:  # fmt: skip
        if self._pending is not None:
            self._factor()
        n, m = Jc.shape[1], Jc.shape[0]
        if Jc is not self._jc:
            self._jc, self._jct = Jc, Jc.T.tocsr()
        JcT = self._jct
        block = self.block.solve

        def mv(v):
            x, y = v[:n], v[n:]
            return np.concatenate([H @ x + JcT @ y, Jc @ x])

        def prec(r):
            out = np.empty_like(r)
            out[:n] = block(r[:n])
            out[n:] = _RHO * r[n:]
            return out

        count = [0]

        def cb(_):
            count[0] += 1

        K = spla.LinearOperator((n + m, n + m), matvec=mv, dtype=float)
        M = spla.LinearOperator((n + m, n + m), matvec=prec, dtype=float)
        sol, info = spla.minres(K, np.concatenate([-g, -c]), M=M, rtol=tol, maxiter=300,
                                callback=cb)  # fmt: skip
        self.minres_its.append(count[0])
        d = sol[:n]
        return (d if info == 0 and np.isfinite(d).all() else None), count[0]


def _solve(problem: _Problem, X: np.ndarray, *, max_iter: int, ftol: float, time_limit: float,
           t0: float, mu_r: float, rms_goal: float | None = None):  # fmt: skip
    """Restoration, then feasible Gauss-Newton SQP steps. ``mu_r`` damps the restoration
    steps (min |d|_H onto the constraints with H = J_s^T J_s + mu_r I: small keeps the fitted
    side on the target and moves the other side freely, large moves every vertex alike).

    Returns X, ok (the constraints are met), a sentence on how the solve ended, the number of
    iterations and the KKT solver (for its statistics)."""
    h = problem.h
    ndof = 3 * problem.grid.nv
    kkt = _KKT(problem.grid)
    refactor_after = 12  # MINRES iterations that call for a fresh factorisation

    def restore(X, c, Jc, steps: int, sqp: bool = False):
        """Newton steps onto the constraints from X; returns X, c, Jc, steps taken, message.
        With ``sqp`` the steps taken while the largest residual is above :data:`_SQP_UNTIL`
        also minimise the Gauss-Newton model of the distance (H d + g, g = J_o^T r_o).

        A step with a fresh Jacobian (and a fresh factorisation of the preconditioner, which
        is only good for the Jacobian it was made with) is followed by chord steps (the same
        Jacobian and factorisation, the residual at the new X) while they contract the
        residual fast enough; else the Jacobian and the factorisation are renewed."""
        cm = float(np.abs(c).max())
        if cm < CONSTRAINT_TOL:
            return X, c, Jc, 0, ""
        zero = np.zeros(ndof)
        renew, fresh, Jref, H = True, False, Jc, None
        use_sqp = sqp
        for k in range(1, steps + 1):
            # met; below the tolerance the chord steps go on (no new factorisation) while they
            # contract fast, to _TOL_AIM: the residuals of d289d47's fits, 1e-12 to 1e-10
            if cm < CONSTRAINT_TOL and (renew or cm < _TOL_AIM):
                return X, c, problem.constraints(X)[1] if Jc is None else Jc, k - 1, ""
            if renew:
                if Jc is None:
                    c, Jc = problem.constraints(X)
                _, Jo = problem.objective(X)
                H = _Normal(Jo, mu_r)
                kkt.refactor(Jo[problem.base_rows], Jc, mu_r)
                Jref, renew, fresh = Jc, False, True
            g = zero
            if use_sqp and cm > _SQP_UNTIL:
                ro, Jo = problem.objective(X)
                g = Jo.T @ ro
            d, n_it = kkt.solve(H, Jref, g, c, tol=_TOL_PROJECT)
            if d is None and not fresh:  # a chord step that fails: renew and retry
                if Jc is None:
                    c, Jc = problem.constraints(X)
                _, Jo = problem.objective(X)
                H = _Normal(Jo, mu_r)
                kkt.refactor(Jo[problem.base_rows], Jc, mu_r)
                Jref, fresh = Jc, True
                d, n_it = kkt.solve(H, Jref, g, c, tol=_TOL_PROJECT)
            if d is None:
                return X, c, Jc, k, "the linear systems of the restoration did not converge"
            # damped Newton: halve the step until the constraint residual falls
            c2 = float(c @ c)
            for alpha in 0.5 ** np.arange(12):
                Xt = X + alpha * d.reshape(-1, 3) * h
                ct = problem.constraints(Xt, jacobian=False)
                if float(ct @ ct) < c2:
                    break
            else:
                if g is not zero:  # the distance's pull: the constraints alone from here
                    use_sqp = False
                    continue
                if not fresh:  # the chord's direction: renew the Jacobian and try again
                    renew = True
                    continue
                return (
                    X,
                    c,
                    Jc,
                    k,
                    (
                        f"the constraints could not be met (no Newton step lowers the largest "
                        f"residual {cm:.3g}): a less curved region, a smaller placement or more "
                        "cells"
                    ),
                )
            if g is not zero and (alpha < 1 or float(np.abs(ct).max()) > 2 * cm):
                # an SQP step that must be shortened or that doubles the largest residual
                # (large sheets: the distance's pull fights the constraints, 0.16 -> 2.1 rad at
                # 10,000 panels): the step is redone on the constraints alone (the same
                # factorisation), and so are the next ones
                use_sqp = False
                continue
            cm_old = cm
            X, c, Jc = Xt, ct, None  # the Jacobian at X is computed only when needed
            cm = float(np.abs(c).max())
            if not np.isfinite(cm):
                return X, c, Jc, k, "the restoration diverged (non-finite constraints)"
            fresh = False
            # chord steps contract linearly: worth it where the last step contracted a
            # hundredfold (or the residual is already small), else a fresh Newton step
            renew = (
                alpha < 1
                or n_it > refactor_after
                or cm > 0.25 * cm_old
                or (cm > 1e-6 and cm > 0.01 * cm_old)
            )
        if Jc is None:
            c, Jc = problem.constraints(X)
        if cm < CONSTRAINT_TOL:
            return X, c, Jc, steps, ""
        return (
            X,
            c,
            Jc,
            steps,
            (
                f"the constraints could not be met (largest residual {cm:.3g} after {steps} Newton "
                "steps): a smaller placement, more cells or a less curved region"
            ),
        )

    c, Jc = problem.constraints(X)
    # ---- phase 1: restoration from the starting tiling
    X, c, Jc, its, why = restore(X, c, Jc, 30, sqp=True)
    if why:
        return X, False, why, its, kkt
    ro, Jo = problem.objective(X)
    ks = len(problem.grid.side)

    def reached() -> bool:  # the side's RMS distance (ro's first rows are n . (x - foot) / h)
        return rms_goal is not None and h * math.sqrt(float(np.mean(ro[:ks] ** 2))) <= rms_goal

    # ---- phase 2: feasible Gauss-Newton with second-order corrections
    mu = _MU_START
    F = float(ro @ ro)
    message = f"stopped after {max_iter} Gauss-Newton iterations (the distance was still falling)"
    for _ in range(max_iter):
        if reached():
            message = f"reached the RMS goal ({rms_goal:.3g} m)"
            break
        if time.perf_counter() - t0 > time_limit:
            message = f"stopped at the time limit ({time_limit:g} s)"
            break
        its += 1
        g = Jo.T @ ro
        cm = float(np.abs(c).max())
        accepted, first, predicted = False, True, None
        while mu <= 1e6:
            kkt.refactor(Jo[problem.base_rows], Jc, mu)
            H = _Normal(Jo, mu)
            d, _ = kkt.solve(H, Jc, g, c, tol=_TOL_STEP)
            if d is None:
                mu *= 10
                continue
            if first:  # the step's own model: a step predicted to gain less than ftol is not
                # taken (its corrections onto the constraints and the retries at a larger
                # damping cost as much as the rest of an iteration)
                first = False
                rp = ro + Jo @ d
                predicted = (F - float(rp @ rp)) / max(F, 1e-300)
                if predicted < ftol:
                    break
            Xn = X + d.reshape(-1, 3) * h
            cn = problem.constraints(Xn, jacobian=False)
            for _ in range(3):  # second-order corrections onto the constraints
                if not np.abs(cn).max() >= CONSTRAINT_TOL:
                    break
                dc, _ = kkt.solve(H, Jc, np.zeros(ndof), cn, tol=_TOL_PROJECT)
                if dc is None:
                    break
                Xn = Xn + dc.reshape(-1, 3) * h
                cn = problem.constraints(Xn, jacobian=False)
            ron, Jon = problem.objective(Xn)
            Fn = float(ron @ ron)
            cnm = float(np.abs(cn).max())
            if np.isfinite(Fn) and np.isfinite(cnm) and Fn <= F and cnm <= max(10 * cm, 1e-8):
                accepted = True
                break
            mu *= 10
        if not accepted and predicted is not None and predicted < ftol:
            message = (f"converged (the next step was predicted to lower the squared distance by "
                       f"{max(predicted, 0.0):.2g})")  # fmt: skip
            break
        if not accepted:
            message = "converged (no step lowers the distance further)"
            break
        X, ro, Jo = Xn, ron, Jon
        c, Jc = problem.constraints(X)
        mu = max(mu / 10, 1e-6)
        gain = (F - Fn) / max(F, 1e-300)
        F = Fn
        if gain < ftol:
            message = f"converged (the last step lowered the squared distance by {gain:.2g})"
            break
    else:
        if reached():
            message = f"reached the RMS goal ({rms_goal:.3g} m)"
    # ---- polish the constraints to the tolerance
    X, c, Jc, k, why = restore(X, c, Jc, 10)
    its += k
    if why:
        return X, False, why, its, kkt
    return X, True, message, its, kkt


def fit_surface(
    surface,
    cells,
    *,
    placement: Placement | None = None,
    gamma: float = math.radians(60.0),
    ext: float = 0.7,
    side: str = "below",
    fairness: float = 1e-4,
    max_iter: int = 6,
    ftol: float = 0.05,
    time_limit: float = 600.0,
    rms_goal: float | None = None,
    units: str | None = None,
) -> SurfaceFit:
    """Fit an m x n generalised Miura-ori to ``surface`` (docs/surface-fit.md).

    Parameters
    ----------
    surface : TargetSurface, built-in spec or mesh file (:func:`load_surface`; ``units`` is a
        file's unit)
    cells : (m, n) ints or "MxN"
        Quads along the zig-zag direction and across it; m n <= MAX_PANELS.
    placement : Placement, optional
        Where the pattern sits on the chart (default: the whole chart).
    gamma : float
        Sector angle of the starting Miura-ori, rad, in (0, pi/2).
    ext : float
        How far the starting Miura-ori is folded: its projected length over its flat length
        along i, in (0, 1).
    side : {"below", "above"}
        Which way the corrugation hangs from the fitted side (against or along the normal).
    fairness : float
        Weight of the fairness term (relative to the distance term).
    max_iter, ftol, time_limit
        Gauss-Newton iterations at most; stop when a step lowers the squared distance by less
        than ``ftol`` (relative), or when the next step's linear model predicts less than that
        (the step is then not taken); wall time limit, s.
    rms_goal : float, optional
        Stop at the first iterate that meets the constraints with an RMS distance of the
        fitted side to the target at most this, m (the restored start, then after each
        Gauss-Newton step): a fit to a given accuracy rather than the best one.

    Returns
    -------
    SurfaceFit
        ``ok`` False with ``message`` when the constraints could not be met.
    """
    t0 = time.perf_counter()
    target = load_surface(surface, units)
    m, n = _cells(cells)
    gamma = check_range("gamma", gamma, 0.0, math.pi / 2, low_open=True, high_open=True)
    ext = check_range("ext", ext, 0.0, 1.0, low_open=True, high_open=True)
    if side not in ("below", "above"):
        raise ParameterError(f"side must be 'below' or 'above', got {side!r}")
    check_range("fairness", fairness, 0.0, None)
    max_iter = check_count("max_iter", max_iter, 0)
    if rms_goal is not None:
        check_range("rms_goal", rms_goal, 0.0, None)
    placement = placement or Placement()
    grid = QuadGrid(m, n)
    X0 = starting_tiling(target, m, n, placement, gamma, ext, side)
    problem = _Problem(grid, target, X0, fairness)
    first = None
    with threadpool_limits(1):  # one core: BLAS threads only contend on these small vectors
        for mu_r in RESTORATION_DAMPING:  # the next only where the last could not restore
            X, ok, message, its, kkt = _solve(problem, X0.copy(), max_iter=max_iter, ftol=ftol,
                                              time_limit=time_limit, t0=t0, mu_r=mu_r,
                                              rms_goal=rms_goal)  # fmt: skip
            first = first or message
            if ok and np.isfinite(X).all():
                break
        else:
            message = first
    if not np.isfinite(X).all():
        raise SurfaceFitError(f"the {m}x{n} fit diverged: {message}")
    c, s, a = placement.resolved(target)
    options = {
        "gamma_deg": math.degrees(gamma),
        "ext": ext,
        "side": side,
        "fairness": fairness,
        **({"rms_goal": rms_goal} if rms_goal is not None else {}),
        "placement": {"centre": c.tolist(), "size": s.tolist(), "angle_deg": math.degrees(a)},
        "restoration_damping": mu_r,
        "factorisations": kkt.n_factor,
        "factorisation": "cholmod" if kkt.block.sparse else "banded",
        "minres_iterations": int(sum(kkt.minres_its)),
    }
    flat = _orient_flat(develop(X, grid), grid)
    residuals = _residuals(X, flat, grid)
    dist = target.distance(X[grid.side])
    if ok and not (residuals["sector_angle_min_deg"] > MIN_SECTOR_DEG
                   and residuals["sector_angle_max_deg"] < 180 - MIN_SECTOR_DEG):  # fmt: skip
        ok, message = (
            False,
            (
                f"the panels degenerated (sector angles "
                f"{residuals['sector_angle_min_deg']:.3g} to "
                f"{residuals['sector_angle_max_deg']:.3g} deg): a less curved region or more cells"
            ),
        )
    fit = SurfaceFit(target, m, n, X, flat, grid.side, dist, residuals, ok, message,
                     its, time.perf_counter() - t0, options)  # fmt: skip
    if ok:
        try:
            fit.pattern  # noqa: B018 - validates the flat pattern (simple, counter-clockwise)
        except ValueError as exc:
            fit = replace(fit, ok=False, message=f"the flat pattern is not valid: {exc}")
    return fit


def _orient_flat(Y: np.ndarray, grid: QuadGrid) -> np.ndarray:
    """The flat layout turned so that the lines of constant i (the straight creases of a
    Miura-ori) run along +y on average and moved to start at the origin (i along +x)."""
    v = Y[grid.vid(np.arange(grid.m + 1), grid.n)] - Y[grid.vid(np.arange(grid.m + 1), 0)]
    a = math.atan2(v[:, 0].sum(), v[:, 1].sum())  # rotate by +a: the mean direction to +y
    R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    Z = Y @ R.T
    return Z - Z.min(axis=0)


def _residuals(X: np.ndarray, flat: np.ndarray, grid: QuadGrid) -> dict[str, float]:
    r, _ = vertex_conditions(X, grid)
    ni = len(grid.interior[0])
    Q = grid.quads
    e = np.concatenate([Q[:, [0, 1]], Q[:, [1, 2]], Q[:, [2, 3]], Q[:, [3, 0]], Q[:, [0, 2]]])
    l3 = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1)
    lf = np.linalg.norm(flat[e[:, 1]] - flat[e[:, 0]], axis=1)
    th = sector_angles(X, Q)
    return {
        "planarity_max": float(quad_warp(X, Q).max()),
        "angle_sum_max": float(np.abs(r[:ni]).max(initial=0.0)),
        "kawasaki_max": float(np.abs(r[ni:]).max(initial=0.0)),
        "development_max": float(np.max(np.abs(lf - l3) / l3)),
        "sector_angle_min_deg": float(np.degrees(th.min())),
        "sector_angle_max_deg": float(np.degrees(th.max())),
    }


def _cells(cells) -> tuple[int, int]:
    if isinstance(cells, str):
        parts = cells.lower().replace("×", "x").split("x")
        if len(parts) != 2:
            raise ParameterError(f"cells must be 'MxN' (e.g. 16x16), got {cells!r}")
        cells = parts
    try:
        m, n = cells
    except (TypeError, ValueError):
        raise ParameterError(f"cells must be two integers (m, n), got {cells!r}") from None
    m, n = check_count("m", m, 2), check_count("n", n, 2)
    if m * n > MAX_PANELS:
        raise ParameterError(f"{m}x{n} = {m * n} panels is more than MAX_PANELS = {MAX_PANELS}")
    return m, n
