"""Cutter profiles: the flat pattern's SVG and DXF for Origami Simulator, lasers and Cricuts."""

from __future__ import annotations

import io
import math
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from holofold.fitting import fit_strip
from holofold.geometry import (
    DXF_LAYERS,
    PROFILES,
    CutterOptions,
    ParameterError,
    export,
    export_dxf,
    export_svg,
    miura_sheet,
)
from holofold.geometry.cutter import cutter_drawing, dashes

NS = {"s": "http://www.w3.org/2000/svg"}
INK = "{http://www.inkscape.org/namespaces/inkscape}"


@pytest.fixture(scope="module")
def miura():
    """The README's printable Miura sheet: 4 x 4, 20 mm panels, 60 degrees."""
    return miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)


@pytest.fixture(scope="module")
def strip():
    """A fitted arch strip's development (the flat pattern of the fit)."""
    return fit_strip("half-circle", 8, 0.2, 0.02, 0.1).flat_pattern


def _paths(svg: str) -> dict[str, list]:
    """Layer id -> [(role, edge, stroke, width, segments (k, 2, 2))] of a cutter SVG."""
    root = ET.fromstring(svg)
    out = {}
    for g in root.findall("s:g", NS):
        assert g.get(f"{INK}groupmode") == "layer" and g.get(f"{INK}label") == g.get("id")
        items = []
        for p in g.findall("s:path", NS):
            nums = [float(v) for v in re.findall(r"-?\d+\.?\d*", p.get("d"))]
            d = p.get("d")
            if d.endswith("Z"):  # a registration hole
                segs = np.array(nums).reshape(-1, 2)
            else:
                segs = np.array(nums).reshape(-1, 2, 2)
            items.append((p.get("data-role"), int(p.get("data-edge", "-1")), p.get("stroke"),
                          float(p.get("stroke-width")), segs))  # fmt: skip
        out[g.get("id")] = items
    return out


def _page(pattern, draw):
    """Vertex positions on the page (mm, y down) as cutter_drawing lays them out."""
    xy = pattern.flat * 1000
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    margin = (draw.width - (hi - lo)[0]) / 2
    return np.column_stack([xy[:, 0] - lo[0] + margin, hi[1] - xy[:, 1] + margin + draw.top])


def test_dashes_stop_short_of_both_ends():
    p0, p1 = np.array([0.0, 0.0]), np.array([20.0, 0.0])
    d = dashes(p0, p1, 3.0, 1.5, (1.5, 1.5))
    assert d[0, 0, 0] == pytest.approx(1.5) and d[-1, 1, 0] == pytest.approx(18.5)
    on = d[:, 1, 0] - d[:, 0, 0]
    off = d[1:, 0, 0] - d[:-1, 1, 0]
    np.testing.assert_allclose(off, 1.5)  # gaps exact, dashes stretched to fit
    assert len(d) == 4 and np.allclose(on, 3.125)  # 4 x 3.125 + 3 x 1.5 = 17 mm
    whole = dashes(p0, p1, 0.0, 0.0, (1.0, 1.0))
    np.testing.assert_allclose(whole, [[[1, 0], [19, 0]]])
    assert len(dashes(p0, p1, 3.0, 1.5, (10.0, 10.0))) == 0  # nothing left between the gaps


@pytest.mark.parametrize("which", ["miura", "strip"])
def test_laser_svg_layers_colours_hairlines_and_gaps(which, request):
    pattern = request.getfixturevalue(which)
    svg = export_svg(pattern, profile="laser")
    assert "<text" not in svg  # a driver would cut or engrave it
    layers = _paths(svg)
    assert list(layers) == ["cut", "score-mountain", "score-valley"]
    want = {"cut": "#ff0000", "score-mountain": "#0000ff", "score-valley": "#00ff00"}
    role_of = {"M": "mountain", "V": "valley", "B": "boundary"}
    draw = cutter_drawing(pattern, "laser")
    P = _page(pattern, draw)
    seen = set()
    for layer, items in layers.items():
        for role, e, stroke, width, segs in items:
            assert stroke == want[layer] and width <= 0.09  # vector cuts need hairlines
            assert role == role_of[str(pattern.assignment[e])]
            a, b = P[pattern.edges[e]]
            L = np.linalg.norm(b - a)
            u = (b - a) / L
            t = (segs - a) @ u  # along the edge, mm
            off = np.abs((segs - a) @ np.array([-u[1], u[0]]))
            assert off.max() < 1e-3  # on the crease line
            if role == "boundary":
                np.testing.assert_allclose(np.sort(t.ravel()), [0, L], atol=1e-3)
            else:  # dashes, 1.5 mm clear of both vertices
                assert t.min() == pytest.approx(1.5, abs=1e-3)
                assert t.max() == pytest.approx(L - 1.5, abs=1e-3)
                assert len(segs) >= 2 and np.all(np.diff(t.ravel()) > -1e-9)
            seen.add(e)
    assert seen == set(np.flatnonzero(np.isin(pattern.assignment, ["M", "V", "B"])))


def test_two_faces_mirror_and_register(miura):
    one = _paths(export_svg(miura, profile="laser"))
    front = _paths(export_svg(miura, profile="laser", side="front"))
    back = _paths(export_svg(miura, profile="laser", side="back"))
    assert set(front) == {"score-mountain", "registration"}
    assert set(back) == {"cut", "score-valley", "registration"}
    w = cutter_drawing(miura, "laser", side="back").width
    # the back's valleys are the one-file valleys mirrored about the page's vertical axis,
    # both drawn with a margin of at least 8 mm for the holes
    shift = 8.0 - 5.0
    ref = {e: s + shift for _, e, _, _, s in one["score-valley"]}
    for _, e, _, _, segs in back["score-valley"]:
        mirrored = segs.copy()
        mirrored[..., 0] = w - mirrored[..., 0]
        np.testing.assert_allclose(mirrored, ref[e], atol=1e-3)
    holes_f = np.array([s.mean(axis=0) for *_, s in front["registration"]])
    holes_b = np.array([s.mean(axis=0) for *_, s in back["registration"]])
    np.testing.assert_allclose(holes_f, holes_b, atol=1e-3)  # the same pins, after the flip
    mirrored = holes_f.copy()
    mirrored[:, 0] = w - mirrored[:, 0]
    np.testing.assert_allclose(np.sort(mirrored, axis=0), np.sort(holes_f, axis=0), atol=1e-3)
    assert len(holes_f) == 3 and len(set(np.round(holes_f[:, 1], 3))) == 2  # a wrong flip shows


def test_cricut_profile(miura):
    svg = export_svg(miura, profile="cricut")
    layers = _paths(svg)
    assert "<text" not in svg and list(layers) == ["cut", "score-mountain", "score-valley"]
    for _, _, stroke, _, segs in layers["score-mountain"]:
        assert stroke == PROFILES["cricut"].strokes["mountain"].colour and len(segs) == 1
    assert {s for _, _, s, _, _ in layers["cut"]} == {"#000000"}


def test_simulator_profile_is_the_default_and_refuses_dashes(miura):
    assert export_svg(miura) == export_svg(miura, profile="origami-simulator")
    with pytest.raises(ParameterError, match="origami-simulator profile draws creases whole"):
        export_svg(miura, dash=2.0)
    with pytest.raises(ParameterError, match="no text"):
        export_svg(miura, profile="laser", legend=True)
    with pytest.raises(ParameterError, match="unknown cutter profile 'plotter'"):
        CutterOptions("plotter")
    with pytest.raises(ParameterError, match="two faces"):
        CutterOptions(two_sided=True)


@pytest.mark.parametrize("which", ["miura", "strip"])
def test_dxf_reads_back_with_layers_and_dashes(which, request, tmp_path):
    import ezdxf

    pattern = request.getfixturevalue(which)
    path = export(pattern, tmp_path / "p.dxf", profile="laser")
    doc = ezdxf.readfile(path)
    assert doc.header["$INSUNITS"] == 4  # millimetres
    names = {layer.dxf.name for layer in doc.layers}
    assert set(DXF_LAYERS.values()) <= names
    assert doc.layers.get("CUT").color == 1 and doc.layers.get("SCORE_M").color == 5
    assert doc.layers.get("SCORE_V").rgb == (0, 255, 0)
    lines = {}
    for e in doc.modelspace().query("LINE"):
        lines.setdefault(e.dxf.layer, []).append([[e.dxf.start.x, e.dxf.start.y],
                                                  [e.dxf.end.x, e.dxf.end.y]])  # fmt: skip
    draw = cutter_drawing(pattern, "laser")
    assert "BOUNDARY" not in lines  # the outline is cut: on CUT (the patterns have no cuts)
    for role, layer in (("boundary", "CUT"), ("mountain", "SCORE_M"), ("valley", "SCORE_V")):
        got = np.array(lines[layer])
        want = draw.lines[role].copy()
        want[..., 1] = draw.height - want[..., 1]  # DXF's y points up
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, atol=1e-9)
    # the outline closes: every boundary end point is shared by two boundary lines (in mm)
    ends = np.round(np.array(lines["CUT"]).reshape(-1, 2), 6)
    _, counts = np.unique(ends, axis=0, return_counts=True)
    assert (counts == 2).all()
    assert not list(doc.modelspace().query("TEXT MTEXT"))


def test_dxf_simulator_profile_has_whole_creases(miura):
    import ezdxf

    doc = ezdxf.read(io.StringIO(export_dxf(miura)))
    by_layer = {}
    for e in doc.modelspace().query("LINE"):
        by_layer[e.dxf.layer] = by_layer.get(e.dxf.layer, 0) + 1
    count = {c: int((miura.assignment == c).sum()) for c in "MVB"}
    assert by_layer == {"SCORE_M": count["M"], "SCORE_V": count["V"], "CUT": count["B"]}


def _render(svg_path, png_path, dpi: int) -> np.ndarray:
    subprocess.run(
        ["rsvg-convert", "-d", str(dpi), "-p", str(dpi), "-b", "white", str(svg_path),
         "-o", str(png_path)], check=True,
    )  # fmt: skip
    import matplotlib.image as mpimg

    return mpimg.imread(png_path)[..., :3]


@pytest.mark.skipif(shutil.which("rsvg-convert") is None, reason="rsvg-convert not installed "
                    "(Debian: apt-get install librsvg2-bin; .ci/run installs it)")  # fmt: skip
@pytest.mark.parametrize("which", ["miura", "strip"])
def test_laser_svg_renders_with_librsvg(which, request, tmp_path):
    """librsvg draws the hairlines in their colours: red cuts, blue and green scores, no
    black (no text, nothing to engrave). The 8 m strip is drawn at 1/40 (a 0.01 mm hairline
    vanishes at the resolution an 8 m page allows)."""
    from dataclasses import replace

    pattern = request.getfixturevalue(which)
    if which == "strip":
        pattern = replace(pattern, coords=pattern.coords / 40, flat=pattern.flat / 40)
    svg = tmp_path / "p.svg"
    svg.write_text(export_svg(pattern, profile="laser"))
    draw = cutter_drawing(pattern, "laser")
    dpi = int(min(1000, 6000 / max(draw.width, draw.height) * 25.4))
    img = _render(svg, tmp_path / "p.png", dpi)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]

    def tinted(c, o1, o2):
        return int(((c - np.maximum(o1, o2)) > 0.02).sum())

    red, blue, green = tinted(r, g, b), tinted(b, r, g), tinted(g, r, b)
    assert red > 100 and blue > 100 and green > 100, (red, blue, green)
    assert (img.max(axis=2) < 0.3).sum() == 0  # nothing dark: no text, no black lines
    # the two-sided back face renders too, with its registration holes
    back = tmp_path / "b.svg"
    back.write_text(export_svg(pattern, profile="laser", side="back"))
    img = _render(back, tmp_path / "b.png", dpi)
    assert tinted(img[..., 1], img[..., 0], img[..., 2]) > 100


def test_dxf_round_trip_through_the_reader(miura, tmp_path):
    """The origami-simulator profile's DXF (whole creases) reads back with holofold's DXF reader
    to the same pattern: vertices (mm -> m, to 1e-9 m), edges and assignments."""
    from holofold.geometry.readers import read_pattern

    back = read_pattern(export(miura, tmp_path / "p.dxf"))
    assert (back.n_vertices, back.n_edges, back.n_faces) == (25, 40, 16)
    # the drawing sits on the page with a margin: compare after removing the offset
    a = miura.flat - miura.flat.min(axis=0)
    b = back.flat - back.flat.min(axis=0)
    order_a = np.lexsort(np.round(a, 6).T)
    order_b = np.lexsort(np.round(b, 6).T)
    np.testing.assert_allclose(b[order_b], a[order_a], atol=1e-9)
    for code in "MVB":
        assert (back.assignment == code).sum() == (miura.assignment == code).sum()


def test_dxf_is_the_same_bytes_every_time(miura):
    import ezdxf

    assert export_dxf(miura, profile="laser") == export_dxf(miura, profile="laser")
    assert ezdxf.options.write_fixed_meta_data_for_testing is False  # restored
