"""The flat printable part of thick panels is one closed 2-manifold body once its STL is read
back (issue 34, validation/last_mile: the hypar roof's offset part had 9 edges in four
triangles, so it was not cut into bed pieces)."""

from __future__ import annotations

import io
from math import radians
from pathlib import Path

import numpy as np
import pytest
import trimesh

from holofold.geometry import (
    DEFAULT_BED,
    miura_path,
    miura_sheet,
    read_pattern,
    segment_part,
    thick_panels,
    thick_printable,
)
from holofold.geometry.thick import panel_solids_of

ROOF = Path(__file__).parent / "data" / "hypar-roof-6x8.fold"
#: the roof's chosen design in validation/last_mile (t_p, t_c, W), m
ROOF_T, ROOF_TC, ROOF_W = 2.726e-3, 0.4136e-3, 2.462e-3
T, W, TC = 2e-3, 2e-3, 0.6e-3


def _read_back(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """The mesh written as binary STL and read again (vertices merged, as a slicer reads it)."""
    return trimesh.load(io.BytesIO(mesh.export(file_type="stl")), file_type="stl")


def _faces_per_edge(mesh: trimesh.Trimesh) -> np.ndarray:
    _, count = np.unique(np.sort(mesh.edges, axis=1), axis=0, return_counts=True)
    return count


def _assert_closed_2_manifold(mesh: trimesh.Trimesh, volume: float) -> None:
    back = _read_back(mesh)
    count = _faces_per_edge(back)
    assert (count == 2).all(), f"{(count != 2).sum()} edges not in exactly two triangles"
    assert back.is_watertight and back.is_winding_consistent
    assert len(back.split(only_watertight=False)) == 1
    # float32 coordinates in the STL: volume within 1e-6 relative, and positive
    assert back.volume == pytest.approx(volume, rel=1e-6) and back.volume > 0


@pytest.fixture(scope="module")
def roof():
    return read_pattern(ROOF)


def _area(poly) -> float:
    x, y = np.asarray(poly, float).T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _hinge_volume(part, crease_thickness):
    """The strips' and patches' prisms under the panels: t_c times their area, m^3."""
    lay = part.metadata["layout"]
    return crease_thickness * sum(_area(p) for p in [*lay.hinges, *lay.patches])


@pytest.mark.parametrize("technique", ["offset", "tapered", "centred"])
def test_roof_part_is_one_closed_body_read_back(roof, technique):
    panels = thick_panels(roof, ROOF_T, ROOF_W, technique)
    part = thick_printable(roof, panels, ROOF_TC)
    _assert_closed_2_manifold(part, part.volume)
    # the geometry is the union it was: the panels (every bevel cuts them above t_c at the hinge
    # line here, 1.5 mm) plus the hinge strips and vertex patches, to 1e-9
    half = ROOF_W / 2 * np.tan(panels.bevel[np.isfinite(panels.bevel)])
    assert half.min(initial=np.inf) > ROOF_TC
    # the panels in the folded state: the same rigid solids as in the flat layout
    slabs = sum(s.volume() for s in panel_solids_of(roof, panels))
    expected = slabs + _hinge_volume(part, ROOF_TC)
    assert part.volume == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("technique", ["offset", "tapered"])
def test_miura_part_is_one_closed_body_read_back(technique):
    state = miura_sheet(4, 4, a=0.02, b=0.02, gamma=radians(60), ext=0.5)
    panels = thick_panels(state, T, W, technique, path=miura_path(state, 6))
    part = thick_printable(state, panels, TC)
    _assert_closed_2_manifold(part, part.volume)
    lo, hi = part.bounds
    assert lo[2] == pytest.approx(0.0, abs=1e-12) and hi[2] == pytest.approx(T, rel=1e-9)


def test_roof_offset_part_is_cut_into_pieces_that_fit_the_bed(roof):
    """Before: "piece 1 is not one closed body once its vertices are merged", no pieces."""
    panels = thick_panels(roof, ROOF_T, ROOF_W, "offset")
    seg = segment_part(roof, ROOF_T, ROOF_TC, ROOF_W, DEFAULT_BED, panels=panels)
    assert not seg.problem, seg.problem
    assert not seg.whole.fits and 4 <= len(seg.segments) <= 8  # 373 x 390 mm on 250 x 210
    assert sorted(np.concatenate([s.panels for s in seg.segments])) == list(range(48))
    for s in seg.segments:
        m = s.mesh  # mm, on the bed
        assert m.bounds[1][0] <= DEFAULT_BED.width + 1e-9
        assert m.bounds[1][1] <= DEFAULT_BED.depth + 1e-9
        assert m.bounds[0][2] == pytest.approx(0.0, abs=1e-9)
        _assert_closed_2_manifold(m, m.volume)
    assert len(seg.joints) >= len(seg.segments) - 1


def test_two_boxes_touching_along_an_edge_are_refused_as_no_2_manifold():
    """The check thick_printable makes: merged as an STL reader merges them, two boxes that
    touch along an edge give that edge four triangles."""
    from holofold.geometry.thick_part import _edges_not_in_two

    a = trimesh.creation.box(extents=(1, 1, 1))
    b = trimesh.creation.box(extents=(1, 1, 1))
    b.apply_translation((1, 1, 0))
    faces = np.vstack([a.faces, b.faces + len(a.vertices)])
    both = trimesh.Trimesh(np.vstack([a.vertices, b.vertices]), faces, process=False)
    assert _edges_not_in_two(a) == 0
    assert both.is_watertight  # unmerged: each box closed on its own
    assert _edges_not_in_two(both) == 1
