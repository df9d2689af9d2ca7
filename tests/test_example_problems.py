"""The worked design problems of examples/ end to end: a design, its files and a report."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from holofold.cli import main
from holofold.design import load_scenario, parse_target

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.mark.parametrize("name", ["petg_canopy", "pa12_miura_sheet", "robot_gripper"])
def test_the_example_scenarios_read(name):
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    assert sc.kind in ("strip", "sheet", "gripper")
    if sc.kind in ("strip", "sheet"):  # a printable part: its panels' overlap is a column
        assert {"overlap", "clearance", "mass"} <= set(sc.performance_names)


def test_the_canopy_curve_is_the_inkscape_path():
    """The canopy is the path "canopy" of an Inkscape drawing (mm document units, a layer
    transform): 750 mm span, its crown at 40 % of the span, 330 mm high."""
    sc = load_scenario(EXAMPLES / "petg_canopy.toml")
    curve = sc.view.args[0].curve
    import numpy as np

    p = curve(np.linspace(0, 1, 2001))
    assert p[0] == pytest.approx([0, 0], abs=1e-12)
    assert p[-1] == pytest.approx([0.75, 0.0], abs=1e-9)
    top = p[np.argmax(p[:, 1])]
    assert top[1] == pytest.approx(0.33, abs=0.01) and 0.3 < top[0] / 0.75 < 0.45


@pytest.mark.slow
def test_the_petg_canopy_ends_with_a_design_files_and_a_report(tmp_path, capsys):
    from _browser import chromium

    out = tmp_path / "canopy"
    target = "Pstiff > 1500 & error < 0.02 & Psnap == 0"
    code = main(["design", str(EXAMPLES / "petg_canopy.toml"), "--target", target, "-o", str(out),
                 "-n", "120", "--verify", "10", "--top", "2", "--rounds", "0", "--no-progress",
                 "--objective", "min mass"])  # fmt: skip
    said = capsys.readouterr().out
    s = json.loads((out / "design.json").read_text())
    assert code == (0 if s["meets_target"] else 1)
    assert s["answer"] in ("rule", "designs") and s["meets_target"] and s["buildable"]
    assert parse_target(target).evaluate(__import__("pandas").DataFrame([s["performance"]]))[0]
    assert s["objective"] == "min mass" and s["chosen"]["objective"] == s["performance"]["mass"]
    assert "chosen: " in said and s["headline"] in said
    # the lightest design meeting the target among the candidates it was chosen from
    assert all(a["performance"]["mass"] >= s["performance"]["mass"] - 1e-12
               for a in s["alternatives"] if a["source"].startswith("best inside")
               and a["rule"] == s["chosen"]["rule"])  # fmt: skip
    for key in ("printable", "fold", "svg"):
        assert (out / s["files"][key]["path"]).is_file(), key
    fab = s["fabrication"]
    assert fab["file"] == "files/printable.stl" and fab["extent_m"][0] > 0.5
    assert not fab["fits"]
    if fab["pieces"]:  # cut into bed-sized pieces, their files beside the part
        assert fab["pieces"] >= 3 and (out / fab["segments"] / "assembly.svg").is_file()
    else:  # the cut failed: the report says which bed it needs
        assert fab["problem"] and "bed of at least" in fab["advice"]
    page = (out / "report.html").read_text()
    first = page[: page.index('id="alternatives"')]  # the first screen
    for words in ("The part to print", fab["extent"], "does not fit", "print time",
                  "The chosen design in 3D", s["headline"][:60]):  # fmt: skip
        assert words.lower() in first.lower(), words
    dom = chromium(tmp_path, "--dump-dom", (out / "report.html").as_uri()).stdout
    viewer = re.search(r'<div class="viewer"[^>]*>', dom).group(0)
    assert 'data-viewer-ready="1"' in viewer
    assert int(re.search(r'data-viewer-triangles="(\d+)"', viewer).group(1)) > 0


def test_the_gripper_kinds_mass_is_the_film_of_its_pattern():
    """A uniform film (bimorph as thick as the panels) weighs density x area x thickness, the
    area being the flat pattern's faces (shoelace in the plane); the creases' bimorph adds
    length x W x (t1 + t2 - tpanel)."""
    import numpy as np

    from holofold.design.scenarios.gripper_kind import gripper_mass
    from holofold.geometry.gripper import gripper_pattern

    sc = load_scenario(EXAMPLES / "robot_gripper.toml")
    assert sc.performance_names[-1] == "mass" and sc.performance[-1].display_unit == "g"
    options = sc.view.args[0]
    rho = options.material.density
    for p in (1, 2, 3):
        row = {"Pattern": p, "L1": 5e-3, "L2": 3e-3, "t1": 4e-6, "t2": 6e-6, "tpanel": 1e-5,
               "rate": 0.4, "W": 2e-4}  # fmt: skip
        g = gripper_pattern(p, 5e-3, 3e-3, 0.4)
        xy = g.pattern.coords[:, :2]
        area = sum(0.5 * abs(np.dot(xy[f, 0], np.roll(xy[f, 1], -1))
                             - np.dot(xy[f, 1], np.roll(xy[f, 0], -1)))
                   for f in g.pattern.faces)  # fmt: skip
        assert gripper_mass(options, row) == pytest.approx(rho * area * 1e-5, rel=1e-12)
        thicker = gripper_mass(options, {**row, "t2": 16e-6})  # 1e-5 more over the creases
        e = g.pattern.edges[g.active]
        length = np.linalg.norm(np.diff(g.pattern.coords[e], axis=1)[:, 0], axis=1).sum()
        assert thicker - gripper_mass(options, row) == pytest.approx(rho * length * 2e-4 * 1e-5)
