"""SVG crease patterns: colours, cut/score groups, y flip (no M/V swap)."""

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from holofold.geometry.errors import FormatError
from holofold.geometry.miura import miura_sheet
from holofold.geometry.svg import COLOURS, export_svg, load_svg


@pytest.fixture(scope="module")
def miura():
    return miura_sheet(3, 3, a=0.02, b=0.03, gamma=math.radians(60), ext=0.5)


def test_round_trip_keeps_coordinates_and_assignments(miura):
    lines = load_svg(export_svg(miura, margin_mm=5.0))
    order = np.argsort(lines.edge)
    assert np.array_equal(lines.edge[order], np.arange(miura.n_edges))
    # our drawing origin is the lower-left corner minus the margin
    expect = miura.flat[miura.edges] - miura.flat.min(axis=0) + 5e-3
    assert np.allclose(lines.segments[order], expect, atol=1e-9)
    assert np.array_equal(lines.assignment[order], miura.assignment)
    assert np.allclose(lines.fold_angle[order], miura.fold_angle, atol=1e-9)


def test_y_axis_is_flipped_so_mountains_stay_mountains(miura):
    """The raw SVG draws the vertex with the larger flat y higher up (smaller SVG y)."""
    root = ET.fromstring(export_svg(miura))
    ns = {"s": "http://www.w3.org/2000/svg"}
    checked = 0
    for el in root.iterfind(".//s:line", ns):
        a, b = miura.edges[int(el.get("data-edge"))]
        dy_flat = miura.flat[b, 1] - miura.flat[a, 1]
        dy_svg = float(el.get("y2")) - float(el.get("y1"))
        if abs(dy_flat) > 1e-9:
            assert np.sign(dy_svg) == -np.sign(dy_flat)
            assert abs(dy_svg) == pytest.approx(abs(dy_flat) * 1000)
            checked += 1
    assert checked > 10
    # a mirrored drawing would turn the pattern's counter-clockwise panels clockwise
    x = np.array([float(el.get("x1")) for el in root.iterfind(".//s:line", ns)])
    assert x.min() == pytest.approx(5.0)


def test_colours_opacity_and_groups(miura):
    root = ET.fromstring(export_svg(miura))
    ns = {"s": "http://www.w3.org/2000/svg"}
    cut = root.find(".//s:g[@id='cut']", ns)
    score = root.find(".//s:g[@id='score']", ns)
    assert {el.get("data-assignment") for el in cut} == {"B"}
    assert {el.get("data-assignment") for el in score} == {"M", "V"}
    for el in score:
        code = el.get("data-assignment")
        assert el.get("stroke") == COLOURS[code]
        assert float(el.get("stroke-opacity")) == pytest.approx(
            abs(float(el.get("data-foldAngle"))) / 180
        )
    assert COLOURS["M"] == "#ff0000" and COLOURS["V"] == "#0000ff"
    assert root.get("width").endswith("mm")


def test_errors(miura):
    with pytest.raises(FormatError, match="not well-formed"):
        load_svg("<svg")
    with pytest.raises(FormatError, match="no <line>"):
        load_svg('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 1 1"></svg>')
    from dataclasses import replace

    with pytest.raises(ValueError, match="no flat layout"):
        export_svg(replace(miura, flat=None))


def test_shallow_creases_stay_visible_and_the_legend_sits_outside():
    nearly_flat = miura_sheet(3, 3, a=0.02, b=0.03, gamma=math.radians(60), ext=0.99)
    text = export_svg(nearly_flat)
    root = ET.fromstring(text)
    ns = {"s": "http://www.w3.org/2000/svg"}
    score = root.find(".//s:g[@id='score']", ns)
    angles = np.array([abs(float(el.get("data-foldAngle"))) for el in score])
    opacity = np.array([float(el.get("stroke-opacity")) for el in score])
    assert angles.max() < 40  # |angle| / 180 alone would be < 0.22: barely visible
    np.testing.assert_allclose(opacity, np.maximum(angles / 180, 0.3), rtol=1e-5)
    legend = root.find(".//s:g[@id='legend']", ns)
    labels = [t.text for t in legend.iterfind("s:text", ns)]
    assert labels[:4] == ["mountain", "valley", "cut", "boundary"]
    samples = [el.get("stroke") for el in legend.iterfind("s:path", ns)]
    assert samples == [COLOURS[c] for c in "MVCB"]
    legend_y = [float(t.get("y")) for t in legend.iterfind("s:text", ns)]
    line_y = [float(el.get(k)) for el in root.iterfind(".//s:line", ns) for k in ("y1", "y2")]
    assert max(legend_y) < min(line_y)  # above the pattern, not on it
    width = float(root.get("viewBox").split()[2])
    assert all(float(t.get("x")) < width for t in legend.iterfind("s:text", ns))
    # reading back ignores the legend and keeps the exact angles
    lines = load_svg(text)
    assert len(lines.edge) == nearly_flat.n_edges
    order = np.argsort(lines.edge)
    np.testing.assert_allclose(lines.fold_angle[order], nearly_flat.fold_angle, atol=1e-9)
    plain = ET.fromstring(export_svg(nearly_flat, min_opacity=0.0, legend=False))
    assert plain.find(".//s:g[@id='legend']", ns) is None
    enc = [float(el.get("stroke-opacity")) for el in plain.find(".//s:g[@id='score']", ns)]
    np.testing.assert_allclose(enc, angles / 180, rtol=1e-5)  # the plain encoding (6 digits)
    with pytest.raises(ValueError, match="min_opacity"):
        export_svg(nearly_flat, min_opacity=2.0)
