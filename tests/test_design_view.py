"""The 3D view of a design in the report: its data from each kind, and the page in Chromium."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from holofold.design import get_scenario
from holofold.design.report.view import DesignView, Load, view_css, view_html

ROOT = Path(__file__).resolve().parents[1]
ROW = {"m": 8, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "offset": 0.2, "stripeWidth": 0.02,
       "extrude": 0.1}  # fmt: skip


def test_the_arch_view_has_its_supports_loads_and_curve():
    view = get_scenario("arch").view(ROW)
    assert view.labels == ("flat, as printed", "folded over the curve")
    flat, folded = view.frames
    assert np.all(flat[:, 2] == 0.0)  # printed flat on the bed
    e = view.edges
    a = np.linalg.norm(flat[e[:, 0]] - flat[e[:, 1]], axis=1)
    b = np.linalg.norm(folded[e[:, 0]] - folded[e[:, 1]], axis=1)
    assert np.max(np.abs(a - b) / b) < 0.05  # the flat state is the strip's development
    assert sorted(view.supports.tolist()) == [0, 16, 17, 33, 34, 50]  # the six end nodes
    assert [ld.vertex for ld in view.loads] == [8, 8]  # the apex, node m, for at = 0.5
    assert np.allclose(folded[8], [2.0, 0.0, 2.0], atol=0.25)  # near the top of the circle
    c = view.curve
    assert np.allclose(c[0], [0, 0, 0]) and np.allclose(c[-1], [4, 0, 0], atol=1e-9)
    assert set(view.kinds) <= set("MVB") and "M" in view.kinds and "V" in view.kinds
    assert len(view.triangles()) == 2 * 4 * 8  # 4m quads, two triangles each


def test_the_sheet_view_folds_through_its_extensions():
    sc = get_scenario("canopy")
    view = sc.view({"pattern": 1, "m": 24, "n": 6, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3})
    assert view.labels == ("flat", "Ext 0.9", "Ext 0.6", "Ext 0.3")
    x = view.frames[:, :, 0]
    spans = x.max(axis=1) - x.min(axis=1)
    assert np.all(np.diff(spans) < 0)  # each state shorter along x than the one before
    assert np.allclose(spans[1:] / spans[0], [0.9, 0.6, 0.3], rtol=1e-6)
    assert np.all(view.frames[0, :, 2] == view.frames[0, 0, 2])  # flat: one plane
    last = view.frames[-1]
    assert np.allclose(last[view.supports, 0], last[:, 0].min())
    tips = {ld.vertex for ld in view.loads}
    assert np.allclose(last[list(tips), 0], last[:, 0].max())


def test_a_view_refuses_what_it_cannot_draw():
    F = np.zeros((1, 3, 3))
    with pytest.raises(ValueError, match="outside 0..2"):
        DesignView(F, ("a",), [[0, 1, 3]])
    with pytest.raises(ValueError, match="labels"):
        DesignView(F, ("a", "b"), [[0, 1, 2]])
    with pytest.raises(ValueError, match="finite"):
        DesignView(np.full((1, 3, 3), np.nan), ("a",), [[0, 1, 2]])
    with pytest.raises(ValueError, match="loads"):
        DesignView(F, ("a",), [[0, 1, 2]], loads=(Load(5, (0, 0, 1)),))


def test_the_view_html_is_self_contained():
    html = view_html(get_scenario("arch").view(ROW))
    assert "http" not in html and "<link" not in html and "import " not in html
    data = re.search(r'<script type="application/json">(.*?)</script>', html, re.S).group(1)
    assert "</" not in data  # the JSON cannot close its script element


@pytest.mark.slow
def test_the_view_turns_and_folds_in_a_real_browser(tmp_path):
    import matplotlib.image
    from _browser import chromium

    html = view_html(get_scenario("arch").view(ROW), "v")
    page = tmp_path / "view.html"
    page.write_text(
        "<!DOCTYPE html><html><head><meta charset='utf-8'><style>" + view_css + "</style>"
        "</head><body style='width:900px;margin:0'>" + html
        + "<script>document.getElementById('v').viewer.set(-0.6, 0.45, 0.5);</script>"
        "</body></html>"
    )  # fmt: skip
    dom = chromium(tmp_path, "--dump-dom", page.as_uri()).stdout
    attrs = dict(re.findall(r'(data-[\w-]+)="([^"]*)"', re.search(r'<div class="viewer"[^>]*>',
                                                                  dom).group(0)))  # fmt: skip
    assert attrs["data-viewer-ready"] == "1"
    assert attrs["data-viewer-triangles"] == str(2 * 4 * 8)
    assert attrs["data-viewer-state"] == "0.5"  # half way from flat to folded, as set
    shot = tmp_path / "view.png"
    chromium(tmp_path, f"--screenshot={shot}", "--window-size=900,520", page.as_uri())
    px = matplotlib.image.imread(shot)[:440, :, :3]
    orange = (px[..., 0] > 0.8) & (px[..., 1] > 0.35) & (px[..., 1] < 0.6) & (px[..., 2] < 0.3)
    green = (px[..., 1] > 0.45) & (px[..., 0] < 0.25) & (px[..., 2] < 0.4)
    dark = px.sum(axis=2) < 0.6  # the supports' triangles
    assert orange.sum() > 100 and green.sum() > 100 and dark.sum() > 50


@pytest.mark.slow
def test_the_gripper_is_shown_closed_with_its_temperatures(tmp_path):
    """The gripper's files and view include its closed (heated) state: the same Tmax as its
    simulation, room temperature where it starts, the arm tips within the closure distance."""
    import trimesh

    from holofold.design import load_scenario
    from holofold.design.scenarios.gripper_kind import closed_gripper

    sc = load_scenario(ROOT / "examples" / "robot_gripper.toml")
    row = {"Pattern": 3.0, "L1": 4.914e-3, "L2": 2.821e-3, "t1": 2e-7, "t2": 8e-7,
           "tpanel": 2e-5, "rate": 0.476, "W": 2.65e-4}  # fmt: skip
    out = sc.evaluate(row)
    assert str(out["status"]) == "converged"
    view = sc.view(row)
    assert view.labels[0] == "flat, at room temperature"
    assert view.labels[1].startswith("closed at heating step")
    assert np.all(view.scalar[0] == 21.0)
    assert view.scalar[1].max() == pytest.approx(out["Tmax"], rel=1e-9)
    facts = dict(view.facts)
    assert facts["hottest point when closed"] == f"{out['Tmax']:.4g} degC (Tmax)"
    assert facts["heating power at closure"] == f"{out['finalQ']:.4g} W (finalQ)"
    files = sc.write_files(row, tmp_path, units="mm")
    names = {f.path.name for f in files}
    assert {"closed.stl", "closed_temperature.ply", "thick.stl", "pattern.fold"} <= names
    res, model = closed_gripper(_options(sc), row)
    closed = trimesh.load_mesh(tmp_path / "closed.stl")
    X = (res.nodes + res.displacement) * 1e3  # mm
    gap = np.linalg.norm(closed.vertices[:, None, :] - X[None], axis=2).min(axis=1)
    assert gap.max() < 1e-3  # every vertex of the file is a node of the closed state
    a, b = model.nodes.tips
    assert np.linalg.norm(X[a] - X[b]) < 1.0  # mm: the tips closed
    hot = trimesh.load_mesh(tmp_path / "closed_temperature.ply", process=False)
    rgb = np.asarray(hot.visual.vertex_colors)[:, :3].astype(int)
    T = res.temperature
    assert rgb[np.argmax(T), 0] == 255 and rgb[np.argmin(T), 2] == 255  # red hot, blue cold


def _options(sc):
    """The GripperOptions behind a gripper scenario (its view's bound argument)."""
    return sc.view.args[0]


@pytest.mark.slow
def test_the_surface_kinds_view_draws_in_a_real_browser(tmp_path):
    """The surface kind's view (issue 34: the pattern and surface kinds had no canvas): the
    shell's 36 quads drawn as 72 triangles in Chromium, the target surface's lines green."""
    import matplotlib.image
    from _browser import chromium

    from holofold.design.scenarios.files import read_scenario

    sc = read_scenario(ROOT / "examples" / "my_shell.toml")
    row = sc.complete({"m": 6.0, "n": 6.0, "tpanel": 2e-3, "tcrease": 0.45e-3, "W": 2e-3,
                       "ext": 0.7, "coverage": 0.825})  # fmt: skip
    html = view_html(sc.view(row), "v")
    assert "target surface" in html
    page = tmp_path / "view.html"
    page.write_text(
        "<!DOCTYPE html><html><head><meta charset='utf-8'><style>" + view_css + "</style>"
        "</head><body style='width:900px;margin:0'>" + html + "</body></html>"
    )  # fmt: skip
    dom = chromium(tmp_path, "--dump-dom", page.as_uri()).stdout
    attrs = dict(re.findall(r'(data-[\w-]+)="([^"]*)"', re.search(r'<div class="viewer"[^>]*>',
                                                                  dom).group(0)))  # fmt: skip
    assert attrs["data-viewer-ready"] == "1" and attrs["data-viewer-triangles"] == "72"
    shot = tmp_path / "view.png"
    chromium(tmp_path, f"--screenshot={shot}", "--window-size=900,520", page.as_uri())
    px = matplotlib.image.imread(shot)[:440, :, :3]
    green = (px[..., 1] > 0.45) & (px[..., 0] < 0.25) & (px[..., 2] < 0.4)
    orange = (px[..., 0] > 0.8) & (px[..., 1] > 0.35) & (px[..., 1] < 0.6) & (px[..., 2] < 0.3)
    assert green.sum() > 100 and orange.sum() > 20
