"""The generalised Miura-ori quad mesh: topology, conditions with analytic Jacobians, flat layout.

An m x n grid of quads (m along the zig-zag direction i, n along j), vertex (i, j) with id
``i (n + 1) + j`` and quad (i, j) with id ``i n + j`` looping (i, j), (i+1, j), (i+1, j+1),
(i, j+1): the numbering of :func:`holofold.geometry.miura.miura_faces`. Its folded state X
(nv, 3) m is a generalised Miura-ori (docs/surface-fit.md §3) when

* every quad is planar: ``P = (x1 - x0) . ((x2 - x0) x (x3 - x0)) = 0``;
* at every interior vertex the four sector angles sum to 2 pi (the mesh develops flat) and
  opposite sectors sum to pi (Kawasaki: it folds flat), written ``a + b + c + d - 2 pi = 0``
  and ``a - b + c - d = 0`` with a..d the corners of quads (i-1, j-1), (i, j-1), (i, j),
  (i-1, j).

With these a flat-foldable quad mesh with one folded state folds rigidly with one degree of
freedom (Tachi 2009). The rows j = 0, 2, 4, ... of vertices are one side of the corrugated sheet
(its vertex side: the zig-zag ridges of one face), the odd rows the other.

Each condition comes with its Jacobian as a scipy sparse matrix; the sparsity pattern is built
once per grid (:class:`SparsePattern`) and only its values are recomputed.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

__all__ = [
    "QuadGrid",
    "SparsePattern",
    "sector_angles",
    "planarity",
    "vertex_conditions",
    "constraints",
    "develop",
    "planarity_scale",
    "quad_warp",
]


class SparsePattern:
    """A fixed COO pattern (rows, cols) turned into CSR matrices from values alone.

    Duplicate (row, col) entries are summed. ``matrix(values)`` costs one gather and one
    ``np.add.reduceat``.
    """

    def __init__(self, rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]):
        rows = np.asarray(rows, np.int64)
        cols = np.asarray(cols, np.int64)
        key = rows * shape[1] + cols
        self.order = np.argsort(key, kind="stable")
        k = key[self.order]
        head = np.flatnonzero(np.concatenate([[True], k[1:] != k[:-1]]))
        self.starts = head
        uk = k[head]
        self.indices = (uk % shape[1]).astype(np.int32)
        r = uk // shape[1]
        self.indptr = np.searchsorted(r, np.arange(shape[0] + 1)).astype(np.int32)
        self.shape = shape

    def matrix(self, values: np.ndarray) -> sp.csr_matrix:
        data = np.add.reduceat(np.asarray(values, float)[self.order], self.starts)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)


def _dofs(v: np.ndarray) -> np.ndarray:
    """(..., 3) DOF ids x, y, z of vertex ids ``v``."""
    return 3 * np.asarray(v)[..., None] + np.arange(3)


@dataclass(frozen=True)
class QuadGrid:
    """Topology of the m x n quad grid (see the module docstring)."""

    m: int
    n: int

    @property
    def nv(self) -> int:
        return (self.m + 1) * (self.n + 1)

    def vid(self, i, j):
        return np.asarray(i) * (self.n + 1) + np.asarray(j)

    @cached_property
    def ij(self) -> tuple[np.ndarray, np.ndarray]:
        """(nv,) i and j of every vertex."""
        k = self.n + 1
        v = np.arange(self.nv)
        return v // k, v % k

    @cached_property
    def quads(self) -> np.ndarray:
        """(m n, 4) vertex loops, quad id i n + j."""
        i, j = np.meshgrid(np.arange(self.m), np.arange(self.n), indexing="ij")
        i, j = i.ravel(), j.ravel()
        return np.stack(
            [self.vid(i, j), self.vid(i + 1, j), self.vid(i + 1, j + 1), self.vid(i, j + 1)], 1
        )

    @cached_property
    def interior(self) -> tuple[np.ndarray, np.ndarray]:
        """Interior vertices: ``ids`` (ni,) and ``corners`` (ni, 4, 2) = (quad, corner) of the
        sectors a, b, c, d around each (quads (i-1, j-1), (i, j-1), (i, j), (i-1, j))."""
        i, j = np.meshgrid(np.arange(1, self.m), np.arange(1, self.n), indexing="ij")
        i, j = i.ravel(), j.ravel()
        n = self.n
        q = np.stack([(i - 1) * n + j - 1, i * n + j - 1, i * n + j, (i - 1) * n + j], 1)
        c = np.broadcast_to(np.array([2, 3, 0, 1]), q.shape)
        return self.vid(i, j), np.stack([q, c], axis=2)

    @cached_property
    def side(self) -> np.ndarray:
        """Vertex ids of the fitted side: rows j = 0, 2, 4, ..."""
        return np.flatnonzero(self.ij[1] % 2 == 0)

    @cached_property
    def fairness_stencils(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Fairness differences as (vertex ids (k, s), weights (s,)): along i the difference
        x(i-1) - x(i) - x(i+1) + x(i+2), zero on a straight zig-zag; along j the step-2 second
        difference x(j-2) - 2 x(j) + x(j+2), zero on a straight corrugation."""
        i, j = self.ij
        out = []
        sel = (i >= 1) & (i + 2 <= self.m)
        ii, jj = i[sel], j[sel]
        out.append((np.stack([self.vid(ii + o, jj) for o in (-1, 0, 1, 2)], 1),
                    np.array([1.0, -1.0, -1.0, 1.0])))  # fmt: skip
        sel = (j >= 2) & (j + 2 <= self.n)
        ii, jj = i[sel], j[sel]
        out.append((np.stack([self.vid(ii, jj + o) for o in (-2, 0, 2)], 1),
                    np.array([1.0, -2.0, 1.0])))  # fmt: skip
        return out

    # ----------------------------------------------------------------- sparsity patterns
    @cached_property
    def constraint_pattern(self) -> SparsePattern:
        """Rows: m n planarity, then ni angle sums, then ni Kawasaki."""
        nq = self.m * self.n
        ids, corners = self.interior
        ni = len(ids)
        rows = [np.repeat(np.arange(nq), 12)]
        cols = [_dofs(self.quads).reshape(-1)]
        q, c = corners[..., 0], corners[..., 1]
        tri = self._corner_vertices(q, c)  # (ni, 4, 3): vertex, next, prev
        for off in (nq, nq + ni):
            rows.append(np.repeat(off + np.arange(ni), 4 * 3 * 3))
            cols.append(_dofs(tri).reshape(-1))
        return SparsePattern(np.concatenate(rows), np.concatenate(cols), (nq + 2 * ni, 3 * self.nv))

    def _corner_vertices(self, q: np.ndarray, c: np.ndarray) -> np.ndarray:
        """(..., 3) the corner vertex, the next and the previous vertex of its quad loop."""
        Q = self.quads
        return np.stack([Q[q, c], Q[q, (c + 1) % 4], Q[q, (c + 3) % 4]], axis=-1)

    @cached_property
    def band_order(self) -> np.ndarray:
        """(3 nv,) DOF order that makes the normal matrix banded: vertices run along the
        shorter side first."""
        i, j = self.ij
        v = np.lexsort((j, i)) if self.n <= self.m else np.lexsort((i, j))
        return _dofs(v).reshape(-1)

    @property
    def bandwidth(self) -> int:
        """Upper bandwidth of J^T J for the constraints and the side terms in :attr:`band_order`."""
        k = min(self.m, self.n) + 1
        return 3 * (2 * k + 2) + 2


# ---------------------------------------------------------------------------- conditions
def sector_angles(X: np.ndarray, quads: np.ndarray, *, gradients: bool = False):
    """Corner angles (nq, 4) rad of every quad in 3-D; with ``gradients`` also their
    derivatives (nq, 4, 3, 3) with respect to the corner, next and previous vertex."""
    p = X[quads]
    u = np.roll(p, -1, axis=1) - p
    w = np.roll(p, 1, axis=1) - p
    lu = np.linalg.norm(u, axis=2)
    lw = np.linalg.norm(w, axis=2)
    uh = u / lu[..., None]
    wh = w / lw[..., None]
    cos = np.einsum("qkd,qkd->qk", uh, wh)
    sin = np.linalg.norm(np.cross(uh, wh), axis=2)
    th = np.arctan2(sin, cos)
    if not gradients:
        return th
    s = np.maximum(sin, 1e-12)[..., None]
    gu = -(wh - cos[..., None] * uh) / (lu[..., None] * s)
    gw = -(uh - cos[..., None] * wh) / (lw[..., None] * s)
    return th, np.stack([-(gu + gw), gu, gw], axis=2)


def planarity(X: np.ndarray, quads: np.ndarray, scale: np.ndarray):
    """Planarity residuals ``P / scale`` (nq,) and their Jacobian values (nq, 4, 3).

    ``P`` is the triple product of the quad's edges from corner 0 (six times the volume of its
    tetrahedron); ``scale`` (nq,) m^3 makes it dimensionless (held fixed during a solve).
    """
    p = X[quads]
    a1, a2, a3 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    g1, g2, g3 = np.cross(a2, a3), np.cross(a3, a1), np.cross(a1, a2)
    P = np.einsum("qd,qd->q", a1, g1)
    G = np.stack([-(g1 + g2 + g3), g1, g2, g3], axis=1) / scale[:, None, None]
    return P / scale, G


def vertex_conditions(X: np.ndarray, grid: QuadGrid):
    """Angle-sum and Kawasaki residuals (2 ni,) rad and their Jacobian values (2, ni, 4, 3, 3)."""
    th, g = sector_angles(X, grid.quads, gradients=True)
    _, corners = grid.interior
    q, c = corners[..., 0], corners[..., 1]
    a = th[q, c]  # (ni, 4)
    ga = g[q, c]  # (ni, 4, 3, 3)
    sign = np.array([1.0, -1.0, 1.0, -1.0])
    r = np.concatenate([a.sum(axis=1) - 2 * np.pi, a @ sign])
    G = np.stack([ga, ga * sign[None, :, None, None]])
    return r, G


def constraints(X: np.ndarray, grid: QuadGrid, scale: np.ndarray, *, jacobian: bool = True):
    """All conditions (planarity, angle sums, Kawasaki) and their Jacobian (sparse)."""
    rp, Gp = planarity(X, grid.quads, scale)
    rv, Gv = vertex_conditions(X, grid)
    r = np.concatenate([rp, rv])
    if not jacobian:
        return r
    return r, grid.constraint_pattern.matrix(np.concatenate([Gp.ravel(), Gv.ravel()]))


def planarity_scale(X: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """(nq,) |d1 x d2| mean(|d1|, |d2|) of the diagonals d1, d2: the scale of the triple product,
    so that ``P / scale`` is the distance between the diagonals over their mean length."""
    p = X[quads]
    d1, d2 = p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]
    l1, l2 = np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)
    return np.linalg.norm(np.cross(d1, d2), axis=1) * 0.5 * (l1 + l2)


def quad_warp(X: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """(nq,) distance between each quad's diagonals over their mean length (0 = planar)."""
    p = X[quads]
    a1, a2, a3 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    P = np.einsum("qd,qd->q", a1, np.cross(a2, a3))
    return np.abs(P) / planarity_scale(X, quads)


# ---------------------------------------------------------------------------- development
def develop(X: np.ndarray, grid: QuadGrid) -> np.ndarray:
    """The flat layout (nv, 2) m of a developable quad mesh, every quad counter-clockwise.

    Each quad is expressed in its own plane (2-D coordinates in a frame on its first edge, its
    normal from its diagonals, so that the loop is counter-clockwise). The quads' rotations in
    the layout are the least-squares solution of the rotation differences across shared edges
    (a graph Laplacian on the quads), then the vertices are the least-squares solution of every
    quad edge and diagonal rotated into place (a Laplacian on the vertices). Both solves are
    global, so rounding does not grow across the sheet as it does when quads are unfolded one
    from the next; where the mesh is developable the layout is exact.
    """
    import scipy.sparse.linalg as spla

    Q = grid.quads
    nq, nv = len(Q), grid.nv
    P = X[Q]  # (nq, 4, 3)
    nrm = np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1])
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    e1 = P[:, 1] - P[:, 0]
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(nrm, e1)
    d = P - P[:, :1]
    loc = np.stack([np.einsum("qkd,qd->qk", d, e1), np.einsum("qkd,qd->qk", d, e2)], axis=2)
    # shared edges: (quad a, side sa) and (quad b, side sb) run the edge in opposite directions
    m, n = grid.m, grid.n
    qid = np.arange(nq).reshape(m, n)
    pairs = []
    # quad (i, j) side 1 (corner 1 -> 2) is quad (i+1, j) side 3 (corner 3 -> 0)
    pairs.append((qid[:-1, :].ravel(), 1, qid[1:, :].ravel(), 3))
    # quad (i, j) side 2 (corner 2 -> 3) is quad (i, j+1) side 0 (corner 0 -> 1)
    pairs.append((qid[:, :-1].ravel(), 2, qid[:, 1:].ravel(), 0))
    rows, cols, vals, rhs = [], [], [], []
    r = 0
    for a, sa, b, sb in pairs:
        va = loc[a, (sa + 1) % 4] - loc[a, sa]
        vb = loc[b, sb] - loc[b, (sb + 1) % 4]  # reversed: same direction as va
        diff = np.arctan2(va[:, 1], va[:, 0]) - np.arctan2(vb[:, 1], vb[:, 0])
        diff = (diff + np.pi) % (2 * np.pi) - np.pi  # psi_b - psi_a
        k = len(a)
        rows += [r + np.arange(k)] * 2
        cols += [b, a]
        vals += [np.ones(k), -np.ones(k)]
        rhs.append(diff)
        r += k
    rows.append(np.array([r]))
    cols.append(np.array([0]))
    vals.append(np.array([1.0]))
    rhs.append(np.array([0.0]))
    A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(r + 1, nq))  # fmt: skip
    psi = spla.spsolve((A.T @ A).tocsc(), A.T @ np.concatenate(rhs))
    c, s = np.cos(psi), np.sin(psi)
    # vertex positions: every side and both diagonals of every quad, rotated by psi
    ends = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [0, 2], [1, 3]])
    va = Q[:, ends[:, 0]].ravel()
    vb = Q[:, ends[:, 1]].ravel()
    dl = loc[:, ends[:, 1]] - loc[:, ends[:, 0]]  # (nq, 6, 2)
    dx = c[:, None] * dl[..., 0] - s[:, None] * dl[..., 1]
    dy = s[:, None] * dl[..., 0] + c[:, None] * dl[..., 1]
    k = len(va)
    B = sp.csr_matrix((np.concatenate([np.ones(k), -np.ones(k), [1.0]]),
                       (np.concatenate([np.arange(k), np.arange(k), [k]]),
                        np.concatenate([vb, va, [Q[0, 0]]]))), shape=(k + 1, nv))  # fmt: skip
    N = (B.T @ B).tocsc()
    solve = spla.factorized(N)
    Y = np.stack([solve(B.T @ np.append(dx.ravel(), 0.0)), solve(B.T @ np.append(dy.ravel(), 0.0))],
                 axis=1)  # fmt: skip
    return Y


def _develop_marching(X: np.ndarray, grid: QuadGrid) -> np.ndarray:
    """Row-by-row unfolding (kept for the tests: it agrees with :func:`develop` on small meshes
    and shows the growth of rounding on large ones)."""
    m, n = grid.m, grid.n
    Q = grid.quads.reshape(m, n, 4)
    P = X[grid.quads]
    nrm = np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1]).reshape(m, n, 3)
    nrm /= np.linalg.norm(nrm, axis=2, keepdims=True)
    Y = np.full((grid.nv, 2), np.nan)

    def place(a, b, p, normal, A, B):
        """Flat image of 3-D points p (k, s, 3) in the plane of edge a->b (k, 3)."""
        e1 = b - a
        e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
        e2 = np.cross(normal, e1)
        d = p - a[:, None]
        s = np.einsum("ksd,kd->ks", d, e1)
        t = np.einsum("ksd,kd->ks", d, e2)
        E1 = B - A
        E1 /= np.linalg.norm(E1, axis=-1, keepdims=True)
        E2 = np.stack([-E1[:, 1], E1[:, 0]], axis=1)
        return A[:, None] + s[..., None] * E1[:, None] + t[..., None] * E2[:, None]

    # row j = 0: quad (0, 0) fixed by its first edge along +x, then neighbours along i
    q0 = Q[0, 0]
    L = np.linalg.norm(X[q0[1]] - X[q0[0]])
    Y[q0[0]] = (0.0, 0.0)
    Y[q0[1]] = (L, 0.0)
    for i in range(m):
        q = Q[i, 0]
        pts = place(X[q[0]][None], X[q[1]][None], X[q[[2, 3]]][None], nrm[i, 0][None],
                    Y[q[0]][None], Y[q[1]][None])[0]  # fmt: skip
        Y[q[3]] = pts[1] if i == 0 else 0.5 * (Y[q[3]] + pts[1])
        Y[q[2]] = pts[0]
        if i + 1 < m:  # next quad's bottom-right corner from this quad's right edge
            nq = Q[i + 1, 0]
            pts = place(X[nq[3]][None], X[nq[0]][None], X[nq[[1]]][None], nrm[i + 1, 0][None],
                        Y[nq[3]][None], Y[nq[0]][None])[0]  # fmt: skip
            Y[nq[1]] = pts[0]
    for j in range(1, n):
        q = Q[:, j]  # (m, 4): bottom edge q0 -> q1 is placed
        pts = place(X[q[:, 0]], X[q[:, 1]], X[q[:, 2:4]], nrm[:, j], Y[q[:, 0]], Y[q[:, 1]])
        top_right, top_left = pts[:, 0], pts[:, 1]
        acc = np.zeros((grid.nv, 2))
        cnt = np.zeros(grid.nv)
        np.add.at(acc, q[:, 2], top_right)
        np.add.at(acc, q[:, 3], top_left)
        np.add.at(cnt, q[:, 2], 1)
        np.add.at(cnt, q[:, 3], 1)
        sel = cnt > 0
        Y[sel] = acc[sel] / cnt[sel, None]
    return Y
