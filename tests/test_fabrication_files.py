"""The fabrication files of a sheet and of a fitted strip, written by the library directly."""

import json
import math

import numpy as np
import pytest
import trimesh

from holofold.fitting import export_strip_files, fit_strip
from holofold.geometry import (
    ParameterError,
    SolidWarning,
    export_pattern_files,
    load_fold,
    miura_sheet,
)


def test_pattern_files_and_their_numbers(tmp_path):
    sheet = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    written = export_pattern_files(sheet, tmp_path / "p", thickness=0.5e-3, crease_width=2e-3)
    assert [p.name for p in written] == [
        "pattern.fold", "pattern.svg", "pattern.dxf", "folded.stl", "folded.obj", "thick.stl"
    ]  # fmt: skip
    back = load_fold((tmp_path / "p" / "pattern.fold").read_text())
    np.testing.assert_allclose(back.coords, sheet.coords, atol=1e-12)
    solid = trimesh.load(tmp_path / "p" / "thick.stl")
    assert solid.is_watertight and len(solid.split()) == sheet.n_faces
    assert sorted(p.name for p in (tmp_path / "p").iterdir()) == sorted(p.name for p in written)


def test_pattern_files_refuse_before_writing(tmp_path):
    sheet = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    with pytest.raises(ParameterError, match="wider than panel"):
        export_pattern_files(sheet, tmp_path / "bad", thickness=1e-3, crease_width=0.5)
    with pytest.raises(ParameterError, match="thickness"):
        export_pattern_files(sheet, tmp_path / "bad", thickness=-1.0)
    assert not (tmp_path / "bad").exists()


def test_strip_files(tmp_path):
    fit = fit_strip("half-circle", 8, 0.2, 0.02, 0.1)
    written = export_strip_files(fit, tmp_path / "s", panel_thickness=2e-3, crease_width=3e-3)
    assert [p.name for p in written] == [
        "strip.fold", "strip.svg", "strip.dxf", "strip.stl", "strip.obj", "strip_solid.stl"
    ]  # fmt: skip
    fold = json.loads((tmp_path / "s" / "strip.fold").read_text())
    assert fold["faces_holofold:thickness"][0] == 2e-3
    mesh = trimesh.load(tmp_path / "s" / "strip.stl")  # millimetres, as slicers read STL
    np.testing.assert_allclose(mesh.bounds[:, [0, 2]], [[0.0, 0.0], [4000.0, 2000.0]], atol=250)
    assert (tmp_path / "s" / "strip.stl").read_bytes()[:25] == b"holofold mesh, units: mm "
    assert (tmp_path / "s" / "strip.obj").read_text().startswith("# holofold mesh, units: mm")
    with pytest.raises(ParameterError, match="both a panel thickness and a crease width"):
        export_strip_files(fit, tmp_path / "t", panel_thickness=2e-3)
    assert not (tmp_path / "t").exists()


def test_strip_files_in_metres_with_the_printable_part(tmp_path):
    fit = fit_strip("half-circle", 8, 0.2, 0.02, 0.1)
    written = export_strip_files(
        fit, tmp_path / "s", panel_thickness=2e-3, crease_width=3e-3, crease_thickness=0.8e-3,
        units="m",
    )  # fmt: skip
    assert [p.name for p in written][:2] == ["printable.stl", "printable_folded.stl"]
    mesh = trimesh.load(tmp_path / "s" / "strip.stl")
    np.testing.assert_allclose(mesh.bounds[:, [0, 2]], [[0.0, 0.0], [4.0, 2.0]], atol=0.25)
    part = trimesh.load(tmp_path / "s" / "printable.stl")
    assert part.is_watertight and part.body_count == 1
    np.testing.assert_allclose(part.bounds[:, 2], [0.0, 2e-3], atol=1e-9)  # flat, on the bed
    fold = json.loads((tmp_path / "s" / "strip.fold").read_text())
    assert fold["edges_holofold:creaseThickness"][0] == 0.8e-3
    with pytest.raises(ParameterError, match="unknown length unit 'yd'"):
        export_strip_files(fit, tmp_path / "u", units="yd")
    with pytest.raises(ParameterError, match="printable part needs a panel thickness"):
        export_strip_files(fit, tmp_path / "u", crease_thickness=1e-3)
    assert not (tmp_path / "u").exists()


def test_pattern_files_with_the_printable_part_in_mm(tmp_path):
    sheet = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    # 2 mm panels with 2 mm creases overlap in the folded state: said, not hidden
    with pytest.warns(SolidWarning, match="thick panels intersect in this folded state"):
        written = export_pattern_files(
            sheet, tmp_path / "p", thickness=2e-3, crease_width=2e-3, crease_thickness=0.6e-3
        )
    names = [p.name for p in written]
    assert names[:2] == ["printable.stl", "printable_folded.stl"] and names[-1] == "thick.stl"
    bent = trimesh.load(tmp_path / "p" / "printable_folded.stl")
    assert bent.is_watertight and bent.body_count == 1
    part = trimesh.load(tmp_path / "p" / "printable.stl")
    assert part.is_watertight and part.body_count == 1
    # the flat sheet: 2 x 4 parallelograms of 20 mm x 20 mm sin 60 ... in mm, 2 mm thick
    np.testing.assert_allclose(part.bounds[:, 2], [0.0, 2.0], atol=1e-6)

    def cross2(u, v):  # the z component of a 2-D cross product (np.cross of 2-D vectors is
        return u[0] * v[1] - u[1] * v[0]  # deprecated in NumPy 2.0)

    area = sum(abs(cross2(*(sheet.flat[f[1:3]] - sheet.flat[f[0]]))) for f in sheet.faces)
    assert area == pytest.approx(16 * 0.02 * 0.02 * math.sin(math.radians(60)), rel=1e-12)
    assert part.bounding_box.primitive.extents[:2].prod() >= area * 1e6  # covers the sheet
    with pytest.raises(ParameterError, match="needs a panel thickness and a crease width > 0"):
        export_pattern_files(sheet, tmp_path / "q", crease_thickness=1e-3)
    assert not (tmp_path / "q").exists()
