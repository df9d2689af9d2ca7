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
