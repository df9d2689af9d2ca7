"""Global energy, internal force and tangent stiffness with a sparse pattern built once.

The pattern (CSR ``indptr``/``indices`` and the data slot of every entry the element kernels
produce) depends only on the connectivity, so it is computed once per topology and cached (keyed
on a hash of the bar and spring connectivity: every sample of one Miura m x n or arch m shares
it); each evaluation runs the compiled element kernels (:mod:`~holofold.mechanics._compiled`)
and fills the CSR data, the dense free-free block or the band by one scatter of the kernels'
entries in the order they lie in memory (bars, springs and the mirrors of their off-diagonal
blocks, each family summed in ``np.bincount``'s order, then added). Supports are handled by
elimination: the free-free slots, the reduced CSR pattern, the fill-reducing orderings and the
sum lists are cached per support mask.

Linear solves on the free DOFs (:meth:`Assembler.evaluate_factorized`) pick the fastest path:
dense LAPACK LU up to :data:`DENSE_MAX_DOF` free DOFs, then a banded Cholesky on a cached reverse
Cuthill-McKee ordering, and SuperLU (LU with a cached minimum-degree ordering, natural column
order at factorisation time) when the band is too wide or the tangent is not positive definite.
Supports by elimination are exactly the reference's "zero the row and column, keep the diagonal,
zero the residual" (the supported increments are 0 either way).

Typical use::

    asm = Assembler(structure)
    energy, f_int, K = asm.evaluate(U)                 # full system, K csr (ndof, ndof)
    energy, f_int, K_ff = asm.evaluate_reduced(U)      # K on the free DOFs (dense or csr)
    energy, f_int, solve = asm.evaluate_factorized(U)  # dU_f = solve(r[asm.free_dofs])
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from functools import cached_property
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg.lapack import dgetrf, dgetrs, dpbtrf, dpbtrs
from scipy.sparse.csgraph import reverse_cuthill_mckee

from holofold.mechanics.bars import ElementResponse
from holofold.mechanics.springs import SPRING_BLOCKS, arccos_shift
from holofold.mechanics.structure import Structure

__all__ = [
    "AssemblyPattern",
    "Assembler",
    "BatchAssembler",
    "AssembledSystem",
    "ReducedPattern",
    "SingularSystemError",
    "assembly_pattern",
    "DENSE_MAX_DOF",
    "BANDED_MAX_WORK",
    "solver_path",
]

#: Reduced systems with at most this many free DOFs are assembled and solved densely (LAPACK);
#: larger ones sparsely (crossover measured at ~200 DOFs).
DENSE_MAX_DOF = 200
#: Sparse systems whose reverse Cuthill-McKee band costs at most this many flops
#: (n * (bandwidth + 1)^2) first try a banded Cholesky factorisation; SuperLU (LU with a cached
#: minimum-degree ordering) handles the rest and every matrix that is not positive definite.
#: Measured (benchmarks/bench_solvers.py, Miura sheets 24 x 8 to 96 x 32, work 1.3e7 to 2.8e9):
#: banded Cholesky + solve is 1.6-3.9x faster than SuperLU at every size (72 x 24: 120 ms
#: against 186 ms), so the banded path is taken up to the largest measured work (it was 3e8,
#: which sent 60 x 20 and 72 x 24 to SuperLU).
BANDED_MAX_WORK = 3e9


_COMPILED = None


def _ck():
    """The compiled kernels (:mod:`holofold.mechanics._compiled`), imported on first use: numba
    is imported only by a process that assembles."""
    global _COMPILED
    if _COMPILED is None:
        from holofold.mechanics import _compiled

        _COMPILED = _compiled
    return _COMPILED


def _sum_lists(families, n: int, dest=None):
    """The lists of :func:`holofold.mechanics._compiled.scatter` for up to three element
    families (bars, springs, spring mirrors) ``pos`` -> targets ``0..n-1`` written to
    ``out[dest[t]]`` (default ``out[t]``): per family the flat kernel-layout index of every
    entry that has a target (``pos`` outside ``0..n-1``: dropped), in flat order, the order in
    which ``np.bincount`` adds them, and its target's position among the targets that receive
    something; then those targets (``out`` must start as zeros)."""
    counts = np.zeros(n, np.intp)
    kept = []
    for pos in families:
        pos = np.asarray(pos).ravel()
        src = np.flatnonzero((pos >= 0) & (pos < n))
        kept.append((src, pos[src]))
        counts += np.bincount(pos[src], minlength=n)
    hit = np.flatnonzero(counts > 0)
    where = np.full(n, -1, np.intp)
    where[hit] = np.arange(hit.size)
    i4 = lambda x: np.ascontiguousarray(x, np.int32)  # noqa: E731 - half the index traffic
    out = []
    for src, tgt in kept:
        out += [i4(src), i4(where[tgt])]
    while len(out) < 6:
        out += [np.zeros(0, np.int32), np.zeros(0, np.int32)]
    targets = hit if dest is None else np.asarray(dest, np.intp)[hit]
    return (*out, i4(targets))


class SingularSystemError(RuntimeError):
    """The reduced tangent stiffness could not be factorised or solved."""


_PATTERN_CACHE: OrderedDict[bytes, AssemblyPattern] = OrderedDict()
_PATTERN_CACHE_SIZE = 8


class AssembledSystem(NamedTuple):
    """Result of one evaluation (unpacks as ``energy, force, stiffness``).

    energy     float                     total strain energy, J
    force      (ndof,) float             internal force vector T(U), N
    stiffness  csr (n, n) | (n, n) array tangent stiffness (full, or free-free block), N/m
    """

    energy: float
    force: np.ndarray
    stiffness: sp.csr_matrix | np.ndarray


class ReducedPattern:
    """Free-DOF reduction of an :class:`AssemblyPattern` for one support mask.

    Attributes
    ----------
    free : (nf,) int
        Free global DOFs (increasing).
    keep : (nnz_f,) int
        CSR slots of the full pattern whose row and column are free.
    indptr, indices : reduced CSR arrays (free DOFs in increasing order).
    dense : (nnz_f,) int
        Flat position ``row * nf + col`` of each kept slot in a dense (nf, nf) matrix.
    banded, banded_slots : computed on first use
        Reverse Cuthill-McKee ordering, half bandwidth, and the position of every element
        entry in LAPACK upper banded storage (banded Cholesky path).
    ordering : (order, perm_keep, perm_indptr, perm_indices), computed on first use
        A fill-reducing symmetric ordering ``order`` (``K[order][:, order]``, multiple minimum
        degree on K + K') and the CSR pattern of the permuted matrix, so that sparse solves
        factorise with SuperLU's natural ordering and no per-iteration ordering cost.
    """

    def __init__(self, pattern: AssemblyPattern, free_mask: np.ndarray):
        self._pattern = pattern
        free = np.flatnonzero(free_mask)
        n = pattern.n_dof
        new = np.full(n, -1, np.intp)
        new[free] = np.arange(free.size)
        r = new[pattern._rows]
        c = new[pattern.indices]
        keep = np.flatnonzero((r >= 0) & (c >= 0))
        nf = free.size
        self.free = free
        self.keep = keep
        self._r = r[keep]
        self._c = c[keep]
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(self._r, minlength=nf))]).astype(
            np.int32
        )
        self.indices = self._c.astype(np.int32)
        self.dense = (self._r * nf + self._c).astype(np.intp)

    @property
    def n_free(self) -> int:
        return self.free.size

    @cached_property
    def banded(self):
        """(perm, bandwidth, upper_keep, ab_pos): reverse Cuthill-McKee permutation of the
        free DOFs, its half bandwidth, the kept slots of the upper triangle of the permuted
        matrix and their flat positions in LAPACK upper banded storage (bw + 1, nf)."""
        nf = self.free.size
        A = sp.csr_matrix((np.ones(self._r.size), self.indices, self.indptr), shape=(nf, nf))
        perm = reverse_cuthill_mckee(A, symmetric_mode=True).astype(np.intp)
        inv = np.empty(nf, np.intp)
        inv[perm] = np.arange(nf)
        pr = inv[self._r]
        pc = inv[self._c]
        bw = int(np.abs(pr - pc).max()) if pr.size else 0
        up = pr <= pc
        ab_pos = (bw + pr[up] - pc[up]) * nf + pc[up]
        return perm, bw, self.keep[up], ab_pos.astype(np.intp)

    @cached_property
    def banded_slots(self):
        """(bar_ab, spring_ab, size): position in the flat upper banded storage (column-major,
        element (r, c) of the (bw + 1, nf) band at ``c (bw + 1) + r``) of every bar
        entry (kernel layout (3, 3, 2, 2, nb)) and every distinct spring-block entry ((3, 3,
        10, ns)), ``size`` (= (bw + 1) nf) for entries that are dropped: supported DOFs and the
        duplicate halves of symmetric pairs (lower node blocks of bars, the strictly lower
        triangle of diagonal blocks), so that one bincount per family fills the band."""
        pat = self._pattern
        perm, bw, _, _ = self.banded
        nf = self.free.size
        size = (bw + 1) * nf
        new = np.full(pat.n_dof, -1, np.intp)
        inv = np.empty(nf, np.intp)
        inv[perm] = np.arange(nf)
        new[self.free] = inv  # global DOF -> permuted reduced index

        def positions(slots, keep_mask):
            r = new[pat._rows[slots]]
            c = new[pat.indices[slots]]
            lo = np.minimum(r, c)
            hi = np.maximum(r, c)
            pos = hi * (bw + 1) + (bw + lo - hi)  # column-major (LAPACK's own layout)
            ok = keep_mask & (lo >= 0)
            return np.where(ok, pos, size).astype(np.intp)

        nb = pat.bar_dofs.shape[0]
        ns = pat.spring_dofs.shape[0]
        i = np.arange(3)[:, None]
        j = np.arange(3)[None, :]
        upper3 = i <= j  # (3, 3)
        # bars (3, 3, 2, 2, nb): keep blocks (0,0), (1,1) upper halves and (0,1) whole
        a = np.arange(2)[:, None]
        b = np.arange(2)[None, :]
        keep_b = ((a < b) | ((a == b) & upper3[:, :, None, None]))[..., None]
        keep_b = np.broadcast_to(keep_b, (3, 3, 2, 2, nb)).ravel()
        # springs (3, 3, 10, ns): off-diagonal blocks whole, diagonal blocks upper halves
        diag = SPRING_BLOCKS[:, 0] == SPRING_BLOCKS[:, 1]
        keep_s = (~diag[None, None, :] | upper3[:, :, None])[..., None]
        keep_s = np.broadcast_to(keep_s, (3, 3, 10, ns)).ravel()
        return positions(pat.bar_slot, keep_b), positions(pat.spring_slot, keep_s), size

    @cached_property
    def dense_sums(self):
        """Sum lists (bars, springs, spring mirrors; :func:`_sum_lists`) of the kept slots,
        for the flat dense free-free block (targets ``dense``)."""
        pat = self._pattern
        kidx = np.full(pat.nnz + 1, -1, np.intp)
        kidx[self.keep] = np.arange(self.keep.size)
        fams = (kidx[pat.bar_slot], kidx[pat.spring_slot], kidx[pat.spring_slot_mirror])
        return _sum_lists(fams, self.keep.size, self.dense)

    @cached_property
    def band_sums(self):
        """Sum lists (bars, springs, none) of the column-major upper band (see
        :attr:`banded_slots`)."""
        bar_ab, spring_ab, size = self.banded_slots
        return _sum_lists((bar_ab, spring_ab), size)

    def tangent_sums(self, path: str):
        """(lists, size) of :func:`_sum_lists` for a solver path's tangent target: the dense
        block (``"dense"``; ``"dense_cm"`` column-major), the band or the CSR data (cached)."""
        cache = self.__dict__.setdefault("_tangent_sums", {})
        if path not in cache:
            pat = self._pattern
            nf = self.n_free
            lists, n = (
                (self.dense_sums, nf**2) if path in ("dense", "dense_cm")
                else (self.band_sums, _band_size(self)) if path == "banded"
                else (pat.data_sums, pat.nnz)
            )  # fmt: skip
            if path == "dense_cm":  # column-major: the Fortran copy LAPACK factorises
                lists = (*lists[:6], (lists[6] % nf) * nf + lists[6] // nf)
            cache[path] = (lists, n)
        return cache[path]

    @cached_property
    def ordering(self):
        nf = self.free.size
        # symbolic ordering from the pattern alone (diagonally dominant stand-in values)
        vals = np.where(self._r == self._c, float(nf + 1), -1.0 / max(nf, 1))
        A = sp.csc_matrix((vals, self.indices, self.indptr), shape=(nf, nf))
        lu = spla.splu(
            A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
        )
        order = np.argsort(lu.perm_c)
        inv = np.empty(nf, np.intp)
        inv[order] = np.arange(nf)
        pr = inv[self._r]
        pc = inv[self._c]
        srt = np.argsort(pr.astype(np.int64) * nf + pc)
        perm_indptr = np.concatenate([[0], np.cumsum(np.bincount(pr, minlength=nf))])
        return (
            order,
            self.keep[srt],
            perm_indptr.astype(np.int32),
            pc[srt].astype(np.int32),
        )


class AssemblyPattern:
    """CSR sparsity pattern of the bar-and-spring tangent and the slot map of local entries.

    Parameters
    ----------
    n_dof : int
        Number of global DOFs (3 per node).
    bar_dofs : (nb, 6) int
        Global DOFs of each bar.
    spring_dofs : (ns, 12) int
        Global DOFs of each spring.

    Attributes
    ----------
    indptr, indices : CSR arrays of the (structurally symmetric) pattern; every diagonal is
        included.
    bar_slot : (36 nb,) int
        CSR data slot of every entry of the bar tangents in kernel layout (3, 3, 2, 2, nb)
        (see :func:`holofold.mechanics.bars.bar_kernel`).
    spring_slot, spring_slot_mirror : (90 ns,) int
        Slots of the ten distinct spring tangent blocks in kernel layout (3, 3, 10, ns) (see
        :func:`~holofold.mechanics.springs.spring_kernel`), and of their transposes (``nnz`` =
        discard, for the diagonal blocks).
    bar_force_dofs, spring_force_dofs : (6 nb,), (12 ns,) int
        Global DOF of every entry of the kernels' force arrays ((3, 2, nb) and (3, 4, ns)).
    nnz : int
    """

    def __init__(self, n_dof: int, bar_dofs: np.ndarray, spring_dofs: np.ndarray):
        self.n_dof = int(n_dof)
        self.bar_dofs = np.ascontiguousarray(bar_dofs, dtype=np.intp)
        self.spring_dofs = np.ascontiguousarray(spring_dofs, dtype=np.intp)
        nd = np.int64(self.n_dof)

        def keys(dofs, nodes):
            # bar kernel layout (3, 3, 2, 2, nb): entry [i, j, a, b, e] couples global
            # DOF (3 n_a + i) of element e with (3 n_b + j)
            d = dofs.astype(np.int64).reshape(-1, nodes, 3).transpose(2, 1, 0)  # (3, nodes, ne)
            return (d[:, None, :, None, :] * nd + d[None, :, None, :, :]).ravel()

        # spring kernel layout (3, 3, 10, ns): the ten distinct blocks (a, b) of SPRING_BLOCKS;
        # each is scattered to (a, b) and, if a != b, transposed to (b, a)
        ds = self.spring_dofs.astype(np.int64).reshape(-1, 4, 3).transpose(2, 1, 0)  # (3, 4, ns)
        ra = ds[:, None, SPRING_BLOCKS[:, 0], :]  # (3, 1, 10, ns): row DOF 3 n_a + i
        cb = ds[None, :, SPRING_BLOCKS[:, 1], :]  # (1, 3, 10, ns): column DOF 3 n_b + j
        ks_direct = (ra * nd + cb).ravel()
        offdiag = SPRING_BLOCKS[:, 0] != SPRING_BLOCKS[:, 1]
        ks_mirror_full = cb * nd + ra  # (3, 3, 10, ns)
        ks_mirror = ks_mirror_full[:, :, offdiag, :].ravel()

        diag = np.arange(nd, dtype=np.int64) * (nd + 1)
        kb = keys(self.bar_dofs, 2)
        allkeys = np.concatenate([kb, ks_direct, ks_mirror, diag])
        ukeys, inverse = np.unique(allkeys, return_inverse=True)
        inverse = inverse.ravel()
        nnz = int(ukeys.size)
        self.bar_slot = inverse[: kb.size].astype(np.intp)
        n1 = kb.size + ks_direct.size
        self.spring_slot = inverse[kb.size : n1].astype(np.intp)
        # mirror slots for every block; diagonal blocks go to a dump slot (index nnz)
        mirror = np.full(ks_mirror_full.shape, nnz, dtype=np.intp)
        mirror[:, :, offdiag, :] = inverse[n1 : n1 + ks_mirror.size].reshape(
            3, 3, int(offdiag.sum()), -1
        )
        self.spring_slot_mirror = mirror.ravel()
        rows = ukeys // nd
        self.indices = (ukeys % nd).astype(np.int32)
        self.indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(rows, minlength=self.n_dof))]
        ).astype(np.int32)
        self.nnz = int(ukeys.size)
        self._rows = rows.astype(np.intp)
        self.bar_force_dofs = self.bar_dofs.reshape(-1, 2, 3).transpose(2, 1, 0).ravel()
        self.spring_force_dofs = self.spring_dofs.reshape(-1, 4, 3).transpose(2, 1, 0).ravel()
        self._reduced: dict[bytes, ReducedPattern] = {}

    @cached_property
    def force_sums(self):
        """Sum lists (bars, springs, none) of the internal force (targets: the DOFs)."""
        n = self.n_dof
        return _sum_lists((self.bar_force_dofs, self.spring_force_dofs), n)

    @cached_property
    def data_sums(self):
        """Sum lists (bars, springs, spring mirrors) of the CSR data (targets: the slots)."""
        n = self.nnz
        return _sum_lists((self.bar_slot, self.spring_slot, self.spring_slot_mirror), n)

    def reduced(self, free_mask: np.ndarray) -> ReducedPattern:
        """The free-DOF reduction for a boolean (ndof,) mask (cached per mask)."""
        free_mask = np.asarray(free_mask, bool).ravel()
        if free_mask.size != self.n_dof:
            raise ValueError(f"free mask must have {self.n_dof} entries, got {free_mask.size}")
        key = np.packbits(free_mask).tobytes()
        red = self._reduced.get(key)
        if red is None:
            red = ReducedPattern(self, free_mask)
            self._reduced[key] = red
        return red

    def compatible(self, n_dof: int, bar_dofs: np.ndarray, spring_dofs: np.ndarray) -> bool:
        """True if this pattern was built for exactly this connectivity."""
        return (
            self.n_dof == n_dof
            and np.array_equal(self.bar_dofs, bar_dofs)
            and np.array_equal(self.spring_dofs, spring_dofs)
        )


def assembly_pattern(structure: Structure) -> AssemblyPattern:
    """The (cached) :class:`AssemblyPattern` of a structure's connectivity.

    Structures with the same number of nodes, bars and springs (e.g. every sample of one Miura
    m x n sheet) share one pattern; a small LRU cache keyed on a hash of the connectivity avoids
    rebuilding it.
    """
    h = hashlib.blake2b(digest_size=16)
    h.update(np.int64(structure.n_dof).tobytes())
    h.update(np.ascontiguousarray(structure.bars, np.int64).tobytes())
    h.update(b"|")
    h.update(np.ascontiguousarray(structure.springs, np.int64).tobytes())
    key = h.digest()
    pat = _PATTERN_CACHE.get(key)
    if pat is not None:
        _PATTERN_CACHE.move_to_end(key)
        return pat
    pat = AssemblyPattern(structure.n_dof, structure.bar_dofs, structure.spring_dofs)
    _PATTERN_CACHE[key] = pat
    while len(_PATTERN_CACHE) > _PATTERN_CACHE_SIZE:
        _PATTERN_CACHE.popitem(last=False)
    return pat


class Assembler:
    """Evaluate the global energy, internal force and tangent of a :class:`Structure`.

    Parameters
    ----------
    structure : Structure
        The model (reference coordinates, element properties, supports).
    pattern : AssemblyPattern, optional
        A pattern built for the same connectivity (default: the cached one).
    dense_max : int
        Reduced systems with at most this many free DOFs are built and solved dense
        (:meth:`evaluate_reduced` with ``dense=None``, :meth:`evaluate_factorized`).

    The assembler reads the structure's arrays once; build a new one for a changed structure
    (it is cheap: the pattern comes from the cache).
    """

    def __init__(
        self,
        structure: Structure,
        pattern: AssemblyPattern | None = None,
        *,
        dense_max: int = DENSE_MAX_DOF,
    ):
        if pattern is None:
            pattern = assembly_pattern(structure)
        elif not pattern.compatible(structure.n_dof, structure.bar_dofs, structure.spring_dofs):
            raise ValueError("pattern was built for another connectivity than this structure")
        self.structure = structure
        self.pattern = pattern
        self.dense_max = int(dense_max)
        self.X = structure.nodes
        self.bars = structure.bars
        self.springs = structure.springs
        self.L0 = structure.bar_length
        self.EA = structure.bar_E * structure.bar_area
        self.k = structure.spring_k
        self.theta0 = structure.spring_rest
        self.n_dof = structure.n_dof
        self._X = np.ascontiguousarray(self.X, dtype=float)
        self._b0 = np.ascontiguousarray(self.bars[:, 0], dtype=np.intp)
        self._b1 = np.ascontiguousarray(self.bars[:, 1], dtype=np.intp)
        XT = self._X.T
        self._D0 = np.ascontiguousarray(XT[:, self._b1] - XT[:, self._b0])  # (3, nb)
        self._sT = np.ascontiguousarray(self.springs.T, dtype=np.intp)  # (4, ns)
        self._L0 = np.ascontiguousarray(self.L0, dtype=float)
        self._EA = np.ascontiguousarray(self.EA, dtype=float)
        self._k = np.ascontiguousarray(self.k, dtype=float)
        self._k_nonneg = bool(np.all(self._k >= 0.0))
        self._arccos = structure.profile.arccos_dihedral and len(self.springs) > 0
        self._work = None

    @cached_property
    def reduction(self) -> ReducedPattern:
        """Free-DOF reduction for the structure's supports."""
        return self.pattern.reduced(~self.structure.supports.ravel())

    @property
    def free_dofs(self) -> np.ndarray:
        """(nf,) int: free global DOFs."""
        return self.reduction.free

    # ------------------------------------------------------------------ evaluation
    def _buffers(self):
        """Element arrays reused by every evaluation of this assembler (not thread-safe: one
        assembler per thread)."""
        if self._work is None:
            self._work = _element_buffers(len(self.bars), len(self.springs))
        return self._work

    def _kernels(self, U, spring_rest, tangent, buffers):
        """Run the compiled bar and spring kernels into ``buffers`` (:func:`_element_buffers`)."""
        _compiled = _ck()
        U = np.ascontiguousarray(np.asarray(U, dtype=float).reshape(-1, 3))
        if U.shape[0] != self.X.shape[0]:
            raise ValueError(f"U must have shape ({self.X.shape[0]}, 3), got {np.shape(U)}")
        if spring_rest is None:
            theta0 = self.theta0
        else:
            theta0 = np.asarray(spring_rest, float)
            if theta0.shape != self.theta0.shape:
                raise ValueError(
                    f"spring_rest must have shape {self.theta0.shape}, got {theta0.shape}"
                )
        if self._arccos:  # the reference's arccos angle (compat.Profile.arccos_dihedral)
            theta0 = theta0 + arccos_shift(self.X + U, self.springs)
        theta0 = np.ascontiguousarray(theta0, dtype=float)
        eb, fb, Kb, es, fs, Ks, th = buffers
        _compiled.bar_elements(
            self._X, U, self._b0, self._b1, self._D0, self._L0, self._EA, tangent, eb, fb, Kb
        )
        _compiled.spring_elements(
            self._X, U, self._sT, self._k, theta0, self._k_nonneg, tangent, es, fs, Ks, th
        )
        return buffers

    def element_response(self, U, spring_rest=None, *, tangent: bool = True):
        """Element-level bar and spring responses ``(bar, spring)`` in the kernels' layouts
        (see :func:`~holofold.mechanics.bars.bar_kernel` and
        :func:`~holofold.mechanics.springs.spring_kernel`); new arrays on every call."""
        eb, fb, Kb, es, fs, Ks, _ = self._kernels(
            U, spring_rest, tangent, _element_buffers(len(self.bars), len(self.springs))
        )
        return (
            ElementResponse(eb, fb, Kb if tangent else None),
            ElementResponse(es, fs, Ks if tangent else None),
        )

    def _elements(self, U, spring_rest, tangent=True):
        buffers = self._kernels(U, spring_rest, tangent, self._buffers())
        eb, fb, _, es, fs, _, _ = buffers
        energy = float(eb.sum() + es.sum())
        f = _sum(self.pattern.force_sums, fb, fs, np.zeros(self.n_dof))
        return energy, f, buffers

    def _scatter(self, buffers):
        """CSR data (nnz,) of the full tangent."""
        return _sum(self.pattern.data_sums, buffers[2], buffers[5], np.zeros(self.pattern.nnz))

    def _dense(self, buffers, red):
        """The free-free tangent block, dense (nf, nf)."""
        nf = red.n_free
        return _sum(red.dense_sums, buffers[2], buffers[5], np.zeros(nf * nf)).reshape(nf, nf)

    def _data(self, U, spring_rest, tangent=True):
        energy, f, buffers = self._elements(U, spring_rest, tangent)
        return energy, f, (self._scatter(buffers) if tangent else None)

    def internal_force(self, U, spring_rest=None) -> tuple[float, np.ndarray]:
        """Energy (J) and internal force (ndof,) N, without the tangent."""
        energy, f, _ = self._data(U, spring_rest, tangent=False)
        return energy, f

    def evaluate(self, U, spring_rest=None) -> AssembledSystem:
        """Energy, internal force (ndof,) and full tangent (csr ndof x ndof) at displacement U.

        Parameters
        ----------
        U : (nn, 3) or (ndof,) float
            Displacements from the reference coordinates, m.
        spring_rest : (ns,) float, optional
            Rest angles to use instead of ``structure.spring_rest``, rad.
        """
        energy, f, data = self._data(U, spring_rest)
        pat = self.pattern
        K = sp.csr_matrix((data, pat.indices, pat.indptr), shape=(self.n_dof, self.n_dof))
        return AssembledSystem(energy, f, K)

    def evaluate_reduced(self, U, spring_rest=None, *, dense: bool | None = None):
        """Energy, full internal force (ndof,) and the free-free tangent block.

        The block is a dense ``(nf, nf)`` array when ``dense`` is True (default: when
        ``nf <= dense_max``), otherwise a csr matrix. Its rows/columns follow
        :attr:`free_dofs`.
        """
        energy, f, rb = self._elements(U, spring_rest)
        red = self.reduction
        nf = red.free.size
        if dense is None:
            dense = nf <= self.dense_max
        if dense:
            K = self._dense(rb, red)
        else:
            data = self._scatter(rb)
            K = sp.csr_matrix((data[red.keep], red.indices, red.indptr), shape=(nf, nf))
        return AssembledSystem(energy, f, K)

    def evaluate_factorized(self, U, spring_rest=None):
        """Energy, full internal force (ndof,) and a solver for the free-free tangent.

        Returns
        -------
        energy : float
        force : (ndof,) float
        solve : callable
            ``solve(rhs)`` with ``rhs`` (nf,) or (nf, k) on :attr:`free_dofs` returns
            ``K_ff^-1 rhs``; one factorisation serves every call. Raises
            :class:`SingularSystemError` if ``K_ff`` is singular or the solution is not finite.
        """
        energy, f, rb = self._elements(U, spring_rest)
        red = self.reduction
        path = solver_path(red, self.dense_max)
        if path == "none":
            return energy, f, lambda rhs: np.zeros_like(rhs, dtype=float)
        if path == "dense":
            return energy, f, _dense_solver(self._dense(rb, red))
        if path == "banded":
            solve = _band_solver(_sum(red.band_sums, rb[2], rb[5], _band_zeros(red)), red)
            if solve is not None:
                return energy, f, solve
            # not positive definite: LU below
        return energy, f, _lu_solver(self._scatter(rb), red)

    def dense_newton_update(self, U, F, spring_rest=None, r=None):
        """One compiled Newton update on the dense path, bit for bit
        ``_, f, solve = evaluate_factorized(U, spring_rest); r = (F - f)[free]; dU = solve(r);
        U[free] += dU`` in one numba call (kernels, scatters, ``dgetrf``/``dgetrs`` by address).

        Parameters
        ----------
        U : (ndof,) float, C-contiguous
            Displacements, updated in place, m.
        F : (ndof,) float, C-contiguous
            External force, N.
        spring_rest : (ns,) float, C-contiguous, optional
            Rest angles (default ``structure.spring_rest``), rad.
        r : (nf,) float, optional
            Filled with the residual ``(F - f_int(U))[free]`` before the update, N.

        Returns
        -------
        (nf,) float or None
            The increment ``dU`` on :attr:`free_dofs` (a buffer the next call overwrites), or
            None (nothing done) where this assembler does not take the dense path or uses the
            reference's arccos angle; then call :meth:`evaluate_factorized`. Raises
            :class:`SingularSystemError` as the dense solver would (U left alone).
        """
        step = self.dense_stepper(U, F, spring_rest, r)
        return None if step is None else step()

    def dense_stepper(self, U, F, spring_rest=None, r=None):
        """``step()``: :meth:`dense_newton_update` with these arguments bound once (a loop of
        Newton iterations on one increment calls it over and over), or None off the dense
        path."""
        st = self._dense_step
        if st is None:
            return None
        fn, X, mid, after, post, dU, info, theta0 = st
        rest = theta0 if spring_rest is None else spring_rest.reshape(1, -1)
        res = dU if r is None else r.reshape(1, -1)
        args = (
            X, U.reshape(1, -1, 3), *mid, rest, *after, F.reshape(1, -1), *post,
            U.reshape(1, -1), dU, info, res,
        )  # fmt: skip
        out = dU[0]

        def step():
            fn(*args)
            if info[0]:
                raise SingularSystemError(_SINGULAR if info[0] == 1 else _NON_FINITE)
            return out

        return step

    @cached_property
    def _dense_step(self):
        """``_compiled.dense_newton_step`` and its fixed arguments for this one design, as a
        batch of one (None off the dense path or with the arccos angle)."""
        red = self.reduction
        if self._arccos or solver_path(red, self.dense_max) != "dense":
            return None
        ck = _ck()
        one = lambda a: a.reshape((1, *a.shape))  # noqa: E731
        mid = tuple(map(one, (self._b0, self._b1, self._D0, self._L0, self._EA, self._sT, self._k)))
        views, flats = _scratch_buffers(len(self.bars), len(self.springs))
        lists, _ = red.tangent_sums("dense_cm")
        force = self.pattern.force_sums
        after = (np.array([self._k_nonneg]), np.zeros(1, np.intp), force, lists, views, flats)
        post = (red.free, ck.lapack_addresses("dgetrf", "dgetrs"))
        dU = np.empty((1, red.n_free))
        theta0 = np.ascontiguousarray(self.theta0, dtype=float).reshape(1, -1)
        return (
            ck.dense_newton_step,
            one(self._X),
            mid,
            after,
            post,
            dU,
            np.zeros(1, np.int8),
            theta0,
        )


def solver_path(red: ReducedPattern, dense_max: int = DENSE_MAX_DOF) -> str:
    """The linear-solver path of a reduction: ``"none"`` (no free DOF), ``"dense"`` (LAPACK LU
    up to ``dense_max`` free DOFs), ``"banded"`` (Cholesky, band work up to
    :data:`BANDED_MAX_WORK`; SuperLU if the tangent is not positive definite) or ``"superlu"``."""
    nf = red.n_free
    if nf == 0:
        return "none"
    if nf <= dense_max:
        return "dense"
    _, bw, _, _ = red.banded
    return "banded" if nf * (bw + 1) ** 2 <= BANDED_MAX_WORK else "superlu"


def _band_zeros(red: ReducedPattern) -> np.ndarray:
    return np.zeros(_band_size(red))


def _dense_solver(K: np.ndarray):
    """``solve(rhs)`` by LAPACK LU of the dense (nf, nf) ``K``.

    One right-hand side: ``dgetrf`` on the first call, ``dgetrs`` per call (two thirds of the
    cost of ``np.linalg.solve`` at 100 DOFs, the same solution bit for bit: 3112 of 3112
    gripper systems and tests/test_compiled.py). Several: ``np.linalg.solve``, whose
    multi-column triangular solves round differently. A singular K raises at the solve.
    """
    lu = None

    def solve(rhs):
        nonlocal lu
        if np.ndim(rhs) != 1:
            try:
                x = np.linalg.solve(K, rhs)
            except np.linalg.LinAlgError as exc:
                raise SingularSystemError(f"singular stiffness matrix ({exc})") from None
            return _finite(x)
        if lu is None:
            lu = dgetrf(K)
        if lu[2] > 0:
            raise SingularSystemError(_SINGULAR)
        x, _ = dgetrs(lu[0], lu[1], rhs)
        return _finite(x)

    return solve


def _band_solver(ab: np.ndarray, red: ReducedPattern):
    """``solve(rhs)`` by banded Cholesky of the flat column-major upper band ``ab`` (factorised
    in place), or None if the matrix is not positive definite."""
    perm, bw, _, _ = red.banded
    nf = red.n_free
    c, info = dpbtrf(ab.reshape(nf, bw + 1).T, lower=0, overwrite_ab=1)
    if info != 0:
        return None

    def solve(rhs):
        y, info = dpbtrs(c, rhs[perm], lower=0)
        if info != 0:  # pragma: no cover - only for invalid arguments
            raise SingularSystemError(f"banded solve failed (LAPACK info {info})")
        x = np.empty_like(y)
        x[perm] = y
        return _finite(x)

    return solve


def _lu_solver(data: np.ndarray, red: ReducedPattern):
    """``solve(rhs)`` by SuperLU of the free-free block of the CSR ``data`` (cached ordering)."""
    nf = red.n_free
    order, perm_keep, perm_indptr, perm_indices = red.ordering
    # csc from the permuted CSR arrays is Kp^T; factorise it and solve with trans='T'
    KpT = sp.csc_matrix((data[perm_keep], perm_indices, perm_indptr), shape=(nf, nf))
    try:
        lu = spla.splu(
            KpT,
            permc_spec="NATURAL",
            diag_pivot_thresh=0.01,
            relax=3,
            panel_size=10,
            options={"SymmetricMode": True},
        )
    except RuntimeError as exc:
        raise SingularSystemError(f"singular stiffness matrix ({exc})") from None

    def solve(rhs):
        y = lu.solve(np.ascontiguousarray(rhs[order]), trans="T")
        x = np.empty_like(y)
        x[order] = y
        return _finite(x)

    return solve


def _sum(lists, bar_values, spring_values, out):
    """``out`` (zeros) filled by :func:`holofold.mechanics._compiled.scatter` with ``lists``
    (:func:`_sum_lists`: bars, springs, spring mirrors) from the element arrays."""
    vb = bar_values.reshape(-1)
    vs = spring_values.reshape(-1)
    acc = np.empty(3 * lists[6].size)
    _ck().scatter(*lists[:2], vb, *lists[2:4], vs, *lists[4:6], vs, lists[6], acc, out)
    return out


def _element_buffers(nb: int, ns: int):
    """Empty element arrays in the kernels' layouts: bar energy (nb,), force (3, 2, nb),
    tangent (3, 3, 2, 2, nb); spring energy (ns,), force (3, 4, ns), tangent (3, 3, 10, ns),
    angle (ns,)."""
    return (
        np.empty(nb), np.empty((3, 2, nb)), np.empty((3, 3, 2, 2, nb)),
        np.empty(ns), np.empty((3, 4, ns)), np.empty((3, 3, 10, ns)), np.empty(ns),
    )  # fmt: skip


def _scratch_buffers(nb: int, ns: int):
    """(views, flats): the element arrays of :func:`_element_buffers` (``views``, the kernels'
    layouts) and the same memory flat (``flats``, which the sum lists index)."""
    views = _element_buffers(nb, ns)
    return views, tuple(v.reshape(-1) for v in views)


_NON_FINITE = "non-finite solution of the linear system (singular stiffness)"
_SINGULAR = "singular stiffness matrix (Singular matrix)"


def _finite(x):
    if not np.all(np.isfinite(x)):
        raise SingularSystemError(_NON_FINITE)
    return x


class BatchAssembler:
    """S structures of one size and one support mask, evaluated together.

    Every sample of an arch m or a Miura m x n sheet has the same nodes, bars and springs up to
    the orientation of some springs (the polarity rule follows the geometry), hence one of a
    few connectivities. One call of :meth:`factorized` runs the compiled kernels once for the
    whole batch and one scatter per connectivity (loops over the samples inside compiled code),
    then factorises each active sample's tangent by the path :class:`Assembler` takes, so every
    sample's numbers are bit for bit those of its own :class:`Assembler`.

    Parameters
    ----------
    structures : sequence of Structure
        Same numbers of nodes, bars and springs and the same supports (``ValueError``
        otherwise).
    dense_max : int
        As for :class:`Assembler`.
    """

    def __init__(self, structures, *, dense_max: int = DENSE_MAX_DOF):
        structures = list(structures)
        if not structures:
            raise ValueError("a batch needs at least one structure")
        asms = [Assembler(s, dense_max=dense_max) for s in structures]
        a0 = asms[0]
        sizes = {(a.n_dof, len(a.bars), len(a.springs)) for a in asms}
        masks = {a.structure.supports.tobytes() for a in asms}
        if len(sizes) > 1 or len(masks) > 1:
            raise ValueError("the structures of a batch need the same sizes and supports")
        self.assemblers = asms
        self.dense_max = int(dense_max)
        self.n = len(asms)
        self.n_dof = a0.n_dof
        groups: dict[int, list[int]] = {}
        for i, a in enumerate(asms):
            groups.setdefault(id(a.pattern), []).append(i)
        #: (pattern, reduction, samples) of each connectivity
        self.groups = [
            (asms[g[0]].pattern, asms[g[0]].reduction, np.array(g, np.intp))
            for g in groups.values()
        ]
        stack = lambda name: np.stack([getattr(a, name) for a in asms])  # noqa: E731
        self._X, self._D0, self._L0, self._EA, self._k = map(
            stack, ("_X", "_D0", "_L0", "_EA", "_k")
        )
        self._b0, self._b1, self._sT = map(stack, ("_b0", "_b1", "_sT"))
        self._theta0 = np.stack([np.asarray(a.theta0, float) for a in asms])
        self._k_nonneg = np.array([a._k_nonneg for a in asms])
        self._arccos = [a._arccos for a in asms]
        self._scratch = _scratch_buffers(len(a0.bars), len(a0.springs))
        self._addrs = None  # LAPACK addresses of the compiled Newton step, on first use

    @property
    def free_dofs(self) -> np.ndarray:
        return self.assemblers[0].free_dofs

    def factorized(self, U, active, spring_rest=None):
        """Internal forces and solvers of the ``active`` samples.

        Parameters
        ----------
        U : (S, nn, 3) float
            Displacements, m.
        active : (S,) bool
            Samples to evaluate (the others are left alone).
        spring_rest : (S, ns) float, optional
            Rest angles instead of the structures' own, rad.

        Returns
        -------
        force : (S, ndof) float
            Internal force of each active sample (rows of the others are zero), N.
        solves : list
            Per sample: ``solve(rhs)`` as from :meth:`Assembler.evaluate_factorized`, the
            :class:`SingularSystemError` its factorisation raised, or None (inactive).
        """
        ck = _ck()
        U = np.ascontiguousarray(np.asarray(U, dtype=float).reshape(self.n, -1, 3))
        active = np.ascontiguousarray(active, dtype=bool)
        rest = self._theta0 if spring_rest is None else np.array(spring_rest, dtype=float)
        if rest.shape != self._theta0.shape:
            raise ValueError(f"spring_rest must have shape {self._theta0.shape}")
        theta0 = rest
        if any(self._arccos):
            theta0 = theta0.copy()
            for s in np.flatnonzero(active):
                if self._arccos[s]:
                    a = self.assemblers[s]
                    theta0[s] = theta0[s] + arccos_shift(a.X + U[s], a.springs)
        theta0 = np.ascontiguousarray(theta0)
        f = np.zeros((self.n, self.n_dof))
        solves: list = [None] * self.n
        for pat, red, members in self.groups:
            idx = np.ascontiguousarray(members[active[members]], dtype=np.intp)
            if idx.size == 0:
                continue
            path = solver_path(red, self.dense_max)
            if path == "none":
                for s in idx:
                    solves[s] = lambda rhs: np.zeros_like(rhs, dtype=float)
                continue
            lists, n = red.tangent_sums(path)
            fj = np.empty((idx.size, self.n_dof))
            kj = np.empty((idx.size, n))
            views, flats = self._scratch
            ck.assemble_batch(
                self._X, U, self._b0, self._b1, self._D0, self._L0, self._EA, self._sT,
                self._k, theta0, self._k_nonneg, idx, pat.force_sums, lists,
                views, flats, fj, kj,
            )  # fmt: skip
            f[idx] = fj
            for j, s in enumerate(idx):
                solves[s] = self._solver(s, path, red, kj[j], U[s], rest[s])
        return f, solves

    def newton_step(self, U, rhs_force, active):
        """One Newton update of the ``active`` samples: ``U[s, free] += dU`` with
        ``dU = K_ff^-1 (rhs_force[s] - f_int[s])[free]``, bit for bit
        ``solve = factorized(U, active)[1][s]; dU = solve((rhs_force[s] - f[s])[free])``.

        Samples on the banded and the dense path are evaluated, factorised and solved in one
        compiled call per connectivity (scipy's LAPACK by address, ``_compiled``'s
        ``band_newton_step`` and ``dense_newton_step``); the others, and banded tangents that
        are not positive definite, by :meth:`factorized`.

        Parameters
        ----------
        U : (S, ndof) float, C-contiguous
            Displacements, updated in place, m.
        rhs_force : (S, ndof) float
            External force of each sample, N.
        active : (S,) bool

        Returns
        -------
        dU : (S, nf) float
            Row s: the increment of active sample s on :attr:`free_dofs` (rows of inactive
            or failed samples are undefined).
        errors : dict
            Sample -> the :class:`SingularSystemError` that stopped it (its U is left alone).
        """
        ck = _ck()
        if U.dtype != float or not U.flags.c_contiguous or U.shape != (self.n, self.n_dof):
            raise ValueError(f"U must be a C-contiguous float ({self.n}, {self.n_dof}) array")
        active = np.ascontiguousarray(active, dtype=bool)
        U3 = U.reshape(self.n, -1, 3)
        Fi = np.ascontiguousarray(rhs_force, dtype=float)
        dU_all = np.empty((self.n, self.free_dofs.size))
        errors: dict = {}
        rest = active.copy()
        if not any(self._arccos):
            for pat, red, members in self.groups:
                idx = np.ascontiguousarray(members[active[members]], dtype=np.intp)
                path = solver_path(red, self.dense_max)
                if idx.size == 0 or path not in ("banded", "dense"):
                    continue
                if self._addrs is None:
                    self._addrs = {
                        "banded": ck.lapack_addresses("dpbtrf", "dpbtrs"),
                        "dense": ck.lapack_addresses("dgetrf", "dgetrs"),
                    }
                views, flats = self._scratch
                common = (
                    self._X, U3, self._b0, self._b1, self._D0, self._L0, self._EA, self._sT,
                    self._k, self._theta0, self._k_nonneg, idx, pat.force_sums,
                )  # fmt: skip
                dU = np.empty((idx.size, red.n_free))
                info = np.zeros(idx.size, np.int8)
                if path == "banded":
                    perm, bw, _, _ = red.banded
                    lists, _ = red.tangent_sums("banded")
                    fj = np.empty((idx.size, self.n_dof))
                    ck.band_newton_step(
                        *common, lists, views, flats, Fi, red.free, perm, bw,
                        self._addrs["banded"], U, dU, fj, info,
                    )  # fmt: skip
                    lu_below = True  # not positive definite: LU by factorized below
                else:
                    lists, _ = red.tangent_sums("dense_cm")
                    ck.dense_newton_step(
                        *common, lists, views, flats, Fi, red.free, self._addrs["dense"], U,
                        dU, info, dU,
                    )  # fmt: skip
                    lu_below = False  # singular
                dU_all[idx] = dU
                rest[idx] = False
                for j in np.flatnonzero(info):  # the failed samples only
                    if info[j] == 1 and lu_below:
                        rest[idx[j]] = True
                    else:
                        errors[int(idx[j])] = SingularSystemError(
                            _SINGULAR if info[j] == 1 else _NON_FINITE
                        )
        if rest.any():
            f, solves = self.factorized(U3, rest)
            free = self.free_dofs
            for s in np.flatnonzero(rest):
                try:
                    if isinstance(solves[s], SingularSystemError):
                        raise solves[s]
                    dU_s = solves[s]((Fi[s] - f[s])[free])
                except SingularSystemError as exc:
                    errors[int(s)] = exc
                    continue
                U[s, free] += dU_s
                dU_all[s] = dU_s
        return dU_all, errors

    def _solver(self, s, path, red, values, U, rest):
        """The solver of sample ``s`` from its dense block, band or CSR data ``values``
        (``rest``: its rest angles, for the LU fallback's own evaluation)."""
        if path == "dense":
            return _dense_solver(values.reshape(red.n_free, red.n_free))
        if path == "banded":
            solve = _band_solver(values, red)
            if solve is not None:
                return solve
            # not positive definite: LU on the CSR data of this sample alone
            a = self.assemblers[s]
            buffers = a._kernels(U, rest, True, a._buffers())
            values = a._scatter(buffers)
        try:
            return _lu_solver(values, red)
        except SingularSystemError as exc:
            return exc


def _band_size(red: ReducedPattern) -> int:
    _, bw, _, _ = red.banded
    return red.n_free * (bw + 1)
