"""The fabrication files of a sheet and of a fitted strip, written by the library directly."""

import json
import math

import numpy as np
import pytest
import trimesh

from holofold.fitting import export_strip_files, fit_strip
from holofold.geometry import ParameterError, export_pattern_files, load_fold, miura_sheet


def test_pattern_files_and_their_numbers(tmp_path):
    sheet = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    written = export_pattern_files(sheet, tmp_path / "p", thickness=0.5e-3, crease_width=2e-3)
    assert [p.name for p in written] == [
        "pattern.fold", "pattern.svg", "folded.stl", "folded.obj", "thick.stl"
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
        "strip.fold", "strip.svg", "strip.stl", "strip.obj", "strip_solid.stl"
    ]  # fmt: skip
    fold = json.loads((tmp_path / "s" / "strip.fold").read_text())
    assert fold["faces_holofold:thickness"][0] == 2e-3
    mesh = trimesh.load(tmp_path / "s" / "strip.stl")
    np.testing.assert_allclose(mesh.bounds[:, [0, 2]], [[0.0, 0.0], [4.0, 2.0]], atol=0.25)
    with pytest.raises(ParameterError, match="both a panel thickness and a crease width"):
        export_strip_files(fit, tmp_path / "t", panel_thickness=2e-3)
    assert not (tmp_path / "t").exists()
