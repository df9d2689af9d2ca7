"""Pattern families in one registry (geometry/families.py; the sheet kind's families in
design/scenarios/sheet_families.py; holofold pattern made from the registry)."""

from __future__ import annotations

import importlib.metadata
import math

import numpy as np
import pytest

import holofold.geometry as g
from holofold.cli import main
from holofold.geometry import ParameterError, families


@pytest.fixture
def clean():
    with families.FAMILIES.saved():  # families registered by a test are gone after it
        yield families


def test_builtin_families_make_the_generators_patterns():
    names = families.family_names()
    assert names[:4] == ("miura", "tmp", "gripper", "file") and "strip" in names
    miura = families.get_family("miura").make(m=4, n=3, gamma=60.0, ext=0.6, a=0.02, b=0.03)
    ref = g.miura_sheet(4, 3, a=0.02, b=0.03, gamma=math.radians(60), ext=0.6)
    assert np.array_equal(miura.coords, ref.coords) and np.array_equal(miura.edges, ref.edges)
    tmp = families.get_family("tmp").make(m=4, n=6, size=0.2, ext=0.5)
    assert np.array_equal(tmp.coords, g.tmp_sheet(4, 6, 0.2, 0.5).coords)
    grip = families.get_family("gripper").make(kind=3, L1=0.02, L2=0.01, rate=0.5)
    assert grip.n_faces == g.gripper_pattern(3, 0.02, 0.01, 0.5).pattern.n_faces
    strip = families.get_family("strip").make(
        curve="half-circle:radius=2", m=12, offset=0.2, strip_width=0.02, extrude=0.1
    )
    assert (strip.n_vertices, strip.n_faces) == (75, 48)
    fam = families.get_family("miura")
    assert fam.node_sets["fixed"] == "side:-x"
    assert [len(f) for f in fam.faces({"m": 2, "n": 2})] == [4] * 4


def test_parameters_are_checked_in_the_callers_terms():
    fam = families.get_family("miura")
    opt = lambda n: "--" + n  # noqa: E731
    with pytest.raises(ParameterError, match=r"--gamma = 90.0 is outside .*\(0.0, 90.0\)"):
        fam.make(opt, m=2, n=2, gamma=90.0, ext=0.5, size=0.1)
    with pytest.raises(ParameterError, match="--gamma is required"):
        fam.make(opt, m=2, n=2, ext=0.5, size=0.1)
    with pytest.raises(ParameterError, match="--m is required"):
        fam.make(opt, n=2, ext=0.5, size=0.1, gamma=60.0)
    with pytest.raises(ParameterError, match="take no --L1; allowed: --m"):
        fam.make(opt, m=2, n=2, ext=0.5, size=0.1, gamma=60.0, L1=1.0)
    with pytest.raises(ParameterError, match="must be an integer"):
        fam.make(m=2.5, n=2, ext=0.5, size=0.1, gamma=60.0)


def _toy_build(v, label):
    flat = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], float) * v["side"]
    return g.CreasePattern.from_faces(np.c_[flat, np.zeros(6)], [[0, 1, 2, 3], [1, 4, 5, 2]],
                                      flat=flat)  # fmt: skip


TOY = families.PatternFamily(
    "toy", "two squares",
    (families.Parameter("side", "m", "square side", low=0.0, open_low=True, required=True),),
    _toy_build,
)  # fmt: skip


def test_a_registered_family_is_a_pattern_kind(clean, tmp_path, capsys):
    clean.register_family(TOY)
    assert "toy" in clean.family_names()
    assert main(["pattern", "toy", "--side", "0.05", "-o", str(tmp_path / "t")]) == 0
    assert "toy: 6 vertices, 1 creases, 2 panels" in capsys.readouterr().out
    assert main(["pattern", "toy", "--side", "-1", "-o", str(tmp_path / "u")]) == 2
    assert "--side = -1.0 is outside" in capsys.readouterr().err
    with pytest.raises(ValueError, match="built in"):
        clean.register_family(families.PatternFamily("miura", "", (), _toy_build))


def test_entry_point_families(monkeypatch, clean):
    group = families.ENTRY_POINT_GROUP
    eps = importlib.metadata.EntryPoints(
        [importlib.metadata.EntryPoint("broken", "holofold_no_such_module:F", group)]
    )
    real = importlib.metadata.entry_points
    monkeypatch.setattr(
        importlib.metadata, "entry_points",
        lambda **kw: eps if kw.get("group") == group else real(**kw),
    )  # fmt: skip
    assert "broken" in families.family_names() and "broken" not in families.pattern_families()
    with pytest.raises(ParameterError, match="holofold_no_such_module:F.*cannot be loaded"):
        families.get_family("broken")
    with pytest.raises(ParameterError, match="unknown pattern family 'nope'; known: miura"):
        families.get_family("nope")


def test_sheet_scenarios_ask_their_families():
    from holofold.design.scenarios.sheet import PATTERNS, SheetSetting, check_sheet, sheet_shape
    from holofold.design.scenarios.sheet_families import SHEET_FAMILIES

    assert PATTERNS == {"miura": 1, "tmp": 2} and set(SHEET_FAMILIES) == {1, 2}
    setting = SheetSetting(gamma=None)
    row = {"pattern": 2, "m": 24, "n": 6, "tcrease": 1e-3, "tpanel": 2e-3, "W": 2e-3}
    assert check_sheet(setting, row) == []
    assert check_sheet(setting, {**row, "m": 25}) == ["m = 25 must be even for a TMP sheet"]
    assert "TMP tubes overlap" in check_sheet(setting, {**row, "m": 4})[0]
    assert check_sheet(setting, {**row, "pattern": 1.5})[0].startswith("pattern = 1.5 must be 1")
    miura = sheet_shape(setting, {**row, "pattern": 1, "gama": 1.2}, 0.7)
    assert miura.meta["kind"] == "miura" and miura.n_faces == 24 * 6
