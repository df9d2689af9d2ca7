"""Reusable analyses on a bar-and-hinge model: secant stiffness under a load group, snap checks.

These are the measurements the paper's scenarios make (docs/scenarios.md §2.3, §3.3, §5.2-5.3):
a group of nodes carries an equal share of a per-increment force in one direction, Newton-Raphson
load control runs a few increments from the stress-free state, and the secant stiffness is the
total force over the mean displacement of the group. :func:`snap_check_mgdcm` offers a path-
following alternative to the paper's displacement-threshold snap flag.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError
from holofold.mechanics.solvers import solve_mgdcm, solve_newton, solve_newton_batch
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.structure import Structure
from holofold.mechanics.threads import single_threaded

__all__ = [
    "LoadGroup",
    "StiffnessResult",
    "load_group",
    "load_along",
    "secant_stiffness",
    "secant_stiffness_batch",
    "SnapCheck",
    "snap_check_mgdcm",
]

_AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class LoadGroup:
    """Nodes sharing a force in one direction.

    Attributes
    ----------
    nodes : (k,) int
        Loaded node ids.
    axis : int
        0, 1, 2 for x, y, z; -1 for an oblique ``vector``.
    sign : float
        +1 or -1 (direction of the force along ``axis``).
    vector : (3,) float or None
        Unit direction of an oblique load (``axis = -1``); None for an axis load.
    """

    nodes: np.ndarray
    axis: int
    sign: float
    vector: np.ndarray | None = None

    def load(self, n_nodes: int, force: float) -> np.ndarray:
        """(n_nodes, 3) load array: ``force`` (N) shared equally by the group's nodes."""
        F = np.zeros((n_nodes, 3))
        if self.vector is None:
            F[self.nodes, self.axis] = self.sign * force / len(self.nodes)
        else:
            F[self.nodes] = (force / len(self.nodes)) * self.vector
        return F

    def displacements(self, U: np.ndarray) -> np.ndarray:
        """Displacement of each loaded node along the load direction, (..., k) m.

        ``U`` is (n_nodes, 3) or a history (steps, n_nodes, 3).
        """
        u = U[..., self.nodes, :]
        if self.vector is None:
            return self.sign * u[..., self.axis]
        return u @ self.vector


def load_group(nodes, direction: str) -> LoadGroup:
    """A :class:`LoadGroup` from node ids and a direction ``"+x"``, ``"-z"``, ...."""
    nodes = np.atleast_1d(np.asarray(nodes, dtype=np.intp))
    if nodes.size == 0:
        raise ParameterError("a load group needs at least one node")
    d = str(direction).strip().lower()
    if len(d) != 2 or d[0] not in "+-" or d[1] not in _AXES:
        raise ParameterError(f"direction = {direction!r}; allowed: +x, -x, +y, -y, +z, -z")
    return LoadGroup(nodes, _AXES[d[1]], 1.0 if d[0] == "+" else -1.0)


def load_along(nodes, direction) -> LoadGroup:
    """A :class:`LoadGroup` along a 3-vector ``direction`` (any length > 0).

    An axis-aligned direction gives the same group as :func:`load_group` (so the same
    numbers, bit for bit); any other is normalised to a unit vector.
    """
    nodes = np.atleast_1d(np.asarray(nodes, dtype=np.intp))
    if nodes.size == 0:
        raise ParameterError("a load group needs at least one node")
    d = np.asarray(direction, dtype=float)
    if d.shape != (3,) or not np.isfinite(d).all() or not np.any(d):
        raise ParameterError(f"direction = {direction!r} must be a finite non-zero 3-vector")
    nz = np.flatnonzero(d)
    if nz.size == 1:
        return LoadGroup(nodes, int(nz[0]), 1.0 if d[nz[0]] > 0 else -1.0)
    return LoadGroup(nodes, -1, 1.0, d / np.linalg.norm(d))


@dataclass(frozen=True)
class StiffnessResult:
    """Secant stiffness of one load case.

    Attributes
    ----------
    stiffness : float
        Total force / mean |displacement| of the loaded nodes along the load axis, N/m.
    displacement : float
        That mean |displacement| after the last increment, m.
    result : SolveResult
        The Newton-Raphson path.
    """

    stiffness: float
    displacement: float
    result: SolveResult

    @property
    def converged(self) -> bool:
        return self.result.ok


@single_threaded
def secant_stiffness(
    structure: Structure,
    group: LoadGroup,
    *,
    force_per_increment: float = 1.0,
    increments: int,
    tol: float,
    max_iter: int = 30,
    assembler=None,
    U0=None,
) -> StiffnessResult:
    """Newton-Raphson load control from the stress-free state (or from ``U0``) and the
    secant stiffness.

    Parameters
    ----------
    structure : Structure
        Model with its supports set.
    group : LoadGroup
        The loaded nodes and the direction.
    force_per_increment : float
        Total force added per increment, N, shared equally by the group (reference
        semantics: at increment i the applied load is i times this).
    increments, tol, max_iter
        Newton-Raphson controls (``tol`` on ||dU||_2 in metres; at most ``max_iter - 1``
        iterations per increment, the reference's cap).
    U0 : (nn, 3) float, optional
        An equilibrium to load from (e.g. a folded state: the structure's rest angles must be
        those it was reached with); the displacement is then measured from it. Default 0.

    Returns
    -------
    StiffnessResult
        ``increments * force_per_increment / mean |U_axis(group)|`` after the last increment
        (``U - U0``).
    """
    load = group.load(structure.n_nodes, force_per_increment)
    res = solve_newton(
        structure, load, increments=increments, tol=tol, max_iter=max_iter, assembler=assembler,
        U0=U0,
    )  # fmt: skip
    return _stiffness(group, res, force_per_increment, U0)


def _stiffness(
    group: LoadGroup, res: SolveResult, force_per_increment: float, U0=None
) -> StiffnessResult:
    U = res.U if U0 is None else res.U - np.asarray(U0, float).reshape(res.U.shape)
    d = np.abs(group.displacements(U))
    u = float(np.add.reduce(d) / d.size) if d.size else float("nan")
    total = force_per_increment * len(res.load_factor)
    k = total / u if u > 0 else float("inf")
    return StiffnessResult(stiffness=k, displacement=u, result=res)


@single_threaded
def secant_stiffness_batch(
    structures,
    groups,
    *,
    force_per_increment: float = 1.0,
    increments: int,
    tol: float,
    max_iter: int = 30,
    batch=None,
) -> list[StiffnessResult]:
    """:func:`secant_stiffness` of S structures of one topology and support mask, solved in
    lockstep by :func:`~holofold.mechanics.solvers.solve_newton_batch` (``groups``: one
    :class:`LoadGroup` per structure); each result is bit for bit the one-at-a-time one."""
    structures = list(structures)
    groups = list(groups)
    if len(groups) != len(structures):
        raise ValueError(f"{len(groups)} load groups for {len(structures)} structures")
    nn = structures[0].n_nodes if structures else 0
    made: dict = {}  # the designs of a batch share few load groups: one load array each
    for g in groups:
        if id(g) not in made:
            made[id(g)] = g.load(nn, force_per_increment)
    loads = np.stack([made[id(g)] for g in groups]) if groups else np.zeros((0, nn, 3))
    runs = solve_newton_batch(
        structures, loads, increments=increments, tol=tol, max_iter=max_iter, batch=batch
    )
    if (
        len(runs) > 1
        and all(g is groups[0] for g in groups)
        and len({len(r.load_factor) for r in runs}) == 1
    ):
        # one load group (and as many increments) for all: their displacements in one go
        g, total = groups[0], force_per_increment * len(runs[0].load_factor)
        d = np.abs(g.displacements(np.stack([r.U for r in runs])))  # (S, k)
        u = np.add.reduce(d, axis=-1) / d.shape[-1] if d.shape[-1] else np.full(len(runs), np.nan)
        return [
            StiffnessResult(
                stiffness=total / ui if ui > 0 else float("inf"), displacement=ui, result=r
            )
            for ui, r in zip(u.tolist(), runs, strict=True)
        ]
    return [_stiffness(g, r, force_per_increment) for g, r in zip(groups, runs, strict=True)]


@dataclass(frozen=True)
class SnapCheck:
    """Snap-through check by path following.

    Attributes
    ----------
    snaps : bool
        True if the load-displacement path has a limit point (the load factor falls) before
        the target load is reached.
    limit_load : float
        Load at the first limit point, N (nan if none): the vertex of a parabola through the
        three path points around the peak.
    reached_load : float
        Largest load reached on the path, N.
    load_factor : (n,) float
        Load factor (fraction of the checked force) after each increment followed.
    status : str
        Status of the last MGDCM chunk.
    """

    snaps: bool
    limit_load: float
    reached_load: float
    load_factor: np.ndarray
    status: str


def _peak(u: np.ndarray, lam: np.ndarray) -> float:
    """Largest load factor of the parabola lambda(u) through three path points."""
    if len(u) < 3 or len(np.unique(u)) < 3:
        return float(lam.max())
    a, b, c = np.polyfit(u, lam, 2)
    if a >= 0:
        return float(lam.max())
    u_star = -b / (2 * a)
    if not (u.min() <= u_star <= u.max()):
        return float(lam.max())
    return float(max(lam.max(), c - b * b / (4 * a)))


@single_threaded
def snap_check_mgdcm(
    structure: Structure,
    group: LoadGroup,
    total_force: float,
    *,
    max_increments: int = 100,
    initial_step: float = 0.05,
    chunk: int = 10,
    tol: float = 1e-7,
    max_iter: int = 30,
) -> SnapCheck:
    """Follow the equilibrium path by MGDCM and look for a limit point below ``total_force``.

    The reference force is ``total_force`` shared by the group, so the load factor lambda is
    the fraction of it carried. The path is followed in chunks of ``chunk`` increments and
    stops as soon as lambda reaches 1 (no snap) or falls (a limit point: snap if it came before
    lambda = 1).

    Parameters
    ----------
    structure : Structure
        Model with supports.
    group : LoadGroup
        Loaded nodes and direction.
    total_force : float
        Force whose reachability is checked, N.
    max_increments : int
        Largest number of MGDCM increments.
    initial_step : float
        Load-factor step (fraction of ``total_force``) of the first increment; later ones keep
        the generalised displacement of MGDCM (no step doubling).
    chunk : int
        Increments per MGDCM call between the checks.
    """
    if not total_force > 0:
        raise ParameterError(f"total_force = {total_force!r} must be > 0")
    load = group.load(structure.n_nodes, total_force)
    lam_all = [0.0]
    u_all = [0.0]
    U0 = None
    step = float(initial_step)
    results = []
    done = 0
    snaps = False
    limit = float("nan")
    while done < max_increments:
        n = min(chunk, max_increments - done)
        res = solve_mgdcm(
            structure,
            load,
            increments=n,
            lambda_bar=step,
            tol=tol,
            max_iter=max_iter,
            U0=U0,
            lambda0=lam_all[-1],
            adapt_step=False,
        )
        results.append(res)
        lam = np.asarray(res.load_factor, float)
        done += len(lam)
        if group.vector is None:
            u_all += list(res.U_history[:, group.nodes, group.axis].mean(axis=1))
        else:
            u_all += list(group.displacements(res.U_history).mean(axis=1))
        full = np.concatenate([lam_all, lam])
        falling = np.flatnonzero(np.diff(full) < 0)
        lam_all = list(full)
        if falling.size:
            i = int(falling[0])
            if full[i] < 1.0:
                snaps = True
                limit = _peak(np.asarray(u_all[i - 1 : i + 2]), full[i - 1 : i + 2])
                limit = min(limit, 1.0) * total_force
            break
        if full[-1] >= 1.0 or res.failed or len(lam) == 0:
            break
        U0 = res.U
        step = max(abs(full[-1] - full[-2]), 1e-6)
    reached = float(np.max(lam_all)) * total_force
    last = results[-1]
    return SnapCheck(
        snaps=snaps,
        limit_load=limit,
        reached_load=reached,
        load_factor=np.asarray(lam_all[1:]),
        status=last.status,
    )
