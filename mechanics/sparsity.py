"""The sparsity of the bar-and-hinge tangent, built once per topology, and its sum lists.

An :class:`AssemblyPattern` holds the CSR pattern of the global tangent and the slot of every
entry the element kernels produce; it depends only on the connectivity, so it is computed once
and cached (:func:`assembly_pattern`, keyed on a hash of the bar and spring connectivity: every
sample of one Miura m x n or arch m shares it). A :class:`ReducedPattern` is its free-DOF
reduction for one support mask: the free-free slots, the reduced CSR pattern, the banded
storage on a reverse Cuthill-McKee ordering (:class:`Band`) and the :class:`SumLists` that fill
each storage of the tangent from the kernels' arrays. Supports by elimination are exactly the
reference's "zero the row and column, keep the diagonal, zero the residual" (the supported
increments are 0 either way).

Storages of the free-free tangent (:data:`STORAGES`): ``"dense"`` (row-major nf x nf),
``"dense_cm"`` (column-major: the Fortran copy LAPACK factorises), ``"dense_upper"`` (its upper
triangle only, for a Cholesky factorisation; the rest stays zero), ``"banded"`` (LAPACK upper
band, column-major), ``"csr"`` (the full CSR data; the reduction keeps :attr:`ReducedPattern.
keep`) and ``"csr_upper"`` (the free-free upper triangle only, the entries of
:attr:`ReducedPattern.upper_keep` in order: what a sparse Cholesky reads).
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from functools import cached_property
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee

from holofold.mechanics.springs import SPRING_BLOCKS
from holofold.mechanics.structure import Structure

__all__ = [
    "AssemblyPattern",
    "ReducedPattern",
    "SumLists",
    "Band",
    "STORAGES",
    "assembly_pattern",
    "sum_lists",
]

STORAGES = ("dense", "dense_cm", "dense_upper", "banded", "csr", "csr_upper")
_PATTERN_CACHE: OrderedDict[bytes, AssemblyPattern] = OrderedDict()
_PATTERN_CACHE_SIZE = 8


class SumLists(NamedTuple):
    """How one target array is summed from the element arrays (the kernels' layouts, flat).

    For each family (bars, springs, the mirrors of the off-diagonal spring blocks): ``*_src``
    the flat index of every entry that has a target, in flat order (the order the values lie
    in memory), and ``*_tgt`` its target in the output array, which must start as zeros; the
    sum of a target is ``out[t] += value`` over its entries, in any order. int32 arrays (half
    the index traffic of intp).
    """

    bar_src: np.ndarray
    bar_tgt: np.ndarray
    spring_src: np.ndarray
    spring_tgt: np.ndarray
    mirror_src: np.ndarray
    mirror_tgt: np.ndarray


def sum_lists(families, n: int, dest=None) -> SumLists:
    """The :class:`SumLists` of up to three families of targets ``pos`` (entries outside
    ``0..n-1`` are dropped), written to ``out[dest[pos]]`` (default ``out[pos]``)."""
    i4 = lambda x: np.ascontiguousarray(x, np.int32)  # noqa: E731
    dest = None if dest is None else np.asarray(dest, np.intp)
    out = []
    for pos in families:
        pos = np.asarray(pos).ravel()
        src = np.flatnonzero((pos >= 0) & (pos < n))
        tgt = pos[src] if dest is None else dest[pos[src]]
        out += [i4(src), i4(tgt)]
    while len(out) < 6:
        out += [np.zeros(0, np.int32), np.zeros(0, np.int32)]
    return SumLists(*out)


class Band(NamedTuple):
    """Banded storage of a reduction: reverse Cuthill-McKee permutation ``perm`` (nf,) of the
    free DOFs, half ``bandwidth``, the kept CSR slots of the upper triangle of the permuted
    matrix ``upper_keep`` and their flat positions ``ab_pos`` in LAPACK upper banded storage
    (bandwidth + 1, nf)."""

    perm: np.ndarray
    bandwidth: int
    upper_keep: np.ndarray
    ab_pos: np.ndarray

    @property
    def size(self) -> int:
        """Entries of the flat band, (bandwidth + 1) nf."""
        return (self.bandwidth + 1) * self.perm.size


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
    rows, cols : (nnz_f,) int
        Reduced row and column of each kept slot.
    band : :class:`Band`, computed on first use.
    """

    def __init__(self, pattern: AssemblyPattern, free_mask: np.ndarray):
        self.pattern = pattern
        free = np.flatnonzero(free_mask)
        new = np.full(pattern.n_dof, -1, np.intp)
        new[free] = np.arange(free.size)
        r = new[pattern.rows]
        c = new[pattern.indices]
        keep = np.flatnonzero((r >= 0) & (c >= 0))
        nf = free.size
        self.free = free
        self.keep = keep
        self.rows = r[keep]
        self.cols = c[keep]
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(self.rows, minlength=nf))])
        self.indptr = self.indptr.astype(np.int32)
        self.indices = self.cols.astype(np.int32)
        self.dense = (self.rows * nf + self.cols).astype(np.intp)
        self._symbolic: dict = {}

    @property
    def n_free(self) -> int:
        return self.free.size

    def symbolic(self, key: str, build):
        """Per-reduction cache of a solver's symbolic data (an ordering, an analysis):
        ``build(self)`` on the first call with ``key``."""
        if key not in self._symbolic:
            self._symbolic[key] = build(self)
        return self._symbolic[key]

    @cached_property
    def upper_keep(self) -> np.ndarray:
        """(nnz_u,) int: the slots of :attr:`keep` in the upper triangle (row <= column), in
        order: the entries of the ``"csr_upper"`` storage."""
        return self.keep[self.rows <= self.cols]

    @cached_property
    def band(self) -> Band:
        nf = self.free.size
        A = sp.csr_matrix((np.ones(self.rows.size), self.indices, self.indptr), shape=(nf, nf))
        perm = reverse_cuthill_mckee(A, symmetric_mode=True).astype(np.intp)
        inv = np.empty(nf, np.intp)
        inv[perm] = np.arange(nf)
        pr = inv[self.rows]
        pc = inv[self.cols]
        bw = int(np.abs(pr - pc).max()) if pr.size else 0
        up = pr <= pc
        ab_pos = (bw + pr[up] - pc[up]) * nf + pc[up]
        return Band(perm, bw, self.keep[up], ab_pos.astype(np.intp))

    @cached_property
    def _band_slots(self):
        """(bar_ab, spring_ab): position in the flat upper band (column-major, element (r, c)
        of the (bw + 1, nf) band at ``c (bw + 1) + r``) of every bar entry (kernel layout
        (3, 3, 2, 2, nb)) and every distinct spring-block entry ((3, 3, 10, ns)); the band's
        size for entries that are dropped: supported DOFs and the duplicate halves of symmetric
        pairs (lower node blocks of bars, the strictly lower triangle of diagonal blocks)."""
        pat = self.pattern
        band = self.band
        bw, nf, size = band.bandwidth, self.free.size, band.size
        new = np.full(pat.n_dof, -1, np.intp)
        inv = np.empty(nf, np.intp)
        inv[band.perm] = np.arange(nf)
        new[self.free] = inv  # global DOF -> permuted reduced index

        def positions(slots, keep_mask):
            r = new[pat.rows[slots]]
            c = new[pat.indices[slots]]
            lo = np.minimum(r, c)
            hi = np.maximum(r, c)
            pos = hi * (bw + 1) + (bw + lo - hi)  # column-major (LAPACK's own layout)
            ok = keep_mask & (lo >= 0)
            return np.where(ok, pos, size).astype(np.intp)

        nb = pat.bar_dofs.shape[0]
        ns = pat.spring_dofs.shape[0]
        upper3 = np.arange(3)[:, None] <= np.arange(3)[None, :]
        a = np.arange(2)[:, None]
        b = np.arange(2)[None, :]
        # bars (3, 3, 2, 2, nb): blocks (0,0), (1,1) upper halves and (0,1) whole
        keep_b = ((a < b) | ((a == b) & upper3[:, :, None, None]))[..., None]
        keep_b = np.broadcast_to(keep_b, (3, 3, 2, 2, nb)).ravel()
        # springs (3, 3, 10, ns): off-diagonal blocks whole, diagonal blocks upper halves
        diag = SPRING_BLOCKS[:, 0] == SPRING_BLOCKS[:, 1]
        keep_s = (~diag[None, None, :] | upper3[:, :, None])[..., None]
        keep_s = np.broadcast_to(keep_s, (3, 3, 10, ns)).ravel()
        return positions(pat.bar_slot, keep_b), positions(pat.spring_slot, keep_s)

    def storage_size(self, storage: str) -> int:
        """Entries of the flat tangent in ``storage`` (one of :data:`STORAGES`)."""
        if storage in ("dense", "dense_cm", "dense_upper"):
            return self.n_free**2
        if storage == "banded":
            return self.band.size
        if storage == "csr":
            return self.pattern.nnz
        if storage == "csr_upper":
            return self.upper_keep.size
        raise ValueError(f"storage must be one of {STORAGES}, got {storage!r}")

    def tangent_sums(self, storage: str) -> SumLists:
        """The :class:`SumLists` of the tangent in ``storage`` (cached)."""
        key = f"sums:{storage}"
        if key not in self._symbolic:
            pat, nf = self.pattern, self.n_free
            if storage in ("dense", "dense_cm", "dense_upper"):
                kidx = np.full(pat.nnz + 1, -1, np.intp)
                kept = np.arange(self.keep.size)
                if storage == "dense_upper":
                    kept[self.rows > self.cols] = -1
                kidx[self.keep] = kept
                fams = (kidx[pat.bar_slot], kidx[pat.spring_slot], kidx[pat.spring_slot_mirror])
                dest = self.dense
                if storage != "dense":  # column-major: the Fortran order LAPACK reads
                    dest = (dest % nf) * nf + dest // nf
                lists = sum_lists(fams, self.keep.size, dest)
            elif storage == "banded":
                lists = sum_lists(self._band_slots, self.band.size)
            elif storage == "csr":
                lists = pat.data_sums
            elif storage == "csr_upper":
                at = np.full(pat.nnz + 1, -1, np.intp)  # full slot -> compact position
                at[self.upper_keep] = np.arange(self.upper_keep.size)
                fams = (at[pat.bar_slot], at[pat.spring_slot], at[pat.spring_slot_mirror])
                lists = sum_lists(fams, self.upper_keep.size)
            else:
                raise ValueError(f"storage must be one of {STORAGES}, got {storage!r}")
            self._symbolic[key] = lists
        return self._symbolic[key]


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
        included. ``rows`` (nnz,): the row of every slot.
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

        # bar kernel layout (3, 3, 2, 2, nb): entry [i, j, a, b, e] couples global DOF
        # (3 n_a + i) of element e with (3 n_b + j)
        d = self.bar_dofs.astype(np.int64).reshape(-1, 2, 3).transpose(2, 1, 0)  # (3, 2, nb)
        kb = (d[:, None, :, None, :] * nd + d[None, :, None, :, :]).ravel()
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
        self.rows = (ukeys // nd).astype(np.intp)
        self.indices = (ukeys % nd).astype(np.int32)
        self.indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows, minlength=self.n_dof))]
        ).astype(np.int32)
        self.nnz = nnz
        self.bar_force_dofs = self.bar_dofs.reshape(-1, 2, 3).transpose(2, 1, 0).ravel()
        self.spring_force_dofs = self.spring_dofs.reshape(-1, 4, 3).transpose(2, 1, 0).ravel()
        self._reduced: dict[bytes, ReducedPattern] = {}

    @cached_property
    def force_sums(self) -> SumLists:
        """Sum lists (bars, springs) of the internal force (targets: the DOFs)."""
        return sum_lists((self.bar_force_dofs, self.spring_force_dofs), self.n_dof)

    @cached_property
    def data_sums(self) -> SumLists:
        """Sum lists (bars, springs, spring mirrors) of the CSR data (targets: the slots)."""
        fams = (self.bar_slot, self.spring_slot, self.spring_slot_mirror)
        return sum_lists(fams, self.nnz)

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

    Structures with the same nodes count, bars and springs (e.g. every sample of one Miura
    m x n sheet) share one pattern; a small LRU cache keyed on a hash of the connectivity
    avoids rebuilding it.
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
