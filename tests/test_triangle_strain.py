"""The in-plane strain of a panel triangle (mechanics/measures.py, ``triangle_strain``)."""

import numpy as np
import pytest

from holofold.mechanics.measures import triangle_strain


def _rotation(rng):
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    return q


def test_uniaxial_stretch_and_rigid_motion():
    X = np.array([[0.0, 0, 0], [2, 0, 0], [0.5, 1.5, 0]])
    lam = 1.03
    x = X * [lam, 1, 1]  # stretched along x only
    Q = _rotation(np.random.default_rng(1))
    x = x @ Q.T + [0.3, -0.2, 0.7]  # then moved rigidly
    e = triangle_strain(X, x - X, [[0, 1, 2]])
    assert e[0] == pytest.approx(0.5 * (lam**2 - 1), rel=1e-12)
    assert triangle_strain(X, X @ Q.T - X, [[0, 1, 2]])[0] < 1e-14


def test_matches_the_deformation_gradient_and_bounds_the_side_strains():
    rng = np.random.default_rng(7)
    for _ in range(20):
        X = rng.standard_normal((3, 3))
        F = np.eye(3) + 0.1 * rng.standard_normal((3, 3))
        x = X @ F.T
        # the reference plane's frame: E restricted to it, by the full 3-D gradient
        e1, e2 = X[1] - X[0], X[2] - X[0]
        a1 = e1 / np.linalg.norm(e1)
        n = np.cross(e1, e2)
        a2 = np.cross(n, a1) / np.linalg.norm(np.cross(n, a1))
        P = np.column_stack([a1, a2])  # 3 x 2
        Ft = F @ P  # maps in-plane coordinates to the deformed space
        E = 0.5 * (Ft.T @ Ft - np.eye(2))
        want = np.abs(np.linalg.eigvalsh(E)).max()
        got = triangle_strain(X, x - X, [[0, 1, 2]])[0]
        assert got == pytest.approx(want, rel=1e-10)
        for i, j in ((0, 1), (1, 2), (2, 0)):  # every side's strain is a directional strain
            side = 0.5 * ((np.sum((x[j] - x[i]) ** 2)) / np.sum((X[j] - X[i]) ** 2) - 1)
            assert abs(side) <= got * (1 + 1e-12)


def _triangle(base, left, right):
    """Plane triangle with sides ``base`` (nodes 0-1), ``left`` (0-2), ``right`` (1-2)."""
    x = (base**2 + left**2 - right**2) / (2 * base)
    return np.array([[0.0, 0, 0], [base, 0, 0], [x, np.sqrt(left**2 - x**2), 0]])


def test_a_squeezed_sliver_shows_what_its_bars_hide():
    """The hypar's sliver (Origami Simulator's hypar.svg at 200 mm: a vertex drawn 0.68 mm
    from a corner): sides 6.73, 0.684 and 6.174 mm, 0.38 mm high. Its long sides stretched and
    shortened by 0.9 % leave it at a third of its height: bar strains under 1 %, the
    strain across it below -0.4."""
    X = _triangle(6.73e-3, 0.684e-3, 6.174e-3)
    x = _triangle(6.73e-3 * 1.009, 0.684e-3, 6.174e-3 * 0.991)
    assert x[2, 1] < 0.33 * X[2, 1]
    sides = [0.5 * (np.sum((x[j] - x[i]) ** 2) / np.sum((X[j] - X[i]) ** 2) - 1)
             for i, j in ((0, 1), (1, 2), (2, 0))]  # fmt: skip
    assert max(abs(s) for s in sides) < 0.01
    assert triangle_strain(X, x - X, [[0, 1, 2]])[0] > 0.4
