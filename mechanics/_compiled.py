"""The compiled kernel path (numba): element kernels, sums and whole Newton steps.

The accelerator over the numpy path (:mod:`~holofold.mechanics._numpy_kernels`): the same
functions, signatures and layouts, chosen by :mod:`~holofold.mechanics.kernels` (import this
module through it: the kernel cache folder is set there). The numpy kernels make some forty
array operations per call, about 95 us of fixed cost whatever the model size; here each bar is
one pass of scalar code, the springs one branch-free loop that runs vectorised across springs
(:mod:`~holofold.mechanics._spring_loop`, after a scalar pass for the angles), each sum one loop
over the kernels' entries in memory order, and a Newton step one call with scipy's LAPACK by
address. The two paths agree to round-off (tests/test_kernel_paths.py), not to the bit.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from holofold.mechanics._jit import OPTS as _OPTS
from holofold.mechanics._spring_loop import spring_force_loop, spring_tangent_loop

__all__ = [
    "bar_elements",
    "spring_angles",
    "spring_elements",
    "scatter",
    "assemble_batch",
    "band_newton_step",
    "small_newton_step",
    "selffold_increments",
    "load_increments",
    "lapack_addresses",
    "thermal_sides",
    "thermal_system",
    "thermal_steady",
]

_TWO_PI = 2.0 * math.pi


@njit(**_OPTS)
def _mod(a, b):
    """``np.mod(a, b)`` for b > 0 (numpy's ``npy_divmod``)."""
    m = np.fmod(a, b)
    if m != 0.0:
        if (b < 0.0) != (m < 0.0):
            m += b
    else:
        m = math.copysign(0.0, b)
    return m


@njit(**_OPTS)
def bar_elements(X, U, b0, b1, D0, L0, EA, tangent, out):
    """Bars of :func:`~holofold.mechanics.bars.bar_kernel` from nodal arrays.

    ``X``, ``U`` (nn, 3) reference coordinates and displacements, m; ``b0``, ``b1`` (nb,)
    end nodes; ``D0`` (3, nb) reference bar vectors; ``L0``, ``EA`` (nb,). Writes ``out =
    (energy, force, K)``: ``energy`` (nb,), ``force`` (3, 2, nb) and, if ``tangent``, ``K``
    (3, 3, 2, 2, nb): the numpy kernel's layouts.
    """
    energy, force, K = out
    nb = b0.shape[0]
    for e in range(nb):
        na = np.uintp(b0[e])  # unsigned: no negative-index wrap-around in the loads
        nbb = np.uintp(b1[e])
        d0 = U[nbb, 0] - U[na, 0]
        d1 = U[nbb, 1] - U[na, 1]
        d2 = U[nbb, 2] - U[na, 2]
        D0x = D0[0, e]
        D0y = D0[1, e]
        D0z = D0[2, e]
        L = L0[e]
        ea = EA[e]
        inv_L2 = 1.0 / (L * L)
        x0 = D0x + d0
        x1 = D0y + d1
        x2 = D0z + d2
        s1 = D0x * d0 + D0y * d1
        s1 = s1 + D0z * d2
        s2 = d0 * d0 + d1 * d1
        s2 = s2 + d2 * d2
        eps = (s1 + 0.5 * s2) * inv_L2
        SA = ea * eps
        energy[e] = 0.5 * ea * L * eps * eps
        c = SA / L
        f0 = c * x0
        f1 = c * x1
        f2 = c * x2
        force[0, 0, e] = -f0
        force[1, 0, e] = -f1
        force[2, 0, e] = -f2
        force[0, 1, e] = f0
        force[1, 1, e] = f1
        force[2, 1, e] = f2
        if tangent:
            coef = ea * inv_L2 / L
            for i in range(3):
                xi = x0 if i == 0 else (x1 if i == 1 else x2)
                for j in range(3):
                    xj = x0 if j == 0 else (x1 if j == 1 else x2)
                    k3 = coef * (xi * xj)
                    k3 = k3 + c * (1.0 if i == j else 0.0)
                    K[i, j, 0, 0, e] = k3 * 1.0
                    K[i, j, 0, 1, e] = k3 * -1.0
                    K[i, j, 1, 0, e] = k3 * -1.0
                    K[i, j, 1, 1, e] = k3 * 1.0


@njit(inline="always", **_OPTS)
def _dot3(a, b):
    s = a[0] * b[0] + a[1] * b[1]
    return s + a[2] * b[2]


@njit(inline="always", **_OPTS)
def _cross3(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(inline="always", **_OPTS)
def _node(X, U, nd):
    nd = np.uintp(nd)  # unsigned: no negative-index wrap-around in the loads
    return (X[nd, 0] + U[nd, 0], X[nd, 1] + U[nd, 1], X[nd, 2] + U[nd, 2])


@njit(inline="always", **_OPTS)
def _sub3(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(**_OPTS)
def spring_angles(X, U, sT, theta):
    """``theta`` (ns,): the dihedral angle of every spring, in [0, 2 pi) (scalar code: atan2
    and the branches of ``np.mod`` do not vectorise)."""
    for s in range(sT.shape[1]):
        P0 = _node(X, U, sT[0, s])
        P1 = _node(X, U, sT[1, s])
        P2 = _node(X, U, sT[2, s])
        P3 = _node(X, U, sT[3, s])
        rij = _sub3(P0, P1)
        rkj = _sub3(P2, P1)
        rkl = _sub3(P2, P3)
        m = _cross3(rij, rkj)
        n = _cross3(rkj, rkl)
        ell = math.sqrt(_dot3(rkj, rkj))
        theta[s] = _mod(math.atan2(ell * _dot3(m, rkl), _dot3(m, n)), _TWO_PI)


@njit(**_OPTS)
def spring_elements(X, U, sT, k, theta0, k_nonneg, tangent, out):
    """Springs of :func:`~holofold.mechanics.springs.spring_kernel` from nodal arrays.

    ``X``, ``U`` (nn, 3); ``sT`` (4, ns) node quadruples (i, j, k, l); ``k``, ``theta0``
    (ns,); ``k_nonneg``: every k >= 0 (the numpy path's branch). Writes ``out = (energy,
    force, K, theta)``: ``energy`` (ns,),
    ``force`` (3, 4, ns), ``theta`` (ns,) and, if ``tangent``, ``K`` (3, 3, 10, ns): the numpy
    kernel's layouts (or any strided views with those indices; the outputs must not overlap
    each other or the inputs). The angles first (:func:`spring_angles`, scalar), then one
    branch-free loop over the springs (:mod:`~holofold.mechanics._spring_loop`), which runs
    vectorised across springs where the outputs are the kernels' contiguous layouts.
    """
    energy, force, K, theta = out
    spring_angles(X, U, sT, theta)
    if tangent:
        spring_tangent_loop(X, U, sT, k, theta0, k_nonneg, energy, force, K, theta)
    else:
        spring_force_loop(X, U, sT, k, theta0, energy, force, theta)


@njit(**_OPTS)
def scatter(src_a, tgt_a, val_a, src_b, tgt_b, val_b, src_c, tgt_c, val_c, out):
    """``out[tgt_a[q]] += val_a[src_a[q]]`` for every q (likewise b, c): each family's values
    read in the order they lie in memory, added straight into their targets (``out`` starts as
    zeros where it is to hold only these sums)."""
    # unsigned indices: numba then skips its negative-index wrap-around
    for q in range(src_a.shape[0]):
        out[np.uintp(tgt_a[q])] += val_a[np.uintp(src_a[q])]
    for q in range(src_b.shape[0]):
        out[np.uintp(tgt_b[q])] += val_b[np.uintp(src_b[q])]
    for q in range(src_c.shape[0]):
        out[np.uintp(tgt_c[q])] += val_c[np.uintp(src_c[q])]


@njit(**_OPTS)
def _assemble_sample(m, s, sc, tangent_lists, f, K):
    """Sample ``s``'s kernels (``m`` a :class:`~holofold.mechanics.kernel_args.ModelArrays`)
    into ``sc.views`` (memory ``sc.flats``), its internal force into ``f`` by ``sc.force``
    and its tangent into ``K`` by ``tangent_lists`` (both zeroed first: the scatters write
    only the entries that receive something)."""
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


@njit(**_OPTS)
def assemble_batch(m, idx, sc, tangent_lists, f_out, k_out):
    """For each sample ``s = idx[j]`` of ``m`` (a :class:`~holofold.mechanics.kernel_args.
    ModelArrays`): the kernels into the element arrays ``sc.views`` (the seven of one sample,
    in the kernels' layouts), then ``f_out[j]`` by ``sc.force`` and ``k_out[j]`` by
    ``tangent_lists`` (each the six lists of :func:`scatter`, without the values), whose
    sources index the memory of the views, ``sc.flats`` (``f_out`` and ``k_out`` need not
    start as zeros)."""
    for j in range(idx.shape[0]):
        _assemble_sample(m, idx[j], sc, tangent_lists, f_out[j], k_out[j])


# ------------------------------------------------------------------------ LAPACK calls
# scipy's LAPACK routines by address (scipy.linalg.cython_lapack, the library that
# scipy.linalg.lapack's wrappers call). The address is an argument, not a constant of the
# compiled code, so the code stays cacheable.


@intrinsic
def _fcall(typingctx, addr, args):
    """Call the void C function at ``addr`` (int) with the data pointers of the tuple of
    arrays ``args`` (Fortran calling convention: every argument by reference)."""
    sig = types.void(addr, args)

    def codegen(context, builder, signature, llargs):
        ptrs = []
        for i, ty in enumerate(signature.args[1].types):
            ary = context.make_array(ty)(context, builder, builder.extract_value(llargs[1], i))
            ptrs.append(builder.bitcast(ary.data, ir.IntType(8).as_pointer()))
        fnty = ir.FunctionType(ir.VoidType(), [ir.IntType(8).as_pointer()] * len(ptrs))
        builder.call(builder.inttoptr(llargs[0], fnty.as_pointer()), ptrs)
        return context.get_dummy_value()

    return sig, codegen


def lapack_addresses(*names: str) -> np.ndarray:
    """Addresses of scipy's LAPACK routines ``names`` (e.g. ``"dpbtrf", "dpbtrs"``)."""
    return _addresses(names).copy()


@cache
def _addresses(names: tuple[str, ...]) -> np.ndarray:
    from numba.extending import get_cython_function_address

    return np.array(
        [get_cython_function_address("scipy.linalg.cython_lapack", n) for n in names], np.int64
    )


@njit(**_OPTS)
def band_newton_step(m, idx, sc, tangent_lists, Fi, fac, Uflat, out):
    """One Newton update of each sample ``s = idx[j]`` on the banded Cholesky path: the
    kernels and scatters of :func:`assemble_batch` (force into ``out.f[j]``), ``dpbtrf`` of
    the band, ``dpbtrs`` of ``(Fi[s] - f)[free]`` in the band's order ``fac.perm``,
    ``out.dU[j]`` the solution on the free DOFs and ``Uflat[s, free] += dU[j]``.
    ``out.info[j]``: 0 done, 1 not positive definite (nothing solved or updated), 2 a
    non-finite solution (U not updated). The operations of ``Assembler.evaluate_factorized``
    and its band solver, in their order. ``fac``: a :class:`~holofold.mechanics.kernel_args.
    Factor` (dpbtrf, dpbtrs); ``out`` a ``BandOut``."""
    free, perm, bw, addrs = fac
    dU, f_out, info = out
    nf = free.shape[0]
    uplo = np.array([ord("U")], np.uint8)
    n_ = np.array([nf], np.int32)
    kd_ = np.array([bw], np.int32)
    ld_ = np.array([bw + 1], np.int32)
    one = np.array([1], np.int32)
    inf_ = np.zeros(1, np.int32)
    ab = np.empty((bw + 1) * nf)
    y = np.empty(nf)
    for j in range(idx.shape[0]):
        s = idx[j]
        f = f_out[j]
        _assemble_sample(m, s, sc, tangent_lists, f, ab)
        _fcall(addrs[0], (uplo, n_, kd_, ab, ld_, inf_))
        if inf_[0] != 0:
            info[j] = 1
            continue
        for q in range(nf):
            d = free[perm[q]]
            y[q] = Fi[s, d] - f[d]
        _fcall(addrs[1], (uplo, n_, kd_, one, ab, ld_, y, n_, inf_))
        x = dU[j]
        for q in range(nf):
            x[perm[q]] = y[q]
        info[j] = _accept(x, Uflat, s, free)


@njit(**_OPTS)
def _accept(x, Uflat, s, free) -> int:
    """The status of a Newton solution ``x`` (free DOFs) of sample ``s``: 2 if any entry is not
    finite, else 0 after adding it to ``Uflat[s, free]``."""
    for q in range(free.shape[0]):
        if not np.isfinite(x[q]):
            return 2
    for q in range(free.shape[0]):
        Uflat[s, free[q]] += x[q]
    return 0


@njit(**_OPTS)
def small_newton_step(m, idx, sc, lists, Fi, fac, Uflat, out):
    """One Newton update of each sample ``s = idx[j]`` on the dense-path model (at most
    ``DENSE_MAX_DOF`` free DOFs) by the cheapest factorisation that holds: a Cholesky, and
    the LU of the whole matrix only where the tangent is not positive definite.

    ``bw >= 0``: the banded Cholesky (``chol_lists`` the ``"banded"`` sums, ``perm`` the
    band's order; ``dpbtrf``/``dpbtrs``); ``bw < 0``: the dense Cholesky of the column-major
    matrix (``chol_lists`` its ``"dense_cm"`` sums; ``dpotrf``/``dpotrs`` on a copy, so that
    the LU finds the matrix whole). Where the Cholesky fails, or ``lu[j]`` is 1 on entry, the
    whole matrix (``full_lists``, ``"dense_cm"``) is factorised by LU (``dgetrf``/``dgetrs``)
    and ``lu[j]`` is set to 1. ``addrs``: dgetrf, dgetrs, then dpbtrf, dpbtrs (banded) or
    dpotrf, dpotrs (dense). ``res[j]`` receives ``(Fi[s] - f)[free]``; ``dU[j]`` the solution;
    ``info[j]``: 0 done (``Uflat[s, free] += dU[j]``), 1 singular, 2 a non-finite solution
    (U not updated). ``lists = (chol_lists, full_lists)``; ``fac`` a :class:`~holofold.
    mechanics.kernel_args.Factor` (free, perm, bw, addrs); ``out`` a ``StepOut`` (dU, info,
    res, lu)."""
    chol_lists, full_lists = lists
    free, perm, bw, addrs = fac
    dU, info, res, lu = out
    nf = free.shape[0]
    c_u = np.array([ord("U")], np.uint8)
    c_n = np.array([ord("N")], np.uint8)
    n_ = np.array([nf], np.int32)
    kd_ = np.array([max(bw, 0)], np.int32)
    ld_ = np.array([max(bw, 0) + 1], np.int32)
    one = np.array([1], np.int32)
    inf_ = np.zeros(1, np.int32)
    piv = np.empty(nf, np.int32)
    a = np.empty(nf * nf)
    c = np.empty((bw + 1) * nf if bw >= 0 else nf * nf)
    y = np.empty(nf)
    f = np.empty(Uflat.shape[1])
    for j in range(idx.shape[0]):
        s = idx[j]
        x = dU[j]
        r = res[j]
        if lu[j] == 0:
            if bw >= 0:
                _assemble_sample(m, s, sc, chol_lists, f, c)
            else:
                _assemble_sample(m, s, sc, full_lists, f, a)
                c[:] = a
            if bw >= 0:
                _fcall(addrs[2], (c_u, n_, kd_, c, ld_, inf_))
            else:
                _fcall(addrs[2], (c_u, n_, c, n_, inf_))
            if inf_[0] == 0:
                for q in range(nf):
                    d = free[q]
                    r[q] = Fi[s, d] - f[d]
                if bw >= 0:
                    for q in range(nf):
                        y[q] = r[perm[q]]
                    _fcall(addrs[3], (c_u, n_, kd_, one, c, ld_, y, n_, inf_))
                    for q in range(nf):
                        x[perm[q]] = y[q]
                else:
                    for q in range(nf):
                        x[q] = r[q]
                    _fcall(addrs[3], (c_u, n_, one, c, n_, x, n_, inf_))
                info[j] = _accept(x, Uflat, s, free)
                continue
            lu[j] = 1
            if bw >= 0:  # the band held only the Cholesky's entries: the whole matrix now
                _assemble_sample(m, s, sc, full_lists, f, a)
        else:
            _assemble_sample(m, s, sc, full_lists, f, a)
        _fcall(addrs[0], (n_, n_, a, n_, piv, inf_))
        if inf_[0] > 0:
            info[j] = 1
            continue
        for q in range(nf):
            d = free[q]
            r[q] = Fi[s, d] - f[d]
            x[q] = r[q]
        _fcall(addrs[1], (c_n, n_, one, a, n_, piv, x, n_, inf_))
        info[j] = _accept(x, Uflat, s, free)


@njit(**_OPTS)
def _record_increment(rec, j, i, U, start, step, R, code, tol):
    """Write increment ``i`` (from 1) of sample row ``j`` into ``rec`` (IncrementRecords): its
    end displacement ``U`` (ndof,) m, the largest move from ``start`` (m), the iterations
    (``step - 1``), the last residual ``R`` and whether it met ``tol``; a nonzero ``code``
    also fills ``failed[j]``. True where the sample stops there (``code`` nonzero)."""
    U_hist, conv, iters, res, moved, failed = rec
    row = i - 1
    mv = 0.0
    for d in range(U.shape[0]):
        U_hist[j, row, d] = U[d]
        mv = max(mv, abs(U[d] - start[d]))
    moved[j, row] = mv
    iters[j, row] = step - 1
    res[j, row] = R
    conv[j, row] = code == 0 and R <= tol
    if code:
        failed[j, 0] = code
        failed[j, 1] = i
        failed[j, 2] = step
        return True
    return False


@njit(**_OPTS)
def newton_increments(m, idx, sc, lists, load, fac, Uflat, rec):
    """Newton-Raphson load control of each sample ``s = idx[j]``, every increment and
    iteration in this one call (:func:`holofold.mechanics.solvers.solve_newton`'s semantics).

    At increment ``i = 1..increments`` the force is ``F0[s] + i P[s]``; iterate
    ``U[free] += K_ff^-1 (F - f_int)[free]`` while ``step < max_iter`` and ``||dU|| > tol``.
    Records per increment (row ``i - 1``): ``U_hist[j]`` (ndof), ``conv[j]`` (R <= tol),
    ``iters[j]`` (steps - 1), ``res[j]`` (the last R) and ``moved[j]`` (max |U - U at the
    increment's start|). The dense path factorises the upper triangle (``tangent_lists``) by
    Cholesky, and the whole matrix (``full_lists``) by LU where that fails (``addrs``: dgetrf,
    dgetrs, dpotrf, dpotrs); the banded one the band (``tangent_lists``) by Cholesky (dpbtrf,
    dpbtrs). A failed step stops the sample: ``failed[j] = (code, increment, step)`` with code
    1 (singular, or not positive definite on the banded path: the caller solves that sample
    another way) or 2 (a non-finite solution), the failing increment recorded with the last U
    and R, not converged.

    ``lists = (tangent_lists, full_lists)``; ``load`` an :class:`~holofold.mechanics.
    kernel_args.Increments` (F0, P, increments, tol, max_iter); ``fac`` a ``Factor`` (free,
    perm, bw, addrs; ``bw < 0``: the dense path); ``rec`` an ``IncrementRecords`` (U_hist,
    conv, iters, res, moved, failed)."""
    tangent_lists, full_lists = lists
    F0, P, increments, tol, max_iter = load
    free, perm, bw, addrs = fac
    failed = rec.failed
    banded = bw >= 0
    nf = free.shape[0]
    nd = Uflat.shape[1]
    c_u = np.array([ord("U")], np.uint8)
    c_n = np.array([ord("N")], np.uint8)
    n_ = np.array([nf], np.int32)
    kd_ = np.array([max(bw, 0)], np.int32)
    ld_ = np.array([max(bw, 0) + 1], np.int32)
    one = np.array([1], np.int32)
    inf_ = np.zeros(1, np.int32)
    piv = np.empty(nf, np.int32)
    a = np.empty((bw + 1) * nf if banded else nf * nf)
    f = np.empty(nd)
    Fi = np.empty(nd)
    start = np.empty(nd)
    x = np.empty(nf)
    y = np.empty(nf)
    for j in range(idx.shape[0]):
        s = idx[j]
        failed[j, 0] = 0
        for i in range(1, increments + 1):
            for d in range(nd):
                Fi[d] = F0[s, d] + i * P[s, d]
                start[d] = Uflat[s, d]
            step = 1
            R = np.inf
            code = 0
            while step < max_iter and R > tol:
                _assemble_sample(m, s, sc, tangent_lists, f, a)
                if banded:
                    _fcall(addrs[0], (c_u, n_, kd_, a, ld_, inf_))
                    if inf_[0] != 0:
                        code = 1
                        break
                    for q in range(nf):
                        d = free[perm[q]]
                        y[q] = Fi[d] - f[d]
                    _fcall(addrs[1], (c_u, n_, kd_, one, a, ld_, y, n_, inf_))
                    for q in range(nf):
                        x[perm[q]] = y[q]
                else:  # Cholesky of the upper triangle; LU where it is not definite
                    for q in range(nf):
                        d = free[q]
                        x[q] = Fi[d] - f[d]
                    _fcall(addrs[2], (c_u, n_, a, n_, inf_))
                    if inf_[0] == 0:
                        _fcall(addrs[3], (c_u, n_, one, a, n_, x, n_, inf_))
                    else:  # the whole matrix this time
                        _assemble_sample(m, s, sc, full_lists, f, a)
                        _fcall(addrs[0], (n_, n_, a, n_, piv, inf_))
                        if inf_[0] > 0:
                            code = 1
                            break
                        _fcall(addrs[1], (c_n, n_, one, a, n_, piv, x, n_, inf_))
                code = _accept(x, Uflat, s, free)
                if code:
                    break
                R2 = 0.0
                for q in range(nf):
                    R2 += x[q] * x[q]
                R = math.sqrt(R2)
                step += 1
            if _record_increment(rec, j, i, Uflat[s], start, step, R, code, tol):
                break


@njit(**_OPTS)
def selffold_increments(m, idx, sc, lists, drive, fac, Uflat, rec):
    """Rest-angle control of each sample ``s = idx[j]`` (dense-path models), every increment
    and iteration in this one call (:func:`holofold.mechanics.solvers.solve_selffold`'s
    semantics, its steps those of :func:`small_newton_step`).

    At increment ``i = 1..increments`` the rest angles ``m.theta0[s]`` (written here) are
    ``(1 - i/n) start[s] + (i/n) target[s]``; iterate ``r = (F0 - f_int)[free]``, ``U[free]
    += K_ff^-1 r``, ``R = ||r||`` (the residual before the update, the update applied even
    when R meets the tolerance) while ``step < max_iter`` and ``R > tol``. Each increment
    starts on the Cholesky and keeps the LU once the tangent was not positive definite.
    Records per increment (row ``i - 1``): ``U[j]`` (ndof), ``conv[j]`` (R <= tol),
    ``iters[j]`` (steps - 1), ``res[j]`` (the last R) and ``moved[j]`` (max |U - U at the
    increment's start|). A failed step stops the sample: ``failed[j] = (code, increment,
    step)`` with code 1 (singular) or 2 (a non-finite solution, U not updated), that
    increment recorded with the last U and R, not converged.

    ``lists``, ``fac``: those of :func:`small_newton_step`; ``drive`` a :class:`~holofold.
    mechanics.kernel_args.RestControl`; ``rec`` an ``IncrementRecords``."""
    F0, start, target, increments, tol, max_iter = drive
    failed = rec.failed
    free = fac[0]
    nf = free.shape[0]
    nd = Uflat.shape[1]
    ns = start.shape[1]
    one = np.empty(1, np.intp)
    dU = np.empty((1, nf))
    info = np.zeros(1, np.int8)
    r = np.empty((1, nf))
    lu = np.zeros(1, np.int8)
    out = (dU, info, r, lu)
    first = np.empty(nd)
    for j in range(idx.shape[0]):
        s = idx[j]
        one[0] = s
        theta0 = m.theta0[s]
        failed[j, 0] = 0
        for i in range(1, increments + 1):
            t = i / increments
            for k in range(ns):
                theta0[k] = (1.0 - t) * start[s, k] + t * target[s, k]
            for d in range(nd):
                first[d] = Uflat[s, d]
            lu[0] = 0
            step = 1
            R = np.inf
            code = 0
            while step < max_iter and R > tol:
                small_newton_step(m, one, sc, lists, F0, fac, Uflat, out)
                if info[0] != 0:
                    code = info[0]
                    break
                R2 = 0.0
                for q in range(nf):
                    R2 += r[0, q] * r[0, q]
                R = math.sqrt(R2)
                step += 1
            if _record_increment(rec, j, i, Uflat[s], first, step, R, code, tol):
                break


@njit(**_OPTS)
def load_increments(m, idx, sc, lists, load, fac, Uflat, rec):
    """Newton-Raphson load control of each sample ``s = idx[j]`` (dense-path models), every
    increment and iteration in this one call, each step that of :func:`small_newton_step`
    (:func:`holofold.mechanics.solvers.solve_newton`'s semantics with one ``DenseStepper`` per
    increment: each increment starts on the Cholesky and keeps the LU once the tangent was not
    positive definite).

    At increment ``i = 1..increments`` the force is ``F0[s] + i P[s]``; iterate ``U[free] +=
    dU`` while ``step < max_iter`` and ``R = ||dU|| > tol`` (``R`` by BLAS ``ddot``, as numpy's
    ``dU @ dU``). Records as :func:`newton_increments` (``res`` the last ||dU||, m); a failed
    step stops the sample: ``failed[j] = (code, increment, step)``, code 1 singular, 2 a
    non-finite solution (U not updated). ``lists``, ``fac``: those of
    :func:`small_newton_step`; ``load`` an :class:`~holofold.mechanics.kernel_args.Increments`;
    ``rec`` an ``IncrementRecords``."""
    F0, P, increments, tol, max_iter = load
    failed = rec.failed
    free = fac[0]
    nf = free.shape[0]
    nd = Uflat.shape[1]
    one = np.empty(1, np.intp)
    dU = np.empty((1, nf))
    info = np.zeros(1, np.int8)
    r = np.empty((1, nf))
    lu = np.zeros(1, np.int8)
    out = (dU, info, r, lu)
    Fi = np.empty_like(F0)
    first = np.empty(nd)
    x = dU[0]
    for j in range(idx.shape[0]):
        s = idx[j]
        one[0] = s
        failed[j, 0] = 0
        for i in range(1, increments + 1):
            for d in range(nd):
                Fi[s, d] = F0[s, d] + i * P[s, d]
                first[d] = Uflat[s, d]
            lu[0] = 0
            step = 1
            R = np.inf
            code = 0
            while step < max_iter and R > tol:
                small_newton_step(m, one, sc, lists, Fi, fac, Uflat, out)
                if info[0] != 0:
                    code = info[0]
                    break
                R = math.sqrt(np.dot(x, x))
                step += 1
            if _record_increment(rec, j, i, Uflat[s], first, step, R, code, tol):
                break


# ------------------------------------------------------------------------ thermal
# The small-model steady temperature of :mod:`holofold.mechanics.thermal` (reference
# geometry) without its forty array operations per heating step (the numpy path keeps
# thermal.py's own array code). numpy keeps the angle (einsum, arctan2, cos, sin) and the
# series sum over the air layers.


@njit(**_OPTS)
def thermal_sides(x, tri, u, v, cross):
    """``u = xb - xa``, ``v = xc - xa`` (nt, 3) and ``cross = |u x v|`` (nt,) as
    ``np.linalg.norm(np.cross(u, v), axis=1)``."""
    for t in range(tri.shape[0]):
        a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]
        for d in range(3):
            u[t, d] = x[b, d] - x[a, d]
            v[t, d] = x[c, d] - x[a, d]
        c0 = u[t, 1] * v[t, 2] - u[t, 2] * v[t, 1]
        c1 = u[t, 2] * v[t, 0] - u[t, 0] * v[t, 2]
        c2 = u[t, 0] * v[t, 1] - u[t, 1] * v[t, 0]
        cross[t] = math.sqrt((c0 * c0 + c1 * c1) + c2 * c2)


@njit(**_OPTS)
def thermal_system(cos, sin, pieces, area, A, Gq):
    """From the angle's ``cos``, ``sin`` (nt,) and the model's fixed ``pieces`` (a
    :class:`~holofold.mechanics.thermal.CompiledPieces`): ``area`` (nt,), the conduction
    matrix ``A`` (flat nn^2, zeros on entry) and the node-layer conductances ``Gq`` (nn, L), as
    ``triangle_edges``, ``_element_matrices`` + ``np.bincount`` and ``_air_links`` + the
    incidence product compute them. Returns False (nothing assembled) if an area is <= 0."""
    Lab, Lac, half_ab_ac, k_th, slots, side, k_env, layers, h, ptr, idx, data = pieces
    nt = cos.shape[0]
    e = np.empty((3, 2))
    for t in range(nt):
        area[t] = half_ab_ac[t] * sin[t]
    for t in range(nt):
        if area[t] <= 0.0:
            return False
    for t in range(nt):
        pc0 = Lac[t] * cos[t]
        pc1 = Lac[t] * sin[t]
        # pa = (0, 0), pb = (Lab, 0): e = [pc - pb, pa - pc, pb - pa]
        e[0, 0] = pc0 - Lab[t]
        e[0, 1] = pc1 - 0.0
        e[1, 0] = 0.0 - pc0
        e[1, 1] = 0.0 - pc1
        e[2, 0] = Lab[t] - 0.0
        e[2, 1] = 0.0 - 0.0
        coef = k_th[t] / (4.0 * area[t])
        for p in range(3):
            for q in range(3):
                s = slots[9 * t + 3 * p + q]
                A[s] += coef * (e[p, 0] * e[q, 0] + e[p, 1] * e[q, 1])
    L = side.shape[1]
    links = np.empty((nt, L))
    for t in range(nt):
        for j in range(L):
            Ac = (2.0 / 3.0) * area[t] + side[t, j]
            links[t, j] = k_env * Ac * layers / h[t]
    for i in range(Gq.shape[0]):
        for j in range(L):
            Gq[i, j] = 0.0
        for jj in range(ptr[i], ptr[i + 1]):
            for j in range(L):
                Gq[i, j] += data[jj] * links[idx[jj], j]
    return True


@njit(**_OPTS)
def _pairwise_sum(a):
    """``a.sum()`` of a contiguous (n,) array, n <= 128, in numpy's order (its pairwise sum:
    eight running sums below 128 entries, combined as a tree, the tail added last)."""
    n = a.shape[0]
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[0], a[1], a[2], a[3]
    r4, r5, r6, r7 = a[4], a[5], a[6], a[7]
    i = 8
    while i < n - n % 8:
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[i]
        i += 1
    return res


@njit(**_OPTS)
def thermal_steady(cos, sin, pieces, q, RT, addrs, area, A, T):
    """The small model's steady temperature (reference geometry) from the angles' ``cos``,
    ``sin`` (nt,) in one call: :func:`thermal_system` (``area`` (nt,) out, ``A`` flat nn^2
    work), the air chains' series conductance ``G`` (nn,) as ``thermal._series`` (0 where a
    node has no positive link; numpy's summation order), then ``(A + diag(G)) T = q + G RT``
    by the Cholesky of the upper triangle (``addrs``: dpotrf, dpotrs) into ``T`` (nn,) °C;
    ``q`` (nn,) W, ``RT`` °C. Returns 0, -1 (an area <= 0: nothing solved) or the order of
    the leading minor that is not positive definite. The numbers of ``steady_temperature``'s
    numpy path to round-off (the same operations in the same order)."""
    n = T.shape[0]
    L = pieces.side.shape[1]
    A[:] = 0.0
    Gq = np.empty((n, L))
    if not thermal_system(cos, sin, pieces, area, A, Gq):
        return -1
    inv = np.empty(L)
    for i in range(n):
        for j in range(L):
            g = Gq[i, j]
            inv[j] = 1.0 / g if g > 0.0 else np.inf
        s = _pairwise_sum(inv) if L <= 128 else inv.sum()
        G = 1.0 / s if np.isfinite(s) else 0.0
        A[i * (n + 1)] += G
        T[i] = q[i] + G * RT
    c_u = np.array([ord("U")], np.uint8)
    n_ = np.array([n], np.int32)
    one = np.array([1], np.int32)
    info = np.zeros(1, np.int32)
    _fcall(addrs[0], (c_u, n_, A, n_, info))
    if info[0] != 0:
        return info[0]
    _fcall(addrs[1], (c_u, n_, one, A, n_, T, n_, info))
    return 0
