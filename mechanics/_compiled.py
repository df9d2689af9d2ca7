"""Compiled element kernels and scatters of the assembly (numba, cached on disk).

The numpy kernels of :mod:`~holofold.mechanics.bars` and :mod:`~holofold.mechanics.springs`
make some forty array operations per call: about 95 us of fixed cost whatever the model size,
and a temporary per operation. Here each element is one pass of scalar code and each scatter
one loop, with no fixed cost beyond the call.

The results are bit for bit those of the numpy kernels and ``np.bincount`` scatters
(tests/test_compiled.py): every element performs the same IEEE operations in the same order
(sums over the three components left to right as numpy reduces a length-3 axis, ``np.mod`` as
numpy's ``npy_divmod``, no fast-math, no fused multiply-add), and :func:`gather` adds the
contributions of a target in the order ``np.bincount`` does (the flat order of the kernel
layout, each family summed on its own, the families added as the numpy path added them). The
layouts are the numpy kernels' (see :func:`~holofold.mechanics.bars.bar_kernel` and
:func:`~holofold.mechanics.springs.spring_kernel`), so one slot map serves both.

numba compiles on first use and caches the machine code next to this file (or under
``NUMBA_CACHE_DIR``): a new process loads it in tens of milliseconds.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["bar_elements", "spring_elements", "gather"]

_TWO_PI = 2.0 * math.pi
_OPTS = dict(cache=True, nogil=True, error_model="numpy", boundscheck=False)


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
def bar_elements(X, U, b0, b1, D0, L0, EA, tangent, energy, force, K):
    """Bars of :func:`~holofold.mechanics.bars.bar_kernel` from nodal arrays.

    ``X``, ``U`` (nn, 3) reference coordinates and displacements, m; ``b0``, ``b1`` (nb,)
    end nodes; ``D0`` (3, nb) reference bar vectors; ``L0``, ``EA`` (nb,). Writes
    ``energy`` (nb,), ``force`` (3, 2, nb) and, if ``tangent``, ``K`` (3, 3, 2, 2, nb): the
    numpy kernel's layouts.
    """
    nb = b0.shape[0]
    for e in range(nb):
        na = b0[e]
        nbb = b1[e]
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


@njit(**_OPTS)
def _dot(a, b):
    s = a[0] * b[0] + a[1] * b[1]
    return s + a[2] * b[2]


@njit(**_OPTS)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(**_OPTS)
def spring_elements(X, U, sT, k, theta0, k_nonneg, tangent, energy, force, K, theta):
    """Springs of :func:`~holofold.mechanics.springs.spring_kernel` from nodal arrays.

    ``X``, ``U`` (nn, 3); ``sT`` (4, ns) node quadruples (i, j, k, l); ``k``, ``theta0``
    (ns,); ``k_nonneg``: every k >= 0 (the numpy path's branch). Writes ``energy`` (ns,),
    ``force`` (3, 4, ns), ``theta`` (ns,) and, if ``tangent``, ``K`` (3, 3, 10, ns): the numpy
    kernel's layouts.
    """
    ns = sT.shape[1]
    P = np.empty((4, 3))
    rij = np.empty(3)
    rkj = np.empty(3)
    rkl = np.empty(3)
    m = np.empty(3)
    n = np.empty(3)
    g = np.empty((4, 3))  # [node, component]
    gk = np.empty((4, 3))
    a1 = np.empty(3)
    a2 = np.empty(3)
    b1 = np.empty(3)
    b2 = np.empty(3)
    dd = np.empty((4, 3))  # dA_j, dA_k, dB_j, dB_k
    gs = np.empty((2, 3))
    coef = np.empty(3)
    hjj = np.empty((3, 3))
    hkk = np.empty((3, 3))
    for s in range(ns):
        for a in range(4):
            nd = sT[a, s]
            for c in range(3):
                P[a, c] = X[nd, c] + U[nd, c]
        for c in range(3):
            rij[c] = P[0, c] - P[1, c]
            rkj[c] = P[2, c] - P[1, c]
            rkl[c] = P[2, c] - P[3, c]
        _cross(rij, rkj, m)
        _cross(rkj, rkl, n)
        dl2 = _dot(rkj, rkj)
        dmm = _dot(m, m)
        dnn = _dot(n, n)
        dA = _dot(rij, rkj)
        dB = _dot(rkl, rkj)
        dmkl = _dot(m, rkl)
        dmn = _dot(m, n)
        ell = math.sqrt(dl2)
        th = _mod(math.atan2(ell * dmkl, dmn), _TWO_PI)
        theta[s] = th
        A = dA / dl2
        B = dB / dl2
        p = ell / dmm
        q = ell / dnn
        al0 = p * (1.0 + 0.0 * A)
        al1 = p * (-1.0 + 1.0 * A)
        al2 = p * (0.0 + -1.0 * A)
        al3 = p * (0.0 + 0.0 * A)
        be0 = q * (0.0 + 0.0 * B)
        be1 = q * (0.0 + 1.0 * B)
        be2 = q * (1.0 + -1.0 * B)
        be3 = q * (-1.0 + 0.0 * B)
        for c in range(3):
            g[0, c] = al0 * m[c] + be0 * n[c]
            g[1, c] = al1 * m[c] + be1 * n[c]
            g[2, c] = al2 * m[c] + be2 * n[c]
            g[3, c] = al3 * m[c] + be3 * n[c]
        kk = k[s]
        dth = th - theta0[s]
        M = kk * dth
        energy[s] = 0.5 * M * dth
        for a in range(4):
            for c in range(3):
                force[c, a, s] = M * g[a, c]
        if not tangent:
            continue
        # k g g' over the ten distinct blocks (0 ii, 1 ij, 2 ik, 3 ll, 4 lj, 5 lk, 6 jj, 7 jk,
        # 8 kk, 9 il)
        if k_nonneg:  # sqrt(k) g_a sqrt(k) g_b' keeps the diagonal blocks exactly symmetric
            sk = math.sqrt(kk)
            for a in range(4):
                for c in range(3):
                    gk[a, c] = sk * g[a, c]
            for t in range(10):
                ga = _GG_A[t]
                gb = _GG_B[t]
                for i in range(3):
                    for j in range(3):
                        K[i, j, t, s] = gk[ga, i] * gk[gb, j]
        else:
            for t in range(10):
                ga = _GG_A[t]
                gb = _GG_B[t]
                for i in range(3):
                    for j in range(3):
                        K[i, j, t, s] = kk * (g[ga, i] * g[gb, j])
        # Hessian (Liu & Paulino 2017) times M, in the numpy path's order of operations
        inv = 1.0 / dl2
        for a in range(4):  # dA_j, dA_k, dB_j, dB_k as combinations of (r_ij, r_kj, r_kl)
            for r in range(3):
                coef[r] = (_TD0[a, r] + _TD1[a, r] * A + _TD2[a, r] * B) * inv
            for c in range(3):
                v = coef[0] * rij[c] + coef[1] * rkj[c]
                dd[a, c] = v + coef[2] * rkl[c]
        _cross(rkj, m, a1)
        _cross(rij, m, a2)
        _cross(rkj, n, b1)
        _cross(rkl, n, b2)
        for c in range(3):
            gs[0, c] = g[0, c] * M
            gs[1, c] = g[3, c] * M
        cm = M * ell / (dmm * dmm)
        cml = M / (dmm * ell)
        cn = M * ell / (dnn * dnn)
        cnl = M / (dnn * ell)
        for i in range(3):
            for j in range(3):
                S1 = m[i] * a1[j] + a1[i] * m[j]
                S2 = m[i] * a2[j] + a2[i] * m[j]
                S4 = n[i] * b1[j] + b1[i] * n[j]
                S5 = n[i] * b2[j] + b2[i] * n[j]
                O4 = m[i] * rkj[j]
                O9 = n[i] * rkj[j]
                H_ij = cm * (S1 - S2) - cml * O4
                H_ik = cm * S2 + cml * O4
                H_lj = cnl * O9 - cn * S5
                H_lk = cn * (S5 - S4) - cnl * O9
                K[i, j, 0, s] -= cm * S1
                K[i, j, 1, s] += H_ij
                K[i, j, 2, s] += H_ik
                K[i, j, 3, s] += cn * S4
                K[i, j, 4, s] += H_lj
                K[i, j, 5, s] += H_lk
                O10 = gs[0, i] * dd[0, j]
                O11 = gs[1, i] * dd[2, j]
                O12 = gs[0, i] * dd[1, j]
                O13 = gs[1, i] * dd[3, j]
                K[i, j, 7, s] += (A - 1.0) * H_ik - B * H_lk + (O12 - O13)
                hjj[i, j] = (A - 1.0) * H_ij - B * H_lj + (O10 - O11)
                hkk[i, j] = (B - 1.0) * H_lk - A * H_ik + (O13 - O12)
        # jj and kk blocks, made exactly symmetric as 0.5 (H + H')
        for i in range(3):
            for j in range(3):
                K[i, j, 6, s] += 0.5 * (hjj[i, j] + hjj[j, i])
                K[i, j, 8, s] += 0.5 * (hkk[i, j] + hkk[j, i])


_GG_A = np.array([0, 0, 0, 3, 3, 3, 1, 1, 2, 0])
_GG_B = np.array([0, 1, 2, 3, 1, 2, 1, 2, 2, 3])
_TD0 = np.array([[-1.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 1.0]])
_TD1 = np.array([[0.0, 2.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
_TD2 = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, -2.0, 0.0]])


@njit(**_OPTS)
def gather(ptr_a, src_a, val_a, ptr_b, src_b, val_b, ptr_c, src_c, val_c, dest, out):
    """``out[dest[p]] = (A_p + B_p) + C_p`` for every listed target p, where ``A_p`` is the
    sum of ``val_a[src_a[ptr_a[p]:ptr_a[p + 1]]]`` from 0.0 in that order (likewise B, C).
    With each family's sources listed in the order ``np.bincount`` meets them, this is
    ``bincount(a) + bincount(b) + bincount(c)`` bit for bit, without scratch arrays and only
    for the targets that receive something (``out`` starts as zeros)."""
    for p in range(dest.shape[0]):
        sa = 0.0
        for q in range(ptr_a[p], ptr_a[p + 1]):
            sa += val_a[src_a[q]]
        sb = 0.0
        for q in range(ptr_b[p], ptr_b[p + 1]):
            sb += val_b[src_b[q]]
        sc = 0.0
        for q in range(ptr_c[p], ptr_c[p + 1]):
            sc += val_c[src_c[q]]
        out[dest[p]] = (sa + sb) + sc


# ------------------------------------------------------------------------ batches
# A batch is S designs of one size: the arrays gain a leading sample axis and each listed
# sample runs the single-design code above on one scratch set of element arrays, which stays
# in cache between the kernels and the gathers (so each design's numbers are bit for bit those
# of its own evaluation).


@njit(**_OPTS)
def assemble_batch(
    X, U, b0, b1, D0, L0, EA, sT, k, theta0, k_nonneg, idx, force_lists, tangent_lists,
    scratch, f_out, k_out,
):  # fmt: skip
    """For each sample ``s = idx[j]``: the kernels into ``scratch`` (the seven element arrays
    of one sample), then ``f_out[j]`` by the ``force_lists`` and ``k_out[j]`` by the
    ``tangent_lists`` (each the seven arguments of :func:`gather` but the values)."""
    eb, fb, Kb, es, fs, Ks, th = scratch
    fa, fsa, fb_, fsb, fc, fsc, fdest = force_lists
    ka, ksa, kb_, ksb, kc, ksc, kdest = tangent_lists
    for j in range(idx.shape[0]):
        s = idx[j]
        bar_elements(X[s], U[s], b0[s], b1[s], D0[s], L0[s], EA[s], True, eb, fb, Kb)
        spring_elements(X[s], U[s], sT[s], k[s], theta0[s], k_nonneg[s], True, es, fs, Ks, th)
        vfb = fb.reshape(-1)
        vfs = fs.reshape(-1)
        gather(fa, fsa, vfb, fb_, fsb, vfs, fc, fsc, vfs, fdest, f_out[j])
        vkb = Kb.reshape(-1)
        vks = Ks.reshape(-1)
        gather(ka, ksa, vkb, kb_, ksb, vks, kc, ksc, vks, kdest, k_out[j])
