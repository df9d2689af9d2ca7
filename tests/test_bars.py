"""Bar element (Green-Lagrange strain, St Venant-Kirchhoff): derivatives and invariants."""

import numpy as np
import pytest

from holofold.mechanics.bars import bar_forces, bar_strain


def _random_bars(rng, nn=6, nb=9):
    X = rng.normal(size=(nn, 3))
    bars = np.array([rng.choice(nn, 2, replace=False) for _ in range(nb)])
    L0 = np.linalg.norm(X[bars[:, 1]] - X[bars[:, 0]], axis=1)
    EA = rng.uniform(1.0, 5.0, nb)
    U = 0.2 * rng.normal(size=(nn, 3))
    return X, U, bars, L0, EA


def _local_energy(X, U, bars, L0, EA, e, u6):
    """Energy of bar e with its local DOFs replaced by u6."""
    U = U.copy()
    U[bars[e, 0]] = u6[:3]
    U[bars[e, 1]] = u6[3:]
    return bar_forces(X, U, bars, L0, EA, tangent=False).energy[e]


def test_force_and_tangent_match_central_differences():
    rng = np.random.default_rng(1)
    worst_f = worst_k = 0.0
    h = 1e-6
    for _ in range(20):
        X, U, bars, L0, EA = _random_bars(rng)
        res = bar_forces(X, U, bars, L0, EA)
        for e in range(len(bars)):
            u6 = np.concatenate([U[bars[e, 0]], U[bars[e, 1]]])
            f_fd = np.zeros(6)
            k_fd = np.zeros((6, 6))
            for a in range(6):
                up, um = u6.copy(), u6.copy()
                up[a] += h
                um[a] -= h
                f_fd[a] = (
                    _local_energy(X, U, bars, L0, EA, e, up)
                    - _local_energy(X, U, bars, L0, EA, e, um)
                ) / (2 * h)
                Up, Um = U.copy(), U.copy()
                Up[bars[e, 0]], Up[bars[e, 1]] = up[:3], up[3:]
                Um[bars[e, 0]], Um[bars[e, 1]] = um[:3], um[3:]
                k_fd[:, a] = (
                    bar_forces(X, Up, bars, L0, EA, tangent=False).force[e]
                    - bar_forces(X, Um, bars, L0, EA, tangent=False).force[e]
                ) / (2 * h)
            worst_f = max(worst_f, np.linalg.norm(f_fd - res.force[e]) / np.linalg.norm(f_fd))
            worst_k = max(worst_k, np.linalg.norm(k_fd - res.tangent[e]) / np.linalg.norm(k_fd))
    assert worst_f <= 1e-6
    assert worst_k <= 1e-6


def test_tangent_symmetric_and_sample_axis():
    rng = np.random.default_rng(2)
    X, U, bars, L0, EA = _random_bars(rng)
    U2 = np.stack([U, -U, 2 * U])
    res = bar_forces(X, U2, bars, L0, EA)
    assert res.tangent.shape == (3, len(bars), 6, 6)
    assert np.array_equal(res.tangent, np.swapaxes(res.tangent, -1, -2))
    for s in range(3):
        one = bar_forces(X, U2[s], bars, L0, EA)
        np.testing.assert_allclose(res.force[s], one.force, rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(res.tangent[s], one.tangent, rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(res.energy[s], one.energy, rtol=1e-14)


def test_rigid_motion_gives_no_force_and_rotates_stress():
    rng = np.random.default_rng(3)
    X, U, bars, L0, EA = _random_bars(rng)
    c, s = np.cos(0.7), np.sin(0.7)
    Q = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]]
    )
    # rigid motion of the reference: zero strain, zero force
    U_rigid = X @ Q.T + np.array([0.3, -1.2, 2.0]) - X
    res = bar_forces(X, U_rigid, bars, L0, EA)
    assert np.abs(res.force).max() < 1e-12 * EA.max()
    assert np.abs(res.energy).max() < 1e-24
    # objectivity: rotating a deformed state rotates the forces, keeps the energy
    x = X + U
    U_rot = x @ Q.T - X
    a = bar_forces(X, U, bars, L0, EA)
    b = bar_forces(X, U_rot, bars, L0, EA)
    np.testing.assert_allclose(b.energy, a.energy, rtol=1e-12)
    fa = a.force.reshape(-1, 2, 3) @ Q.T
    np.testing.assert_allclose(b.force.reshape(-1, 2, 3), fa, atol=1e-12 * np.abs(fa).max())


def test_single_bar_small_strain_and_green_lagrange():
    X = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    bars = np.array([[0, 1]])
    L0 = np.array([2.0])
    EA = np.array([3.0e5])
    for u in (1e-7, 0.3):
        U = np.array([[0.0, 0.0, 0.0], [u, 0.0, 0.0]])
        eps = (4.0 * u + u * u) / 8.0  # (|x|^2 - L0^2) / (2 L0^2) without cancellation
        assert bar_strain(X, U, bars, L0)[0] == pytest.approx(eps, rel=1e-14)
        res = bar_forces(X, U, bars, L0, EA)
        # axial force on node b: S A (L0 + u) / L0
        assert res.force[0, 3] == pytest.approx(EA[0] * eps * (2.0 + u) / 2.0, rel=1e-13)
        assert res.energy[0] == pytest.approx(0.5 * EA[0] * 2.0 * eps**2, rel=1e-13)
    # small-load limit: force = EA u / L0
    u = 1e-9
    U = np.array([[0.0, 0.0, 0.0], [u, 0.0, 0.0]])
    assert bar_forces(X, U, bars, L0, EA).force[0, 3] == pytest.approx(EA[0] * u / 2.0, rel=1e-8)
    # tangent at rest: axial stiffness EA/L0, no transverse stiffness
    K = bar_forces(X, np.zeros_like(X), bars, L0, EA).tangent[0]
    assert K[3, 3] == pytest.approx(EA[0] / 2.0, rel=1e-14)
    assert K[4, 4] == 0.0 and K[5, 5] == 0.0
