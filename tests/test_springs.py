"""Rotational springs: dihedral angle convention, gradient/Hessian vs finite differences."""

import numpy as np
import pytest

from holofold.mechanics.springs import (
    dihedral_angle,
    dihedral_derivatives,
    dihedral_gradient,
    spring_forces,
)

SPR = np.array([[0, 1, 2, 3]])


def _wrap(d):
    return (d + np.pi) % (2 * np.pi) - np.pi


def _random_config(rng):
    # keep the two triangles well shaped (no |m| or |n| near 0)
    while True:
        x = rng.normal(size=(4, 3))
        m = np.cross(x[0] - x[1], x[2] - x[1])
        n = np.cross(x[2] - x[1], x[2] - x[3])
        if min(np.linalg.norm(m), np.linalg.norm(n)) > 0.3:
            return x


def _nudged(x, a, h):
    """``x`` (4, 3) with its flat coordinate ``a`` moved by +h and by -h (central differences)."""
    xp, xm = x.ravel().copy(), x.ravel().copy()
    xp[a] += h
    xm[a] -= h
    return xp.reshape(4, 3), xm.reshape(4, 3)


def test_gradient_and_hessian_match_central_differences():
    rng = np.random.default_rng(10)
    h = 1e-6
    worst_g = worst_h = 0.0
    for _ in range(100):
        x = _random_config(rng)
        theta, g, H = dihedral_derivatives(x, SPR)
        g_fd = np.zeros(12)
        H_fd = np.zeros((12, 12))
        for a in range(12):
            xp, xm = _nudged(x, a, h)
            g_fd[a] = _wrap(dihedral_angle(xp, SPR)[0] - dihedral_angle(xm, SPR)[0]) / (2 * h)
            H_fd[:, a] = (dihedral_gradient(xp, SPR)[1][0] - dihedral_gradient(xm, SPR)[1][0]) / (
                2 * h
            )
        worst_g = max(worst_g, np.linalg.norm(g_fd - g[0]) / np.linalg.norm(g[0]))
        worst_h = max(worst_h, np.linalg.norm(H_fd - H[0]) / np.linalg.norm(H[0]))
        assert np.array_equal(H[0], H[0].T)
    assert worst_g <= 1e-6
    assert worst_h <= 1e-6


def test_spring_force_and_tangent_match_energy_differences():
    rng = np.random.default_rng(11)
    h = 1e-6
    k = np.array([2.5])
    worst_f = worst_k = 0.0
    for _ in range(30):
        x = _random_config(rng)
        theta0 = dihedral_angle(x, SPR) + rng.uniform(-0.5, 0.5, 1)
        res = spring_forces(x, SPR, k, theta0)
        f_fd = np.zeros(12)
        k_fd = np.zeros((12, 12))
        for a in range(12):
            xp, xm = _nudged(x, a, h)
            rp = spring_forces(xp, SPR, k, theta0, tangent=False)
            rm = spring_forces(xm, SPR, k, theta0, tangent=False)
            f_fd[a] = (rp.energy[0] - rm.energy[0]) / (2 * h)
            k_fd[:, a] = (rp.force[0] - rm.force[0]) / (2 * h)
        worst_f = max(worst_f, np.linalg.norm(f_fd - res.force[0]) / np.linalg.norm(f_fd))
        worst_k = max(worst_k, np.linalg.norm(k_fd - res.tangent[0]) / np.linalg.norm(k_fd))
        assert np.array_equal(res.tangent[0], res.tangent[0].T)
    assert worst_f <= 1e-6
    assert worst_k <= 1e-6


def test_atan2_form_equals_reference_arccos_form():
    rng = np.random.default_rng(12)
    x = rng.normal(size=(40, 3))
    springs = np.array([rng.choice(40, 4, replace=False) for _ in range(200)])
    a = dihedral_angle(x, springs)
    b = dihedral_angle(x, springs, form="acos")
    assert np.all((a >= 0) & (a < 2 * np.pi))
    assert np.abs(_wrap(a - b)).max() < 1e-7


def _hinge(phi):
    """Triangles (i, j, k) and (j, k, l) on the hinge j-k (x axis); wing l rotated by phi."""
    return np.array(
        [
            [0.4, -1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.6, np.cos(phi), np.sin(phi)],
        ]
    )


def test_flat_is_pi_and_polarity():
    assert dihedral_angle(_hinge(0.0), SPR)[0] == pytest.approx(np.pi, abs=1e-15)
    # m = r_ij x r_kj points to +z here (the builders' polarity rule)
    x = _hinge(0.0)
    assert np.cross(x[0] - x[1], x[2] - x[1])[2] > 0
    # lifting wing l toward +z opens the angle above pi, toward -z closes it
    assert dihedral_angle(_hinge(0.3), SPR)[0] == pytest.approx(np.pi + 0.3, abs=1e-14)
    assert dihedral_angle(_hinge(-0.3), SPR)[0] == pytest.approx(np.pi - 0.3, abs=1e-14)
    # nearly closed on either side stays inside [0, 2 pi)
    assert dihedral_angle(_hinge(np.pi - 1e-3), SPR)[0] == pytest.approx(2 * np.pi - 1e-3)
    assert dihedral_angle(_hinge(-np.pi + 1e-3), SPR)[0] == pytest.approx(1e-3)


def test_single_hinge_moment_is_k_dtheta():
    k = np.array([0.8])
    theta0 = np.array([np.pi])
    for dphi in (1e-4, 0.2, 1.0):
        x = _hinge(dphi)
        res = spring_forces(x, SPR, k, theta0)
        M = k[0] * dphi
        assert res.energy[0] == pytest.approx(0.5 * k[0] * dphi**2, rel=1e-12)
        # force on the wing tip l: magnitude M / (distance of l to the hinge = 1), tangential
        f_l = res.force[0, 9:]
        t = np.array([0.0, -np.sin(dphi), np.cos(dphi)])  # direction of increasing angle
        np.testing.assert_allclose(f_l, M * t, rtol=1e-12, atol=1e-15)
        # forces are self-equilibrated (no net force, no net moment)
        f = res.force[0].reshape(4, 3)
        assert np.abs(f.sum(0)).max() < 1e-14
        assert np.abs(np.cross(x, f).sum(0)).max() < 1e-14


def test_sample_axis_matches_single_evaluations():
    rng = np.random.default_rng(13)
    x = np.stack([_random_config(rng) for _ in range(3)])
    theta, g, H = dihedral_derivatives(x, SPR)
    assert H.shape == (3, 1, 12, 12)
    for s in range(3):
        t1, g1, H1 = dihedral_derivatives(x[s], SPR)
        np.testing.assert_allclose(theta[s], t1, rtol=1e-13)
        np.testing.assert_allclose(g[s], g1, rtol=1e-13, atol=1e-14)
        np.testing.assert_allclose(H[s], H1, rtol=1e-13, atol=1e-14)
    r = spring_forces(x, SPR, np.array([1.0]), theta + 0.1)
    assert r.tangent.shape == (3, 1, 12, 12)


def test_batched_angles_and_orientation_are_each_designs_own():
    """dihedral_angle with one spring set per design, and the batch form of orient_springs,
    give every design the bits it gets alone (the batch model builders rely on it)."""
    from holofold.mechanics.hinges import _orient_batch, orient_springs

    rng = np.random.default_rng(7)
    S, nn, ns = 6, 12, 15
    x = rng.normal(size=(S, nn, 3))
    quads = np.array([rng.choice(nn, 4, replace=False) for _ in range(ns)])
    for z_only in (True, False):
        batch = _orient_batch(x, quads, z_only)
        alone = np.stack([orient_springs(x[s], quads, z_only=z_only) for s in range(S)])
        assert np.array_equal(batch, alone)
    assert any((batch[s] != batch[0]).any() for s in range(S))  # orientations differ
    theta = dihedral_angle(x, batch)
    for s in range(S):
        assert np.array_equal(theta[s], dihedral_angle(x[s], batch[s]))
