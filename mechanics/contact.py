"""Barrier contact between thick panels, with collision-free steps (issue 32 item 2).

:class:`PanelContact` wraps the IPC Toolkit (``ipctk``, MIT; optional extra
``holofold[contact]``) over a model's panel triangles: a smooth log barrier between
point-triangle and edge-edge pairs (Incremental Potential Contact), in its thickness-offset form
for shells: the distance between mid-surfaces minus ``dmin`` = the panel thickness (two half
thicknesses touch), activated below ``dhat`` = the panel thickness beyond that. Primitives that
share a vertex are never paired (ipctk's CollisionMesh excludes them). Energy J, gradient (ndof,)
N and sparse Hessian (ndof x ndof) N/m on the model's DOFs (3 per node, node-major, as in
:class:`~holofold.mechanics.assembly.Assembler`).

The barrier stiffness ``kappa`` (N/m, energy = kappa * b(d) with b in m^2) is the median of the
diagonal of the model's own tangent at the flat state: the barrier at half its activation
distance is about as stiff as one node of the sheet, so contact forces stop panels without
dominating the elastic solve.

:meth:`PanelContact.step` is the hook of :func:`~holofold.mechanics.folding.fold_pattern`: it
keeps the contact-free Newton result unchanged when the straight path to it is collision free
and no pair is active there (then contact costs one broad phase + CCD per step), otherwise it
solves the step again with the barrier in the residual and tangent and every Newton update
limited by continuous collision detection, so that no accepted state intersects.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from holofold.geometry.errors import EnvironmentFault, ParameterError

__all__ = ["Barrier", "PanelContact", "contact_model", "has_ipctk", "intersects"]

INSTALL = "panel contact needs the IPC Toolkit: pip install 'holofold[contact]' (ipctk)"
CCD_SAFETY = 0.9  # fraction of the collision-free step taken
#: Levenberg-Marquardt shift of the barrier solve where the tangent gives no descent (a snap
#: with panels in contact), from MU_MIN to MU_MAX x the tangent's mean diagonal
MU_MIN, MU_MAX = 1e-8, 1e8
#: the farthest one barrier-Newton update moves a node, as a fraction of the sheet's size (a
#: trust region: a near-singular tangent gave updates of 1e10 m, whose continuous collision
#: check asked ipctk's spatial hash for gigabytes)
MAX_MOVE = 0.1


def has_ipctk() -> bool:
    """True where ``ipctk`` imports."""
    try:
        import ipctk  # noqa: F401
    except ImportError:
        return False
    return True


def _ipctk():
    try:
        import ipctk
    except ImportError as exc:
        raise EnvironmentFault(INSTALL) from exc
    return ipctk


class Barrier(NamedTuple):
    """The contact barrier at a state: ``energy`` J, ``gradient`` (ndof,) N, ``hessian``
    (ndof, ndof) csc N/m and the number of active primitive ``pairs``."""

    energy: float
    gradient: np.ndarray
    hessian: object
    pairs: int


class PanelContact:
    """Barrier contact over ``structure.triangles`` (nodes of ``structure.nodes``).

    Parameters
    ----------
    structure : Structure
        Model with panel triangles (nt, 3) and ``tri_thickness`` (nt,) m.
    thickness : float, optional
        Panel thickness, m (default: the largest ``tri_thickness``): ``dmin`` and ``dhat``.
    kappa : float, optional
        Barrier stiffness, N/m (default: see the module docstring; needs ``stiffness``).
    stiffness : float, optional
        The model's stiffness scale, N/m (median tangent diagonal), for the default kappa.
    """

    def __init__(self, structure, thickness=None, kappa=None, stiffness=None):
        ipc = _ipctk()
        tri = structure.triangles
        if tri is None or len(tri) == 0:
            raise ParameterError("panel contact: the model has no panel triangles")
        if thickness is None:
            tt = structure.tri_thickness
            if tt is None:
                raise ParameterError("panel contact: give the panel thickness")
            thickness = float(np.max(tt))
        thickness = float(thickness)
        if not thickness > 0 or not math.isfinite(thickness):
            raise ParameterError(f"panel contact: thickness = {thickness!r}; allowed: > 0 m")
        if kappa is None:
            if stiffness is None or not stiffness > 0:
                raise ParameterError("panel contact: give kappa > 0 or the model's stiffness")
            kappa = float(stiffness)
        self.ipc = ipc
        self.X0 = np.asfortranarray(structure.nodes, dtype=float)
        faces = np.asfortranarray(tri, dtype=np.int32)
        edges = np.asfortranarray(ipc.edges(faces), dtype=np.int32)
        self.mesh = ipc.CollisionMesh(self.X0, edges, faces)
        self.dmin = thickness
        self.dhat = thickness
        self.kappa = float(kappa)
        self.barrier = ipc.BarrierPotential(self.dhat, self.kappa)
        self.n_dof = self.X0.size
        self.size = float(np.ptp(self.X0, axis=0).max()) if len(self.X0) else 0.0
        # additive CCD (Li, Kaufman, Jiang 2021: the CCD of codimensional IPC, made for a
        # minimum distance); ipctk's default tight-inclusion CCD ran out of memory (> 13 GB)
        # on two parallel layers 1.4 mm apart with a 1 mm minimum distance (a z-fold)
        self.ccd = ipc.AdditiveCCD()
        self._panels_of_node = _panels_of_node(structure)
        self._chol = (None, None)  # (pattern key, sparse Cholesky analysis) of the last solve
        self._last_collisions = (None, None)  # (X, collisions) of the last broad phase
        self.last_active = 0
        self.touched = (0, (-1, -1))  # the most pairs within reach in the last solve, and where
        self.newton_steps = 0
        self.exact_updates = 0  # of those, updates by the exact Hessian (the rest: projected)
        X = self.X0
        if ipc.has_intersections(self.mesh, X) and _crossing(X, tri):
            raise ParameterError("panel contact: the panels intersect in the starting state")
        self.excluded = self._exclude_neighbours(X)
        c = self._collisions(X)
        if len(c) and not np.isfinite(self.barrier(c, self.mesh, X)):
            raise ParameterError(
                f"panel contact: panels closer than the thickness {thickness:g} m at the start"
            )

    def _exclude_neighbours(self, X) -> int:
        """Where the starting state is a flat sheet, primitives within the barrier's reach in
        it never collide with each other: neighbours in its plane (thin triangles round a
        vertex, the two coincident sides of a cut), which a barrier infinite below the
        thickness could not start from and would push apart in the plane (the exclusion of
        rest-state neighbours of cloth simulators). A starting state that is not flat keeps
        every pair (its layers are layers). Sets the mesh's collision filter; returns the
        number of vertex pairs excluded. Their crossing is still caught by the intersection
        check."""
        if not len(self._collisions(X)):
            return 0
        # out of plane: the smallest singular value of the centred nodes (RMS distance from
        # their best plane x sqrt(n)); a start that is not flat keeps every pair (a pair closer
        # than the thickness there is refused below)
        out_of_plane = np.linalg.svd(X - X.mean(axis=0), compute_uv=False)[-1]
        if out_of_plane > 1e-9 * max(self.size, 1e-300) * math.sqrt(len(X)):
            return 0
        reach = self.dmin + self.dhat
        cand = self.ipc.Candidates()
        cand.build(self.mesh, X, 0.5 * reach)
        E, F = self.mesh.edges, self.mesh.faces
        pairs = {}
        for group in (cand.vv_candidates, cand.ev_candidates, cand.ee_candidates,
                      cand.fv_candidates):  # fmt: skip
            for k in range(len(group)):
                near = group[k]
                if near.compute_distance(near.dof(X, E, F)) >= reach * reach:
                    continue
                ids = sorted({int(v) for v in near.vertex_ids(E, F) if v >= 0})
                for i, u in enumerate(ids):  # every pair across the two primitives
                    for w in ids[i + 1 :]:
                        pairs[(u, w)] = False
        self.mesh.can_collide = self.ipc.make_sparse_filter(pairs, True)
        self._last_collisions = (None, None)  # found before the filter
        return len(pairs)

    # ----------------------------------------------------------------- evaluation
    def _pos(self, U) -> np.ndarray:
        return np.asfortranarray(self.X0 + np.asarray(U, float).reshape(-1, 3))

    def _collisions(self, X):
        """The pairs within reach at ``X`` (IPC Toolkit's broad and narrow phase), kept for the
        last ``X``: a Newton update's accepted state is evaluated again by the next update and
        by :meth:`touching` (the broad phase was 16 % of a fold's time where panels touch)."""
        last_X, last_c = self._last_collisions
        if last_X is not None and last_X.shape == X.shape and np.array_equal(last_X, X):
            return last_c
        c = self.ipc.NormalCollisions()
        c.build(self.mesh, X, self.dhat, self.dmin)
        self._last_collisions = (X.copy(), c)
        return c

    def energy(self, U) -> float:
        """Barrier energy at displacement ``U`` ((nn, 3) or (ndof,), m), J (inf if touching)."""
        X = self._pos(U)
        c = self._collisions(X)
        return float(self.barrier(c, self.mesh, X)) if len(c) else 0.0

    def gradient(self, U) -> np.ndarray:
        """Barrier gradient (ndof,), N."""
        X = self._pos(U)
        c = self._collisions(X)
        if not len(c):
            return np.zeros(self.n_dof)
        return np.asarray(self.barrier.gradient(c, self.mesh, X)).ravel()

    def hessian(self, U):
        """Barrier Hessian (csc ndof x ndof), N/m."""
        import scipy.sparse as sp

        X = self._pos(U)
        c = self._collisions(X)
        if not len(c):
            return sp.csc_matrix((self.n_dof, self.n_dof))
        return self.barrier.hessian(c, self.mesh, X)

    def evaluate(self, U, psd: bool = True) -> Barrier:
        """The barrier at ``U`` (a :class:`Barrier`); its Hessian projected to positive
        semi-definite per pair when ``psd`` (for Newton)."""
        import scipy.sparse as sp

        X = self._pos(U)
        c = self._collisions(X)
        n = len(c)
        if not n:
            return Barrier(0.0, np.zeros(self.n_dof), sp.csc_matrix((self.n_dof, self.n_dof)), 0)
        proj = self.ipc.PSDProjectionMethod.CLAMP if psd else self.ipc.PSDProjectionMethod.NONE
        E = float(self.barrier(c, self.mesh, X))
        g = np.asarray(self.barrier.gradient(c, self.mesh, X)).ravel()
        H = self.barrier.hessian(c, self.mesh, X, proj)
        return Barrier(E, g, H, n)

    def active(self, U) -> int:
        """Number of pairs closer than ``dmin + dhat``."""
        return len(self._collisions(self._pos(U)))

    def touching(self, U) -> tuple[int, tuple[int, int]]:
        """``(pairs, (panel, panel))``: the number of primitive pairs closer than ``dmin +
        dhat`` at ``U`` and two panels of the closest one, each a panel holding the whole of
        its primitive (``(-1, -1)`` when none)."""
        X = self._pos(U)
        c = self._collisions(X)
        if not len(c):
            return 0, (-1, -1)
        E, F = self.mesh.edges, self.mesh.faces
        best, k = math.inf, 0
        for i in range(len(c)):
            d = c[i].compute_distance(c[i].dof(X, E, F))
            if d < best:
                best, k = d, i
        # each c[i] is a view into the set: read the closest one by index, while c lives
        one, other = _primitives(c[k], E, F)
        a, b = self._panels_of(one), self._panels_of(other)
        pa = min(a, default=-1)
        pb = min(b - {pa}, default=min(b, default=-1))
        return len(c), (min(pa, pb), max(pa, pb))

    def _panels_of(self, nodes) -> set:
        """The panels holding every node of ``nodes``."""
        sets = [self._panels_of_node[n] for n in nodes]
        return set.intersection(*sets) if sets else set()

    def free_step(self, U0, U1) -> float:
        """Largest fraction in [0, 1] of the straight path ``U0 -> U1`` on which no two
        primitives come closer than ``dmin`` (CCD). A path moving a node farther than the
        sheet's size is checked over its first sheet size only (0 for a non-finite one)."""
        U0 = np.asarray(U0, float)
        move = np.asarray(U1, float) - U0
        far = float(np.abs(move).max()) if move.size else 0.0
        if not math.isfinite(far):
            return 0.0
        reach = min(1.0, self.size / far) if far > 0 and self.size > 0 else 1.0
        X1 = self._pos(U0 + reach * move)
        return reach * float(
            self.ipc.compute_collision_free_stepsize(
                self.mesh, self._pos(U0), X1, self.dmin, None, self.ccd
            )
        )

    def intersects(self, U) -> bool:
        """True if the mid-surfaces intersect at ``U`` (ipctk ``has_intersections``)."""
        return bool(self.ipc.has_intersections(self.mesh, self._pos(U)))

    # ----------------------------------------------------------------- the Newton hook
    def step(self, asm, U_prev, U_trial, rest, tol, max_iter: int = 30, deadline=None):
        """The accepted state of one fold step: ``U_trial`` (the contact-free equilibrium, or
        None) itself if the path ``U_prev -> U_trial`` is collision free and no pair is active
        at ``U_trial``; else the equilibrium with the barrier (Newton with CCD-limited,
        energy-decreasing updates, by the exact Hessian where the tangent is positive definite,
        else the barrier's projected per pair: on Origami Simulator's miura-ori 51 -> 10.5 CPU
        s), or None if that does not reach ``tol``. It starts from ``U_trial`` where the path
        there is clean and pairs are only within reach, else from ``U_prev`` (a start partway
        to the first collision, 0.5 or 0.9 of the clean way, sits close to it where the barrier
        is stiff: Kirigami/triPerfTess 5.0 -> 10.4 and 11.7 CPU s). Where
        the contact-free solve found no equilibrium (``U_trial`` None) and no pair is within
        reach at ``U_prev``, contact is not why: None, and the fold shortens its step as it
        does without contact (the barrier solve there cost 50 of 86 s on a 2304-panel Miura
        sheet that never touches). The barrier solve takes at most ``4 max_iter`` updates (60 at
        least) and gives up (None) past ``deadline`` (a ``time.perf_counter()`` value)."""
        U_prev = np.asarray(U_prev, float).reshape(-1, 3)
        start = U_prev
        if U_trial is not None and np.isfinite(U_trial).all():
            U_trial = np.asarray(U_trial, float).reshape(-1, 3)
            free = self.free_step(U_prev, U_trial)
            if free >= 1.0:
                if self.active(U_trial) == 0:
                    self.last_active = 0
                    self.touched = (0, (-1, -1))
                    return U_trial
                start = U_trial  # clean, only within the barrier's reach: start there
        elif self.active(U_prev) == 0:
            self.last_active = 0
            self.touched = (0, (-1, -1))
            return None
        return self._solve(asm, start, rest, tol, max_iter, deadline)

    def _solve(self, asm, U, rest, tol, max_iter, deadline=None):
        import time

        from scipy.sparse.linalg import splu

        free = asm.free_dofs
        U = U.ravel().copy()
        self.touched = (0, (-1, -1))

        def total(Uv):
            b = self.energy(Uv)
            return asm.internal_force(Uv, rest)[0] + b if math.isfinite(b) else math.inf

        import scipy.sparse as sp

        mu, scale = 0.0, 0.0  # Levenberg-Marquardt shift where the tangent is not a descent
        for _ in range(max(4 * max_iter, 60)):
            if deadline is not None and time.perf_counter() > deadline:
                return None
            e, f, K = asm.evaluate_reduced(U, rest, dense=False)
            eb, gb, Hb, n = self.evaluate(U, psd=False)
            self.last_active = n
            if n > self.touched[0]:
                self.touched = self.touching(U)
            r = -(f + gb)[free]
            if math.sqrt(r @ r) <= tol:
                return U.reshape(-1, 3)
            A = (K + Hb[free][:, free]).tocsc()
            scale = scale or float(np.abs(A.diagonal()).mean())
            # Newton on the exact Hessian where the whole tangent is positive definite
            # (quadratic convergence); else the barrier's Hessian projected per pair
            d = self._cholesky_solve(A, r) if not mu and n else None
            if d is not None and np.isfinite(d).all() and float(r @ d) > 0:
                self.exact_updates += 1
            else:
                if n:
                    Hp = self.barrier.hessian(
                        self._collisions(self._pos(U)), self.mesh, self._pos(U),
                        self.ipc.PSDProjectionMethod.CLAMP,
                    )  # fmt: skip
                    A = (K + Hp[free][:, free]).tocsc()
                d = self._descent(A, r, mu, scale, sp, splu)
                if d is None:
                    return None
                d, mu = d
            far = float(np.abs(d).max())
            if far > MAX_MOVE * self.size > 0:  # a trust region for near-singular tangents
                d = d * (MAX_MOVE * self.size / far)
            self.newton_steps += 1
            trial = U.copy()
            trial[free] += d
            alpha = min(1.0, self.free_step(U, trial))
            if alpha < 1.0:
                alpha *= CCD_SAFETY
            E0 = e + eb
            slope = -float(r @ d)
            while alpha > 1e-12:
                cand = U.copy()
                cand[free] += alpha * d
                Ec = total(cand)
                if Ec <= E0 + 1e-4 * alpha * slope or (
                    alpha == 1.0 and abs(Ec - E0) <= 1e-12 * abs(E0)
                ):
                    break
                alpha *= 0.5
            else:  # no decrease along the update: a larger shift (a shorter, steeper step)
                mu = max(4.0 * mu, MU_MIN * scale)
                if mu > MU_MAX * scale:
                    return None
                continue
            U = cand
            mu = mu / 4.0 if mu > MU_MIN * scale else 0.0
        return None

    def _descent(self, A, r, mu, scale, sp, splu):
        """``(d, mu)``: the update solving ``(A + mu I) d = r`` with ``mu`` raised from the given
        one until ``d`` descends (``r @ d > 0``); None past ``MU_MAX * scale``. A positive
        definite ``A + mu I`` is solved by the sparse Cholesky of the assembly's ``"cholesky"``
        path (its analysis kept while the pattern repeats), any other by SuperLU's LU."""
        eye = sp.identity(A.shape[0], format="csc")
        while True:
            M = (A + mu * eye).tocsc() if mu else A
            d = self._cholesky_solve(M, r)
            if d is None:
                try:
                    d = splu(M).solve(r)
                except RuntimeError:
                    d = None
            if d is not None and np.isfinite(d).all() and float(r @ d) > 0:
                return d, mu
            mu = max(4.0 * mu, MU_MIN * scale)
            if mu > MU_MAX * scale:
                return None

    def _cholesky_solve(self, M, r):
        """``M^-1 r`` by a sparse Cholesky of the symmetric csc ``M`` (CHOLMOD, or holofold's
        supernodal one where the compiled kernels run); None where ``M`` is not positive
        definite or neither is available. Factorising the barrier's systems by SuperLU's LU
        cost 0.86 s each against CHOLMOD's 0.05 s for the fold's own tangents (Huffman's
        stars-triangles, 2026-12-07): 35 % of the fold."""
        from holofold.mechanics.linear import SingularSystemError, cholesky_backend

        backend = cholesky_backend()
        if backend is None:
            return None
        M.sort_indices()
        key = (M.shape[0], M.indptr.tobytes(), M.indices.tobytes())
        if self._chol[0] != key:
            if backend == "cholmod":
                from holofold.mechanics.sparse_cholesky import SparseCholesky as Analysis
            else:
                from holofold.mechanics.supernodal import SupernodalCholesky as Analysis
            try:  # a symmetric matrix's CSC arrays are its CSR arrays
                self._chol = (key, Analysis(M.indptr, M.indices))
            except ValueError:  # a pattern it does not take (a missing diagonal entry)
                self._chol = (None, None)
                return None
        factor = self._chol[1].factor(M.data)
        if factor is None:
            return None
        try:
            return factor.solve(r)
        except SingularSystemError:
            return None


def _crossing(X, triangles) -> bool:
    """True where holofold's own test finds two panel triangles crossing (IPC Toolkit's test
    also flags coincident coplanar edges, as the two sides of a cut in a flat sheet)."""
    from holofold.mechanics.intersection import has_intersections

    return bool(has_intersections(np.asarray(X), np.asarray(triangles), backend="numpy"))


def _primitives(collision, edges, faces) -> tuple[list[int], list[int]]:
    """The node ids of a collision's two primitives. IPC Toolkit lists a pair's nodes as
    ``(v, f0, f1, f2)`` (face-vertex), ``(v, e0, e1, -1)`` (edge-vertex), ``(v0, v1, -1, -1)``
    (vertex-vertex): the vertex first; edge-edge as ``(a0, a1, b0, b1)``."""
    ids = [int(v) for v in collision.vertex_ids(edges, faces)]
    if type(collision).__name__.startswith("EdgeEdge"):
        return ids[:2], ids[2:]
    return ids[:1], [v for v in ids[1:] if v >= 0]


def _panels_of_node(structure) -> list[set]:
    """The panels holding each node (empty for none), from ``structure.tri_panel``. A crease
    strip's triangles (``tri_panel`` -1, the compliant model) belong to the panels their nodes
    touch, so a contact on a crease strip names the panels the crease joins, never panel -1."""
    out: list[set] = [set() for _ in range(len(structure.nodes))]
    panel = getattr(structure, "tri_panel", None)
    if panel is None:
        return out
    tris, panel = np.asarray(structure.triangles), np.asarray(panel)
    for tri, p in zip(tris, panel, strict=True):
        if p >= 0:
            for n in tri:
                out[n].add(int(p))
    strip = [(tri, set().union(*(out[n] for n in tri))) for tri in tris[panel < 0]]
    for tri, joined in strip:
        for n in tri:
            if not out[n]:
                out[n] = set(joined)
    for tri, _ in strip:  # a strip node reached only through other strip nodes
        for n in tri:
            if not out[n]:
                out[n] = set().union(*(out[m] for m in tri))
    return out


def contact_model(contact, structure, asm=None, thickness=None):
    """The :class:`PanelContact` of ``fold_pattern(contact=...)``: None for None/False, the
    given one, or (True) one built with kappa from ``asm``'s tangent at the flat state."""
    if contact is None or contact is False:
        return None
    if isinstance(contact, PanelContact):
        return contact
    if contact is not True:
        raise ParameterError(f"contact = {contact!r}; allowed: None, False, True, PanelContact")
    _ipctk()
    stiffness = None
    if asm is not None:
        K = asm.evaluate_reduced(np.zeros(asm.n_dof), dense=False)[2]
        diag = np.abs(K.diagonal())
        stiffness = float(np.median(diag[diag > 0])) if (diag > 0).any() else 1.0
    return PanelContact(structure, thickness=thickness, stiffness=stiffness)


def intersects(structure, U) -> bool:
    """True if the panel triangles of ``structure`` displaced by ``U`` intersect (ipctk)."""
    ipc = _ipctk()
    X = np.asfortranarray(structure.nodes + np.asarray(U, float).reshape(-1, 3))
    faces = np.asfortranarray(structure.triangles, dtype=np.int32)
    mesh = ipc.CollisionMesh(X, np.asfortranarray(ipc.edges(faces), dtype=np.int32), faces)
    return bool(ipc.has_intersections(mesh, X))
