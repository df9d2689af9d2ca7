"""The flat printable part: panels joined by hinge strips, one watertight body, exact volume."""

import io
import math

import numpy as np
import pytest
import trimesh

from holofold.fitting import fit_strip
from holofold.geometry import (
    DegenerateGeometryError,
    InvalidPatternError,
    ParameterError,
    folded_printable_solid,
    miura_sheet,
    printable_layout,
    printable_solid,
)
from holofold.geometry.mesh import export_mesh
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.solid import shrunk_panels

TP, TC, W = 2e-3, 0.6e-3, 2e-3


def _area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _flat_area(p):
    return sum(_area(p.flat[f]) for f in p.faces)


def _as_flat_3d(p):
    return p.with_coords(np.column_stack([p.flat, np.zeros(p.n_vertices)]), measure=False)


SHEETS = {
    "miura": lambda: miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6),
    "arch": lambda: fit_strip("half-circle", 12, 0.2, 0.02, 0.1).flat_pattern,
}


@pytest.mark.parametrize("name", sorted(SHEETS))
def test_one_watertight_body_with_the_volume_of_panels_and_hinges(name):
    p = SHEETS[name]()
    part = printable_solid(p, TP, TC, W)
    lay = part.metadata["layout"]
    assert part.is_watertight and part.is_volume and part.body_count == 1
    assert part.volume == pytest.approx(lay.volume(TP, TC), rel=1e-6)
    assert abs(part.volume / lay.volume(TP, TC) - 1) < 1e-9  # double precision throughout
    # the regions tile the sheet exactly: nothing sticks out, nothing is missing
    assert lay.panel_area + lay.hinge_area == pytest.approx(_flat_area(p), rel=1e-12)
    # the panels are those of the compliant-crease model (pulled back by W/2 in the plane)
    expected = sum(_area(c[:, :2]) for c in shrunk_panels(_as_flat_3d(p), W))
    assert lay.panel_area == pytest.approx(expected, rel=1e-12)
    # one strip per fold line, W wide: its panel-1 side is W from its panel-2 side
    folds = np.flatnonzero(p.interior & np.isin(p.assignment, ("M", "V", "F", "U")))
    assert np.array_equal(np.unique(lay.hinge_edges), folds)
    quads = np.array([h for h in lay.hinges if len(h) == 4])
    d = quads[:, 2] - quads[:, 3]
    off = quads[:, 0] - quads[:, 3]
    dist = np.abs(d[:, 0] * off[:, 1] - d[:, 1] * off[:, 0]) / np.linalg.norm(d, axis=1)
    np.testing.assert_allclose(dist, W, rtol=1e-9)
    np.testing.assert_allclose(part.bounds[:, 2], [0.0, TP], atol=1e-12)  # flat on the bed


def test_stl_round_trip_in_mm_keeps_the_volume():
    p = SHEETS["miura"]()
    part = printable_solid(p, TP, TC, W)
    back = trimesh.load(io.BytesIO(export_mesh(part, "stl")), file_type="stl")
    assert back.is_watertight
    assert back.volume == pytest.approx(part.volume * 1e9, rel=1e-5)  # mm^3, float32 file


def test_middle_alignment_and_thick_hinges():
    p = SHEETS["miura"]()
    part = printable_solid(p, TP, TC, W, align="middle")
    np.testing.assert_allclose(part.bounds[:, 2], [-TP / 2, TP / 2], atol=1e-12)
    lay = part.metadata["layout"]
    assert part.volume == pytest.approx(lay.volume(TP, TC), rel=1e-9)
    thick_hinge = printable_solid(p, TC, TP, W)  # hinges thicker than panels: still one body
    assert thick_hinge.volume == pytest.approx(lay.volume(TC, TP), rel=1e-9)


def _grid(assign_cut: bool):
    """Four unit squares (mm) in a 2 x 2 grid; the edge between the two top squares is a cut."""
    xy = np.array([[x, y] for y in range(3) for x in range(3)], float) * 1e-2
    faces = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]
    p = CreasePattern.from_faces(xy, faces, flat=xy)
    asg = p.assignment.copy()
    asg[p.interior] = "V"
    if assign_cut:
        asg[[i for i, e in enumerate(p.edges.tolist()) if e == [4, 7]]] = "C"
    return CreasePattern(p.coords, p.faces, p.edges, asg, p.fold_angle, flat=p.flat)


def test_a_cut_is_a_gap_and_the_part_stays_connected():
    p = _grid(True)
    part = printable_solid(p, TP, TC, W, cut_width=1e-3)
    lay = part.metadata["layout"]
    assert part.body_count == 1 and part.is_watertight
    assert len(lay.hinges) == 3  # four interior edges, one of them cut
    # the two top panels are 1 mm apart across the cut (x = 10 mm +- 0.5 mm)
    left, right = lay.panels[2], lay.panels[3]
    assert left[:, 0].max() == pytest.approx(0.01 - 0.5e-3)
    assert right[:, 0].min() == pytest.approx(0.01 + 0.5e-3)
    assert len(lay.patches) == 0  # the only interior vertex is on the cut: left open
    assert lay.panel_area + lay.hinge_area == pytest.approx(4e-4 - 1e-3 * 0.01 + 0, rel=0.05)
    full = printable_solid(_grid(False), TP, TC, W).metadata["layout"]
    assert len(full.patches) == 4  # the interior vertex: four triangles of W/2 x W/2
    assert full.panel_area + full.hinge_area == pytest.approx(4e-4, rel=1e-12)


def test_joined_triangles_print_as_one_panel():
    xy = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], float) * 1e-2
    faces = [[0, 1, 2], [0, 2, 3], [1, 4, 5, 2]]
    p = CreasePattern.from_faces(xy, faces, flat=xy)
    asg = p.assignment.copy()
    asg[[i for i, e in enumerate(p.edges.tolist()) if e == [0, 2]]] = "J"
    asg[[i for i, e in enumerate(p.edges.tolist()) if e == [1, 2]]] = "M"
    p = CreasePattern(p.coords, p.faces, p.edges, asg, p.fold_angle, flat=p.flat)
    part = printable_solid(p, TP, TC, W)
    lay = part.metadata["layout"]
    assert len(lay.hinges) == 1 and part.body_count == 1
    expected = ((0.01 - W / 2) * 0.01 * 2) * TP + W * 0.01 * TC
    # where the join meets the fold, the uncut triangle keeps a sliver of W^2/8 over the hinge
    sliver = (W / 2) ** 2 / 2 * (TP - TC)
    assert part.volume == pytest.approx(expected + sliver, rel=1e-9)


def test_bad_input_is_one_clear_error():
    p = SHEETS["miura"]()
    with pytest.raises(ParameterError, match="crease_width"):
        printable_solid(p, TP, TC, 0.0)
    with pytest.raises(ParameterError, match="crease_thickness"):
        printable_solid(p, TP, -1.0, W)
    with pytest.raises(ParameterError, match="align"):
        printable_solid(p, TP, TC, W, align="top")
    with pytest.raises(ParameterError, match="wider than panel"):
        printable_solid(p, TP, TC, 0.05)
    with pytest.raises(InvalidPatternError, match="flat layout"):
        printable_layout(fit_strip("half-circle", 8, 0.2, 0.02, 0.1).pattern, W)
    two = _grid(False)
    asg = two.assignment.copy()
    asg[two.interior] = "C"  # every panel cut loose
    loose = CreasePattern(two.coords, two.faces, two.edges, asg, two.fold_angle, flat=two.flat)
    with pytest.raises(DegenerateGeometryError, match="4 separate bodies"):
        printable_solid(loose, TP, TC, W)


def test_folded_part_at_ext_1_is_the_flat_part_without_vertex_patches():
    flat = miura_sheet(3, 3, a=0.02, b=0.02, gamma=math.radians(60), ext=1.0)
    bent = folded_printable_solid(flat, TP, TC, W)
    lay = printable_layout(flat, W)
    # the folded part keeps the model's quadrilateral strips (not clipped at inward corners)
    strips = sum(_area(h[1:] if len(h) == 5 else h) for h in lay.hinges)
    assert bent.body_count == 1 and bent.is_watertight
    # to a sliver: where a run-in slab meets its panel's corner it cuts across by ~W^2 / 100
    assert bent.volume == pytest.approx(lay.panel_area * TP + strips * TC, rel=1e-5)


def test_folded_part_with_bent_hinges_is_one_body():
    p = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    bent = folded_printable_solid(p, 0.5e-3, 0.3e-3, W)
    assert bent.body_count == 1 and bent.is_watertight
    panels = sum(_area3(c) for c in shrunk_panels(p, W)) * 0.5e-3
    folds = p.interior
    hinge_max = float((p.edge_lengths[folds] * W).sum()) * 0.3e-3
    # the panels, plus bent hinges shorter than W (0.79 W at 90 degrees) and vertices left open
    assert panels < bent.volume < panels + hinge_max
    assert bent.volume - panels > 0.6 * hinge_max
    with pytest.raises(ParameterError, match="crease_thickness"):
        folded_printable_solid(p, 0.5e-3, 1e-3, W)  # hinges thicker than the panels
    arch = fit_strip("half-circle", 8, 0.2, 0.02, 0.1).pattern  # warped quads, deep folds
    assert folded_printable_solid(arch, 3e-3, 0.6e-3, 6e-3).body_count == 1


def _area3(c):
    return 0.5 * np.linalg.norm(np.cross(c, np.roll(c, -1, axis=0)).sum(axis=0))
