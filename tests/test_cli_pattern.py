"""``holofold pattern``: files written, numbers in them, errors that write nothing."""

import json

import numpy as np
import pytest
import trimesh

from holofold.cli import main
from holofold.geometry.fold_io import load_fold


def test_miura_writes_all_files(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["pattern", "miura", "--m", "4", "--n", "4", "--gamma", "60", "--ext", "0.6",
            "--a", "0.02", "--b", "0.02", "--thickness", "0.5e-3", "--crease-width", "2e-3",
            "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "folded.obj", "folded.stl", "pattern.dxf", "pattern.fold", "pattern.svg", "thick.stl"
    ]  # fmt: skip
    summary = capsys.readouterr().out
    assert "25 vertices, 24 creases, 16 panels" in summary
    p = load_fold((out / "pattern.fold").read_text())
    assert p.n_faces == 16 and p.meta["m"] == 4
    # x extent of a folded Miura: m b sin(theta), theta = asin(ext sin gamma)
    theta = np.arcsin(0.6 * np.sin(np.radians(60)))
    assert np.ptp(p.coords[:, 0]) == pytest.approx(4 * 0.02 * np.sin(theta), rel=1e-12)
    cw = json.loads((out / "pattern.fold").read_text())["edges_holofold:creaseWidth"]
    assert sorted(set(cw)) == [0.0, 2e-3]
    solid = trimesh.load(out / "thick.stl")
    assert solid.is_watertight and len(solid.split()) == 16


def test_tmp_pattern(tmp_path):
    out = tmp_path / "t"
    assert main(["pattern", "tmp", "--m", "4", "--n", "6", "--size", "0.2", "--ext", "0.5",
                 "-o", str(out)]) == 0  # fmt: skip
    p = load_fold((out / "pattern.fold").read_text())
    assert np.ptp(p.coords[:, 0]) == pytest.approx(0.2 * 0.5, rel=1e-12)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["miura", "--gamma", "60", "--ext", "0", "--size", "0.2"], "--ext = 0.0 is outside"),
        (["miura", "--gamma", "60", "--ext", "1.5", "--size", "0.2"], "(0.0, 1.0]"),
        (["miura", "--gamma", "90", "--ext", "0.5", "--size", "0.2"], "--gamma = 90.0"),
        (["miura", "--ext", "0.5", "--size", "0.2"], "--gamma is required"),
        (["miura", "--gamma", "60", "--ext", "0.5"], "--size, or both --a and --b"),
        (["tmp", "--ext", "0.5", "--size", "0.2", "--m", "5"], "must be even"),
        (["tmp", "--ext", "0.5", "--size", "0.2", "--n", "4"], "multiple of 3"),
        (["miura", "--gamma", "60", "--ext", "0.5", "--size", "0.2", "--thickness", "-1"],
         "--thickness"),
        (["miura", "--gamma", "60", "--ext", "0.5", "--size", "0.2", "--thickness", "1e-3",
          "--crease-width", "0.2"], "wider than panel"),
        (["miura", "--gamma", "60", "--ext", "0.5", "--size", "0.2", "--printable",
          "--thickness", "1e-3"], "--printable needs --crease-thickness, --crease-width > 0"),
        (["miura", "--gamma", "60", "--ext", "0.5", "--size", "0.2", "--crease-thickness",
          "1e-3"], "add --printable"),
        (["miura", "--gamma", "60", "--ext", "0.5", "--size", "0.2", "--m", "100000"],
         "600000 panels; at most 10000"),
    ],
)  # fmt: skip
def test_bad_arguments_exit_nonzero_and_write_nothing(tmp_path, capsys, extra, message):
    kind, rest = extra[0], extra[1:]
    mn = {"--m": "4", "--n": "6"}
    for k in ("--m", "--n"):
        if k in rest:
            i = rest.index(k)
            mn[k] = rest[i + 1]
            rest = rest[:i] + rest[i + 2 :]
    out = tmp_path / "bad"
    code = main(["pattern", kind, "--m", mn["--m"], "--n", mn["--n"], *rest, "-o", str(out)])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_overlapping_thick_tmp_is_refused_and_mild_overlap_is_a_one_line_warning(tmp_path, capsys):
    out = tmp_path / "tmp"
    argv = ["pattern", "tmp", "--m", "6", "--n", "6", "--size", "0.2", "--ext", "0.6",
            "--thickness", "0.5e-3", "-o", str(out)]  # fmt: skip
    assert main(argv) == 2  # the folded tubes run through each other: no watertight solid
    assert "not a watertight solid" in capsys.readouterr().err
    assert not out.exists()
    ok = tmp_path / "miura"
    argv = ["pattern", "miura", "--m", "4", "--n", "4", "--gamma", "60", "--ext", "0.6",
            "--size", "0.2", "--thickness", "2e-3", "--crease-width", "2e-3",
            "-o", str(ok)]  # fmt: skip
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert (
        err.startswith("holofold pattern: warning: thick panels intersect") and err.count("\n") == 1
    )
    assert (ok / "thick.stl").is_file()


def test_printable_part_in_mm_and_folded_surface_in_metres(tmp_path, capsys):
    out = tmp_path / "p"
    argv = ["pattern", "miura", "--m", "4", "--n", "4", "--gamma", "60", "--ext", "0.6",
            "--a", "0.02", "--b", "0.02", "--printable", "--panel-thickness", "2e-3",
            "--crease-thickness", "0.6e-3", "--crease-width", "2e-3", "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert "printable.stl" in capsys.readouterr().out
    part = trimesh.load(out / "printable.stl")
    assert part.is_watertight and part.body_count == 1
    np.testing.assert_allclose(part.bounds[:, 2], [0.0, 2.0], atol=1e-5)  # mm
    # the flat sheet's area in mm^2, covered by panels (2 mm) and hinges (0.6 mm)
    area = 16 * 20 * 20 * np.sin(np.radians(60))
    assert 0.6 * area < part.volume < 2.0 * area
    assert main([*argv[:-2], "--units", "m", "-o", str(tmp_path / "m")]) == 0
    folded = trimesh.load(tmp_path / "m" / "folded.stl")
    assert np.ptp(folded.bounds[:, 0]) < 0.1  # metres
