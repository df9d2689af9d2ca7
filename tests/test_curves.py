"""Planar target curves: construction, parsing, lengths, resampling, distances, errors."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from holofold.fitting import CurveSelectionWarning
from holofold.fitting.curve_files import (
    CurveUnitWarning,
    load_curve,
    read_points_csv,
    read_svg_curve,
)
from holofold.fitting.curves import (
    CurveError,
    PlanarCurve,
    builtin_curve,
    parse_curve_spec,
)
from holofold.geometry.errors import FormatError, ParameterError

T = np.linspace(0.0, 1.0, 7)


def test_half_circle_is_the_paper_curve():
    c = parse_curve_spec("half-circle:radius=2")
    np.testing.assert_array_equal(
        c(T), np.column_stack([2 - 2 * np.cos(np.pi * T), 2 * np.sin(np.pi * T)])
    )
    assert c.default_sampling == "paper"
    np.testing.assert_allclose(c.length, 2 * np.pi, rtol=1e-7)
    assert parse_curve_spec("half-circle").params == {"radius": 2.0}


@pytest.mark.parametrize(
    "spec, length",
    [
        ("arc:radius=2,angle=180", 2 * np.pi),
        ("arc:radius=3,angle=90", 3 * np.pi / 2),
        # parabola z = 4H t(1-t), x = L t: closed-form arc length
        ("parabola:span=4,height=1", 2 * (np.sqrt(2) + np.arcsinh(1.0))),
        ("catenary:span=4,height=2", None),
        ("sine:span=4,amplitude=0.5,periods=1", None),
    ],
)
def test_builtins(spec, length):
    c = parse_curve_spec(spec)
    p = c(np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(p[0], [0.0, 0.0], atol=1e-12)
    if length is not None:
        np.testing.assert_allclose(c.length, length, rtol=1e-7)
    assert c.default_sampling == "arclength"


def test_arc_180_equals_half_circle_and_catenary_shape():
    a = parse_curve_spec("arc:radius=2,angle=180")
    h = parse_curve_spec("half-circle:radius=2")
    np.testing.assert_allclose(a(T), h(T), atol=1e-14)
    c = parse_curve_spec("catenary:span=4,height=2")
    p = c(np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(p, [[0, 0], [2, 2], [4, 0]], atol=1e-12)
    a_ = c.params["a"]
    np.testing.assert_allclose(a_ * (np.cosh(2 / a_) - 1), 2.0, rtol=1e-12)


def test_arclength_resampling_gives_equal_lengths():
    c = parse_curve_spec("parabola:span=4,height=1")
    t, p = c.resample(17, "arclength")

    # exact arc length of x = 4t, z = 4t(1-t) from 0 to t
    # |c'(t)| = 4 sqrt(1 + w^2) with w = 1 - 2t
    def s(t):
        w = 1 - 2 * t
        return (np.sqrt(2) + np.arcsinh(1)) - (w * np.sqrt(1 + w**2) + np.arcsinh(w))

    seg = np.diff(s(t))
    np.testing.assert_allclose(seg, seg.mean(), rtol=1e-6)
    np.testing.assert_allclose(s(1.0), c.length, rtol=1e-7)
    tp, pp = c.resample(5, "parameter")
    np.testing.assert_array_equal(tp, [0, 0.25, 0.5, 0.75, 1])
    np.testing.assert_allclose(c.parameter_at_length(c.arc_length(T)), T, atol=1e-9)


def test_closest_point_distance_circle_exact():
    c = parse_curve_spec("half-circle:radius=2")
    q = np.random.default_rng(1).normal(size=(2000, 2)) * 3 + [2.0, 0.0]
    d, t, foot = c.closest_point(q)
    th = np.arctan2(q[:, 1], q[:, 0] - 2)
    r = np.linalg.norm(q - [2, 0], axis=1)
    ends = np.minimum(np.linalg.norm(q, axis=1), np.linalg.norm(q - [4, 0], axis=1))
    exact = np.where(th >= 0, np.abs(r - 2), ends)
    np.testing.assert_allclose(d, exact, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(foot - q, axis=1), d, atol=1e-15)
    np.testing.assert_allclose(c(t), foot, atol=1e-15)


def test_points_and_csv(tmp_path):
    pts = np.column_stack([np.linspace(0, 4, 9), np.sin(np.linspace(0, np.pi, 9))])
    c = PlanarCurve.from_points(pts)
    # the spline interpolates the points at their chord-length parameters
    chord = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    np.testing.assert_allclose(c(chord / chord[-1]), pts, atol=1e-12)
    f = tmp_path / "pts.csv"
    f.write_text("x,z\n" + "\n".join(f"{x},{z}" for x, z in pts))
    np.testing.assert_allclose(read_points_csv(f)(T), c(T), atol=1e-12)
    g = tmp_path / "pts.txt"  # no header, blank separated
    g.write_text("\n".join(f"{x} {z}" for x, z in pts))
    np.testing.assert_allclose(load_curve(g)(T), c(T), atol=1e-12)
    # two points: a straight segment
    line = PlanarCurve.from_points([[0, 0], [3, 4]])
    np.testing.assert_allclose(line.length, 5.0, rtol=1e-12)


SVG = """<svg xmlns="http://www.w3.org/2000/svg" width="400" height="300">
  <path id="arch" d="M 0 200 C 0 0 400 0 400 200"/>
  <path id="half" d="M 0 100 A 100 100 0 0 1 200 100"/>
</svg>"""


@pytest.mark.filterwarnings("ignore::holofold.fitting.CurveUnitWarning")  # 200 m across
def test_svg(tmp_path):
    f = tmp_path / "drawing.svg"
    f.write_text(SVG)
    half = read_svg_curve(f"{f}#half")
    p = half(np.array([0.0, 0.5, 1.0]))
    # y down in SVG -> z up: the arc bulges to +z; origin at the first point
    np.testing.assert_allclose(p, [[0, 0], [100, 100], [200, 0]], atol=1e-3)
    np.testing.assert_allclose(half.length, np.pi * 100, rtol=1e-6)
    with pytest.warns(
        CurveSelectionWarning, match=r"has 2 paths \(ids arch, half\); read the first"
    ):
        arch = load_curve(str(f))  # first path
    np.testing.assert_allclose(arch(np.array([0.5])), [[200.0, 150.0]], atol=1e-2)
    assert arch.scaled(0.01).length == pytest.approx(arch.length * 0.01, rel=1e-12)
    direct = PlanarCurve.from_svg_path("M 0 0 L 3 -4")
    np.testing.assert_allclose(direct(np.array([1.0])), [[3.0, 4.0]], atol=1e-12)


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda: PlanarCurve.from_points([[1.0, 2.0]]), "at least two distinct points"),
        (lambda: PlanarCurve.from_points([[1.0, 2.0], [1.0, 2.0]]), "two distinct points"),
        (lambda: PlanarCurve.from_points([[0, 0], [np.nan, 1]]), "non-finite"),
        (lambda: PlanarCurve.from_points(np.zeros((3, 3))), "shape"),
        (lambda: PlanarCurve.from_function(lambda t: (0 * t + 1, 0 * t)), "zero length"),
        (lambda: PlanarCurve.from_function(lambda t: (t, np.log(t - 0.5))), "non-finite"),
        (lambda: parse_curve_spec("spiral:turns=3"), "unknown curve 'spiral'"),
        (lambda: parse_curve_spec("half-circle:diameter=2"), "no parameter 'diameter'"),
        (lambda: parse_curve_spec("half-circle:radius=two"), "not a number"),
        (lambda: parse_curve_spec("half-circle:radius"), "not key=value"),
    ],
)
@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_curve_errors(make, match):
    with pytest.raises(CurveError, match=match):
        make()


def test_parameter_and_file_errors(tmp_path):
    with pytest.raises(ParameterError, match="radius"):
        parse_curve_spec("half-circle:radius=-1")
    with pytest.raises(ParameterError, match="angle"):
        parse_curve_spec("arc:angle=400")
    with pytest.raises(FormatError, match="does not exist"):
        load_curve(tmp_path / "missing.csv")
    bad = tmp_path / "bad.csv"
    bad.write_text("x,z\n0,0\n1,oops\n")
    with pytest.raises(FormatError, match="line 3"):
        read_points_csv(bad)
    svg = tmp_path / "bad.svg"
    svg.write_text("<svg><path d='M 0 0 L 1 1'/>")  # truncated XML
    with pytest.raises(FormatError, match="cannot read SVG"):
        read_svg_curve(svg)
    svg.write_text(SVG)
    with pytest.raises(FormatError, match="no <path id='nope'>"):
        read_svg_curve(f"{svg}#nope")
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="Q oops"/></svg>')
    with pytest.raises(FormatError, match="has no segments"):
        read_svg_curve(svg)
    with pytest.raises(FormatError, match="cannot parse SVG path data"):
        PlanarCurve.from_svg_path("Q oops")


def test_self_intersection_warns():
    with pytest.warns(UserWarning, match="intersects itself"):
        # nodal cubic x = s^2 - 1, z = s (s^2 - 1), s in [-1.5, 1.5]: crosses at s = +-1
        PlanarCurve.from_function(
            lambda t: ((3 * t - 1.5) ** 2 - 1, (3 * t - 1.5) ** 3 - (3 * t - 1.5))
        )
    with pytest.warns(UserWarning, match="intersects itself"):  # a loop crossing a line
        PlanarCurve.from_points([[0, 0], [2, 0], [1, 1], [1, -1]], degree=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        builtin_curve("parabola")  # simple: no warning
        PlanarCurve.from_function(lambda t: (np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)))


def _svg(tmp_path, head, body, name="d.svg"):
    f = tmp_path / name
    f.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" {head}>{body}</svg>')
    return f


def test_svg_document_units_viewbox_and_transforms(tmp_path):
    # 400 mm wide drawing, viewBox in mm, the path inside a group scaled by 2: a 0.4 m chord
    arc = '<path id="arch" d="M 0 100 A 50 50 0 0 1 200 100"/>'
    f = _svg(tmp_path, 'width="400mm" height="200mm" viewBox="0 0 400 200"',
             f'<g transform="scale(2)">{arc}</g>')  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a plausible size: no warning
        arch = read_svg_curve(f"{f}#arch")
    np.testing.assert_allclose(arch(np.array([0.0, 0.5, 1.0])),
                               [[0, 0], [0.2, 0.2], [0.4, 0]], atol=1e-9)  # fmt: skip
    assert arch.length == pytest.approx(np.pi * 0.2, rel=1e-6)
    assert arch.params["units"] == "mm"
    # a viewBox of tenths of a millimetre, and inches
    g = _svg(tmp_path, 'width="400mm" height="200mm" viewBox="0 0 4000 2000"',
             '<path d="M 0 0 L 3000 0"/>', "tenths.svg")  # fmt: skip
    assert read_svg_curve(g).length == pytest.approx(0.3, rel=1e-12)
    h = _svg(tmp_path, 'width="10in" height="5in" viewBox="0 0 10 5"',
             '<path d="M 0 0 L 5 0"/>', "in.svg")  # fmt: skip
    assert read_svg_curve(h).length == pytest.approx(5 * 0.0254, rel=1e-12)
    # no viewBox: user units are CSS px (96 per inch)
    k = _svg(tmp_path, 'width="400mm" height="200mm"', '<path d="M 0 0 L 96 0"/>', "px.svg")
    assert read_svg_curve(k).length == pytest.approx(0.0254, rel=1e-12)


def test_svg_units_given_and_implausible_sizes(tmp_path):
    f = _svg(tmp_path, 'width="400" height="300"', '<path id="a" d="M 0 100 Q 200 -100 400 100"/>')
    # no unit in the file: one user unit = 1 m, and a 400 m arch gets a warning naming mm
    with pytest.warns(CurveUnitWarning, match=r"400 m across .* in mm, it is 0\.4 m"):
        big = read_svg_curve(f"{f}#a")
    assert np.ptp(big.polyline(), axis=0)[0] == pytest.approx(400.0, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mm = read_svg_curve(f"{f}#a", units="mm")  # as the scenario files say it
    assert np.ptp(mm.polyline(), axis=0)[0] == pytest.approx(0.4, rel=1e-9)
    # a document in mm read as if its user unit were a metre: warned, and done as asked
    g = _svg(tmp_path, 'width="400mm" height="300mm" viewBox="0 0 400 300"',
             '<path d="M 0 0 L 300 0"/>', "g.svg")  # fmt: skip
    with pytest.warns(CurveUnitWarning, match="declares one user unit = 1 mm"):
        read_svg_curve(g, units="m", check_size=False)
    with pytest.raises(ParameterError, match="unknown length unit 'furlong'"):
        read_svg_curve(g, units="furlong")
    two = _svg(tmp_path, "", '<path d="M 0 0 L 1 0 M 5 5 L 6 6"/>', "two.svg")
    with pytest.raises(FormatError, match="2 subpaths"):
        read_svg_curve(two)


def test_csv_units_and_a_tiny_arch(tmp_path):
    t = np.linspace(0, 1, 11)
    f = tmp_path / "arch_mm.csv"
    f.write_text("x,z\n" + "\n".join(f"{3000 * s},{4 * 800 * s * (1 - s)}" for s in t))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = read_points_csv(f, units="mm")
    assert np.ptp(c.polyline(), axis=0)[0] == pytest.approx(3.0, rel=1e-12)
    assert load_curve(str(f), units="mm").length == pytest.approx(c.length, rel=1e-12)
    with pytest.warns(CurveUnitWarning, match="3000 m across"):
        read_points_csv(f)  # default metres: a 3 km arch
    g = tmp_path / "tiny.csv"
    g.write_text("0,0\n1,1\n2,0\n")
    with pytest.warns(CurveUnitWarning, match=r"0\.002 m across read in mm.* in m, it is 2 m"):
        read_points_csv(g, units="mm")
