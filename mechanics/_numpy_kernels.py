"""The reference kernel path: numpy and scipy only, always available.

Every function has the signature and the output layouts of its compiled twin in
:mod:`~holofold.mechanics._compiled` (so the assembly calls either through
:func:`holofold.mechanics.kernels.active`), and agrees with it to round-off: forces, tangents and
energies to 1e-12 relative to their scale (tests/test_kernel_paths.py). The element kernels are
:func:`~holofold.mechanics.bars.bar_kernel` and :func:`~holofold.mechanics.springs.spring_kernel`,
the sums ``np.bincount``, the factorisations scipy's LAPACK wrappers; samples of a batch are a
Python loop. About 3-5x the compiled assembly time (benchmarks/bench_kernels.py).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dgetrf, dgetrs, dpbtrf, dpbtrs, dpotrf, dpotrs

from holofold.mechanics.bars import bar_kernel
from holofold.mechanics.springs import spring_kernel

__all__ = [
    "bar_elements",
    "spring_elements",
    "scatter",
    "assemble_batch",
    "band_newton_step",
    "small_newton_step",
    "newton_increments",
    "selffold_increments",
    "load_increments",
    "lapack_addresses",
]


def bar_elements(X, U, b0, b1, D0, L0, EA, tangent, out):
    """Bars into ``out = (energy, force, K)``: ``energy`` (nb,), ``force`` (3, 2, nb) and, if
    ``tangent``, ``K`` (3, 3, 2, 2, nb) (see ``_compiled.bar_elements``)."""
    energy, force, K = out
    d = (U[b1] - U[b0]).T
    res = bar_kernel(D0, d, L0, EA, tangent=tangent)
    energy[...] = res.energy
    force[...] = res.force
    if tangent:
        K[...] = res.tangent


def spring_elements(X, U, sT, k, theta0, k_nonneg, tangent, out):
    """Springs into ``out = (energy, force, K, theta)``: ``energy`` (ns,), ``force``
    (3, 4, ns), ``theta`` (ns,) and, if ``tangent``, ``K`` (3, 3, 10, ns) (see
    ``_compiled.spring_elements``)."""
    energy, force, K, theta = out
    res, th = spring_kernel((X + U).T[:, sT], k, theta0, tangent=tangent)
    energy[...] = res.energy
    force[...] = res.force
    theta[...] = th
    if tangent:
        K[...] = res.tangent


def scatter(src_a, tgt_a, val_a, src_b, tgt_b, val_b, src_c, tgt_c, val_c, out):
    """``out[tgt[q]] += val[src[q]]`` for every entry of each family (``np.bincount``)."""
    n = out.shape[0]
    for src, tgt, val in ((src_a, tgt_a, val_a), (src_b, tgt_b, val_b), (src_c, tgt_c, val_c)):
        if src.size:
            out += np.bincount(tgt, weights=val[src], minlength=n)


def _assemble_sample(m, s, sc, tangent_lists, f, K):
    eb, fb, Kb, es, fs, Ks, th = sc.views
    f[:] = 0.0
    K[:] = 0.0
    _, vfb, vkb, _, vfs, vks, _ = sc.flats
    fa, fsa, fb_, fsb, fc, fsc = sc.force
    ka, ksa, kb_, ksb, kc, ksc = tangent_lists
    bar_elements(m.X[s], m.U[s], m.b0[s], m.b1[s], m.D0[s], m.L0[s], m.EA[s], True, (eb, fb, Kb))
    spring_elements(
        m.X[s], m.U[s], m.sT[s], m.k[s], m.theta0[s], m.k_nonneg[s], True, (es, fs, Ks, th)
    )
    scatter(fa, fsa, vfb, fb_, fsb, vfs, fc, fsc, vfs, f)
    scatter(ka, ksa, vkb, kb_, ksb, vks, kc, ksc, vks, K)


def assemble_batch(m, idx, sc, tangent_lists, f_out, k_out):
    """Samples ``idx``: force into ``f_out[j]``, tangent target into ``k_out[j]``."""
    for j in range(idx.shape[0]):
        _assemble_sample(m, idx[j], sc, tangent_lists, f_out[j], k_out[j])


def _accept(x, Uflat, s, free) -> int:
    if not np.all(np.isfinite(x)):
        return 2
    Uflat[s, free] += x
    return 0


def band_newton_step(m, idx, sc, tangent_lists, Fi, fac, Uflat, out):
    """One Newton update per sample on the banded Cholesky path (``_compiled``'s twin: info
    0 done, 1 not positive definite, 2 a non-finite solution)."""
    free, perm, bw, _ = fac
    dU, f_out, info = out
    nf = free.shape[0]
    ab = np.empty((bw + 1) * nf)
    for j in range(idx.shape[0]):
        s = idx[j]
        f = f_out[j]
        _assemble_sample(m, s, sc, tangent_lists, f, ab)
        c, inf = dpbtrf(ab.reshape(nf, bw + 1).T, lower=0, overwrite_ab=1)
        if inf != 0:
            info[j] = 1
            continue
        y, _ = dpbtrs(c, (Fi[s] - f)[free][perm], lower=0)
        x = dU[j]
        x[perm] = y
        info[j] = _accept(x, Uflat, s, free)


def small_newton_step(m, idx, sc, lists, Fi, fac, Uflat, out):
    """One Newton update per sample on a dense-path model: banded (``bw >= 0``) or dense
    Cholesky, the LU of the whole matrix where it fails or ``lu[j]`` is 1 (then set); the
    compiled twin's semantics (``_compiled.small_newton_step``)."""
    chol_lists, full_lists = lists
    free, perm, bw, _ = fac
    dU, info, res, lu = out
    nf = free.shape[0]
    a = np.empty(nf * nf)
    c = np.empty((bw + 1) * nf if bw >= 0 else nf * nf)
    f = np.empty(Uflat.shape[1])
    for j in range(idx.shape[0]):
        s = idx[j]
        if lu[j] == 0:
            if bw >= 0:
                _assemble_sample(m, s, sc, chol_lists, f, c)
                fac, inf = dpbtrf(c.reshape(nf, bw + 1).T, lower=0, overwrite_ab=1)
            else:
                _assemble_sample(m, s, sc, full_lists, f, a)
                fac, inf = dpotrf(a.reshape(nf, nf).T, lower=0, clean=0)
            if inf == 0:
                r = (Fi[s] - f)[free]
                res[j] = r
                if bw >= 0:
                    dU[j, perm] = dpbtrs(fac, r[perm], lower=0)[0]
                else:
                    dU[j] = dpotrs(fac, r, lower=0)[0]
                info[j] = _accept(dU[j], Uflat, s, free)
                continue
            lu[j] = 1
        _assemble_sample(m, s, sc, full_lists, f, a)
        fac, piv, inf = dgetrf(a.reshape(nf, nf).T)
        if inf > 0:
            info[j] = 1
            continue
        r = (Fi[s] - f)[free]
        res[j] = r
        dU[j] = dgetrs(fac, piv, r)[0]
        info[j] = _accept(dU[j], Uflat, s, free)


def _record_increment(rec, j, i, U, start, step, R, code, tol) -> bool:
    """Write increment ``i`` (from 1) of sample row ``j`` into ``rec`` (IncrementRecords):
    its end displacement ``U`` (ndof,) m, the largest move from ``start`` (m), the iterations
    (``step - 1``), the last ||dU|| ``R`` (m) and whether it converged to ``tol``; a nonzero
    ``code`` also fills ``failed[j]``. True where the sample stops there (``code`` nonzero)."""
    row = i - 1
    rec.U[j, row] = U
    rec.moved[j, row] = np.abs(U - start).max(initial=0.0)
    rec.iters[j, row] = step - 1
    rec.res[j, row] = R
    rec.conv[j, row] = code == 0 and R <= tol
    if code:
        rec.failed[j] = (code, i, step)
    return bool(code)


def newton_increments(m, idx, sc, lists, load, fac, Uflat, rec):
    """Newton-Raphson load control of each sample, every increment in this call (the
    compiled twin's semantics and records; see ``_compiled.newton_increments``)."""
    tangent_lists, full_lists = lists
    F0, P, increments, tol, max_iter = load
    free, perm, bw, _ = fac
    failed = rec.failed
    banded = bw >= 0
    nf = free.shape[0]
    a = np.empty((bw + 1) * nf if banded else nf * nf)
    f = np.empty(Uflat.shape[1])
    for j in range(idx.shape[0]):
        s = idx[j]
        failed[j] = 0
        for i in range(1, increments + 1):
            Fi = F0[s] + i * P[s]
            start = Uflat[s].copy()
            step, R, code = 1, np.inf, 0
            while step < max_iter and R > tol:
                _assemble_sample(m, s, sc, tangent_lists, f, a)
                r = (Fi - f)[free]
                if banded:
                    c, inf = dpbtrf(a.reshape(nf, bw + 1).T, lower=0, overwrite_ab=1)
                    if inf != 0:
                        code = 1
                        break
                    x = np.empty(nf)
                    x[perm] = dpbtrs(c, r[perm], lower=0)[0]
                else:  # Cholesky of the upper triangle; LU where it is not definite
                    c, inf = dpotrf(a.reshape(nf, nf).T, lower=0, clean=0)
                    if inf == 0:
                        x = dpotrs(c, r, lower=0)[0]
                    else:
                        _assemble_sample(m, s, sc, full_lists, f, a)
                        lu, piv, inf = dgetrf(a.reshape(nf, nf).T)
                        if inf > 0:
                            code = 1
                            break
                        x = dgetrs(lu, piv, r)[0]
                code = _accept(x, Uflat, s, free)
                if code:
                    break
                R = float(np.sqrt(x @ x))
                step += 1
            if _record_increment(rec, j, i, Uflat[s], start, step, R, code, tol):
                break


def selffold_increments(m, idx, sc, lists, drive, fac, Uflat, rec):
    """Rest-angle control of each sample, every increment in this call, each step a
    :func:`small_newton_step` (the compiled twin's semantics and records; see
    ``_compiled.selffold_increments``)."""
    F0, start, target, increments, tol, max_iter = drive
    failed = rec.failed
    nf = fac[0].shape[0]
    out = (np.empty((1, nf)), np.zeros(1, np.int8), np.empty((1, nf)), np.zeros(1, np.int8))
    _, info, r, lu = out
    for j in range(idx.shape[0]):
        s = idx[j]
        one = np.array([s], np.intp)
        failed[j] = 0
        for i in range(1, increments + 1):
            t = i / increments
            m.theta0[s] = (1.0 - t) * start[s] + t * target[s]
            first = Uflat[s].copy()
            lu[0] = 0
            step, R, code = 1, np.inf, 0
            while step < max_iter and R > tol:
                small_newton_step(m, one, sc, lists, F0, fac, Uflat, out)
                if info[0] != 0:
                    code = int(info[0])
                    break
                R = float(np.sqrt(r[0] @ r[0]))
                step += 1
            if _record_increment(rec, j, i, Uflat[s], first, step, R, code, tol):
                break


def load_increments(m, idx, sc, lists, load, fac, Uflat, rec):
    """Newton-Raphson load control of each sample, every increment in this call, each step a
    :func:`small_newton_step` (the compiled twin's semantics and records; see
    ``_compiled.load_increments``)."""
    F0, P, increments, tol, max_iter = load
    failed = rec.failed
    nf = fac[0].shape[0]
    out = (np.empty((1, nf)), np.zeros(1, np.int8), np.empty((1, nf)), np.zeros(1, np.int8))
    dU, info, _, lu = out
    Fi = np.empty_like(F0)
    for j in range(idx.shape[0]):
        s = idx[j]
        one = np.array([s], np.intp)
        failed[j] = 0
        for i in range(1, increments + 1):
            Fi[s] = F0[s] + i * P[s]
            first = Uflat[s].copy()
            lu[0] = 0
            step, R, code = 1, np.inf, 0
            while step < max_iter and R > tol:
                small_newton_step(m, one, sc, lists, Fi, fac, Uflat, out)
                if info[0] != 0:
                    code = int(info[0])
                    break
                R = float(np.sqrt(dU[0] @ dU[0]))
                step += 1
            if _record_increment(rec, j, i, Uflat[s], first, step, R, code, tol):
                break


def lapack_addresses(*names: str) -> np.ndarray:
    """Placeholder addresses (the numpy path calls scipy's wrappers by name)."""
    return np.zeros(len(names), np.int64)
