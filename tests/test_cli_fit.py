"""``holofold fit``: files written, JSON summary, exit codes, nothing written on bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh

from holofold.cli import main
from holofold.fitting.error import paper_error

BASE = ["fit", "--curve", "half-circle:radius=2"]
DESIGN = ["--m", "12", "--offset", "0.2", "--strip-width", "0.02", "--extrude", "0.1"]


def _summary(capsys) -> dict:
    out = capsys.readouterr().out.strip().splitlines()
    return json.loads(out[-1])


def test_fit_half_circle_writes_files(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([*BASE, *DESIGN, "-o", str(out)]) == 0
    s = _summary(capsys)
    for name in ("strip.fold", "strip.svg", "strip.stl", "strip.obj"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0
    assert s["m"] == 12 and s["sampling"] == "paper"
    np.testing.assert_allclose(s["index_error"], paper_error("half-circle", 12, 0.2), rtol=1e-14)
    np.testing.assert_allclose(s["index_error"], 0.097180, atol=6e-7)
    np.testing.assert_allclose(s["closest_max"], 0.2, rtol=1e-9)
    fold = json.loads((out / "strip.fold").read_text())
    # crease pattern (flat development) with the 3-D strip as folded-form frame
    assert fold["frame_classes"] == ["creasePattern"]
    assert len(fold["vertices_coords"]) == 6 * 12 + 3
    assert len(fold["faces_vertices"]) == 4 * 12
    assert len(fold["edges_vertices"]) == 10 * 12 + 2
    X3 = np.array(fold["file_frames"][0]["vertices_coords"])
    np.testing.assert_allclose(X3[12], [2.0, 0.0, 2.0], atol=1e-15)  # apex = node m
    mesh = trimesh.load(out / "strip.stl")  # millimetres by default
    # surface area of the fanned strip: a positive number, bounded by the bounding box
    assert mesh.area > 0
    np.testing.assert_allclose(mesh.bounds[:, 1], [-100.0, 100.0], atol=1e-3)
    assert "<svg" in (out / "strip.svg").read_text()


def test_fit_points_csv_and_svg(tmp_path, capsys):
    t = np.linspace(0, 1, 15)
    pts = np.column_stack([4 * t, 4 * t * (1 - t)])
    csv = tmp_path / "points.csv"
    csv.write_text("x,z\n" + "\n".join(f"{x:.12g},{z:.12g}" for x, z in pts))
    args = ["--m", "6", "--offset", "0.15", "--strip-width", "0.01", "--extrude", "0.1"]
    assert main(["fit", "--curve", str(csv), *args, "-o", str(tmp_path / "a")]) == 0
    s = _summary(capsys)
    assert s["sampling"] == "arclength" and s["m"] == 6
    svg = tmp_path / "drawing.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><path id="other" d="M 0 0 L 5 5"/>'
        '<path id="arch" d="M 0 200 Q 200 -200 400 200"/></svg>'
    )
    out = tmp_path / "b"
    ref = ["--curve", f"{svg}#arch", "--curve-scale", "0.01"]
    assert main(["fit", *ref, *args, "-o", str(out)]) == 0
    s2 = _summary(capsys)
    assert s2["curve"] == "arch"
    # the quadratic Bezier is a parabola: span 4 m, height 2 m after scaling
    fold = json.loads((out / "strip.fold").read_text())
    X = np.array(fold["file_frames"][0]["vertices_coords"])
    np.testing.assert_allclose(X[[0, 12], 0], [0.0, 4.0], atol=1e-9)


def test_fit_auto(tmp_path, capsys):
    out = tmp_path / "auto"
    args = [*BASE, "--auto", "--tolerance", "0.05", "--m-range", "2:24:2", "-o", str(out)]
    assert main(args) == 0
    s = _summary(capsys)
    assert s["closest_max"] <= 0.05 * (1 + 1e-9)
    assert (out / "candidates.csv").is_file()
    assert s["m"] in range(2, 25, 2)


def test_fit_auto_warp_limit_no_overlap_printable_in_metres(tmp_path, capsys):
    out = tmp_path / "auto"
    args = ["fit", "--curve", "parabola:span=4,height=1", "--auto", "--tolerance", "0.05",
            "--strip-width", "0.02", "--extrude", "0.1", "--panel-thickness", "0.002",
            "--crease-width", "0.003", "--crease-thickness", "0.0008", "--printable",
            "--no-overlap", "--units", "m", "-o", str(out)]  # fmt: skip
    assert main(args) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    s = json.loads(lines[-1])
    assert s["warp_max"] <= 0.035 and "(limit 3.5 %)" in lines[-2]
    assert f"quads warp up to {100 * s['warp_max']:.3g} %" in lines[-2]
    assert s["units"]["mesh files"] == "m" and s["units"]["strip.fold"] == "m"
    table = __import__("pandas").read_csv(out / "candidates.csv")
    chosen = table[table["chosen"]].iloc[0]
    assert chosen["overlap"] == 0.0 and chosen["warp_max"] == pytest.approx(s["warp_max"])
    part = trimesh.load(out / "printable.stl")
    assert part.is_watertight and part.body_count == 1
    np.testing.assert_allclose(part.bounds[:, 2], [0.0, 0.002], atol=1e-9)  # metres
    strip = trimesh.load(out / "strip.stl")
    assert 3.9 < np.ptp(strip.bounds[:, 0]) < 4.2


def test_fit_csv_in_mm_and_a_warning_for_an_svg_in_mm_read_as_metres(tmp_path, capsys):
    t = np.linspace(0, 1, 15)
    csv = tmp_path / "mm.csv"
    csv.write_text("\n".join(f"{4000 * a:.12g},{4000 * a * (1 - a):.12g}" for a in t))
    args = ["--m", "6", "--offset", "0.15", "--strip-width", "0.01", "--extrude", "0.1"]
    assert main(["fit", "--curve", str(csv), "--curve-units", "mm", *args,
                 "-o", str(tmp_path / "a")]) == 0  # fmt: skip
    cap = capsys.readouterr()
    assert cap.err == ""  # a 4 m curve: plausible, no warning
    fold = json.loads((tmp_path / "a" / "strip.fold").read_text())
    X = np.array(fold["file_frames"][0]["vertices_coords"])
    np.testing.assert_allclose(X[[0, 12], 0], [0.0, 4.0], atol=1e-9)
    svg = tmp_path / "arch.svg"  # a drawing without units: its 400 user units read as metres
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="400" height="200">'
                   '<path d="M 0 200 Q 200 -200 400 200"/></svg>')  # fmt: skip
    assert main(["fit", "--curve", str(svg), *args, "-o", str(tmp_path / "b")]) in (0, 2)
    err = capsys.readouterr().err
    assert "warning: curve 'arch' from arch.svg is 400 m across" in err
    assert "--curve-units mm" in err


def test_thick_solid(tmp_path, capsys):
    out = tmp_path / "solid"
    thick = ["--panel-thickness", "0.004", "--crease-width", "0.002"]
    assert main([*BASE, *DESIGN, *thick, "-o", str(out)]) == 0
    captured = capsys.readouterr()  # 4 mm panels, 2 mm gaps: one line of warning
    assert captured.err.startswith("holofold fit: warning: thick panels intersect")
    assert captured.err.count("\n") == 1
    s = json.loads(captured.out.strip().splitlines()[-1])
    assert str(out / "strip_solid.stl") in s["files"]
    mesh = trimesh.load(out / "strip_solid.stl")
    assert mesh.is_watertight
    # volume: panel area (shrunk by the hinge gaps) x thickness, below the unshrunk bound
    area = trimesh.load(out / "strip.stl").area  # mm^2
    assert 0.9 * area * 4.0 < mesh.volume < area * 4.0
    fold = json.loads((out / "strip.fold").read_text())
    assert fold["faces_holofold:thickness"][0] == 0.004
    # a crease wider than the panels: rejected before anything is written
    bad = tmp_path / "bad"
    argv = [*BASE, *DESIGN, "--panel-thickness", "0.004", "--crease-width", "5", "-o", str(bad)]
    assert main(argv) == 2
    assert "wider than panel" in capsys.readouterr().err
    assert not bad.exists()


def test_plan_view_svg_without_layout():
    from holofold.fitting import fit_strip
    from holofold.geometry import polylines_svg

    fit = fit_strip("half-circle", 8, 0.2, 0.02, 0.1)
    svg = polylines_svg([fit.centre_line, fit.side_line], ["#000", "#777"], "plan view")
    assert svg.count("<polyline") == 2 and "plan view" in svg
    # first point P_0 = (0, 0), in mm from the lower-left corner minus a 5 mm margin, y down
    first = svg.split('points="')[1].split()[0]
    pts = np.vstack([fit.centre_line, fit.side_line]) * 1000.0
    expect = [5.0 - pts[:, 0].min(), 5.0 + pts[:, 1].max()]
    np.testing.assert_allclose([float(v) for v in first.split(",")], expect, atol=1e-5)
    np.testing.assert_allclose(expect[0], 5.0 + 157.7276, atol=1e-3)


@pytest.mark.parametrize(
    "argv, match",
    [
        (
            [*BASE, "--m", "12", "--offset", "0.2", "--strip-width", "-0.02", "--extrude", "0.1"],
            "--strip-width",
        ),
        (
            [*BASE, "--m", "1", "--offset", "0.2", "--strip-width", "0.02", "--extrude", "0.1"],
            "--m must be an integer >= 2",
        ),
        (
            [*BASE, "--m", "12", "--offset", "0.2", "--strip-width", "0.02", "--extrude", "-1"],
            "--extrude",
        ),
        (["fit", "--curve", "spiral:turns=2", *DESIGN], "unknown curve"),
        (["fit", "--curve", "missing.csv", *DESIGN], "does not exist"),
        ([*BASE, "--m", "12"], "missing --offset"),
        ([*BASE, "--auto"], "--auto needs --tolerance"),
        ([*BASE, *DESIGN, "--panel-thickness", "0.001"], "both --panel-thickness"),
        (
            [
                *BASE,
                *DESIGN,
                "--printable",
                "--panel-thickness",
                "0.002",
                "--crease-width",
                "0.002",
            ],
            "--printable needs --crease-thickness",
        ),
        ([*BASE, *DESIGN, "--crease-thickness", "0.001"], "add --printable"),
        ([*BASE, *DESIGN, "--no-overlap"], "--no-overlap needs --auto"),
        ([*BASE, "--auto", "--tolerance", "0.05", "--max-warp", "0"], "--max-warp"),
        ([*BASE, *DESIGN, "--curve-scale", "-1"], "--curve-scale"),
        ([*BASE, "--m", "100000", *DESIGN[2:]], "more than 2000 units"),
        ([*BASE, "--auto", "--tolerance", "0.05", "--m-range", "2:100000"], "beyond m = 2000"),
    ],
)
def test_bad_input_writes_nothing(tmp_path, capsys, argv, match):
    out = tmp_path / "out"
    assert main([*argv, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "holofold fit: error:" in err and match in err
    assert not out.exists()


def test_unreadable_file(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("x,z\n0,0\n1,what\n")
    out = tmp_path / "out"
    assert main(["fit", "--curve", str(bad), *DESIGN, "-o", str(out)]) == 2
    assert "line 3" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_example_fit_curves(tmp_path):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "fit_curves.py"
    spec = importlib.util.spec_from_file_location("fit_curves_example", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    res = mod.main(tmp_path)
    assert res is mod.RESULT
    assert res["backend"] in ("pyvista", "matplotlib")
    assert Path(res["png"]).stat().st_size > 10_000
    half, cat, roof = res["strips"]
    np.testing.assert_allclose(half["index_error"], 0.097180, atol=6e-7)
    np.testing.assert_allclose(half["closest_max"], 0.2, rtol=1e-9)
    assert cat["closest_max"] <= 0.02 * (1 + 1e-9) and cat["m"] >= 2
    assert roof["m"] == 10 and roof["closest_max"] > 0
