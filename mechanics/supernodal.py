"""Multifrontal supernodal Cholesky of the reduced tangent, on the plain install (issue 37, 1).

holofold's own sparse Cholesky (BSD-3-Clause like the rest): numba for the symbolic analysis
and the assembly of the frontal matrices, scipy's BLAS and LAPACK (``dpotrf``, ``dtrsm``,
``dsyrk`` through ``scipy.linalg.cython_blas`` / ``cython_lapack``, by address) for the dense
work of each front, so it needs nothing beyond the core dependencies (numpy, scipy, numba) and
runs wherever they have wheels. It stands in for CHOLMOD (``holofold[cholmod]``, GPL) where
cvxopt is not installed (``benchmarks/large_solvers.md``).

A :class:`SupernodalCholesky` is built once per sparsity pattern: a fill-reducing ordering
(multiple minimum degree on K + K', scipy's SuperLU ordering; from :data:`METIS_MIN_DOF` rows
also METIS's nested dissection where pymetis is installed, keeping the one with fewer flops),
postordered along its elimination tree; column counts; supernodes (consecutive columns with
nested structure, merged further while the explicit zeros they add stay small); each
supernode's row structure and the positions of its children's update rows in it. Each
:meth:`SupernodalCholesky.factor` then assembles and factorises every front in postorder
(``dpotrf`` of the pivot block, ``dtrsm`` of the rows below, ``dsyrk`` of the update matrix
passed to the parent on a stack) and returns a :class:`SupernodalFactor` (``solve(rhs)``), or
None when the matrix is not positive definite. For symmetric indefinite matrices (issue 37,
item 2) :meth:`SupernodalCholesky.factor_ldl` factorises each pivot block by LAPACK's
Bunch-Kaufman ``dsytrf`` (pivoting within the block only) and eliminates the rows below it
(``dsytrs``, ``dgemm``), checked by one solve; None (use LU) where a pivot block is singular or
the check fails. Factors are independent arrays.

Typical use::

    chol = SupernodalCholesky(K.indptr, K.indices)   # once per pattern (csr)
    factor = chol.factor(K.data)                      # per Newton iteration; None: not SPD
    x = factor.solve(rhs)                             # (n,) or (n, k)
"""

from __future__ import annotations

from functools import cache
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit
from numba.core import config

from holofold.mechanics import kernels
from holofold.mechanics._jit import OPTS
from holofold.mechanics.sparse_cholesky import nested_dissection
from holofold.mechanics.status import SingularSystemError

__all__ = [
    "SupernodalCholesky",
    "SupernodalFactor",
    "mmd_order",
    "metis_order",
    "METIS_MIN_DOF",
    "RELAX_ZEROS",
    "LDL_CHECK",
]

#: Patterns of at least this many rows also try METIS's nested dissection (where pymetis is
#: installed) and keep the ordering with fewer flops.
METIS_MIN_DOF = 10_000
#: A child supernode is merged into its parent while the explicit zeros this adds stay at
#: most this fraction of the merged supernode's entries (relaxed amalgamation: fewer, larger
#: fronts do more of their work in BLAS-3).
RELAX_ZEROS = 0.1


#: the compiled kernels' call of a Fortran routine by address (imported through
#: :mod:`~holofold.mechanics.kernels`, which sets their cache folder)
_fcall = kernels.kernel_path("compiled").module._fcall


def _jit(fn):
    """``njit`` with the compiled kernels' options, cached in their folder (numba reads the
    cache folder when a function is decorated): compiled by their background compile
    (``mechanics._warmup``) and keyed on this file's source with them."""
    before = config.CACHE_DIR
    config.CACHE_DIR = str(kernels.cache_folder())
    try:
        return njit(**OPTS)(fn)
    finally:
        config.CACHE_DIR = before


@cache
def _addresses() -> np.ndarray:
    """Addresses of scipy's ``dpotrf``, ``dtrsm``, ``dsyrk``, ``dtrsv``, ``dgemv``, ``dsytrf``,
    ``dsytrs``, ``dgemm``."""
    from numba.extending import get_cython_function_address as addr

    return np.array(
        [
            addr("scipy.linalg.cython_lapack", "dpotrf"),
            addr("scipy.linalg.cython_blas", "dtrsm"),
            addr("scipy.linalg.cython_blas", "dsyrk"),
            addr("scipy.linalg.cython_blas", "dtrsv"),
            addr("scipy.linalg.cython_blas", "dgemv"),
            addr("scipy.linalg.cython_lapack", "dsytrf"),
            addr("scipy.linalg.cython_lapack", "dsytrs"),
            addr("scipy.linalg.cython_blas", "dgemm"),
        ],
        np.int64,
    )


# ------------------------------------------------------------------------ symbolic analysis
@_jit
def _etree(n, rp, ci):
    """Elimination tree (parent, -1 at roots) of the symmetric matrix whose strictly lower
    triangle is the CSR (rp, ci) (row i: columns < i)."""
    parent = np.full(n, -1, np.int64)
    anc = np.full(n, -1, np.int64)
    for i in range(n):
        for p in range(rp[i], rp[i + 1]):
            k = ci[p]
            while k != -1 and k < i:
                nxt = anc[k]
                anc[k] = i
                if nxt == -1:
                    parent[k] = i
                k = nxt
    return parent


@_jit
def _postorder(parent):
    """A postorder of the forest ``parent`` (children in increasing order)."""
    n = parent.shape[0]
    head = np.full(n, -1, np.int64)
    nxt = np.full(n, -1, np.int64)
    for j in range(n - 1, -1, -1):
        p = parent[j]
        if p != -1:
            nxt[j] = head[p]
            head[p] = j
    post = np.empty(n, np.int64)
    stack = np.empty(n, np.int64)
    k = 0
    for root in range(n):
        if parent[root] != -1:
            continue
        top = 0
        stack[0] = root
        while top >= 0:
            j = stack[top]
            c = head[j]
            if c == -1:
                top -= 1
                post[k] = j
                k += 1
            else:
                head[j] = nxt[c]
                top += 1
                stack[top] = c
    return post


@_jit
def _colcounts(n, rp, ci, parent):
    """Nonzeros of each column of L (diagonal included): row subtrees of the strictly lower CSR."""
    count = np.ones(n, np.int64)
    mark = np.full(n, -1, np.int64)
    for i in range(n):
        mark[i] = i
        for p in range(rp[i], rp[i + 1]):
            k = ci[p]
            while mark[k] != i:
                mark[k] = i
                count[k] += 1
                k = parent[k]
    return count


@_jit
def _supernodes(parent, count, relax):
    """Supernode of each column: runs of columns j-1 -> j (parent) with nested structure, then
    children merged into their parents while the explicit zeros stay within ``relax``."""
    n = parent.shape[0]
    first = [0]
    for j in range(1, n):
        if not (parent[j - 1] == j and count[j - 1] == count[j] + 1):
            first.append(j)
    ns = len(first)
    start = np.empty(ns + 1, np.int64)
    for s in range(ns):
        start[s] = first[s]
    start[ns] = n
    # relaxed amalgamation of a chain child -> parent (the child the last column before
    # the parent's first): merged if contiguous and the added zeros are few
    cols = np.empty(ns, np.int64)  # columns of each (merged) supernode
    rows = np.empty(ns, np.int64)  # rows of its first column
    zeros = np.zeros(ns, np.int64)  # explicit zeros it holds
    keep = np.ones(ns, np.bool_)
    for s in range(ns):
        cols[s] = start[s + 1] - start[s]
        rows[s] = count[start[s]]
    for s in range(ns - 1):
        last = start[s + 1] - 1
        p = parent[last]
        if p != start[s + 1]:
            continue  # the next supernode is not this one's parent: not contiguous
        t = s + 1
        nc, nt = cols[s], cols[t]
        # merged: nc + nt columns, rows[s] rows of the merged first column would be
        # nc + rows[t] (the parent's structure plus the child's columns)
        new_rows = nc + rows[t]
        added = zeros[s] + zeros[t] + nc * (new_rows - rows[s])
        total = (nc + nt) * new_rows - ((nc + nt) * (nc + nt - 1)) // 2
        if added <= relax * total:
            keep[s] = False
            cols[t] = nc + nt
            rows[t] = new_rows
            zeros[t] = added
    out = []
    for s in range(ns):
        if keep[s]:
            out.append(start[s + 1])
    sup = np.empty(len(out) + 1, np.int64)
    sup[0] = 0
    for k in range(len(out)):
        sup[k + 1] = out[k]
    return sup


@_jit
def _structure(n, sup, parent, cp, ri):
    """Row structure of each supernode (its columns first, then the rows below in increasing
    order), the supernodes' parents, and the position of each child's update rows in its
    parent's structure. (cp, ri): CSC of the lower triangle (diagonal included)."""
    ns = sup.shape[0] - 1
    snode = np.empty(n, np.int64)
    for s in range(ns):
        for j in range(sup[s], sup[s + 1]):
            snode[j] = s
    sparent = np.full(ns, -1, np.int64)
    for s in range(ns):
        p = parent[sup[s + 1] - 1]
        if p != -1:
            sparent[s] = snode[p]
    # children lists
    chead = np.full(ns, -1, np.int64)
    cnext = np.full(ns, -1, np.int64)
    for s in range(ns - 1, -1, -1):
        p = sparent[s]
        if p != -1:
            cnext[s] = chead[p]
            chead[p] = s
    mark = np.full(n, -1, np.int64)
    rptr = np.zeros(ns + 1, np.int64)
    rows_list = []
    tmp = np.empty(n, np.int64)
    for s in range(ns):
        f, l1 = sup[s], sup[s + 1]
        m = 0
        for j in range(f, l1):
            mark[j] = s
            tmp[m] = j
            m += 1
        for j in range(f, l1):
            for p in range(cp[j], cp[j + 1]):
                i = ri[p]
                if mark[i] != s:
                    mark[i] = s
                    tmp[m] = i
                    m += 1
        c = chead[s]
        while c != -1:
            nc = sup[c + 1] - sup[c]
            for q in range(rptr[c] + nc, rptr[c + 1]):
                i = rows_list[q]
                if mark[i] != s:
                    mark[i] = s
                    tmp[m] = i
                    m += 1
            c = cnext[c]
        below = np.sort(tmp[l1 - f : m])
        for q in range(l1 - f):
            rows_list.append(tmp[q])
        for q in range(below.shape[0]):
            rows_list.append(below[q])
        rptr[s + 1] = rptr[s] + m
    rows = np.empty(len(rows_list), np.int64)
    for q in range(rows.shape[0]):
        rows[q] = rows_list[q]
    # local position of each row of a child's update block in its parent's structure
    rel = np.full(rows.shape[0], -1, np.int64)
    loc = np.full(n, -1, np.int64)
    for s in range(ns):
        for q in range(rptr[s], rptr[s + 1]):
            loc[rows[q]] = q - rptr[s]
        c = chead[s]
        while c != -1:
            nc = sup[c + 1] - sup[c]
            for q in range(rptr[c] + nc, rptr[c + 1]):
                rel[q] = loc[rows[q]]
            c = cnext[c]
    return snode, sparent, rows, rptr, rel, chead, cnext


@_jit
def _entry_positions(n, sup, snode, rows, rptr, cp, ri):
    """Front position (column-major, ld = the supernode's row count) of each lower-triangle
    entry in CSC order."""
    loc = np.full(n, -1, np.int64)
    pos = np.empty(ri.shape[0], np.int64)
    ns = sup.shape[0] - 1
    for s in range(ns):
        m = rptr[s + 1] - rptr[s]
        for q in range(rptr[s], rptr[s + 1]):
            loc[rows[q]] = q - rptr[s]
        for j in range(sup[s], sup[s + 1]):
            for p in range(cp[j], cp[j + 1]):
                pos[p] = loc[ri[p]] + (j - sup[s]) * m
    return pos


@_jit
def _stack_size(sup, rptr, sparent, chead, cnext):
    """Largest total of update blocks alive at once on the multifrontal stack (postorder)."""
    ns = sup.shape[0] - 1
    top = 0
    peak = 0
    upd = np.zeros(ns, np.int64)
    for s in range(ns):
        c = chead[s]
        while c != -1:
            top -= upd[c]
            c = cnext[c]
        if sparent[s] != -1:
            u = rptr[s + 1] - rptr[s] - (sup[s + 1] - sup[s])
            upd[s] = u * u
            top += upd[s]
            peak = max(peak, top)
    return peak


# ------------------------------------------------------------------------ numeric factor
class FrontPlan(NamedTuple):
    """What the numeric factorisation reads of the symbolic analysis (see ``_Analysis``):
    value slots, column pointers, entry positions, supernode bounds and relative row maps,
    row and factor pointers, the supernodal tree (parent, first child, next sibling), and
    the update stack's and largest front's sizes."""

    slots: np.ndarray
    cp: np.ndarray
    pos: np.ndarray
    sup: np.ndarray
    rel: np.ndarray
    rptr: np.ndarray
    lptr: np.ndarray
    sparent: np.ndarray
    chead: np.ndarray
    cnext: np.ndarray
    stack_n: int
    max_front: int


@_jit
def _factor(data, plan, addrs, lx, ldl, ipiv):
    """Multifrontal numeric factorisation of the values ``data`` by ``plan`` (a
    :class:`FrontPlan`) into ``lx`` (each supernode's m x nc block, column-major); 0, or 1 +
    the column where the matrix is not positive definite (``ldl``: where a pivot block is
    singular). ``ldl``: each pivot block by LAPACK's Bunch-Kaufman ``dsytrf`` (pivots in
    ``ipiv``, interchanges within the block only) and the rows below kept as they are (block
    elimination), for symmetric indefinite matrices."""
    slots, cp, pos, sup, rel, rptr, lptr, sparent, chead, cnext, stack_n, max_front = plan
    ns = sup.shape[0] - 1
    F = np.empty(max_front)
    X = np.empty(max_front)
    nb = 1
    for s in range(ns):
        nb = max(nb, sup[s + 1] - sup[s])
    work = np.empty(64 * nb)
    lwork = np.array([64 * nb], np.int32)
    stk = np.empty(max(stack_n, 1))
    off = np.zeros(ns, np.int64)
    top = 0
    lo = np.array([ord("L")], np.uint8)
    rt = np.array([ord("R")], np.uint8)
    tr = np.array([ord("T")], np.uint8)
    no = np.array([ord("N")], np.uint8)
    one = np.array([1.0])
    mone = np.array([-1.0])
    n_ = np.zeros(1, np.int32)
    m_ = np.zeros(1, np.int32)
    k_ = np.zeros(1, np.int32)
    ld = np.zeros(1, np.int32)
    info = np.zeros(1, np.int32)
    for s in range(ns):
        f = sup[s]
        nc = sup[s + 1] - f
        m = rptr[s + 1] - rptr[s]
        mu = m - nc
        fr = F[: m * m]
        fr[:] = 0.0
        for j in range(f, f + nc):  # the matrix's own entries
            for p in range(cp[j], cp[j + 1]):
                fr[pos[p]] += data[slots[p]]
        c = chead[s]  # extend-add the children's update blocks
        lowest = top
        while c != -1:
            ncc = sup[c + 1] - sup[c]
            mc = rptr[c + 1] - rptr[c] - ncc
            base = off[c]
            lowest = min(lowest, base)
            r0 = rptr[c] + ncc
            for b in range(mc):
                col = rel[r0 + b] * m
                src = base + b * mc
                for a in range(b, mc):
                    fr[col + rel[r0 + a]] += stk[src + a]
            c = cnext[c]
        top = lowest
        ld[0] = m
        n_[0] = nc
        if ldl:
            piv = ipiv[f : f + nc]
            _fcall(addrs[5], (lo, n_, fr, ld, piv, work, lwork, info))
            if info[0] != 0:
                return 1 + f + info[0] - 1
            lx[lptr[s] : lptr[s] + m * nc] = fr[: m * nc]
            if sparent[s] != -1 and mu > 0:
                for a in range(mu):  # X = F21' (nc x mu), then X = F11^-1 F21'
                    for j in range(nc):
                        X[a * nc + j] = fr[j * m + nc + a]
                m_[0] = mu
                _fcall(addrs[6], (lo, n_, m_, fr, ld, piv, X, n_, info))
                blk = stk[top : top + mu * mu]
                for b in range(mu):
                    src = (nc + b) * m + nc
                    blk[b * mu : (b + 1) * mu] = fr[src : src + mu]
                _fcall(addrs[7], (no, no, m_, m_, n_, mone, fr[nc:], ld, X, n_, one, blk, m_))
                off[s] = top
                top += mu * mu
            continue
        _fcall(addrs[0], (lo, n_, fr, ld, info))
        if info[0] != 0:
            return 1 + f + info[0] - 1
        if mu > 0:
            m_[0] = mu
            _fcall(addrs[1], (rt, lo, tr, no, m_, n_, one, fr, ld, fr[nc:], ld))
        lx[lptr[s] : lptr[s] + m * nc] = fr[: m * nc]
        if sparent[s] != -1 and mu > 0:
            blk = stk[top : top + mu * mu]
            for b in range(mu):
                src = (nc + b) * m + nc
                blk[b * mu + b : (b + 1) * mu] = fr[src + b : src + mu]
            m_[0] = mu
            k_[0] = nc
            n_[0] = mu
            _fcall(addrs[2], (lo, no, n_, k_, mone, fr[nc:], ld, one, blk, m_))
            off[s] = top
            top += mu * mu
    return 0


@_jit
def _solve(lx, sup, rows, rptr, lptr, addrs, y):
    """Solve L L' x = y in place (y (k, n): k right-hand sides in the factor's order), each
    supernode by BLAS ``dtrsv`` and ``dgemv`` on its gathered rows."""
    ns = sup.shape[0] - 1
    lo = np.array([ord("L")], np.uint8)
    tr = np.array([ord("T")], np.uint8)
    no = np.array([ord("N")], np.uint8)
    one = np.array([1.0])
    mone = np.array([-1.0])
    inc = np.ones(1, np.int32)
    n_ = np.zeros(1, np.int32)
    m_ = np.zeros(1, np.int32)
    ld = np.zeros(1, np.int32)
    w = np.empty(max(int(np.max(np.diff(rptr))), 1) if ns else 1)
    for r in range(y.shape[0]):
        x = y[r]
        for s in range(ns):
            m = rptr[s + 1] - rptr[s]
            nc = sup[s + 1] - sup[s]
            R = rows[rptr[s] : rptr[s + 1]]
            L = lx[lptr[s] : lptr[s] + m * nc]
            for a in range(m):
                w[a] = x[R[a]]
            n_[0] = nc
            ld[0] = m
            _fcall(addrs[3], (lo, no, no, n_, L, ld, w, inc))
            if m > nc:
                m_[0] = m - nc
                _fcall(addrs[4], (no, m_, n_, mone, L[nc:], ld, w, inc, one, w[nc:], inc))
            for a in range(m):
                x[R[a]] = w[a]
        for s in range(ns - 1, -1, -1):
            m = rptr[s + 1] - rptr[s]
            nc = sup[s + 1] - sup[s]
            R = rows[rptr[s] : rptr[s + 1]]
            L = lx[lptr[s] : lptr[s] + m * nc]
            for a in range(m):
                w[a] = x[R[a]]
            n_[0] = nc
            ld[0] = m
            if m > nc:
                m_[0] = m - nc
                _fcall(addrs[4], (tr, m_, n_, mone, L[nc:], ld, w[nc:], inc, one, w, inc))
            _fcall(addrs[3], (lo, tr, no, n_, L, ld, w, inc))
            for a in range(nc):
                x[R[a]] = w[a]


@_jit
def _solve_ldl(lx, ipiv, sup, rows, rptr, lptr, addrs, y):
    """Solve K x = y in place from the block-elimination factor of ``_factor(ldl=True)``
    (y (k, n) in the factor's order): forward z_p = A^-1 b_p, b_q -= B z_p; backward
    x_p = z_p - A^-1 B' x_q, per supernode (A its pivot block, B the rows below)."""
    ns = sup.shape[0] - 1
    lo = np.array([ord("L")], np.uint8)
    tr = np.array([ord("T")], np.uint8)
    no = np.array([ord("N")], np.uint8)
    one = np.array([1.0])
    zero = np.array([0.0])
    mone = np.array([-1.0])
    inc = np.ones(1, np.int32)
    n_ = np.zeros(1, np.int32)
    m_ = np.zeros(1, np.int32)
    ld = np.zeros(1, np.int32)
    info = np.zeros(1, np.int32)
    mmax = 1
    for s in range(ns):
        mmax = max(mmax, rptr[s + 1] - rptr[s])
    w = np.empty(mmax)
    t = np.empty(mmax)
    for r in range(y.shape[0]):
        x = y[r]
        for s in range(ns):
            f = sup[s]
            m = rptr[s + 1] - rptr[s]
            nc = sup[s + 1] - f
            R = rows[rptr[s] : rptr[s + 1]]
            L = lx[lptr[s] : lptr[s] + m * nc]
            for a in range(m):
                w[a] = x[R[a]]
            n_[0] = nc
            ld[0] = m
            _fcall(addrs[6], (lo, n_, inc, L, ld, ipiv[f : f + nc], w, n_, info))
            if m > nc:
                m_[0] = m - nc
                _fcall(addrs[4], (no, m_, n_, mone, L[nc:], ld, w, inc, one, w[nc:], inc))
            for a in range(m):
                x[R[a]] = w[a]
        for s in range(ns - 1, -1, -1):
            f = sup[s]
            m = rptr[s + 1] - rptr[s]
            nc = sup[s + 1] - f
            if m == nc:
                continue
            R = rows[rptr[s] : rptr[s + 1]]
            L = lx[lptr[s] : lptr[s] + m * nc]
            for a in range(m):
                w[a] = x[R[a]]
            n_[0] = nc
            ld[0] = m
            m_[0] = m - nc
            _fcall(addrs[4], (tr, m_, n_, one, L[nc:], ld, w[nc:], inc, zero, t, inc))
            _fcall(addrs[6], (lo, n_, inc, L, ld, ipiv[f : f + nc], t, n_, info))
            for j in range(nc):
                x[f + j] = w[j] - t[j]


@_jit
def _matvec(cp, ri, slots, data, x, out):
    """out = K x in the factor's order, K from its lower triangle (CSC cp, ri; values
    ``data[slots]``)."""
    out[:] = 0.0
    for j in range(cp.shape[0] - 1):
        for p in range(cp[j], cp[j + 1]):
            i = ri[p]
            v = data[slots[p]]
            out[i] += v * x[j]
            if i != j:
                out[j] += v * x[i]


#: the largest relative residual ||K x - b|| / (||K|| ||x|| + ||b||) (inf-norms) of the check
#: solve that an LDL^T factor may give; above it :meth:`SupernodalCholesky.factor_ldl` refuses
#: (restricted pivoting met a bad pivot block) and the caller takes LU
LDL_CHECK = 1e-12


# ------------------------------------------------------------------------ orderings
def mmd_order(n: int, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Multiple minimum degree order of the symmetric pattern (rows, cols) (scipy's SuperLU
    ordering ``MMD_AT_PLUS_A``, taken from a factorisation of diagonally dominant stand-in
    values on the pattern)."""
    vals = np.where(rows == cols, float(n + 1), -1.0 / max(n, 1))
    A = sp.csc_matrix((vals, (rows, cols)), shape=(n, n))
    A = A + sp.identity(n, format="csc") * 0.0  # every diagonal entry present
    lu = spla.splu(
        A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )
    return np.argsort(lu.perm_c).astype(np.int64)


def metis_order(n: int, rows: np.ndarray, cols: np.ndarray) -> np.ndarray | None:
    """METIS's nested-dissection order of the pattern, or None where pymetis is missing
    (:func:`~holofold.mechanics.sparse_cholesky.nested_dissection`)."""
    return nested_dissection(rows, cols, n)


class _Analysis:
    """The symbolic factorisation of the pattern's upper entries (r, c) in one order."""

    def __init__(self, n, r, c, slots, order):
        order = np.asarray(order, np.int64)
        for attempt in range(2):  # the given order, then it postordered along its etree
            inv = np.empty(n, np.int64)
            inv[order] = np.arange(n)
            p, q = inv[r], inv[c]
            lo, hi = np.maximum(p, q), np.minimum(p, q)
            strict = lo != hi
            srt = np.lexsort((hi[strict], lo[strict]))  # strictly lower CSR, row-major
            rp = np.concatenate([[0], np.cumsum(np.bincount(lo[strict], minlength=n))])
            parent = _etree(n, rp, np.ascontiguousarray(hi[strict][srt]))
            if attempt == 0:
                order = order[_postorder(parent)]
        count = _colcounts(n, rp, np.ascontiguousarray(hi[strict][srt]), parent)
        sup = _supernodes(parent, count, RELAX_ZEROS)
        csc = np.lexsort((lo, hi))  # the lower triangle (diagonal included) by columns
        cp = np.concatenate([[0], np.cumsum(np.bincount(hi, minlength=n))]).astype(np.int64)
        ri = np.ascontiguousarray(lo[csc])
        snode, sparent, srows, rptr, rel, chead, cnext = _structure(n, sup, parent, cp, ri)
        self.n = n
        self.order = order
        self.sup, self.sparent, self.rows, self.rptr, self.rel = sup, sparent, srows, rptr, rel
        self.chead, self.cnext, self.cp = chead, cnext, cp
        self.slots = np.ascontiguousarray(slots[csc], np.int64)
        self.pos = _entry_positions(n, sup, snode, srows, rptr, cp, ri)
        m = np.diff(rptr)
        nc = np.diff(sup)
        self.lptr = np.concatenate([[0], np.cumsum(m * nc)]).astype(np.int64)
        self.max_front = int((m * m).max()) if m.size else 0
        self.stack = int(_stack_size(sup, rptr, sparent, chead, cnext))
        self.plan = FrontPlan(
            self.slots, cp, self.pos, sup, rel, rptr, self.lptr, sparent, chead, cnext,
            self.stack, self.max_front,
        )  # fmt: skip
        self.flops = float((count.astype(float) ** 2).sum())
        self.ri = ri


class SupernodalCholesky:
    """Ordering and symbolic factorisation of one symmetric sparsity pattern, for numeric
    Cholesky factorisations of any values on it (the interface of
    :class:`~holofold.mechanics.sparse_cholesky.SparseCholesky`).

    Parameters
    ----------
    indptr : (n + 1,) int
        CSR row pointers of the pattern.
    indices : (nnz,) int
        CSR column indices; the pattern must hold every diagonal entry and be structurally
        symmetric (both triangles) or hold the upper triangle only.
    ordering : (n,) int or "mmd", optional
        A fill-reducing elimination order (``K[o][:, o]`` is factorised; it is postordered
        along its elimination tree), or ``"mmd"``: multiple minimum degree alone. Default:
        MMD, and from :data:`METIS_MIN_DOF` rows METIS's nested dissection where pymetis is
        installed, keeping the one with fewer flops.
    data_slots : (nnz,) int, optional
        Where each pattern entry lies in the ``data`` given to :meth:`factor` (default: the
        CSR data itself).
    """

    def __init__(self, indptr, indices, *, ordering=None, data_slots=None):
        indptr = np.asarray(indptr, np.int64)
        indices = np.asarray(indices, np.int64)
        n = indptr.size - 1
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
        slots = np.arange(indices.size) if data_slots is None else np.asarray(data_slots)
        up = indices >= rows
        r, c, sl = rows[up], indices[up], slots[up].astype(np.int64)
        if ordering is None or (isinstance(ordering, str) and ordering == "mmd"):
            cands = [mmd_order(n, r, c)]
            if ordering is None and n >= METIS_MIN_DOF:
                nd = metis_order(n, r, c)
                if nd is not None:
                    cands.append(nd)
        else:
            cands = [np.asarray(ordering, np.int64)]
        analyses = [_Analysis(n, r, c, sl, o) for o in cands]
        self._a = min(analyses, key=lambda a: a.flops)
        self.n = n
        self.order = self._a.order

    def factor(self, data) -> SupernodalFactor | None:
        """The factor of the matrix with pattern values ``data`` (upper entries read), or None
        if it is not positive definite."""
        a = self._a
        lx = np.empty(int(a.lptr[-1]))
        code = _factor(
            np.ascontiguousarray(data, dtype=float), a.plan, _addresses(), lx, False,
            np.zeros(1, np.int32),
        )  # fmt: skip
        return None if code else SupernodalFactor(a, lx)

    def factor_ldl(self, data) -> SupernodalFactor | None:
        """An LDL^T factor of the symmetric (indefinite) matrix with pattern values ``data``:
        Bunch-Kaufman pivoting within each supernode's pivot block (no delayed pivots), checked
        by one solve (relative residual at most :data:`LDL_CHECK`); None if a pivot block is
        singular or the check fails (then use LU)."""
        a = self._a
        data = np.ascontiguousarray(data, dtype=float)
        lx = np.empty(int(a.lptr[-1]))
        ipiv = np.zeros(a.n, np.int32)
        code = _factor(data, a.plan, _addresses(), lx, True, ipiv)
        if code:
            return None
        x = np.sin(np.arange(1.0, a.n + 1.0))  # a check solve, in the factor's order
        b = np.empty(a.n)
        _matvec(a.cp, a.ri, a.slots, data, x, b)
        y = b.copy().reshape(1, -1)
        _solve_ldl(lx, ipiv, a.sup, a.rows, a.rptr, a.lptr, _addresses(), y)
        r = np.empty(a.n)
        _matvec(a.cp, a.ri, a.slots, data, y[0], r)
        row_sums = np.zeros(a.n)
        _matvec(a.cp, a.ri, a.slots, np.abs(data), np.ones(a.n), row_sums)
        scale = row_sums.max() * np.abs(y).max() + np.abs(b).max()
        if not np.abs(r - b).max() <= LDL_CHECK * scale:
            return None
        return SupernodalFactor(a, lx, ipiv)


class SupernodalFactor:
    """A numeric factor: :meth:`solve` (also by calling it, as a linear solver's ``solve``)."""

    def __init__(self, analysis: _Analysis, lx: np.ndarray, ipiv: np.ndarray | None = None):
        self._a = analysis
        self._lx = lx
        self._ipiv = ipiv  # LDL^T pivots, None for a Cholesky factor

    @property
    def ldl(self) -> bool:
        """True for an LDL^T factor (:meth:`SupernodalCholesky.factor_ldl`)."""
        return self._ipiv is not None

    def solve(self, rhs) -> np.ndarray:
        """x with K x = rhs, for rhs (n,) or (n, k); :class:`SingularSystemError` if x is not
        finite."""
        a = self._a
        b = np.asarray(rhs, dtype=float)
        y = np.array(b.reshape(a.n, -1)[a.order].T, order="C")
        if self._ipiv is None:
            _solve(self._lx, a.sup, a.rows, a.rptr, a.lptr, _addresses(), y)
        else:
            _solve_ldl(self._lx, self._ipiv, a.sup, a.rows, a.rptr, a.lptr, _addresses(), y)
        x = np.empty((a.n, y.shape[0]))
        x[a.order] = y.T
        if not np.all(np.isfinite(x)):
            raise SingularSystemError("non-finite solution of the linear system")
        return x.reshape(b.shape)

    __call__ = solve
