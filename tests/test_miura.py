"""Miura-ori generator: spec formulas (docs/scenarios.md §2.1), rigid folding, flat-foldability."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _rigidity import panel_errors

from holofold.geometry.errors import ParameterError
from holofold.geometry.miura import miura_cell, miura_sheet, miura_sheet_paper

EXTS = (0.3, 0.6, 0.9, 1.0)
GAMMA70 = math.radians(70.0)


def spec_miura(a, b, gamma, m, n, ext):
    """Independent transcription of docs/scenarios.md §2.1, 1-based ids, law-of-cosines beta."""
    h = b * math.sin(gamma) * ext
    theta = math.asin(ext * math.sin(gamma))
    diag2 = (a + b * math.cos(gamma)) ** 2 + (b * math.sin(gamma)) ** 2
    c = (diag2 - h**2 - a**2 - (b * math.cos(theta)) ** 2) / (2 * a * b * math.cos(theta))
    beta = math.acos(min(1.0, c))
    dx, dy0, dy1, dz = (
        b * math.sin(theta),
        b * math.cos(theta),
        a * math.cos(beta),
        a * math.sin(beta),
    )
    nodes = {}
    for i in range(1, m + 2):
        for j in range(1, n + 2):
            k = (i - 1) * (n + 1) + j
            y = (j - 1) * dy1 + (dy0 if i % 2 == 0 else 0.0)
            z = 0.0 if j % 2 == 1 else dz
            nodes[k] = ((i - 1) * dx, y, z)
    panels = {}
    for i in range(1, m + 1):
        for j in range(1, n + 1):
            panels[(i - 1) * n + j] = [
                (i - 1) * (n + 1) + j,
                i * (n + 1) + j,
                i * (n + 1) + j + 1,
                (i - 1) * (n + 1) + j + 1,
            ]
    X = np.array([nodes[k] for k in range(1, len(nodes) + 1)])
    P = [np.array(panels[k]) - 1 for k in range(1, len(panels) + 1)]
    return X, P


def interior_vertices(p):
    inner = p.edges[p.interior]
    border = np.unique(p.edges[~p.interior])
    return np.setdiff1d(np.unique(inner), border)


@pytest.mark.parametrize("m,n,ext", [(2, 2, 0.6), (24, 6, 0.6), (30, 9, 0.3), (36, 12, 0.9)])
def test_nodes_and_panels_equal_spec(m, n, ext):
    L = 0.2 if m > 2 else 0.04
    b = L / m
    a = (L - b / math.tan(GAMMA70)) / n
    p = miura_sheet_paper(m, n, L, GAMMA70, ext)
    X, P = spec_miura(a, b, GAMMA70, m, n, ext)
    assert p.coords.shape == ((m + 1) * (n + 1), 3)
    np.testing.assert_allclose(p.coords, X, rtol=0, atol=1e-15 * L)
    assert len(p.faces) == m * n
    for f, g in zip(p.faces, P, strict=True):
        assert f.tolist() == g.tolist()


def test_paper_parametrisation_uses_cot():
    p = miura_sheet_paper(24, 6, 0.2, GAMMA70, 0.6)
    b = 0.2 / 24
    assert p.meta["b"] == pytest.approx(b, rel=1e-15)
    assert p.meta["a"] == pytest.approx((0.2 - b * math.cos(GAMMA70) / math.sin(GAMMA70)) / 6)
    assert p.meta["a"] == pytest.approx(0.032827819119, rel=1e-10)
    assert p.meta["kind"] == "miura" and p.meta["size"] == 0.2
    assert (p.meta["m"], p.meta["n"], p.meta["ext"]) == (24, 6, 0.6)


def test_single_cell_counts():
    p = miura_cell(0.01, 0.02, math.radians(60), 0.6)
    assert (p.n_vertices, p.n_faces, p.n_edges, int(p.interior.sum())) == (9, 4, 12, 4)
    # same numbers as the scenario-1 call (L = 0.04, m = n = 2)
    q = miura_sheet_paper(2, 2, 0.04, math.radians(60), 0.3)
    assert (q.n_vertices, q.n_faces, q.n_edges, int(q.interior.sum())) == (9, 4, 12, 4)


@pytest.mark.parametrize("m,n", [(3, 4), (24, 6), (36, 12)])
def test_sheet_counts(m, n):
    p = miura_sheet(m, n, 0.01, 0.012, GAMMA70, 0.5)
    assert p.n_vertices == (m + 1) * (n + 1)
    assert p.n_faces == m * n
    assert p.n_edges == m * (n + 1) + (m + 1) * n
    assert int(p.interior.sum()) == (m - 1) * n + m * (n - 1)
    assert int((p.assignment == "B").sum()) == 2 * (m + n)


@pytest.mark.parametrize("ext", EXTS)
def test_panels_rigid_and_planar(ext):
    p = miura_sheet_paper(24, 6, 0.2, GAMMA70, ext)
    len_err, plan_err = panel_errors(p)
    assert len_err <= 1e-12
    assert plan_err <= 1e-12
    # all pattern edges (creases included) keep their flat length
    rel = np.abs(p.edge_lengths - p.flat_edge_lengths) / p.flat_edge_lengths
    assert rel.max() <= 1e-12


def test_flat_layout_is_ext_one_and_ccw():
    p = miura_sheet(4, 3, 0.01, 0.02, math.radians(55), 1.0)
    np.testing.assert_allclose(p.coords[:, :2], p.flat, atol=1e-17)
    assert np.all(p.coords[:, 2] == 0.0)
    # flat panels: parallelograms with sides a, b and angle gamma, positive area a b sin(gamma)
    for f in p.faces:
        q = p.flat[f]
        x, y = q[:, 0], q[:, 1]
        area = 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
        assert area == pytest.approx(0.01 * 0.02 * math.sin(math.radians(55)), rel=1e-12)
    # ext < 1 keeps the same flat layout
    q = miura_sheet(4, 3, 0.01, 0.02, math.radians(55), 0.4)
    np.testing.assert_array_equal(q.flat, p.flat)


def test_sector_angles_sum_to_two_pi_and_kawasaki():
    p = miura_sheet_paper(6, 4, 0.2, GAMMA70, 0.6)
    inner = interior_vertices(p)
    assert len(inner) == 5 * 3
    total = np.zeros(p.n_vertices)
    for f, ang in zip(p.faces, p.sector_angles(), strict=True):
        np.add.at(total, f, ang)
    np.testing.assert_allclose(total[inner], 2 * math.pi, rtol=0, atol=1e-12)
    # Kawasaki: sector angles around each degree-4 vertex alternate gamma, pi - gamma
    for v in inner:
        angles = sorted(
            float(ang[list(f).index(v)])
            for f, ang in zip(p.faces, p.sector_angles(), strict=True)
            if v in f
        )
        assert angles == pytest.approx([GAMMA70, GAMMA70, math.pi - GAMMA70, math.pi - GAMMA70])


@pytest.mark.parametrize("ext", EXTS)
def test_maekawa_and_assignment_stable(ext):
    p = miura_sheet_paper(6, 4, 0.2, GAMMA70, ext)
    ref = miura_sheet_paper(6, 4, 0.2, GAMMA70, 0.5)
    np.testing.assert_array_equal(p.assignment, ref.assignment)
    for v in interior_vertices(p):
        at = (p.edges == v).any(axis=1)
        assert at.sum() == 4
        n_m = int((p.assignment[at] == "M").sum())
        n_v = int((p.assignment[at] == "V").sum())
        assert abs(n_m - n_v) == 2
    if ext == 1.0:
        assert np.all(p.fold_angle == 0.0)
    else:
        # fold angles carry the assignment's sign and match the geometry
        np.testing.assert_allclose(p.fold_angle, p.measured_fold_angles(), atol=1e-9)
        crease = p.interior
        assert np.all(np.sign(p.fold_angle[crease]) == np.where(p.assignment[crease] == "V", 1, -1))


@pytest.mark.parametrize("ext", (0.3, 0.6, 0.9))
def test_fold_angles_closed_form(ext):
    """Straight creases fold by 2 acos(ext); zig-zag ones by tan(r/2) = tan(r_s/2)/cos(gamma)."""
    gamma = math.radians(60.0)
    p = miura_sheet(4, 4, 0.01, 0.015, gamma, ext)
    rho_s = 2 * math.acos(ext)
    rho_z = 2 * math.atan(math.tan(rho_s / 2) / math.cos(gamma))
    e, crease = p.edges, p.interior
    straight = crease & (e[:, 1] - e[:, 0] == 1)  # same row i: (i, j)-(i, j+1)
    zigzag = crease & (e[:, 1] - e[:, 0] == 5)  # (i, j)-(i+1, j)
    assert straight.sum() == 3 * 4 and zigzag.sum() == 4 * 3
    np.testing.assert_allclose(np.abs(np.radians(p.fold_angle[straight])), rho_s, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.radians(p.fold_angle[zigzag])), rho_z, atol=1e-12)


@pytest.mark.parametrize("ext", EXTS)
def test_x_extent(ext):
    p = miura_sheet_paper(24, 6, 0.2, GAMMA70, ext)
    theta = math.asin(ext * math.sin(GAMMA70))
    b = 0.2 / 24
    assert np.ptp(p.coords[:, 0]) == pytest.approx(24 * b * math.sin(theta), rel=1e-14)
    assert np.ptp(p.coords[:, 0]) / np.ptp(p.flat[:, 0]) == pytest.approx(ext, rel=1e-14)


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(ext=0.0), "ext"),
        (dict(ext=1.2), "ext"),
        (dict(ext=-0.5), "ext"),
        (dict(gamma=math.radians(95)), "gamma"),
        (dict(gamma=0.0), "gamma"),
        (dict(gamma=60.0), "radians"),  # degrees passed by mistake
        (dict(a=-0.01), "a"),
        (dict(b=0.0), "b"),
        (dict(m=0), "m"),
        (dict(n=2.5), "n"),
        (dict(ext=float("nan")), "ext"),
    ],
)
def test_invalid_parameters(kwargs, name):
    args = dict(m=4, n=4, a=0.01, b=0.01, gamma=GAMMA70, ext=0.5) | kwargs
    with pytest.raises(ParameterError, match=name):
        miura_sheet(**args)


def test_invalid_paper_parametrisation():
    # m tan(gamma) <= 1 gives a <= 0
    with pytest.raises(ParameterError, match="tan"):
        miura_sheet_paper(1, 2, 0.04, math.radians(40), 0.5)
    with pytest.raises(ParameterError, match="L = -0.04"):
        miura_sheet_paper(2, 2, -0.04, math.radians(60), 0.5)
    with pytest.raises(ParameterError, match="gamma"):
        miura_cell(0.01, 0.02, math.radians(95), 0.5)
    with pytest.raises(ParameterError, match="not both"):
        miura_sheet(2, 2, 0.01, 0.01, GAMMA70, 0.5, size=0.04)
