"""The example scripts run and leave their results where the README says."""

import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_render_miura_writes_a_png(tmp_path, monkeypatch):
    png = tmp_path / "miura.png"
    monkeypatch.setattr(sys, "argv", ["render_miura.py", str(png)])
    ns = runpy.run_path(str(ROOT / "examples" / "render_miura.py"))
    res = ns["RESULT"]
    assert res["png"] == png and res["watertight"] and res["panels"] == 36
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width = int.from_bytes(data[16:20], "big")
    height = int.from_bytes(data[20:24], "big")
    assert (width, height) == (1400, 600)


@pytest.mark.skipif(
    __import__("shutil").which("rsvg-convert") is None, reason="rsvg-convert not installed"
)
def test_render_cutter_profiles_writes_a_png(tmp_path, monkeypatch):
    png = tmp_path / "profiles.png"
    monkeypatch.setattr(sys, "argv", ["render_cutter_profiles.py", str(png)])
    runpy.run_path(str(ROOT / "examples" / "render_cutter_profiles.py"))
    import matplotlib.image as mpimg

    img = mpimg.imread(png)[..., :3]
    assert img.shape[:2] == (810, 1170)  # 13 x 9 in at 90 dpi
    red = (img[..., 0] - img[..., 1:].max(axis=2)) > 0.3
    blue = (img[..., 2] - img[..., :2].max(axis=2)) > 0.3
    assert red.sum() > 500 and blue.sum() > 500  # the profiles' lines are drawn


#: (closing step, stiff N/m, Tmax °C) of the example's two designs, recorded on 2026-11-22
RECORDED_GRIPPERS = {3: (155, 2.0807132979735573e-04, 337.41693604377355),
                     2: (116, 5.822928844141693e-04, 229.6125885094683)}  # fmt: skip


@pytest.mark.slow
def test_gripper_closing_example(tmp_path, monkeypatch):
    from holofold.design.scenarios.gripper import gripper_model, published_q

    png = tmp_path / "gripper.png"
    monkeypatch.setattr(sys, "argv", ["gripper_closing.py", str(png)])
    ns = runpy.run_path(str(ROOT / "examples" / "gripper_closing.py"), run_name="__main__")
    res = ns["RESULT"]
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width = int.from_bytes(data[16:20], "big")
    height = int.from_bytes(data[20:24], "big")
    assert (width, height) == (1400, 900)
    assert sorted(k for k in res) == [2, 3]
    for pattern, row in res.items():
        sim, d = row["result"], row["design"]
        step = row["closing_step"]
        assert row["png"] == png and d["Pattern"] == pattern
        assert step is not None and step == sim.closing_step == len(sim.tip_distance)
        assert sim.tip_distance[step - 1] < 1e-3 < sim.tip_distance[step - 2]
        assert row["Tmax"] == sim.temperature.max() == sim.Tmax_history[-1]
        assert row["finalQ"] == float(published_q(pattern, d["L1"], d["L2"], step))
        # converged mode is repeatable (< 1e-11): values of the first run, all solves converged
        step0, stiff0, tmax0 = RECORDED_GRIPPERS[pattern]
        assert (step, str(sim.status)) == (step0, "converged")
        assert row["stiff"] == pytest.approx(stiff0, rel=1e-6)
        assert row["Tmax"] == pytest.approx(tmax0, rel=1e-9)
        # the drawn shape is the closed one: arms lifted off the plane, tips within 1 mm
        x = sim.nodes + sim.displacement
        a, b = gripper_model(d).nodes.tips
        assert np.linalg.norm(x[a] - x[b]) == pytest.approx(sim.tip_distance[-1], rel=1e-12)
        assert sim.triangles.max() < len(x) and x[:, 2].max() > 1e-3


@pytest.mark.slow
def test_design_my_arch_example_chooses_a_design_that_meets_its_target(tmp_path):
    ns = runpy.run_path(str(ROOT / "examples" / "design_my_arch.py"))
    summary = ns["main"](tmp_path / "my-arch", samples=200, verify=10)
    from holofold.design import parse_target, read_scenario

    perf = summary["performance"]
    assert perf["Vstiff"] > 300 and perf["error"] < 0.04 and min(summary["margins"].values()) > 0
    # the Python scenario and examples/my_arch.toml are the same problem: same numbers
    toml = read_scenario(ROOT / "examples" / "my_arch.toml")
    again = toml.evaluate(summary["features"])
    for c, v in perf.items():
        assert again[c] == pytest.approx(v, rel=1e-12), c
    assert parse_target(ns["TARGET"]).columns == ("Vstiff", "error")
    for f in ("strip.fold", "strip.svg", "strip.stl", "strip.obj", "strip_solid.stl"):
        assert (tmp_path / "my-arch" / "files" / f).is_file()
    assert (tmp_path / "my-arch" / "design.json").is_file()
