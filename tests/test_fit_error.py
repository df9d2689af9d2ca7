"""Fitting errors: the published index-matched error (5.5) and the closest-point error."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.fitting import fit_strip
from holofold.fitting.curves import PlanarCurve, parse_curve_spec
from holofold.fitting.error import (
    closest_point_error,
    index_matched_error,
    paper_error,
    polyline_distance,
)
from holofold.geometry.errors import ParameterError

HALF = parse_curve_spec("half-circle:radius=2")


def test_published_error_column_all_rows(reference_data):
    df = reference_data.load("data3_ShapeFit")
    assert len(df) == 3000
    e = paper_error(HALF, df["m"].to_numpy().astype(int), df["offset"].to_numpy())
    rel = np.abs(e - df["error"].to_numpy()) / df["error"].to_numpy()
    assert rel.max() < 1e-12, rel.max()


@pytest.mark.parametrize(
    "m, expected",
    [
        (8, [0.043684, 0.093679, 0.143678]),
        (12, [0.047181, 0.097180, 0.147180]),
        (16, [0.048412, 0.098412, 0.148412]),
        (24, [0.049294, 0.099294, 0.149294]),
    ],
)
def test_spec_test_vectors(m, expected):
    e = paper_error("half-circle:radius=2", m, [0.1, 0.2, 0.3])
    np.testing.assert_allclose(e, expected, atol=6e-7)


def test_paper_error_matches_the_strip_and_broadcasts():
    fit = fit_strip(HALF, 12, 0.17, 0.03, 0.1)
    np.testing.assert_allclose(fit.index_error, paper_error(HALF, 12, 0.17), rtol=1e-14)
    np.testing.assert_allclose(index_matched_error(HALF, fit.centre_line, fit.t), fit.index_error)
    e = paper_error(HALF, np.array([[8], [16]]), np.array([0.1, 0.2]))
    assert e.shape == (2, 2)
    np.testing.assert_allclose(e[1, 1], paper_error(HALF, 16, 0.2), rtol=1e-15)
    assert isinstance(paper_error(HALF, 8, 0.2), float)


def test_paper_error_bad_input():
    with pytest.raises(ParameterError, match="m must be integers"):
        paper_error(HALF, 0, 0.2)
    with pytest.raises(ParameterError, match="m must be integers"):
        paper_error(HALF, 2.5, 0.2)
    with pytest.raises(ParameterError, match="offset must be finite"):
        paper_error(HALF, 8, np.inf)


def test_closest_point_error_exact_fit_is_zero():
    # the centre line of a fit, used itself as the target curve: distance ~ 0
    fit = fit_strip(HALF, 8, 0.2, 0.02, 0.1)
    poly = PlanarCurve.from_points(fit.centre_line, degree=1)
    err = closest_point_error(poly, fit.centre_line)
    assert err.max < 1e-12 and err.mean < 1e-12
    assert err.curve_max < 1e-12


def test_closest_point_error_circle_analytic():
    fit = fit_strip(HALF, 16, 0.25, 0.02, 0.1)
    err = fit.closest
    # exact: distance to the circle is | |q - c| - R | for points above the diameter
    P = fit.centre_line
    j = np.arange(11) / 10
    Q = (P[:-1, None] * (1 - j)[None, :, None] + P[1:, None] * j[None, :, None]).reshape(-1, 2)
    d = np.abs(np.linalg.norm(Q - [2.0, 0.0], axis=1) - 2.0)
    np.testing.assert_allclose(err.max, d.max(), rtol=1e-9)
    np.testing.assert_allclose(err.max, 0.25, rtol=1e-9)
    # curve -> centre line: the worst points are the even vertices' neighbourhood, < offset
    assert 0 < err.curve_mean < err.curve_max < 0.25


def test_polyline_distance():
    poly = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    q = np.array([[0.5, 0.3], [2.0, 0.5], [-1.0, 0.0], [1.2, 2.0]])
    np.testing.assert_allclose(polyline_distance(q, poly), [0.3, 1.0, 1.0, np.hypot(0.2, 1.0)])
