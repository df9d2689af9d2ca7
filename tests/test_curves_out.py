"""Curves kept through to the files (issue 36 items 1 and 4): a curved crease read from SVG is
a curve on the pattern (metres, its pieces marked), written to FOLD (``holofold:curves``) and
read back, drawn as a path with C / A commands in the SVG cutter file and as ARC / SPLINE in the
DXF one; a finely cut curve whose pieces are shorter than the merge tolerance keeps its faces."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from holofold.geometry.curved import discretise
from holofold.geometry.line_drawing import PatternWarning
from holofold.geometry.svg_reader import read_svg_pattern, svg_drawing

MM = 1e-3
# a 100 x 100 mm sheet (1 px = 1 mm): a valley cubic across the top, a mountain quarter circle
# of radius 40 about the lower-left corner (SVG y down: the corner is (0, 100))
SHEET = b"""<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm"
 viewBox="0 0 100 100">
 <path d="M 0 0 H 100 V 100 H 0 Z" stroke="#000000" fill="none"/>
 <path d="M 0 20 C 30 0 70 40 100 20" stroke="#0000ff" fill="none"/>
 <path d="M 40 100 A 40 40 0 0 0 0 60" stroke="#ff0000" fill="none"/>
</svg>"""
# the same in metres, y up, lower-left corner at the origin: y = (100 - y_svg) mm
CUBIC = np.array([[0, 80], [30, 100], [70, 60], [100, 80]]) * MM
CENTRE, RADIUS = np.array([0.0, 0.0]), 40 * MM


def _read(data=SHEET, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PatternWarning)
        return read_svg_pattern(data, **kw)


def _pieces(curve_px, size):
    """The number of pieces the reader cuts a curve (SVG px) into on a sheet ``size`` px wide."""
    return (
        len(discretise(curve_px, chord=1e-3 * size, length=0.05 * size, shortest=2e-3 * size)) - 1
    )


@pytest.fixture(scope="module")
def sheet():
    return _read()


def test_svg_curves_are_kept_on_the_pattern_in_metres(sheet):
    p = sheet
    assert len(p.curves) == 2
    cub = next(c for c in p.curves if c.kind == "bezier")
    arc = next(c for c in p.curves if c.kind == "arc")
    np.testing.assert_allclose(np.array(cub.points), CUBIC, rtol=0, atol=1e-12)
    assert (cub.assignment, arc.assignment) == ("V", "M")
    np.testing.assert_allclose(arc.centre, CENTRE, atol=1e-12)
    np.testing.assert_allclose(arc.radii, [RADIUS, RADIUS], rtol=1e-12)
    # from (40, 0) mm to (0, 40) mm: a quarter turn counter-clockwise (y up)
    np.testing.assert_allclose(arc.point([0.0, 1.0]), [[0.04, 0.0], [0.0, 0.04]], atol=1e-12)
    assert abs(abs(arc.sweep) - math.pi / 2) < 1e-12


def test_edge_curve_marks_exactly_the_pieces(sheet):
    p = sheet
    ec = p.edge_curve
    assert ec.shape == (p.n_edges,)
    ic = next(i for i, c in enumerate(p.curves) if c.kind == "bezier")
    ia = 1 - ic
    # every valley edge is a piece of the cubic, every mountain one of the arc, nothing else
    np.testing.assert_array_equal(ec == ic, p.assignment == "V")
    np.testing.assert_array_equal(ec == ia, p.assignment == "M")
    # the marked edges are the reader's pieces (two collinear ones at the cubic's inflection
    # may be one edge): their ends are the pieces' ends and their lengths add up to the pieces'
    d = svg_drawing(SHEET)
    size = float(np.ptp(d.segments.reshape(-1, 2), axis=0).max())  # px (svgelements' mm)
    for i, c in enumerate(p.curves):
        px = next(x for x in d.curves if x.kind == c.kind)
        cp = discretise(px, chord=1e-3 * size, length=0.05 * size, shortest=2e-3 * size)
        cp = (cp - [0.0, -size]) * d.unit  # px (y up) -> m, lower-left at the origin
        E = p.edges[ec == i]
        assert len(cp) - 1 - 1 <= len(E) <= len(cp) - 1 and len(E) > 8
        ends = p.flat[np.unique(E)]
        assert np.linalg.norm(ends[:, None] - cp[None], axis=2).min(axis=1).max() < 1e-12
        total = np.linalg.norm(p.flat[E[:, 0]] - p.flat[E[:, 1]], axis=1).sum()
        assert total == pytest.approx(np.linalg.norm(np.diff(cp, axis=0), axis=1).sum(), rel=1e-9)
    # the piece ends lie on their curve
    for i, c in enumerate(p.curves):
        v = np.unique(p.edges[ec == i])
        dense = c.point(np.linspace(0, 1, 20001))
        gap = np.linalg.norm(p.flat[v][:, None] - dense[None], axis=2).min(axis=1)
        assert gap.max() < 1e-5 * 0.1  # 1e-5 of the sheet (the dense sampling's own gap)


def test_fold_round_trip_keeps_the_curves(sheet, tmp_path):
    from holofold.geometry.fold_io import export_fold, load_fold

    text = export_fold(sheet)
    d = json.loads(text)
    assert len(d["holofold:curves"]) == 2
    arc = next(c for c in d["holofold:curves"] if c["kind"] == "arc")
    assert arc["assignment"] == "M" and abs(abs(arc["sweep"]) - 90.0) < 1e-9  # degrees
    back = load_fold(text)
    np.testing.assert_array_equal(back.edge_curve, sheet.edge_curve)
    for a, b in zip(sheet.curves, back.curves, strict=True):
        assert (a.kind, a.assignment, a.fold_angle) == (b.kind, b.assignment, b.fold_angle)
        for f in ("points", "centre", "radii", "rotation", "start", "sweep"):
            x, y = np.asarray(getattr(a, f), float), np.asarray(getattr(b, f), float)
            np.testing.assert_allclose(y, x, rtol=1e-12, atol=1e-15)
    # the registry's reader (FOLD files as other tools write them) keeps them too
    from holofold.geometry import read_pattern

    f = tmp_path / "sheet.fold"
    f.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        again = read_pattern(f)
    assert len(again.curves) == 2
    np.testing.assert_array_equal(again.edge_curve, sheet.edge_curve)


def test_fold_reader_refuses_a_bad_curve_record(sheet):
    from holofold.geometry.errors import FormatError
    from holofold.geometry.fold_io import fold_dict, load_fold

    d = fold_dict(sheet)
    d["holofold:curves"][0]["edges"] = [10**6]
    with pytest.raises(FormatError, match=r"holofold:curves\[0\]\.edges"):
        load_fold(d)
    d = fold_dict(sheet)
    d["holofold:curves"][1]["kind"] = "spiral"
    with pytest.raises(FormatError, match="allowed: bezier, arc"):
        load_fold(d)


def test_edits_that_rebuild_edges_drop_the_curves_with_a_warning(sheet):
    from dataclasses import replace

    with pytest.warns(UserWarning, match="2 curve\\(s\\) dropped: the flat layout"):
        half = replace(sheet, coords=sheet.coords * 0.5, flat=sheet.flat * 0.5)
    assert half.curves == () and half.edge_curve is None
    moved = replace(sheet, coords=sheet.coords.copy())  # same edges and layout: kept
    assert len(moved.curves) == 2


def _svg_paths(text):
    import xml.etree.ElementTree as ET

    return [el for el in ET.fromstring(text).iter() if el.tag.endswith("path")]


@pytest.mark.parametrize("profile", ["origami-simulator", "cricut"])
def test_svg_cutter_file_draws_the_arc_as_an_arc(sheet, profile):
    import re

    from holofold.geometry.svg import export_svg

    text = export_svg(sheet, profile=profile, margin_mm=5.0, legend=False)
    curved = [el for el in _svg_paths(text) if el.get("data-edges")]
    assert len(curved) == 2
    arcs = [el.get("d") for el in curved if " A " in el.get("d")]
    cubics = [el.get("d") for el in curved if " C " in el.get("d")]
    assert len(arcs) == 1 and len(cubics) == 1
    # page: x + 5 mm, y down from the top (100 mm sheet + 5 mm margin)
    nums = [float(v) for v in re.findall(r"-?\d+\.\d+", arcs[0])]
    if profile == "origami-simulator":  # whole: from (40, 0) to (0, 40) mm, radius 40
        x0, y0, rx, ry, x1, y1 = nums[0], nums[1], nums[2], nums[3], *nums[-2:]
        np.testing.assert_allclose([x0, y0, x1, y1], [45, 105, 5, 65], rtol=1e-9)
        np.testing.assert_allclose([rx, ry], [40, 40], rtol=1e-9)
        # no straight <line> stands in for a piece of a curve
        n_lines = text.count("<line ")
        assert n_lines == int((sheet.assignment != "J").sum() - (sheet.edge_curve >= 0).sum())
    else:  # 1 mm clear of both ends, on the circle
        x0, y0, x1, y1 = nums[0], nums[1], *nums[-2:]
        for x, y in ((x0, y0), (x1, y1)):
            assert math.hypot(x - 5, y - 105) == pytest.approx(40, rel=1e-9)
        assert math.hypot(x0 - 45, y0 - 105) == pytest.approx(1.0, rel=1e-3)


@pytest.mark.processes
def test_svg_cutter_file_renders(sheet, tmp_path):
    import shutil
    import subprocess

    from holofold.geometry.svg import export_svg

    exe = shutil.which("rsvg-convert")
    if exe is None:
        pytest.skip("rsvg-convert is not installed")
    f = tmp_path / "sheet.svg"
    f.write_text(export_svg(sheet))
    png = tmp_path / "sheet.png"
    subprocess.run([exe, "-w", "200", "-b", "white", str(f), "-o", str(png)], check=True,
                   timeout=60)  # fmt: skip
    assert png.stat().st_size > 0


RABBIT_JS = r"""
// The whole FOLD file (extension keys and all) through Rabbit Ear: valid, the keys kept.
const ear = require("rabbit-ear");
const fs = require("fs");
const fold = JSON.parse(fs.readFileSync(process.argv[2], "utf8"));
const g = JSON.parse(JSON.stringify(fold));
delete g.file_frames;
const graph = ear.graph(JSON.parse(JSON.stringify(fold)));
process.stdout.write(JSON.stringify({
  summary: ear.graph.validate(g).summary,
  kept: Object.keys(JSON.parse(JSON.stringify(graph))).filter((k) => k.startsWith("holofold:")),
}));
"""


@pytest.mark.slow
@pytest.mark.processes
def test_rabbit_ear_accepts_the_fold_file_with_curves(sheet, tmp_path):
    import os
    import shutil
    import subprocess
    from pathlib import Path

    from holofold.geometry.fold_io import export_fold

    sys_cache = os.environ.get("HOLOFOLD_NODE_CACHE", Path.home() / ".cache" / "holofold-node")
    mods = Path(sys_cache) / "node_modules"
    if shutil.which("node") is None or not (mods / "rabbit-ear" / "package.json").is_file():
        pytest.skip("Rabbit Ear is not installed (tests/test_real_clients.py installs it)")
    f = tmp_path / "sheet.fold"
    f.write_text(export_fold(sheet))
    js = tmp_path / "check.js"
    js.write_text(RABBIT_JS)
    run = subprocess.run(["node", str(js), str(f)], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "NODE_PATH": str(mods)})  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    out = json.loads(run.stdout)
    assert out["summary"] == "valid"
    assert "holofold:curves" in out["kept"]


def test_dxf_cutter_file_has_arc_and_spline(sheet):
    import io

    ezdxf = pytest.importorskip("ezdxf")
    from ezdxf import recover

    from holofold.geometry.dxf import export_dxf

    text = export_dxf(sheet, margin_mm=5.0)
    doc, auditor = recover.read(io.BytesIO(text.encode()))
    assert not auditor.has_errors
    msp = doc.modelspace()
    arcs, splines = msp.query("ARC"), msp.query("SPLINE")
    assert len(arcs) == 1 and len(splines) == 1
    a = arcs[0]
    # the DXF is y up in mm with the page's margin: the corner at (5, 5)
    np.testing.assert_allclose(list(a.dxf.center)[:2], [5, 5], atol=1e-9)
    assert a.dxf.radius == pytest.approx(40, rel=1e-9)
    assert {round(a.dxf.start_angle % 360, 9), round(a.dxf.end_angle % 360, 9)} == {0.0, 90.0}
    sp = splines[0]
    assert sp.dxf.degree == 3
    np.testing.assert_allclose(
        np.array(sp.control_points)[:, :2], CUBIC / MM + 5, rtol=0, atol=1e-9
    )
    # the curve pieces are not also drawn as LINEs: only the border's pieces stay straight (the
    # 4 sides cut at the 4 curve ends and at the Steiner points where the rulings between the
    # cubic and the top border end): together the 400 mm outline once
    lines = msp.query("LINE")
    assert len(lines) == (sheet.assignment == "B").sum() >= 8
    length = sum(math.dist(tuple(ln.dxf.start)[:2], tuple(ln.dxf.end)[:2]) for ln in lines)
    assert length == pytest.approx(400.0, rel=1e-9)
    del ezdxf


# a spiral tip drawn as a chain of Bezier pieces each shorter than the merge tolerance
# (Origami Simulator's HexSpiralTess: it read as 7 panels, the curls dropped piece by piece)
def _curl_sheet(n=12):
    # a mountain from the left edge to the sheet's centre, ending in n tiny cubics of 1.2 px
    # (the merge tolerance is 2e-3 x 1000 = 2 px); a valley from the centre to the right edge
    d = "M 0 500 C 150 450 350 550 494 500"
    x = 494.0
    for k in range(n):
        d += f" c 0.3 {0.2 * (-1) ** k} 0.9 {0.2 * (-1) ** k} 1.2 0"
        x += 1.2
    body = (
        '<path d="M 0 0 H 1000 V 1000 H 0 Z" stroke="#000000" fill="none"/>'
        f'<path d="{d}" stroke="#ff0000" fill="none"/>'
        f'<path d="M {x:.1f} 500 C 600 400 800 600 1000 500" stroke="#0000ff" fill="none"/>'
        '<path d="M 500 0 L 500 500" stroke="#0000ff" fill="none"/>'
    )
    return (
        '<svg xmlns="http://www.w3.org/2000/svg" width="1000mm" height="1000mm" '
        f'viewBox="0 0 1000 1000">{body}</svg>'
    ).encode()


def test_a_chain_of_pieces_shorter_than_the_tolerance_keeps_its_faces():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = read_svg_pattern(_curl_sheet(), split="none")
    notes = [str(w.message) for w in caught]
    # the creases divide the sheet into 3 panels (above, below-left, below-right ... ) and the
    # curl is contracted to one vertex with a line saying so; nothing dangling was dropped
    assert p.n_faces == 3
    assert any("contracted" in n for n in notes)
    assert any("apart (more than twice the merge tolerance" in n for n in notes)
    assert not any("dangling" in n for n in notes)


def test_a_smaller_tolerance_keeps_the_curl_itself():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = read_svg_pattern(_curl_sheet(), split="none", tol=0.05)
    assert p.n_faces == 3
    assert not any("contracted" in str(w.message) for w in caught)
    # the curl's 12 pieces (no finer than the merge tolerance allows) are edges of the pattern
    assert (p.edge_curve >= 0).sum() >= 12 + 2


def _dxf_sheet() -> bytes:
    import io

    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new("R2010", units=4)  # mm
    msp = doc.modelspace()
    for a, b in (((0, 0), (100, 0)), ((100, 0), (100, 100)), ((100, 100), (0, 100)),
                 ((0, 100), (0, 0))):  # fmt: skip
        msp.add_line(a, b, dxfattribs={"layer": "BOUNDARY"})
    msp.add_arc((0, 0), 40, 0, 90, dxfattribs={"layer": "SCORE_M"})
    msp.add_open_spline(CUBIC / MM, degree=3, dxfattribs={"layer": "SCORE_V"})
    msp.add_ellipse((100, 0), (30, 0), 0.5, math.pi / 2, math.pi, dxfattribs={"layer": "SCORE_V"})
    s = io.StringIO()
    doc.write(s)
    return s.getvalue().encode()


def test_dxf_reader_keeps_arcs_ellipses_and_splines_as_curves():
    from ezdxf import path as ezpath

    from holofold.geometry.dxf_reader import dxf_drawing, read_dxf_pattern

    data = _dxf_sheet()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PatternWarning)
        p = read_dxf_pattern(data)
    kinds = {(c.kind, c.assignment): c for c in p.curves}
    arc, cub, ell = kinds[("arc", "M")], kinds[("bezier", "V")], kinds[("arc", "V")]
    np.testing.assert_allclose(arc.centre, CENTRE, atol=1e-15)
    np.testing.assert_allclose(arc.radii, [RADIUS, RADIUS], rtol=1e-12)
    np.testing.assert_allclose(arc.point([0.0, 1.0]), [[0.04, 0.0], [0.0, 0.04]], atol=1e-15)
    np.testing.assert_allclose(np.array(cub.points), CUBIC, rtol=1e-12)
    np.testing.assert_allclose(ell.point([0.0, 1.0]), [[0.1, 0.015], [0.07, 0.0]], atol=1e-15)
    for c in range(3):  # every curve has pieces; no straight crease is marked
        assert (p.edge_curve == c).sum() > 4
    assert not (p.edge_curve[p.assignment == "B"] >= 0).any()
    # the pieces follow the old flattening (ezdxf's, 1e-3 of each curve's extent) within the
    # two tolerances: 1e-3 of the drawing (0.1 mm) plus the old 1e-3 x extent
    import ezdxf

    doc = ezdxf.read(__import__("io").StringIO(data.decode()))
    d = dxf_drawing(data)
    for e in doc.modelspace():
        if e.dxftype() == "LINE":
            continue
        pth = ezpath.make_path(e)
        ext = float(np.ptp(np.array([(v.x, v.y) for v in pth.control_vertices()]), axis=0).max())
        old = np.array([(v.x, v.y) for v in pth.flattening(distance=1e-3 * ext)])
        S = d.segments[d.assignment == ("M" if e.dxftype() == "ARC" else "V")]
        a, u = S[:, 0], S[:, 1] - S[:, 0]
        w = old[:, None] - a[None]
        t = np.clip(np.einsum("psj,sj->ps", w, u) / np.einsum("sj,sj->s", u, u), 0, 1)
        near = np.linalg.norm(w - t[..., None] * u, axis=2).min(axis=1)  # to the pieces
        mine = near[near < 5]  # the other valley curve's points are far away
        assert mine.size > 0.9 * len(old) and mine.max() < 0.1 + 1e-3 * ext


def test_dxf_cutter_file_reads_back_with_its_curves(sheet):
    pytest.importorskip("ezdxf")
    from holofold.geometry.dxf import export_dxf
    from holofold.geometry.dxf_reader import read_dxf_pattern

    text = export_dxf(sheet, margin_mm=5.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PatternWarning)
        back = read_dxf_pattern(text.encode())
    # the outline is on CUT (a cut on the outline is its border); lower-left at the origin
    arc = next(c for c in back.curves if c.kind == "arc")
    cub = next(c for c in back.curves if c.kind == "bezier")
    np.testing.assert_allclose(arc.radii, [RADIUS, RADIUS], rtol=1e-9)
    np.testing.assert_allclose(arc.centre, CENTRE, atol=1e-12)
    np.testing.assert_allclose(np.array(cub.points), CUBIC, atol=1e-12)
    assert back.n_faces == sheet.n_faces


def test_short_straight_lines_are_dropped_as_before():
    import re

    # the curl drawn with straight lines: a straight file reads as it always did (dropped,
    # with the note; the pieces that hung from them dangle and go, named too)
    text = _curl_sheet().decode()
    text = text.replace(" c 0.3 0.2 0.9 0.2 1.2 0", " l 1.2 0").replace(
        " c 0.3 -0.2 0.9 -0.2 1.2 0", " l 1.2 0"
    )
    text = text.replace("C 150 450 350 550 494 500", "L 494 500").replace(
        "C 600 400 800 600 1000 500", "L 1000 500"
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = read_svg_pattern(text.encode(), split="none")
    notes = [str(w.message) for w in caught]
    assert any(
        re.search(r"12 line\(s\) shorter than the merge tolerance .* dropped", n) for n in notes
    )
    assert not any("contracted" in n for n in notes)
    assert any("dangling" in n for n in notes)
    assert p.n_faces == 1  # the creases all dangle: the sheet is one panel (as on main)


@pytest.mark.parametrize(
    "profile, side, bound",
    [("origami-simulator", "both", 0.11), ("origami-simulator", "back", 0.11),
     ("laser", "both", 1.6), ("laser", "front", 1.6)],
)  # fmt: skip
def test_page_curves_follow_their_chords(sheet, profile, side, bound):
    """Each drawn part of a curve (whole, dashed, or on the mirrored back face) lies on the
    chords of the pieces it stands for: within the discretisation's chord deviation (0.1 mm
    here) when whole; dashed, within a dash gap (1.5 mm) of the nearest chord dash."""
    from holofold.geometry.cutter import FACE_ROLES, cutter_drawing

    draw = cutter_drawing(sheet, profile, side=side)
    assert set(draw.curves) == {"mountain", "valley"} & set(FACE_ROLES[side])
    for role, entries in draw.curves.items():
        segs, owner = draw.lines[role], draw.edges[role]
        for parts, ids in entries:
            S = segs[np.isin(owner, ids)]
            a, u = S[:, 0], S[:, 1] - S[:, 0]
            for cv in parts:
                q = cv.point(np.linspace(0, 1, 33))
                w = q[:, None] - a[None]
                t = np.clip(np.einsum("psj,sj->ps", w, u) / np.einsum("sj,sj->s", u, u), 0, 1)
                gap = np.linalg.norm(w - t[..., None] * u, axis=2).min(axis=1)
                assert gap.max() < bound


def test_an_elliptic_arc_goes_to_dxf_as_an_ellipse_and_back():
    pytest.importorskip("ezdxf")
    import io

    from ezdxf import recover

    from holofold.geometry.dxf import export_dxf
    from holofold.geometry.dxf_reader import read_dxf_pattern

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PatternWarning)
        p = read_dxf_pattern(_dxf_sheet())
        text = export_dxf(p, margin_mm=5.0)
        back = read_dxf_pattern(text.encode())
    doc, auditor = recover.read(io.BytesIO(text.encode()))
    assert not auditor.has_errors
    assert len(doc.modelspace().query("ELLIPSE")) == 1
    ell = next(c for c in back.curves if c.kind == "arc" and c.radii[0] != c.radii[1])
    np.testing.assert_allclose(ell.radii, [0.03, 0.015], rtol=1e-9)
    # the same quarter of the ellipse, whichever way it runs
    ends = sorted(map(tuple, np.round(ell.point([0.0, 1.0]), 12).tolist()))
    assert ends == [(0.07, 0.0), (0.1, 0.015)]


def test_load_svg_says_it_leaves_the_curve_paths_out(sheet):
    from holofold.geometry.svg import export_svg, load_svg

    with pytest.warns(UserWarning, match="2 curved crease path\\(s\\) .* not read"):
        lines = load_svg(export_svg(sheet))
    assert len(lines.segments) == int(
        (sheet.assignment != "J").sum() - (sheet.edge_curve >= 0).sum()
    )


def test_a_scaled_pattern_keeps_its_curves_scaled(sheet):
    from holofold.mechanics import scaled_pattern

    p = sheet
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no 'curves dropped' warning
        q = scaled_pattern(p, 0.5)
    assert len(q.curves) == len(p.curves) and q.edge_curve.tolist() == p.edge_curve.tolist()
    for a, b in zip(p.curves, q.curves, strict=True):
        for t in (0.0, 0.3, 1.0):
            assert np.allclose(b.point(t), 0.5 * np.asarray(a.point(t)), rtol=1e-12, atol=0)
