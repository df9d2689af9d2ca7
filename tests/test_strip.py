"""The analytic Miura-like strip of docs/strip-fit.md §3."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.fitting import StripFit, fit_strip, strip_geometry
from holofold.fitting.curves import PlanarCurve, parse_curve_spec
from holofold.fitting.strip import (
    quad_warp,
    side_line,
    strip_faces,
    zigzag_centre_line,
)
from holofold.geometry.errors import DegenerateGeometryError, ParameterError

HALF = parse_curve_spec("half-circle:radius=2")


@pytest.fixture(scope="module")
def fit8() -> StripFit:
    return fit_strip(HALF, 8, 0.2, 0.02, 0.1)


def test_centre_line_test_vector(fit8):
    P = fit8.centre_line
    np.testing.assert_allclose(P[1], [-0.157728, 0.429199], atol=5e-7)
    np.testing.assert_allclose(np.linalg.norm(P[1] - [2, 0]), 2.2, rtol=1e-14)
    # every odd vertex at R + l_o, every even vertex on the circle; apex is node m
    r = np.linalg.norm(P - [2.0, 0.0], axis=1)
    np.testing.assert_allclose(r[1::2], 2.2, rtol=1e-14)
    np.testing.assert_allclose(r[::2], 2.0, rtol=1e-14)
    np.testing.assert_allclose(P[8], [2.0, 2.0], atol=1e-15)
    assert fit8.sampling == "paper"
    np.testing.assert_array_equal(fit8.t, np.arange(17) / 16)


def test_end_shifts_are_asymmetric(fit8):
    S, P = fit8.side_line, fit8.centre_line
    np.testing.assert_allclose(S[0] - P[0], [0.0188, 0.0069], atol=5e-5)
    np.testing.assert_allclose(S[-1] - P[-1], [0.0188, -0.0069], atol=5e-5)
    np.testing.assert_allclose(np.linalg.norm(S[0] - P[0]), 0.02, rtol=1e-14)


def test_interior_shift_is_tangential_with_length_ws_cot_phi(fit8):
    P, S = fit8.centre_line, fit8.side_line
    u = np.diff(P, axis=0)
    u /= np.linalg.norm(u, axis=1)[:, None]
    v = 0.5 * (u[:-1] + u[1:])
    shift = S[1:-1] - P[1:-1]
    cross = v[:, 0] * shift[:, 1] - v[:, 1] * shift[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-15)  # along the mean tangent
    phi = np.arctan2(
        np.abs(v[:, 0] * u[1:, 1] - v[:, 1] * u[1:, 0]), np.einsum("ij,ij->i", v, u[1:])
    )
    np.testing.assert_allclose(np.linalg.norm(shift, axis=1), 0.02 / np.tan(phi), rtol=1e-12)


@pytest.mark.parametrize("m, ne, ni", [(8, 82, 46), (24, 242, 142)])
def test_counts(m, ne, ni):
    p = fit_strip(HALF, m, 0.2, 0.02, 0.1).pattern
    assert p.n_vertices == 6 * m + 3
    assert p.n_faces == 4 * m
    assert p.n_edges == ne
    assert int(p.interior.sum()) == ni


def test_node_numbering_and_panel_order(fit8):
    p, m = fit8.pattern, 8
    X = p.coords
    np.testing.assert_array_equal(X[: 2 * m + 1, 1], 0.0)
    np.testing.assert_array_equal(X[2 * m + 1 : 4 * m + 2, 1], -0.1)
    np.testing.assert_array_equal(X[4 * m + 2 :, 1], 0.1)
    np.testing.assert_array_equal(X[: 2 * m + 1][:, [0, 2]], fit8.centre_line)
    np.testing.assert_array_equal(X[2 * m + 1 : 4 * m + 2][:, [0, 2]], fit8.side_line)
    # 1-based [i, 2m+1+i, 2m+2+i, i+1] and [i, 4m+2+i, 4m+3+i, i+1] minus 1, segment by segment
    i = 3
    np.testing.assert_array_equal(p.faces[2 * (i - 1)], np.array([i, 17 + i, 18 + i, i + 1]) - 1)
    np.testing.assert_array_equal(p.faces[2 * i - 1], np.array([i, 34 + i, 35 + i, i + 1]) - 1)
    np.testing.assert_array_equal(np.stack(p.faces), strip_faces(8))
    assert p.flat is None
    assert {k: p.meta[k] for k in ("m", "offset", "strip_width", "extrude", "sampling")} == {
        "m": 8,
        "offset": 0.2,
        "strip_width": 0.02,
        "extrude": 0.1,
        "sampling": "paper",
    }


@pytest.mark.parametrize(
    "curve, sampling", [(HALF, "paper"), ("parabola:span=4,height=1.5", "arclength")]
)
def test_sector_angles_sum_to_two_pi(curve, sampling):
    fit = fit_strip(curve, 6, 0.15, 0.03, 0.12, sampling=sampling)
    p = fit.pattern
    total = np.zeros(p.n_vertices)
    for f, a in zip(p.faces, p.sector_angles(), strict=True):
        np.add.at(total, f, a)
    np.testing.assert_allclose(total[1:12], 2 * np.pi, atol=1e-12)
    assert fit.max_angle_defect < 1e-12


def test_quads_are_warped_and_warp_measure(fit8):
    # a planar square has zero warp; lifting one corner by h gives h / diag (diagonal distance)
    X = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    np.testing.assert_allclose(quad_warp(X, np.array([[0, 1, 2, 3]])), 0.0, atol=1e-16)
    X[2, 2] = 0.1
    w = quad_warp(X, np.array([[0, 1, 2, 3]]))[0]
    # diagonals (0,0,0)-(1,1,.1) and (1,0,0)-(0,1,0): distance 0.1/2 * 2/sqrt(2.01) ... exact:
    d1, d2 = X[2] - X[0], X[3] - X[1]
    n = np.cross(d1, d2)
    gap = abs(np.dot(X[1] - X[0], n)) / np.linalg.norm(n)
    np.testing.assert_allclose(w, gap / (0.5 * (np.linalg.norm(d1) + np.linalg.norm(d2))))
    assert fit8.warp.shape == (32,)
    assert 1e-3 < fit8.warp.max() < 0.05  # the published quads are not planar


def test_flat_layout_keeps_centre_and_transverse_lengths(fit8):
    fp = fit8.flat_pattern
    assert fp is not None and fp.flat is not None
    np.testing.assert_allclose(fit8.flat[:17, 1], 0.0)  # the centre line develops straight
    l3 = fp.edge_lengths
    lf = fp.flat_edge_lengths
    e = fp.edges
    centre_or_transverse = (e[:, 0] <= 16) | (e[:, 1] <= 16)
    np.testing.assert_allclose(lf[centre_or_transverse], l3[centre_or_transverse], rtol=1e-12)
    rel = np.abs(lf - l3) / l3
    # sector angles at centre-line vertices are those of the 3-D strip, corner by corner
    flat_angles, angles3d = fp.sector_angles(), fit8.pattern.sector_angles()
    checked = 0
    for k, (fl, f3) in enumerate(zip(fp.faces, fit8.pattern.faces, strict=True)):
        for pos, v in enumerate(fl):
            if v <= 16:
                pos3 = int(np.flatnonzero(f3 == v)[0])
                np.testing.assert_allclose(flat_angles[k][pos], angles3d[k][pos3], atol=1e-12)
                checked += 1
    assert checked == 64
    np.testing.assert_allclose(rel.max(), fit8.flat_length_error, rtol=1e-12)
    assert 0 < fit8.flat_length_error < 1e-3


def test_arclength_sampling_default_for_user_curves():
    fit = fit_strip("parabola:span=4,height=1", 4, 0.3, 0.02, 0.1)
    assert fit.sampling == "arclength"
    s = fit.curve.arc_length(fit.t)
    np.testing.assert_allclose(np.diff(s), s[-1] / 8, rtol=1e-9)


def test_closest_error_of_circle_strip_is_analytic(fit8):
    # for the half circle the farthest centre-line points are the odd vertices at R + l_o
    np.testing.assert_allclose(fit8.closest.max, 0.2, rtol=1e-9)
    assert 0 < fit8.closest.mean < 0.2


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"m": 1}, "m must be an integer >= 2"),
        ({"m": 2.5}, "m must be an integer >= 2"),
        ({"offset": 0.0}, "offset"),
        ({"offset": -0.1}, "offset"),
        ({"strip_width": -0.02}, "strip_width"),
        ({"extrude": float("nan")}, "extrude"),
        ({"sampling": "chord"}, "sampling"),
    ],
)
def test_bad_parameters(kwargs, match):
    args = {"m": 8, "offset": 0.2, "strip_width": 0.02, "extrude": 0.1} | kwargs
    sampling = args.pop("sampling", None)
    with pytest.raises(ParameterError, match=match):
        fit_strip(HALF, **args, sampling=sampling)


def test_degenerate_turning_is_an_error():
    # a centre line with a straight vertex: phi = 0 and W_s / sin(phi) is unbounded
    P = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 1.0], [4.0, 0.0]])
    with pytest.raises(DegenerateGeometryError, match="does not turn at vertex 1"):
        side_line(P, 0.02)
    # zigzag: the offset makes even a straight curve turn, so the strip exists
    line = PlanarCurve.from_function(lambda t: np.column_stack([4 * t, 0 * t]), name="line")
    fit = fit_strip(line, 2, 0.1, 0.02, 0.1)
    np.testing.assert_allclose(fit.centre_line[1::2, 1], 0.1)
    assert zigzag_centre_line(fit.samples, 0.1).shape == (5, 2)


def test_overlapping_strip_is_a_clear_error():
    # small offset on a nearly straight stretch: W_s cot(phi) exceeds the segment length
    with pytest.raises(DegenerateGeometryError, match="self-overlapping.*smaller strip_width"):
        fit_strip("parabola:span=4,height=1", 4, 0.1, 0.02, 0.1)


def test_odd_m_is_allowed_but_apex_is_shifted():
    fit = fit_strip(HALF, 3, 0.2, 0.02, 0.1)
    assert fit.pattern.n_vertices == 21 and fit.pattern.n_faces == 12
    # t = 1/2 is the odd vertex 3, moved outward by l_o: no vertex stays at the apex
    np.testing.assert_allclose(fit.centre_line[3], [2.0, 2.2], atol=1e-15)
    assert np.linalg.norm(fit.centre_line - [2.0, 2.0], axis=1).min() > 0.19


def test_strip_geometry_names_the_paper_nodes():
    """ends = the six end nodes of the three lines (the paper's supports), apex = node m."""
    g = strip_geometry(HALF, 8, 0.2, 0.02, 0.1)
    assert g.nodes.shape == (51, 3) and g.faces.shape == (32, 4)
    assert g.ends.tolist() == [0, 16, 17, 33, 34, 50]
    assert g.apex == 8 and np.allclose(g.nodes[g.apex, [0, 2]], [2.0, 2.0])  # the top
    np.testing.assert_allclose(g.nodes[g.side_a, 1], -0.1)
    np.testing.assert_allclose(g.nodes[g.side_b, 1], 0.1)
    np.testing.assert_array_equal(g.nodes[g.centre, 1], 0.0)
    fit = fit_strip(HALF, 8, 0.2, 0.02, 0.1)
    np.testing.assert_array_equal(fit.geometry.nodes, g.nodes)
    np.testing.assert_array_equal(fit.pattern.coords, g.nodes)
    with pytest.raises(ParameterError, match="offset"):
        strip_geometry(HALF, 8, -0.2, 0.02, 0.1)
