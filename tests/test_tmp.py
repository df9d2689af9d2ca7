"""Tachi-Miura polyhedron sheet generator: spec formulas (docs/scenarios.md §3.1), rigid folding."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _rigidity import panel_errors

from holofold.geometry.errors import ParameterError
from holofold.geometry.tmp import tmp_node_count, tmp_sheet

EXTS = (0.3, 0.6, 0.9, 1.0)
L = 0.2


def interior_vertices(p):
    border = np.unique(p.edges[~p.interior])
    return np.setdiff1d(np.unique(p.edges[p.interior]), border)


def spec_tmp(m, n, L, ext):
    """Independent transcription of docs/scenarios.md §3.1 with the spec's 1-based ids."""
    a, b = L / n, L / m
    delta = b * math.sqrt(1 - ext**2)
    theta = math.atan(2 * delta / a)
    zs, ys = a * math.sin(2 * theta), a * math.cos(2 * theta)
    p = a + 2 * ys
    node = {}

    def A(i, r):  # id of row r of column A_i (1-based)
        return (i - 1) * (2 * n + 1) + r

    def B(i, r):
        return (i - 1) * (2 * n + 1) + n + 1 + r

    for i in range(1, m // 2 + 2):
        x = 2 * (i - 1) * b * ext
        for j in range(1, n // 3 + 1):
            y0 = p * (j - 1)
            node[A(i, 3 * j - 2)] = (x, y0, zs + delta)
            node[A(i, 3 * j - 1)] = (x, y0 + ys, delta)
            node[A(i, 3 * j)] = (x, y0 + a + ys, delta)
        node[A(i, n + 1)] = (x, p * n / 3, zs + delta)
    for i in range(1, m // 2 + 1):
        x = (2 * i - 1) * b * ext
        for j in range(1, n // 3 + 1):
            y0 = p * (j - 1)
            node[B(i, 3 * j - 2)] = (x, y0 + a / 2, zs)
            node[B(i, 3 * j - 1)] = (x, y0 + a / 2 + ys, 0.0)
            node[B(i, 3 * j)] = (x, y0 + a / 2 + 2 * ys, zs)
    panels = []
    K = n // 3 - 1
    for i in range(1, m // 2 + 1):

        def a_(r, i=i):
            return A(i, r)

        def b_(r, i=i):
            return B(i, r)

        def a2(r, i=i):
            return A(i + 1, r)

        for j in range(1, K + 1):
            s = 3 * (j - 1)
            panels += [
                [a_(s + 1), b_(s + 1), b_(s + 2), a_(s + 2)],
                [a_(s + 2), b_(s + 2), a_(s + 3)],
                [a_(s + 3), b_(s + 2), b_(s + 3), a_(s + 4)],
                [a_(s + 4), b_(s + 3), b_(s + 4)],
            ]
        panels += [
            [a_(n - 2), b_(n - 2), b_(n - 1), a_(n - 1)],
            [a_(n - 1), b_(n - 1), a_(n)],
            [a_(n), b_(n - 1), b_(n), a_(n + 1)],
        ]
        for j in range(1, K + 1):
            s = 3 * (j - 1)
            panels += [
                [b_(s + 1), a2(s + 1), a2(s + 2), b_(s + 2)],
                [b_(s + 2), a2(s + 2), a2(s + 3)],
                [b_(s + 2), a2(s + 3), a2(s + 4), b_(s + 3)],
                [b_(s + 3), a2(s + 4), b_(s + 4)],
            ]
        panels += [
            [b_(n - 2), a2(n - 2), a2(n - 1), b_(n - 1)],
            [b_(n - 1), a2(n - 1), a2(n)],
            [b_(n - 1), a2(n), a2(n + 1), b_(n)],
        ]
    X = np.array([node[k] for k in range(1, len(node) + 1)])
    return X, [np.array(q) - 1 for q in panels]


@pytest.mark.parametrize(
    "m,n,ext,n_nodes,n_panels",
    [(24, 6, 0.6, 163, 168), (30, 9, 0.3, 295, 330), (36, 12, 0.9, 463, 540), (2, 3, 0.5, 11, 6)],
)
def test_nodes_and_panels_equal_spec(m, n, ext, n_nodes, n_panels):
    p = tmp_sheet(m, n, L, ext)
    X, P = spec_tmp(m, n, L, ext)
    assert p.n_vertices == n_nodes == tmp_node_count(m, n) == (m // 2) * (2 * n + 1) + n + 1
    assert p.n_faces == n_panels == 2 * (4 * (n // 3 - 1) + 3) * (m // 2)
    assert X.shape == p.coords.shape
    np.testing.assert_allclose(p.coords, X, rtol=0, atol=1e-15 * L)
    for f, g in zip(p.faces, P, strict=True):
        assert f.tolist() == g.tolist()
    sizes = np.array([len(f) for f in p.faces])
    per_strip = 4 * (n // 3 - 1) + 3
    assert (sizes == 3).sum() == (m // 2) * 2 * (2 * (n // 3 - 1) + 1)
    assert (sizes == 4).sum() == p.n_faces - (sizes == 3).sum()
    assert per_strip * m == p.n_faces


def test_flat_state_is_square_sheet():
    m, n = 24, 6
    p = tmp_sheet(m, n, L, 1.0)
    a, b = L / n, L / m
    assert np.all(p.coords[:, 2] == 0.0)
    np.testing.assert_allclose(p.coords[:, :2], p.flat, atol=1e-17)
    assert np.ptp(p.flat[:, 0]) == pytest.approx(L, rel=1e-14)
    assert np.ptp(p.flat[:, 1]) == pytest.approx(L, rel=1e-14)
    # A columns: n + 1 nodes spaced a; B columns: n nodes offset a / 2
    np.testing.assert_allclose(p.flat[: n + 1, 1], a * np.arange(n + 1), atol=1e-16)
    np.testing.assert_allclose(p.flat[n + 1 : 2 * n + 1, 1], a / 2 + a * np.arange(n), atol=1e-16)
    np.testing.assert_allclose(p.flat[n + 1 : 2 * n + 1, 0], b, rtol=1e-15)
    # the panels tile the zig-zag-bounded sheet: total area L^2 minus the 2 m border notches
    area = sum(
        0.5 * abs(np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(np.roll(q[:, 0], -1), q[:, 1]))
        for q in (p.flat[f] for f in p.faces)
    )
    assert area == pytest.approx(L * L - 2 * m * (b * a / 4), rel=1e-12)
    # every face counter-clockwise in the flat layout (construction would raise otherwise)
    for f in p.faces:
        q = p.flat[f]
        assert np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(np.roll(q[:, 0], -1), q[:, 1]) > 0


@pytest.mark.parametrize("ext", EXTS)
@pytest.mark.parametrize("m,n", [(24, 6), (36, 12)])
def test_panels_rigid_and_planar(m, n, ext):
    p = tmp_sheet(m, n, L, ext)
    len_err, plan_err = panel_errors(p)
    assert len_err <= 1e-12
    assert plan_err <= 1e-12
    rel = np.abs(p.edge_lengths - p.flat_edge_lengths) / p.flat_edge_lengths
    assert rel.max() <= 1e-12


@pytest.mark.parametrize("ext", EXTS)
def test_x_extent_and_column_creases(ext):
    m, n = 30, 9
    p = tmp_sheet(m, n, L, ext)
    assert np.ptp(p.coords[:, 0]) == pytest.approx(L * ext, rel=1e-14)
    # creases inside a column (constant x) are mirror planes: |fold angle| = 2 acos(ext)
    e = p.edges
    same_x = p.interior & (np.abs(p.coords[e[:, 0], 0] - p.coords[e[:, 1], 0]) < 1e-12)
    same_x &= np.abs(p.flat[e[:, 0], 0] - p.flat[e[:, 1], 0]) < 1e-12
    # interior A columns (m/2 - 1 of them, n creases each) and B columns (m/2, n - 1 each)
    assert same_x.sum() == (m // 2 - 1) * n + (m // 2) * (n - 1)
    np.testing.assert_allclose(
        np.abs(np.radians(p.fold_angle[same_x])), 2 * math.acos(ext), rtol=0, atol=1e-12
    )


def test_sector_angles_sum_to_two_pi_and_assignment():
    p = tmp_sheet(6, 6, L, 0.6)
    inner = interior_vertices(p)
    assert len(inner) > 0
    total = np.zeros(p.n_vertices)
    for f, ang in zip(p.faces, p.sector_angles(), strict=True):
        np.add.at(total, f, ang)
    np.testing.assert_allclose(total[inner], 2 * math.pi, rtol=0, atol=1e-12)
    # the flat sheet keeps the assignment of the folded mechanism
    flat = tmp_sheet(6, 6, L, 1.0)
    np.testing.assert_array_equal(flat.assignment, p.assignment)
    assert np.all(flat.fold_angle == 0.0)
    assert set(p.assignment[p.interior]) <= {"M", "V"}
    np.testing.assert_allclose(p.fold_angle, p.measured_fold_angles(), atol=1e-9)


@pytest.mark.parametrize(
    "args,name",
    [
        ((5, 6, L, 0.5), "m = 5"),
        ((24, 7, L, 0.5), "n = 7"),
        ((24, 6, L, 0.0), "ext"),
        ((24, 6, L, 1.2), "ext"),
        ((24, 6, 0.0, 0.5), "L"),
        ((0, 6, L, 0.5), "m"),
        ((24, 0, L, 0.5), "n"),
        ((24.5, 6, L, 0.5), "m"),
    ],
)
def test_invalid_parameters(args, name):
    with pytest.raises(ParameterError, match=name):
        tmp_sheet(*args)


def test_overlap_warning(caplog):
    # 2 b sqrt(1 - ext^2) > a: the tubes pass 2 theta = 90 deg; still rigid, but warned about
    with caplog.at_level("WARNING", logger="holofold.geometry.tmp"):
        p = tmp_sheet(2, 3, L, 0.5)
    assert "overlap" in caplog.text
    assert p.meta["delta"] * 2 > p.meta["a"]
    assert max(panel_errors(p)) <= 1e-12
    caplog.clear()
    with caplog.at_level("WARNING", logger="holofold.geometry.tmp"):
        tmp_sheet(24, 6, L, 0.3)
    assert caplog.text == ""
