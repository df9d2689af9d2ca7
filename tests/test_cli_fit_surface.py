"""``holofold fit --surface``: a mesh in mm, fitted, folded by simulation, files and errors."""

from __future__ import annotations

import json

import pytest
import trimesh

from holofold.cli import main
from holofold.fitting import builtin_surface


@pytest.fixture(scope="module")
def dome_mm(tmp_path_factory):
    """A spherical cap of radius 150 mm, 120 mm across, as an STL in millimetres."""
    s = builtin_surface("sphere-cap", radius=0.15, rim=0.06)
    mesh = s.mesh.copy()
    mesh.apply_scale(1000.0)
    path = tmp_path_factory.mktemp("dome") / "dome.stl"
    mesh.export(path)
    return path


def test_fit_surface_from_mm_mesh(dome_mm, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["fit", "--surface", str(dome_mm), "--units", "mm", "--cells", "8x8",
                 "-o", str(out)]) == 0  # fmt: skip
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["ok"] and summary["fold_reached"]
    assert summary["units"] == "mm" and summary["target_size"] == pytest.approx(0.12, rel=1e-6)
    assert summary["rms_error_mm"] == pytest.approx(1000 * summary["rms_error"])
    assert summary["rms_error_rel"] < 1e-3 and summary["kawasaki_max"] < 1e-10
    for name in ("pattern.fold", "pattern.svg", "folded.stl", "target.stl", "errors.json"):
        assert (out / name).is_file(), name
    folded = trimesh.load(out / "folded.stl")  # in mm, like the input
    assert 80 < folded.extents.max() < 130
    fold = json.loads((out / "pattern.fold").read_text())
    assert set(fold["edges_assignment"]) == {"M", "V", "B"}


def test_fit_surface_refuses_bad_input_before_writing(dome_mm, tmp_path, capsys):
    out = tmp_path / "none"
    assert main(["fit", "--surface", str(dome_mm), "--cells", "8by8", "-o", str(out)]) == 2
    assert "--cells" in capsys.readouterr().err and not out.exists()
    assert main(["fit", "--surface", "torus:radius=1", "--cells", "8x8", "-o", str(out)]) == 2
    assert "built-ins" in capsys.readouterr().err and not out.exists()
    assert main(["fit", "--cells", "8x8", "-o", str(out)]) == 2
    assert "--curve" in capsys.readouterr().err


def test_fit_surface_refuses_strip_options_and_back(dome_mm, tmp_path, capsys):
    out = tmp_path / "none"
    argv = ["fit", "--surface", str(dome_mm), "--cells", "8x8", "-o", str(out)]
    assert main([*argv, "--m", "12", "--offset", "0.1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["holofold fit: error: --m, --offset are for --curve (a strip), not --surface"]
    assert main([*argv, "--metric", "mean"]) == 2
    assert "--metric is for --curve" in capsys.readouterr().err
    curve = ["fit", "--curve", "half-circle:radius=2", "--m", "4", "--offset", "0.2",
             "--strip-width", "0.02", "--extrude", "0.1", "-o", str(out)]  # fmt: skip
    assert main([*curve, "--cells", "8x8"]) == 2
    assert "--cells is for --surface" in capsys.readouterr().err
    assert not out.exists()


def test_fit_surface_over_its_fold_time_limit_is_not_verified(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["fit", "--surface", "sphere-cap:radius=1,rim=0.45", "--cells", "4x4", "-o", str(out),
            "--fold-time-limit", "1e-9"]  # fmt: skip
    assert main(argv) == 1
    captured = capsys.readouterr()
    summary = json.loads(captured.out.strip().splitlines()[-1])
    assert summary["ok"] and summary["fold_timed_out"] and not summary["fold_reached"]
    assert "holofold fit: the fit is not verified: the fold ran over its time limit" in captured.err
