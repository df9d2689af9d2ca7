"""Scenario and option mistakes refused once, before any row (issue 33 item 6)."""

import math
import shutil
from pathlib import Path

import pytest
from _scenario_texts import waterbomb_scenario

import holofold.geometry as g
from holofold.geometry.bed import Bed
from holofold.geometry.cutter import cutter_drawing
from holofold.geometry.errors import ParameterError

OS = Path(__file__).parent / "data" / "origami-simulator"


def _scenario(tmp_path, at):
    from holofold.design import read_scenario

    shutil.copy(OS / "waterbombBase.svg", tmp_path / "wb.svg")
    (tmp_path / "wb.toml").write_text(waterbomb_scenario(at), encoding="utf-8")
    return read_scenario(tmp_path / "wb.toml")


def test_pattern_scenario_with_too_few_supports_refused_once(tmp_path):
    assert _scenario(tmp_path, "side:-x").name == "waterbomb"
    with pytest.raises(ValueError, match="supports hold 1 vertex"):
        _scenario(tmp_path, "near:0%,0%")


@pytest.mark.parametrize("text", ["1e308x1e308", "20000x200"])
def test_bed_beyond_any_printer_refused(text):
    with pytest.raises(ParameterError, match="no printer's bed"):
        Bed.parse(text)
    assert Bed.parse("250x210").width == pytest.approx(0.25, rel=1e-12)


@pytest.mark.parametrize("what", ["gap", "dash", "vertex_gap"])
def test_sub_micrometre_cutter_lengths_refused(what):
    p = g.miura_sheet(3, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=1.0)
    kw = {"dash": 2.0, "gap": 1.0, "vertex_gap": 0.5, what: 1e-308}
    with pytest.raises(ParameterError, match="finer than any cutter"):
        cutter_drawing(p, g.get_profile("laser"), **kw)


def test_thick_offset_without_thickness_refused(tmp_path, capsys):
    from holofold.cli import main

    args = ["pattern", "miura", "--m", "3", "--n", "3", "--size", "0.1", "--ext", "0.7"]
    code = main([*args, "--gamma", "60", "--thick", "offset", "-o", str(tmp_path / "o")])
    assert code == 2 and "needs --thickness" in capsys.readouterr().err
    assert not (tmp_path / "o" / "pattern.fold").exists()


def test_sheet_whose_creases_are_wider_than_any_panel_refused_once(tmp_path):
    # "1 m panels on a 6 cm sheet": crease widths 5-8 cm on a 6 cm sheet of 8-16 panels
    # (panels at most 7.5 mm across) made every row a failed row, exit 0
    from holofold.design import read_scenario

    text = (Path(__file__).parents[1] / "examples" / "pa12_miura_sheet.toml").read_text()
    text = text.replace("size_x = 0.2 ", "size_x = 0.06").replace("size_y = 0.2", "size_y = 0.06")
    path = tmp_path / "six.toml"
    path.write_text(text.replace("W = [4.0e-3, 8.0e-3]", "W = [0.05, 0.08]"))
    with pytest.raises(ValueError, match=r"as wide as the widest panel of any design \(0.0075 m"):
        read_scenario(path)
    path.write_text(text.replace("W = [4.0e-3, 8.0e-3]", "W = [1e-3, 2e-3]"))
    assert read_scenario(path).name == "pa12-miura-sheet"  # narrower creases: a scenario
