"""Four-node rotational springs: dihedral angle, gradient, Hessian (docs/bar-and-hinge.md §2.2-2.4).

A spring (i, j, k, l) has its hinge on j-k; node i lies on one face and l on the other. With
``r_ij = x_i - x_j``, ``r_kj = x_k - x_j``, ``r_kl = x_k - x_l``, ``m = r_ij x r_kj``,
``n = r_kj x r_kl`` and ``l = |r_kj|``::

    theta = mod(atan2(l (m . r_kl), m . n), 2 pi)        in [0, 2 pi), pi = flat

This is the reference simulator's angle (``mod(sign(m . r_kl) arccos(m.n / |m||n|), 2 pi)``) in a
form that keeps full precision near the flat state. The builders order (i, j, k, l) so that ``m``
points to +z on a flat xy pattern (the polarity rule); the angle then grows above pi when the
wings rotate toward +z. The gradient and Hessian are those of Liu & Paulino (2017)
(docs/bar-and-hinge.md §2.2-2.4), built as 3x3 blocks from batched outer products of a few
stacked vectors (no loop over springs; checked against central finite differences in
tests/test_springs.py).
The constitutive law is linear: ``M = k (theta - theta0)``, energy ``k (theta - theta0)^2 / 2``,
force ``M grad``, tangent ``k grad grad' + M hess``.

Public functions take coordinates ``(..., nn, 3)`` (optional leading sample axes) and return
element-first arrays; local DOF order (i_x, i_y, i_z, j_x, ..., l_z). :func:`spring_kernel` is
the hot-path variant on component-major arrays (spring axis last) used by the assembly.
"""

from __future__ import annotations

import numpy as np

from holofold.mechanics.bars import ElementResponse

__all__ = [
    "dihedral_angle",
    "arccos_shift",
    "dihedral_gradient",
    "dihedral_derivatives",
    "spring_forces",
    "spring_kernel",
    "SPRING_BLOCKS",
]

TWO_PI = 2.0 * np.pi

# The kernel works on component-major arrays (..., 3, nv, ns): component, vector, spring. The
# spring axis is last, so every numpy call runs long contiguous loops, and per-spring scalars
# (..., ns) broadcast as [..., None, :] or [..., None, None, :].
_R_PLUS = np.array([0, 2, 2])  # r_ij, r_kj, r_kl = x[+] - x[-]
_R_MINUS = np.array([1, 1, 3])
_C1 = np.array([1, 2, 0])
_C2 = np.array([2, 0, 1])
# dot products over bank [r_ij, r_kj, r_kl, m, n]:
#   0 l^2 = r_kj.r_kj, 1 |m|^2, 2 |n|^2, 3 r_ij.r_kj, 4 r_kl.r_kj, 5 m.r_kl, 6 m.n
_DOT_A = np.array([1, 3, 4, 0, 2, 3, 3])
_DOT_B = np.array([1, 3, 4, 1, 1, 2, 4])
# crosses a1 = r_kj x m, a2 = r_ij x m, b1 = r_kj x n, b2 = r_kl x n
_X_R = np.array([1, 0, 1, 2])
_X_MN = np.array([0, 0, 1, 1])
# outer-product terms p (x) q over bank
#   V = [0 m, 1 n, 2 a1, 3 a2, 4 b1, 5 b2, 6 g_i, 7 g_l, 8 dA_j, 9 dA_k, 10 dB_j, 11 dB_k, 12 r_kj]
#   t: 0 m.a1  1 a1.m  2 m.a2  3 a2.m  4 m.r_kj  5 n.b1  6 b1.n  7 n.b2  8 b2.n  9 n.r_kj
#      10 g_i.dA_j  11 g_l.dB_j  12 g_i.dA_k  13 g_l.dB_k
_O_LEFT = np.array([0, 2, 0, 3, 0, 1, 4, 1, 5, 1, 6, 7, 6, 7])
_O_RIGHT = np.array([2, 0, 3, 0, 12, 4, 1, 5, 1, 12, 8, 10, 9, 11])
# the ten distinct 3x3 blocks of the 4x4 block matrix (rows/cols i, j, k, l):
#   0 ii, 1 ij, 2 ik, 3 ll, 4 lj, 5 lk, 6 jj, 7 jk, 8 kk, 9 il
# gradient pairs (a, b) of the ten blocks, for k g_a g_b'
_GG_A = np.array([0, 0, 0, 3, 3, 3, 1, 1, 2, 0])
_GG_B = np.array([0, 1, 2, 3, 1, 2, 1, 2, 2, 3])
#: (row node, column node) of the ten distinct tangent blocks returned by :func:`spring_kernel`
#: (0 = i, 1 = j, 2 = k, 3 = l).
SPRING_BLOCKS = np.stack([_GG_A, _GG_B], axis=1)
# dA_j = ((2A-1) r_kj - r_ij)/l^2, dA_k = (r_ij - 2A r_kj)/l^2, dB_j = (2B r_kj - r_kl)/l^2,
# dB_k = ((1-2B) r_kj + r_kl)/l^2: coefficients on (r_ij, r_kj, r_kl) = T0 + T1 A + T2 B
_TD0 = np.array([[-1.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 1.0]])[..., None]
_TD1 = np.array([[0.0, 2.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])[..., None]
_TD2 = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, -2.0, 0.0]])[..., None]
# gradient: g_a = alpha_a m + beta_a n with alpha = p (G0 + G1 A), beta = q (H0 + H1 B),
# p = l/|m|^2, q = l/|n|^2: g_i = p m, g_j = (A-1) p m + B q n, g_k = -A p m + (1-B) q n,
# g_l = -q n
_G0 = np.array([1.0, -1.0, 0.0, 0.0])[:, None]
_G1 = np.array([0.0, 1.0, -1.0, 0.0])[:, None]
_H0 = np.array([0.0, 0.0, 1.0, -1.0])[:, None]
_H1 = np.array([0.0, 1.0, -1.0, 0.0])[:, None]
# 4x4 layout (row block a, column block b) over [blocks 0..9, their transposes 10..19]
_LAYOUT = np.array([[0, 1, 2, 9], [11, 6, 7, 14], [12, 17, 8, 15], [19, 4, 5, 3]]).ravel()


def _cross(a, b):
    """Cross product along the component axis -3 of (..., 3, nv, ns) arrays."""
    return a.take(_C1, axis=-3) * b.take(_C2, axis=-3) - a.take(_C2, axis=-3) * b.take(_C1, axis=-3)


def _gather(x, springs):
    """(..., nn, 3) coordinates -> (..., 3, 4, ns) node positions [component, node, spring];
    ``springs`` (ns, 4), or (S, ns, 4) for ``x`` (S, nn, 3): one connectivity per design."""
    xT = np.swapaxes(np.asarray(x, float), -1, -2)
    springs = np.asarray(springs)
    if springs.ndim == 3:
        idx = np.swapaxes(springs, -1, -2)[:, None]  # (S, 1, 4, ns)
        return np.take_along_axis(xT[:, :, None, :], idx, axis=-1)
    return xT[..., springs.T]


def _banks(P):
    R = P.take(_R_PLUS, axis=-2) - P.take(_R_MINUS, axis=-2)  # (..., 3, 3, ns): r_ij, r_kj, r_kl
    MN = _cross(R[..., :2, :], R[..., 1:, :])  # (..., 3, 2, ns): m, n
    bank = np.concatenate([R, MN], axis=-2)
    d = (bank.take(_DOT_A, axis=-2) * bank.take(_DOT_B, axis=-2)).sum(-3)  # (..., 7, ns)
    return R, MN, d


def _angle_from_dots(d, form="atan2", ell=None):
    if form == "atan2":
        if ell is None:
            ell = np.sqrt(d[..., 0, :])
        return np.mod(np.arctan2(ell * d[..., 5, :], d[..., 6, :]), TWO_PI)
    if form == "acos":  # the reference's form and order of operations (compat.arccos_dihedral)
        eta = np.where(d[..., 5, :] == 0.0, 1.0, np.sign(d[..., 5, :]))
        c = d[..., 6, :] / np.sqrt(d[..., 1, :]) / np.sqrt(d[..., 2, :])
        return np.mod(eta * np.arccos(np.clip(c, -1.0, 1.0)), TWO_PI)
    raise ValueError(f"form must be 'atan2' or 'acos', got {form!r}")


def dihedral_angle(x, springs, *, form: str = "atan2") -> np.ndarray:
    """Dihedral angle of every spring, rad, in [0, 2 pi) (pi = flat).

    Parameters
    ----------
    x : (..., nn, 3) float
        Current nodal coordinates, m.
    springs : (ns, 4) int
        Node quadruples (i, j, k, l), hinge j-k; or (S, ns, 4), one set per design of ``x``
        (S, nn, 3).
    form : {"atan2", "acos"}
        ``"atan2"`` (default, accurate near flat) or the reference's clamped arccos form.

    Returns
    -------
    (..., ns) float
    """
    _, _, d = _banks(_gather(x, springs))
    return _angle_from_dots(d, form)


def arccos_shift(x, springs) -> np.ndarray:
    """``theta_atan2 - theta_arccos`` of every spring, wrapped to [-pi, pi), rad, (..., ns).

    Adding it to the rest angles makes the linear spring law act on the reference's arccos
    angle while gradient and Hessian stay those of the exact angle
    (:attr:`holofold.mechanics.compat.Profile.arccos_dihedral`).
    """
    _, _, d = _banks(_gather(x, springs))
    exact = _angle_from_dots(d, "atan2")
    return np.mod(exact - _angle_from_dots(d, "acos") + np.pi, TWO_PI) - np.pi


def _first_order(P):
    R, MN, d = _banks(P)
    ell2 = d[..., 0, :]
    ell = np.sqrt(ell2)
    theta = _angle_from_dots(d, "atan2", ell)
    A = d[..., 3, :] / ell2
    B = d[..., 4, :] / ell2
    alpha = (ell / d[..., 1, :])[..., None, :] * (_G0 + _G1 * A[..., None, :])  # (..., 4, ns)
    beta = (ell / d[..., 2, :])[..., None, :] * (_H0 + _H1 * B[..., None, :])
    g = alpha[..., None, :, :] * MN[..., :, 0:1, :] + beta[..., None, :, :] * MN[..., :, 1:2, :]
    return theta, g, R, MN, d, ell, A, B  # g: (..., 3, 4, ns)


def _add_hessian(out, scale, g, R, MN, d, ell, A, B):
    """``out[..., :9, :] += scale * H`` for the Hessian blocks ii, ij, ik, ll, lj, lk, jj, jk,
    kk (each (..., 3, 3, ns); Liu & Paulino 2017, docs/bar-and-hinge.md §2.3); ``scale``
    (..., ns)."""
    # dA_j, dA_k, dB_j, dB_k as combinations of (r_ij, r_kj, r_kl)
    coef = (_TD0 + _TD1 * A[..., None, None, :] + _TD2 * B[..., None, None, :]) * (
        1.0 / d[..., 0, :]
    )[..., None, None, :]
    dd = (coef[..., None, :, :, :] * R[..., None, :, :]).sum(-2)  # (..., 3, 4, ns)
    X = _cross(R.take(_X_R, axis=-2), MN.take(_X_MN, axis=-2))  # a1, a2, b1, b2
    gs = g[..., ::3, :] * scale[..., None, None, :]  # scale * (g_i, g_l)
    V = np.concatenate([MN, X, gs, dd, R[..., 1:2, :]], axis=-2)
    # O[..., p, q, t, s] = left_t[p] right_t[q]
    O = V.take(_O_LEFT, axis=-2)[..., :, None, :, :] * V.take(_O_RIGHT, axis=-2)[..., None, :, :, :]
    mm = d[..., 1, :]
    nn = d[..., 2, :]
    e = (..., None, None, slice(None))  # per-spring scalar against (..., 3, 3, ns)
    cm = (scale * ell / (mm * mm))[e]
    cml = (scale / (mm * ell))[e]
    cn = (scale * ell / (nn * nn))[e]
    cnl = (scale / (nn * ell))[e]
    Ae = A[e]
    Be = B[e]
    S1 = O[..., 0, :] + O[..., 1, :]  # sym(m, a1)
    S2 = O[..., 2, :] + O[..., 3, :]  # sym(m, a2)
    S4 = O[..., 5, :] + O[..., 6, :]  # sym(n, b1)
    S5 = O[..., 7, :] + O[..., 8, :]  # sym(n, b2)
    H_ij = cm * (S1 - S2) - cml * O[..., 4, :]
    H_ik = cm * S2 + cml * O[..., 4, :]
    H_lj = cnl * O[..., 9, :] - cn * S5
    H_lk = cn * (S5 - S4) - cnl * O[..., 9, :]
    out[..., 0, :] -= cm * S1
    out[..., 1, :] += H_ij
    out[..., 2, :] += H_ik
    out[..., 3, :] += cn * S4
    out[..., 4, :] += H_lj
    out[..., 5, :] += H_lk
    H_jj = (Ae - 1.0) * H_ij - Be * H_lj + (O[..., 10, :] - O[..., 11, :])
    out[..., 7, :] += (Ae - 1.0) * H_ik - Be * H_lk + (O[..., 12, :] - O[..., 13, :])
    H_kk = (Be - 1.0) * H_lk - Ae * H_ik + (O[..., 13, :] - O[..., 12, :])
    # analytically symmetric; make it exact
    out[..., 6, :] += 0.5 * (H_jj + np.swapaxes(H_jj, -2, -3))
    out[..., 8, :] += 0.5 * (H_kk + np.swapaxes(H_kk, -2, -3))


def _layout(blocks10):
    """(..., 3, 3, 10, ns) distinct blocks -> (..., 3, 3, 16, ns) in 4x4 block order."""
    allb = np.concatenate([blocks10, np.swapaxes(blocks10, -3, -4)], axis=-2)
    return allb[..., _LAYOUT, :]


def _to_matrix(K16):
    """(..., 3, 3, 16, ns) [i, j, a*4+b, s] -> (..., ns, 12, 12)."""
    K = K16.reshape(*K16.shape[:-2], 4, 4, K16.shape[-1])  # (..., i, j, a, b, s)
    # (..., i, j, a, b, s) -> (..., s, a, i, b, j)
    K = np.moveaxis(K, (-5, -4, -3, -2, -1), (-3, -1, -4, -2, -5))
    return K.reshape(*K.shape[:-4], 12, 12)


def _grad_matrix(g):
    """(..., 3, 4, ns) -> (..., ns, 12) in local order (i_x, i_y, i_z, j_x, ...)."""
    return np.swapaxes(g, -1, -3).reshape(*g.shape[:-3], g.shape[-1], 12)


def dihedral_gradient(x, springs):
    """Angle (..., ns) and its gradient (..., ns, 12) with respect to (x_i, x_j, x_k, x_l)."""
    theta, g, *_ = _first_order(_gather(x, springs))
    return theta, _grad_matrix(g)


def dihedral_derivatives(x, springs):
    """Angle, gradient and Hessian of every spring.

    Parameters
    ----------
    x : (..., nn, 3) float
        Current nodal coordinates, m.
    springs : (ns, 4) int
        Node quadruples (i, j, k, l).

    Returns
    -------
    theta : (..., ns) float, rad
    grad : (..., ns, 12) float, rad/m
    hess : (..., ns, 12, 12) float, rad/m^2 (exactly symmetric)
    """
    theta, g, *rest = _first_order(_gather(x, springs))
    H10 = np.zeros((*g.shape[:-2], 3, 10, g.shape[-1]))
    _add_hessian(H10, np.ones_like(theta), g, *rest)
    return theta, _grad_matrix(g), _to_matrix(_layout(H10))


def spring_kernel(P, k, theta0, *, tangent: bool = True):
    """Linear springs on component-major node positions (the layout the assembly scatters).

    Parameters
    ----------
    P : (..., 3, 4, ns) float
        Current positions of nodes (i, j, k, l) [component, node, spring], m.
    k : (ns,) float
        Rotational stiffness, N m/rad.
    theta0 : (..., ns) float
        Rest angles, rad.

    Returns
    -------
    (ElementResponse, theta)
        energy (..., ns); force (..., 3, 4, ns) [component, node, spring]; tangent
        (..., 3, 3, 10, ns) [i, j, block, spring] or None: the ten distinct 3x3 blocks of the
        symmetric 4x4 node-block matrix, in the order (i,i), (i,j), (i,k), (l,l), (l,j), (l,k),
        (j,j), (j,k), (k,k), (i,l) (row node, column node; see ``SPRING_BLOCKS``); the other
        six blocks are the transposes of the off-diagonal ones. theta (..., ns).
    """
    k = np.asarray(k, float)
    theta, g, *rest = _first_order(P)
    dtheta = theta - theta0
    M = k * dtheta
    energy = 0.5 * M * dtheta
    force = M[..., None, None, :] * g
    if not tangent:
        return ElementResponse(energy, force, None), theta
    # ten distinct blocks of k g g' + M H (H_il = 0); sqrt(k) keeps the diagonal blocks of
    # k g g' exactly symmetric
    if np.all(k >= 0.0):
        gk = np.sqrt(k) * g
        K10 = (
            gk.take(_GG_A, axis=-2)[..., :, None, :, :]
            * gk.take(_GG_B, axis=-2)[..., None, :, :, :]
        )
    else:
        K10 = k * (
            g.take(_GG_A, axis=-2)[..., :, None, :, :] * g.take(_GG_B, axis=-2)[..., None, :, :, :]
        )
    _add_hessian(K10, M, g, *rest)
    return ElementResponse(energy, force, K10), theta


def spring_forces(x, springs, k, theta0, *, tangent: bool = True) -> ElementResponse:
    """Energy, internal force and tangent of linear rotational springs ``M = k (theta - theta0)``.

    Parameters
    ----------
    x : (..., nn, 3) float
        Current nodal coordinates, m.
    springs : (ns, 4) int
        Node quadruples (i, j, k, l).
    k : (ns,) float
        Rotational stiffness, N m/rad.
    theta0 : (..., ns) float
        Rest angles, rad.
    tangent : bool
        Also compute the tangent ``k grad grad' + M hess``.

    Returns
    -------
    ElementResponse
        energy (..., ns) J, force (..., ns, 12) N, tangent (..., ns, 12, 12) N/m or None.
    """
    res, _ = spring_kernel(_gather(x, springs), k, theta0, tangent=tangent)
    K = None if res.tangent is None else _to_matrix(_layout(res.tangent))
    return ElementResponse(res.energy, _grad_matrix(res.force), K)
