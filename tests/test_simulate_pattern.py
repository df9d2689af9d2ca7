"""Simulating a user's crease pattern: named vertex sets, holofold simulate, the pattern kind
of scenario files (geometry/vertex_sets.py, mechanics/pattern_simulation.py,
design/scenarios/pattern_kind.py, holofold/cli/simulate.py)."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from _scenario_texts import waterbomb_scenario

import holofold.geometry as g
from holofold.cli import main
from holofold.design import read_scenario
from holofold.geometry import ParameterError, parse_vertex_set
from holofold.mechanics import (
    PatternLoad,
    PatternSetting,
    get_material,
    simulate_pattern,
    write_simulation,
)

OS = Path(__file__).parent / "data" / "origami-simulator"


def _miura(ext=0.6):
    return g.miura_sheet(4, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=ext)


# ------------------------------------------------------------------ vertex sets
def test_vertex_sets_select_sides_points_boxes_ids():
    p = _miura()
    xy = p.flat
    left = parse_vertex_set("side:-x").select(p)
    assert np.allclose(xy[left, 0], xy[:, 0].min()) and len(left) == 4
    top = parse_vertex_set("side:top").select(p)
    assert np.allclose(xy[top, 1], xy[:, 1].max())
    near = parse_vertex_set("near:50%,50%,3").select(p)
    centre = xy.min(axis=0) + 0.5 * np.ptp(xy, axis=0)
    d = np.linalg.norm(xy - centre, axis=1)
    assert set(near) == set(np.argsort(d)[:3])
    lo = xy.min(axis=0)
    box = parse_vertex_set(f"box:{lo[0]},{lo[1]},{lo[0] + 0.03},{lo[1] + 0.05}").select(p)
    inside = (xy[:, 0] <= lo[0] + 0.03 + 1e-12) & (xy[:, 1] <= lo[1] + 0.05 + 1e-12)
    assert set(box) == set(np.flatnonzero(inside))
    assert parse_vertex_set("ids:3,1,3").select(p).tolist() == [1, 3]
    assert len(parse_vertex_set("boundary").select(p)) == 2 * (4 + 3)
    for bad, why in (("side:up", "allowed"), ("near:1", "near:X,Y"), ("ids:a", "integers"),
                     ("box:0,0,1", "box:X0"), ("corner:1,2", "unknown kind"),
                     ("near:0,0,0", "integer >= 1")):  # fmt: skip
        with pytest.raises(ParameterError, match=why):
            parse_vertex_set(bad)
    with pytest.raises(ParameterError, match="selects no vertex"):
        parse_vertex_set("box:5,5,6,6").select(p)
    with pytest.raises(ParameterError, match="outside 0..19"):
        parse_vertex_set("ids:20").select(p)


# ------------------------------------------------------------------ simulate
def _cantilever_setting(**kw):
    return PatternSetting(
        material=get_material("petg"), panel_thickness=1e-3, crease_thickness=0.3e-3,
        crease_width=1e-3, fold=1.0, supports=("side:-x",),
        loads=(PatternLoad("tip", "side:+x", (0, 0, -1), 0.05, 5),), **kw,
    )  # fmt: skip


def test_simulate_a_miura_folds_and_loads():
    """A Miura sheet driven to its Ext 0.6 angles, clamped on its left edge and pushed down on
    its right: the folded state is the rigid one, and the stiffness is that of the same model
    built in that state (the fold leaves no stress: compatible targets)."""
    from holofold.mechanics import build_concentrated, load_along, secant_stiffness
    from holofold.mechanics.compat import PHYSICAL

    p = _miura()
    sim = simulate_pattern(p, _cantilever_setting())
    assert sim.fold.verdict == "folds rigidly" and sim.status.converged
    (tip,) = sim.loads
    # the same model built directly on the folded geometry
    s = build_concentrated(
        sim.fold.folded(), crease_width=1e-3, crease_thickness=0.3e-3, panel_thickness=1e-3,
        E_panel=2e9, E_crease=2e9, nu_panel=0.38, nu_crease=0.38, profile=PHYSICAL,
    )  # fmt: skip
    left, right = (parse_vertex_set(x).select(p) for x in ("side:-x", "side:+x"))
    s = s.fixed(s.vertex_nodes(left), "xyz")
    ref = secant_stiffness(s, load_along(s.vertex_nodes(right), (0, 0, -1)),
                           force_per_increment=0.01, increments=5, tol=1e-9)  # fmt: skip
    assert tip.stiffness == pytest.approx(ref.stiffness, rel=1e-5)
    line = sim.status_line()
    assert line.startswith("folds rigidly: reached 100 % of 100 %") and "tip" in line


def test_mass_is_the_thinned_flat_sheet():
    p = _miura(ext=1.0)
    s = _cantilever_setting()
    xy = p.flat
    area = 0.0
    for f in p.faces:
        q = xy[f]
        area += 0.5 * abs(
            np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(np.roll(q[:, 0], -1), q[:, 1])
        )
    e = p.edges[p.interior]
    L = np.linalg.norm(xy[e[:, 1]] - xy[e[:, 0]], axis=1).sum()
    from holofold.mechanics import pattern_mass

    assert pattern_mass(p, s) == pytest.approx(
        1270 * (area * 1e-3 + L * 1e-3 * (0.3e-3 - 1e-3)), rel=1e-12
    )


def test_supports_must_hold_the_pattern():
    with pytest.raises(ParameterError, match="loads need supports"):
        PatternSetting(loads=(PatternLoad("tip", "side:+x"),))
    bad = PatternSetting(supports=("near:0%,0%",), loads=(PatternLoad("tip", "side:+x"),))
    with pytest.raises(ParameterError, match="can still turn as a whole"):
        simulate_pattern(_miura(), bad)


def test_write_simulation_files(tmp_path):
    sim = simulate_pattern(_miura(), _cantilever_setting())
    files = write_simulation(sim, tmp_path / "out")
    names = sorted(p.name for p in files)
    assert names == ["folded.fold", "folded.obj", "folded.stl", "panels.csv", "picture.png",
                     "simulation.json"]  # fmt: skip
    fold = json.loads((tmp_path / "out" / "folded.fold").read_text())
    frames = fold["file_frames"]
    assert len(frames) == len(sim.fold.fractions) and frames[-1]["holofold:foldFraction"] == 1.0
    assert np.allclose(fold["vertices_coords"], sim.pattern.flat)  # the key frame: the CP
    last = np.array(frames[-1]["vertices_coords"])
    assert np.allclose(last, sim.fold.coords[-1])
    back = g.read_pattern(tmp_path / "out" / "folded.fold")  # the crease pattern, as simulated
    assert np.allclose(back.flat, sim.pattern.flat)
    assert np.array_equal(back.edges, sim.pattern.edges)
    with pytest.warns(g.PatternWarning, match=f"folded coordinates of frame {len(frames)} over"):
        last = g.read_pattern(tmp_path / "out" / "folded.fold", frame=len(frames))
    assert np.allclose(last.coords, sim.fold.coords[-1])
    summary = json.loads((tmp_path / "out" / "simulation.json").read_text())
    assert summary["loads"][0]["stiffness_N_m"] == pytest.approx(sim.loads[0].stiffness)
    assert summary["fold"]["verdict"] == "folds rigidly"
    rows = (tmp_path / "out" / "panels.csv").read_text().splitlines()
    assert len(rows) == 1 + sim.pattern.n_faces
    assert (tmp_path / "out" / "picture.png").stat().st_size > 20_000


# ------------------------------------------------------------------ the command
def test_simulate_command_on_svg_fold_and_dxf(tmp_path, capsys):
    """holofold simulate folds and loads a pattern from each of FOLD, SVG and DXF."""
    ezdxf = pytest.importorskip("ezdxf")
    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(OS / "waterbombBase.svg", src / "wb.svg")
    g.export(_miura(), src / "miura.fold")
    doc = ezdxf.new("R2010", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 100), (0, 100)], close=True,
                       dxfattribs={"layer": "BOUNDARY"})  # fmt: skip
    msp.add_line((50, 0), (50, 100), dxfattribs={"layer": "SCORE_V"})
    msp.add_line((0, 50), (50, 50), dxfattribs={"layer": "SCORE_M"})
    msp.add_line((50, 50), (100, 50), dxfattribs={"layer": "SCORE_M"})
    doc.saveas(src / "cp.dxf")
    runs = {
        "wb.svg": ["--fold", "0.5", "--size", "0.1", "--support", "side:-x",
                   "--load", "side:+x", "--force", "0.1"],
        "miura.fold": ["--support", "side:-x", "--load", "side:+x", "--force", "0.05"],
        "cp.dxf": ["--fold", "0.4", "--support", "side:-x", "--support", "near:50%,50%",
                   "--load", "near:100%,100%", "--direction", "0,0,1", "--force", "0.01"],
    }  # fmt: skip
    for name, extra in runs.items():
        out = tmp_path / name.replace(".", "_")
        code = main(["simulate", str(src / name), *extra, "-o", str(out)])
        text = capsys.readouterr().out
        assert code == 0, text
        summary = json.loads((out / "simulation.json").read_text())
        assert summary["fold"]["reached"] == pytest.approx(summary["setting"]["fold_fraction"])
        assert summary["loads"][0]["stiffness_N_m"] > 0
        assert "reached" in text.splitlines()[-1]


def test_simulate_command_refuses_in_one_line(tmp_path, capsys):
    code = main(["simulate", str(OS / "simpleVertex.svg"), "--frame", "1", "-o", str(tmp_path)])
    assert code == 2 and "take no --frame" in capsys.readouterr().err
    code = main(["simulate", str(OS / "simpleVertex.svg"), "--load", "side:+x", "-o",
                 str(tmp_path / "o")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "loads need supports" in err and len(err.strip().splitlines()) == 1
    code = main(["simulate", str(OS / "simpleVertex.svg"), "--material", "wood", "-o",
                 str(tmp_path / "o")])  # fmt: skip
    assert code == 2 and "known: paper" in capsys.readouterr().err


def test_contact_without_ipc_toolkit_stops_before_any_work(tmp_path, capsys, monkeypatch):
    import holofold.mechanics.pattern_simulation as sim

    monkeypatch.setattr(sim, "has_ipctk", lambda: False)
    out = tmp_path / "o"
    code = main(["simulate", str(OS / "simpleVertex.svg"), "--contact", "-o", str(out)])
    err = capsys.readouterr().err
    assert code != 0 and "pip install 'holofold[contact]'" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_contact_is_on_where_ipc_toolkit_is_and_off_where_it_is_not(tmp_path, monkeypatch):
    """The default ("auto"): the simulation folds with contact where IPC Toolkit is installed
    and without it elsewhere, and simulation.json says which; --no-contact turns it off."""
    import json

    import holofold.mechanics.pattern_simulation as sim

    monkeypatch.setattr(sim, "has_ipctk", lambda: False)
    assert PatternSetting().contact_on is False
    code = main(["simulate", str(OS / "waterbombBase.svg"), "-o", str(tmp_path / "a")])
    assert code == 0
    assert (
        json.loads((tmp_path / "a" / "simulation.json").read_text())["setting"]["contact"] is False
    )
    monkeypatch.setattr(sim, "has_ipctk", lambda: True)
    assert PatternSetting().contact_on is True and PatternSetting(contact=False).contact_on is False
    code = main(["simulate", str(OS / "waterbombBase.svg"), "--no-contact", "-o",
                 str(tmp_path / "b")])  # fmt: skip
    assert code == 0
    assert (
        json.loads((tmp_path / "b" / "simulation.json").read_text())["setting"]["contact"] is False
    )
    with pytest.raises(ParameterError, match="allowed: 'auto', True, False"):
        PatternSetting(contact="yes")


def test_a_sheet_too_small_for_its_creases_is_refused_not_given_a_negative_mass(tmp_path, capsys):
    """The issue's Miura scaled to 3 mm with 1 mm creases: the panels vanish under their hinge
    strips (before: mass -0.0045 g, 'folds rigidly'); refused in one line, nothing written."""
    src = tmp_path / "src"
    assert main(["pattern", "miura", "--m", "4", "--n", "4", "--ext", "0.7", "--gamma", "60",
                 "--size", "0.1", "-o", str(src)]) == 0  # fmt: skip
    capsys.readouterr()
    out = tmp_path / "o"
    code = main(["simulate", str(src / "pattern.fold"), "--scale", "0.03", "-o", str(out)])
    err = capsys.readouterr().err.strip()
    # a 2.9 mm sheet is warned about (its size is unlikely), then refused in one error line
    lines = err.splitlines()
    assert code == 2 and len([e for e in lines if "warning:" not in e]) == 1, err
    # the first check that fails: its 1 mm panels are thicker than a panel is wide
    assert "panel thickness 1 mm is not under panel" in lines[-1]
    assert not out.exists() or not any(out.iterdir())
    # at full size the same file folds and weighs what the thinned sheet weighs
    assert main(["simulate", str(src / "pattern.fold"), "-o", str(tmp_path / "ok")]) == 0
    assert json.loads((tmp_path / "ok" / "simulation.json").read_text())["mass_kg"] > 0


# ------------------------------------------------------------------ scenario kind
SCENARIO = waterbomb_scenario()


def test_pattern_scenario_file(tmp_path):
    shutil.copy(OS / "waterbombBase.svg", tmp_path / "wb.svg")
    (tmp_path / "wb.toml").write_text(SCENARIO, encoding="utf-8")
    sc = read_scenario(tmp_path / "wb.toml")
    assert sc.kind == "pattern"
    assert sc.feature_names == ["tpanel", "tcrease", "W", "fold", "scale"]
    assert sc.performance_names == [
        "tipstiff", "energy", "mass", "overlap", "clearance", "thick", "reached",
    ]  # fmt: skip
    row = {"tpanel": 1e-3, "tcrease": 0.3e-3, "W": 1e-3, "fold": 0.5, "scale": 1.0}
    out = sc.evaluate(row)
    assert out["status"].converged and out["reached"] == 0.5 and out["tipstiff"] > 0
    thick = sc.evaluate({**row, "tpanel": 2e-3})
    assert thick["mass"] > out["mass"]
    # mass = rho (s^2 A tpanel + s L W (tcrease - tpanel)): areas scale by s^2, lengths by s
    m1, m12, m08 = (sc.evaluate({**row, "scale": s})["mass"] for s in (1.0, 1.2, 0.8))
    a, b = np.linalg.solve([[1, 1], [1.44, 1.2]], [m1, m12])
    assert m08 == pytest.approx(0.64 * a + 0.8 * b, rel=1e-9) and b < 0 < a
    import pickle

    assert pickle.loads(pickle.dumps(sc)).evaluate(row)["tipstiff"] == out["tipstiff"]


@pytest.mark.parametrize(
    "change, message",
    [
        (('file = "wb.svg"', 'file = "nope.svg"'), "no such file"),
        (('file = "wb.svg"', 'file = "wb.svg"\nframe = 1'), "take no 'frame'"),
        (('at = "side:+x"', 'at = "side:+q"'), "side '\\+q'"),
        (('at = ["side:-x"]', 'at = ["box:5,5,6,6"]'), "selects no vertex"),
        (("fold = [0.3, 0.6]", "fold = [0.3, 1.6]"), "must lie in \\[0, 1\\]"),
        (("size = 0.1", "size = -1"), "size = -1"),
    ],
)
def test_pattern_scenario_file_refusals(tmp_path, change, message):
    shutil.copy(OS / "waterbombBase.svg", tmp_path / "wb.svg")
    (tmp_path / "bad.toml").write_text(SCENARIO.replace(*change), encoding="utf-8")
    with pytest.raises(ValueError, match=message):
        read_scenario(tmp_path / "bad.toml")


@pytest.mark.slow
def test_holofold_design_on_a_users_pattern(tmp_path, capsys):
    """A pattern scenario through the whole loop (issue 26): a design meeting the target, its
    re-simulation the same, its files written."""
    shutil.copy(OS / "waterbombBase.svg", tmp_path / "wb.svg")
    (tmp_path / "wb.toml").write_text(SCENARIO, encoding="utf-8")
    out = tmp_path / "design"
    target = "tipstiff > 1000"  # about 16 % of the feature box
    code = main(["design", str(tmp_path / "wb.toml"), "--target", target, "-n", "60",
                 "--rounds", "3", "--workers", "1", "--no-progress", "-o", str(out)])  # fmt: skip
    s = json.loads((out / "design.json").read_text())
    assert code == 0 and s["meets_target"] and s["answer"] in ("rule", "designs")
    assert s["performance"]["tipstiff"] > 1000
    again = read_scenario(tmp_path / "wb.toml").evaluate(s["features"])
    assert again["status"].converged
    assert again["tipstiff"] == pytest.approx(s["performance"]["tipstiff"], rel=1e-9)
    for key in ("fold", "svg"):
        assert (out / s["files"][key]["path"]).is_file(), key
    assert (out / "report.html").is_file()
