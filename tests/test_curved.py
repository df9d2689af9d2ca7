"""Curved creases: the curve as data, its discretisation, SVG curves read (issue 36)."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.geometry import ParameterError
from holofold.geometry.curved import Curve, discretise
from holofold.geometry.svg_reader import svg_lines


def _arc(r=10.0, sweep=np.pi):
    return Curve("arc", "V", 180.0, centre=(1.0, 2.0), radii=(r, r), start=0.3, sweep=sweep)


@pytest.mark.parametrize("chord", [1e-1, 1e-2, 1e-3])
def test_circle_arc_chord_deviation_within_tolerance(chord):
    r = 10.0
    pts = discretise(_arc(r), chord=chord)
    assert np.allclose(np.hypot(*(pts - [1.0, 2.0]).T), r, rtol=1e-12)  # vertices on the arc
    half = np.arctan2(np.linalg.norm(np.diff(pts, axis=0), axis=1) / 2, r)
    dev = r * (1 - np.cos(half))  # sagitta of each piece, the arc's largest deviation
    assert dev.max() <= chord * (1 + 1e-12)
    assert dev.max() > chord / 4.0 * 0.99  # not finer than one halving beyond the bound


def test_piece_counts_grow_as_the_square_root_of_the_tolerance():
    n = [len(discretise(_arc(), chord=c)) - 1 for c in (1e-2, 2.5e-3, 6.25e-4)]
    # sagitta ~ r theta^2 / 8: a quarter of the tolerance doubles the count (halving is binary)
    assert n[1] == 2 * n[0] and n[2] == 2 * n[1]
    assert len(discretise(_arc(), chord=1.0, length=0.5)) - 1 >= np.pi * 10 / 0.5


def test_bezier_points_and_bad_tolerance():
    c = Curve("bezier", "M", -180.0, points=((0, 0), (10, 20), (30, -20), (40, 0)))
    assert np.allclose(c.point(0.5)[0], [20.0, 0.0])  # (0 + 3*10 + 3*30 + 40)/8
    pts = discretise(c, chord=1e-2)
    assert np.allclose(pts[[0, -1]], [[0, 0], [40, 0]])
    with pytest.raises(ParameterError, match="must be > 0"):
        discretise(c, chord=0.0)


def test_svg_c_q_a_read_to_the_analytic_points(tmp_path):
    body = (
        '<path d="M 0 50 Q 50 0 100 50" stroke="#0000ff" fill="none"/>'
        '<path d="M 0 60 C 0 80 100 80 100 60" stroke="#ff0000" fill="none"/>'
        '<path d="M 10 90 A 40 40 0 0 0 90 90" stroke="#ff0000" fill="none"/>'
    )
    f = tmp_path / "c.svg"
    f.write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">{body}</svg>',
        encoding="utf-8",
    )
    S, codes, angles, notes, _ = svg_lines(f, curves="keep", curve_chord=1e-3)
    P = S.reshape(-1, 2) * [1, -1]  # back to y down
    q = P[np.repeat(codes, 2) == "V"]
    # quadratic: y = 50 - 50 * 2 t (1 - t), x = 100 t  ->  y = 50 - x (100 - x) / 100
    assert np.allclose(q[:, 1], 50 - q[:, 0] * (100 - q[:, 0]) / 100, atol=1e-9)
    assert q[:, 1].min() == pytest.approx(25.0)
    m = P[np.repeat(codes, 2) == "M"]
    arc = m[m[:, 1] >= 90 - 1e-9]
    cubic = m[m[:, 1] < 90 - 1e-9]
    assert cubic[:, 1].max() == pytest.approx(75.0)  # 60 + 3/4 * 20 at t = 1/2
    centre = np.array([50.0, 90.0 - np.sqrt(40**2 - 40**2)])  # chord 80 = diameter
    assert np.allclose(np.hypot(*(arc - centre).T), 40.0, atol=1e-9)
    assert arc[:, 1].max() == pytest.approx(130.0)  # sweep 0 from left to right: below
    assert np.allclose(angles[codes == "V"], 180.0) and any("kept" in n for n in notes)


def test_origami_simulator_wavy_pleats_reads_its_curves():
    from pathlib import Path

    from holofold.geometry import read_pattern

    f = Path(__file__).parent / "data" / "origami-simulator" / "wavy_pleats.svg"
    S, codes, _, notes, _ = svg_lines(f)
    assert any(n.startswith("10 curve(s) kept") for n in notes)  # 5 creases x 2 cubics
    assert (codes == "M").sum() + (codes == "V").sum() == len(S) - 4  # all but the border
    # every crease runs from the top edge (y = -0.5 px, y up) to the bottom (y = -425.7 px)
    creases = S[codes != "B"].reshape(-1, 2)
    assert creases[:, 1].max() == pytest.approx(-0.5) and creases[:, 1].min() == pytest.approx(
        -425.7
    )
    with pytest.warns(Warning):
        p = read_pattern(f)
    assert p.n_faces > 6 and np.ptp(p.flat, axis=0).max() > 0


def test_dxf_arc_crease_kept_on_its_circle(tmp_path):
    ezdxf = pytest.importorskip("ezdxf", reason="ezdxf is needed for DXF files")
    from holofold.geometry.dxf_reader import dxf_lines

    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4  # mm
    doc.layers.add("SCORE_M")
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 100), (0, 100)], close=True)
    msp.add_arc((50, 50), 10, 0, 90, dxfattribs={"layer": "SCORE_M"})
    doc.saveas(tmp_path / "a.dxf")
    S, codes, _, _, _ = dxf_lines(tmp_path / "a.dxf")
    arc = S[codes == "M"].reshape(-1, 2)
    assert len(arc) >= 2 * 8  # a quarter circle, chord deviation 1e-3 of 10 mm
    r = np.hypot(*(arc - 50.0).T)  # ezdxf traces an arc by cubic Beziers: within its tolerance
    assert np.abs(r - 10.0).max() <= 1e-3 * 10.0
    with pytest.raises(Exception, match="curved crease"):
        dxf_lines(tmp_path / "a.dxf", curves="refuse")
