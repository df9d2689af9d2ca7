"""Thick panels that keep the zero-thickness kinematics: offset and tapered panels, checked
along the fold path of the README's printable Miura sheet (2 mm panels, 2 mm hinges)."""

from __future__ import annotations

from math import radians

import numpy as np
import pytest

from holofold.geometry import (
    ParameterError,
    miura_path,
    miura_sheet,
    path_overlap,
    thick_panels,
    thick_printable,
    write_fabrication_set,
)
from holofold.geometry.printable import folded_printable_solid
from holofold.geometry.thick import panel_solids_of

T, W, TC = 2e-3, 2e-3, 0.6e-3


def _miura(ext):
    return miura_sheet(4, 4, a=0.02, b=0.02, gamma=radians(60), ext=ext)


@pytest.fixture(scope="module")
def path():
    return miura_path(_miura(0.1), 10)  # ext 1.0, 0.9, ..., 0.1


def test_centred_panels_collide_along_the_path(path):
    """Before: slabs centred on the mid-surface overlap from ext 0.8 on (the issue's 2.41 % at
    0.6 is this measure)."""
    over = path_overlap(path, thick_panels(path[-1], T, W, "centred"))
    exts = [p.meta["ext"] for p in path]
    assert over.volume[0] == 0 and over.volume[1] == 0  # flat and ext 0.9
    assert (over.volume[2:] > 0).all()
    assert over.fraction[exts.index(0.6)] == pytest.approx(0.0241, abs=5e-4)
    assert over.fraction[-1] > 0.4


@pytest.mark.parametrize("technique, kept", [("offset", 0.399), ("tapered", 0.508)])
def test_offset_and_tapered_fold_to_ext_01_without_overlap(path, technique, kept):
    panels = thick_panels(path[-1], T, W, technique, path=path)
    over = path_overlap(path, panels)
    assert (over.volume == 0).all(), over.volume  # every state, not only the end
    assert panels.kept == pytest.approx(kept, abs=0.01)
    # the bevels are the largest exact cut-back: folding further than the path overlaps
    beyond = path_overlap([_miura(0.08)], panels)
    assert beyond.volume[0] > 1e-9  # m^3 (> 1 mm^3)


def test_offset_keeps_the_hinges_on_the_reference_surface():
    """Every offset panel lies on one side of its zero-thickness facet, within t of it, and the
    facet (pulled back W/2) is its face: the hinges are where the mechanics model has them."""
    state = _miura(0.5)
    panels = thick_panels(state, T, W, "offset", path=miura_path(state, 5))
    assert panels.side in (1, -1)
    from holofold.geometry.pattern import newell_normals, orient_faces

    faces = orient_faces(state.faces)
    n = newell_normals(state.coords, faces)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    for f, solid in enumerate(panel_solids_of(state, panels)):
        v = np.asarray(solid.to_mesh64().vert_properties)[:, :3]
        h = (v - state.coords[faces[f][0]]) @ n[f] * panels.side
        assert h.min() > -1e-12 and h.max() < T + 1e-12
        assert np.isclose(h, 0.0, atol=1e-12).sum() >= 3  # a face on the reference surface


def test_readme_example_at_ext_06_keeps_most_of_the_panels():
    state = _miura(0.6)
    for technique in ("offset", "tapered"):
        panels = thick_panels(state, T, W, technique, path=miura_path(state, 6))
        assert panels.kept > 0.9


def test_printable_parts_of_offset_panels():
    state = _miura(0.1)
    panels = thick_panels(state, T, W, "offset", path=miura_path(state, 10))
    part = thick_printable(state, panels, TC)
    assert part.is_watertight and part.body_count == 1
    lo, hi = part.bounds
    assert lo[2] == pytest.approx(0.0, abs=1e-12) and hi[2] == pytest.approx(T, rel=1e-9)
    # flat on the bed: the hinge face is the bottom, every panel and hinge touches z = 0
    bottom = part.vertices[np.isclose(part.vertices[:, 2], 0.0, atol=1e-12)]
    assert np.ptp(bottom[:, 0]) == pytest.approx(np.ptp(part.vertices[:, 0]), rel=1e-9)
    bent = folded_printable_solid(state, T, TC, W, panels=panels)
    assert bent.is_watertight and bent.body_count == 1


def test_fabrication_set_with_offset_panels(tmp_path):
    files = write_fabrication_set(
        _miura(0.1), tmp_path, panel_thickness=T, crease_width=W, crease_thickness=TC,
        thick="offset",
    )  # fmt: skip
    assert {"thick", "printable", "printable_folded"} <= {f.key for f in files}
    (note,) = files.notes
    assert "offset panels" in note and "11 states of the fold path: none" in note
    with pytest.raises(ParameterError, match="unknown thickness technique 'thin'"):
        write_fabrication_set(_miura(0.5), tmp_path / "x", panel_thickness=T, thick="thin")
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_demo_strip_overlap_shrinks_with_offset_panels():
    """The demo's chosen arch design overlaps by 7.2e-7 m^3 with centred 5.64 mm panels; the
    offset panels remove the overlap of panels that share a crease (what is left is between
    panels that share only a vertex of these warped quads)."""
    import holofold as hf

    fit = hf.fit_strip(hf.builtin_curve("half-circle", radius=2.0), m=8, offset=0.1,
                       strip_width=0.01136, extrude=0.1417)  # fmt: skip
    fp = fit.flat_pattern
    before = path_overlap([fp], thick_panels(fp, 0.00564, 0.001379, "centred")).volume[0]
    after = path_overlap([fp], thick_panels(fp, 0.00564, 0.001379, "offset")).volume[0]
    assert before == pytest.approx(7.2e-7, rel=0.02)
    assert after < before / 50


def test_fit_auto_reports_the_overlap_of_the_chosen_technique():
    """The demo's arch design as an automatic fit: the candidates' overlap is that of the
    technique's panels (centred 7.2e-7 m^3, offset < 1/50 of it)."""
    from holofold.fitting import fit_auto

    kw = dict(m_range=[8], offsets=[0.1], strip_width=0.01136, extrude=0.1417,
              panel_thickness=0.00564, crease_width=0.001379, max_warp=None)  # fmt: skip
    centred = fit_auto("half-circle", 0.5, **kw).candidates
    offset = fit_auto("half-circle", 0.5, thick="offset", **kw).candidates
    assert centred["overlap"].iloc[0] == pytest.approx(7.2e-7, rel=0.02)
    assert 0 < offset["overlap"].iloc[0] < centred["overlap"].iloc[0] / 50
    with pytest.raises(ParameterError, match="unknown thickness technique 'thin'"):
        fit_auto("half-circle", 0.5, thick="thin", **kw)
