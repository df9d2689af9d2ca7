"""Thick panels with hinge gaps, unioned with manifold3d."""

import math

import manifold3d as m3d
import numpy as np
import pytest

from holofold.geometry.errors import ParameterError
from holofold.geometry.miura import miura_sheet
from holofold.geometry.solid import SolidWarning, panel_solids, shrunk_panels, thick_solid
from holofold.geometry.tmp import tmp_sheet

W, T = 2e-3, 0.5e-3


def _area(corners):
    n = np.zeros(3)
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        n += np.cross(a, b)
    return 0.5 * np.linalg.norm(n)


@pytest.mark.parametrize("ext", [1.0, 0.6])
def test_miura_solid_is_watertight_with_the_expected_volume(ext):
    p = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=ext)
    solid = thick_solid(p, T, W)
    assert solid.is_watertight and solid.is_volume
    expected = sum(_area(c) for c in shrunk_panels(p, W)) * T
    assert solid.volume == pytest.approx(expected, rel=1e-2)
    assert abs(solid.volume / expected - 1) < 1e-5  # disjoint panels: the union loses nothing


def test_flat_gap_is_the_crease_width_and_borders_stay():
    p = miura_sheet(2, 2, a=0.02, b=0.02, gamma=math.radians(60), ext=1.0)
    sh = shrunk_panels(p, W)
    # Parallelogram panel: each interior side pulled in by W/2 along its normal; area shrinks by
    # exactly (side_a - W/(2 sin g)) * (height_b - W/2) for one interior side of each kind.
    g = math.radians(60)
    h_full = 0.02 * math.sin(g)
    area = _area(sh[0])
    assert area == pytest.approx((0.02 - W / 2 / math.sin(g)) * (h_full - W / 2), rel=1e-12)
    # border vertices of the corner panel stay where they were
    assert np.allclose(sh[0][0], p.coords[p.faces[0][0]])


def test_no_two_panels_intersect_in_a_folded_miura():
    p = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    parts = [
        m3d.Manifold(m3d.Mesh(vert_properties=np.asarray(s.vertices, np.float32),
                              tri_verts=np.asarray(s.faces, np.uint32)))
        for s in panel_solids(p, T, W)
    ]  # fmt: skip
    worst = max((parts[i] ^ parts[j]).volume() for i in range(len(parts)) for j in range(i))
    assert worst == 0.0
    assert len(thick_solid(p, T, W).split()) == p.n_faces  # every panel its own body


def test_tmp_solid_and_per_panel_option():
    p = tmp_sheet(4, 3, 0.1, 0.8)
    solids = thick_solid(p, 0.3e-3, 1e-3, union=False)
    assert len(solids) == p.n_faces and all(s.is_watertight for s in solids)


def test_crease_wider_than_panel_and_bad_thickness_raise():
    p = miura_sheet(2, 2, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    with pytest.raises(ParameterError, match="wider than panel"):
        thick_solid(p, T, 0.05)
    with pytest.raises(ParameterError, match="thickness"):
        thick_solid(p, -1e-3, W)
    with pytest.raises(ParameterError, match="crease width"):
        shrunk_panels(p, -1.0)


def test_overlapping_thick_panels_are_reported():
    p = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    with pytest.warns(SolidWarning, match="panels intersect"):
        thick_solid(p, 1e-3, W)  # 1 mm panels with 2 mm gaps collide at ext 0.6
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        thick_solid(p, T, W)  # 0.5 mm panels do not


def test_a_straight_corner_moves_inward_by_the_larger_inset():
    """A square with a vertex in the middle of its bottom side (a crease ending there from the
    panel below, a T-junction): that corner is straight; the offset keeps the panel a rectangle
    pulled back by the larger inset, where it used to refuse the panel."""
    from holofold.geometry.solid import offset_corners

    coords = np.array([[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    # insets of the sides leaving each corner: bottom-left half 0.1, bottom-right half 0.2
    inset = np.array([0.1, 0.2, 0.0, 0.0, 0.0])
    q = offset_corners(coords, [np.arange(5)], inset)
    # the left half's side is 0.1 in, the right half's 0.2; the straight corner takes 0.2
    assert q[0] == pytest.approx([0.0, 0.1, 0.0], abs=1e-12)
    assert q[1] == pytest.approx([0.5, 0.2, 0.0], abs=1e-12)
    assert q[2] == pytest.approx([1.0, 0.2, 0.0], abs=1e-12)
    with pytest.raises(ParameterError, match="folds back on itself"):
        offset_corners(
            np.array([[0, 0, 0], [1, 0, 0], [0.5, 0, 0], [0.5, 1, 0]], float),
            [np.arange(4)], np.zeros(4),
        )  # fmt: skip
