"""The sheet and gripper kinds of scenario files (docs/scenarios.md, "Scenario files").

The shipped files reproduce the paper's Python scenarios bit for bit on fixed published rows;
user files change the outputs in the physically right direction; bad files are refused in one
line naming the key and what is allowed; every scenario survives pickling.
"""

from __future__ import annotations

import math
import pickle

import cloudpickle
import numpy as np
import pytest

from holofold.design.scenarios import get_scenario
from holofold.design.scenarios.files import ScenarioFileError, read_scenario, shipped_text
from holofold.geometry.tmp import tmp_nodes

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

GRIPPER_ROWS = {  # label: (published file, row), quick rows
    "miura-based": ("data2_MiuraBased_sample", 2),
    "two-panel": ("data2_TwoPanel_sample", 1),
}


def _file(tmp_path, text, name="mine.toml"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def _shipped(name):
    from holofold.design.scenarios.files import shipped_scenarios

    return read_scenario(shipped_scenarios()[name])


def _rows(reference_data, sc, stem, index):
    d = reference_data.load(stem)
    feats = [c for c in sc.feature_names if c in d.columns]
    return [sc.complete(d.iloc[i][feats].to_dict()) for i in index]


def _same(a, b, columns):
    for c in columns:
        assert a[c] == b[c], c  # bit for bit
    assert str(a["status"]) == str(b["status"])


# ---------------------------------------------------------------------- shipped files
def test_shipped_canopy_is_the_python_canopy(reference_data):
    toml, py = _shipped("canopy"), get_scenario("canopy")
    assert toml.kind == "sheet" and toml.features == py.features
    assert toml.categorical == py.categorical
    assert toml.performance_names == [
        *py.performance_names,
        "mass",
        "overlap",
        "clearance",
        "thick",
    ]
    rows = _rows(reference_data, py, "data1_MiuraSheet_sample", [0])
    rows += _rows(reference_data, py, "data1_TMPSheet_sample", [0])
    rows += _rows(reference_data, py, "data4_TMPSheetMat_sample", [0])  # creaseE, panelE
    assert rows[2]["creaseE"] != 2e9
    for row in rows:
        _same(toml.evaluate(row), py.evaluate(row), py.performance_names)


def test_shipped_single_miura_is_the_python_cell(reference_data):
    toml, py = _shipped("single-miura"), get_scenario("single-miura")
    assert toml.features == py.features and toml.feature_names == ["tcrease", "tpanel", "W", "gama"]
    d = reference_data.load("data0_SingleMiura")
    rows = _rows(reference_data, py, "data0_SingleMiura", range(0, len(d), len(d) // 10))
    for row in rows:
        a, b = toml.evaluate(row), py.evaluate(row)
        _same(a, b, py.performance_names)
        assert a["mass"] > 0


@pytest.fixture(scope="module")
def gripper_rows(reference_data):
    """label -> (row, the Python scenario's outputs)."""
    py = get_scenario("gripper")
    out = {}
    for label, (stem, i) in GRIPPER_ROWS.items():
        row = _rows(reference_data, py, stem, [i])[0]
        out[label] = row, py.evaluate(row)
    return out


@pytest.mark.slow
def test_shipped_gripper_is_the_python_gripper(gripper_rows):
    toml, py = _shipped("gripper"), get_scenario("gripper")
    assert toml.kind == "gripper" and toml.features == py.features
    assert toml.performance_names == [*py.performance_names, "mass"]  # the kind adds mass
    for row, ref in gripper_rows.values():
        _same(toml.evaluate(row), ref, py.performance_names)


@pytest.mark.slow
def test_converged_true_is_the_converged_scenario(tmp_path, gripper_rows):
    text = shipped_text("gripper").replace("converged = false", "converged = true", 1)
    toml = read_scenario(_file(tmp_path, text))
    row = gripper_rows["two-panel"][0]
    py = get_scenario("gripper-converged")
    _same(toml.evaluate(row), py.evaluate(row), py.performance_names)


# ---------------------------------------------------------------------- user sheets
USER_SHEET = """
kind = "sheet"
name = "awning"

[sheet]
size_x = 0.3
size_y = 0.15
gamma_deg = 60.0
extensions = [0.5, 0.8]
pattern = "miura"

[material]
E = {E}
density = 900.0

[[load]]
name = "lift"
direction = [0, 0, 1]
force = {force}
increments = 2

[features]
m = {{choices = [12, 16]}}
n = {{choices = [6]}}
"""
SHEET_ROW = dict(m=12.0, n=6.0, tcrease=8e-4, tpanel=2e-3, W=2e-3)


def _user_sheet(tmp_path, E=2e9, force=3.0, name="mine.toml"):
    return read_scenario(_file(tmp_path, USER_SHEET.format(E=E, force=force), name))


def test_user_sheet_columns_and_linear_scaling(tmp_path):
    sc = _user_sheet(tmp_path)
    assert sc.performance_names == [
        "liftstiff50", "liftstiff80", "mass", "overlap", "clearance", "thick",
    ]  # fmt: skip
    assert sc.feature_names == ["m", "n", "tcrease", "tpanel", "W"]  # pattern fixed, no moduli
    assert sc.categorical == ("m", "n")
    assert sc.setting["footprint (m)"] == "0.3 x 0.15"
    row = sc.complete(SHEET_ROW)
    assert sc.check(row) == []
    base = sc.evaluate(row)
    assert str(base["status"]) == "converged"
    assert 0 < base["liftstiff80"] < base["liftstiff50"]  # the flatter sheet bends more easily
    # every stiffness is proportional to E: twice E and twice the force give the same path
    both = _user_sheet(tmp_path, E=4e9, force=6.0, name="both.toml").evaluate(row)
    for c in ("liftstiff50", "liftstiff80"):
        assert both[c] / base[c] == pytest.approx(2.0, rel=1e-9), c
    # twice E under the same small force: (nearly) linear, so (nearly) twice as stiff
    small = _user_sheet(tmp_path, force=1e-3, name="s.toml").evaluate(row)
    stiff = _user_sheet(tmp_path, E=4e9, force=1e-3, name="t.toml").evaluate(row)
    for c in ("liftstiff50", "liftstiff80"):
        assert stiff[c] / small[c] == pytest.approx(2.0, rel=1e-3), c
    assert stiff["mass"] == base["mass"]


def test_sheet_overlap_and_clearance_at_the_most_folded_state(tmp_path):
    """Thick panels collide where creases are narrow for their thickness (W = t: they overlap
    at Ext 0.5), not where the hinges are wide (W = 6 t: apart, with a positive gap); the
    overlap only grows as the hinges narrow."""
    from holofold.design.scenarios.sheet import sheet_shape
    from holofold.geometry import printability

    text = USER_SHEET.format(E=2e9, force=3.0).replace('name = "awning"', _CENTRED)
    sc = read_scenario(_file(tmp_path, text, "centred.toml"))
    assert sc.performance[3].display_unit == "mm^3" and sc.performance[4].display_unit == "mm"
    rows = [sc.complete({**SHEET_ROW, "tpanel": 1e-3, "W": w}) for w in (1e-3, 2e-3, 6e-3)]
    out = [sc.evaluate(r) for r in rows]
    ov = [o["overlap"] for o in out]
    assert ov[0] > ov[1] > 0 and ov[2] == 0.0
    assert [o["thick"] for o in out] == [0, 0, 0]
    assert out[2]["clearance"] > 0 and out[0]["clearance"] < out[2]["clearance"]
    # at the sheet's smallest extension (0.5), where it is most folded: the 0.8 state overlaps less
    flatter = printability(sheet_shape(_setting(sc), rows[1], 0.8), 1e-3, 2e-3).overlap
    assert flatter < ov[1]


_CENTRED = 'name = "awning"\nthick = "centred"'


def test_sheet_thick_auto_keeps_the_first_technique_that_folds_clear(tmp_path):
    """thick = "auto" (the default): where centred panels overlap folded to Ext 0.5 (W = t),
    offset panels fold from flat to 0.5 without any overlap at five states, and the row says
    so (thick 1, overlap 0, clearance a lower bound one thickness below the centred one);
    where centred panels are clear (W = 6 t) they are kept (thick 0, the same numbers)."""
    from holofold.design.scenarios.sheet import sheet_fold_path
    from holofold.geometry.thick import path_overlap, thick_panels

    auto = _user_sheet(tmp_path)
    text = USER_SHEET.format(E=2e9, force=3.0).replace('name = "awning"', _CENTRED)
    centred = read_scenario(_file(tmp_path, text, "centred.toml"))
    rows = [auto.complete({**SHEET_ROW, "tpanel": 1e-3, "W": w}) for w in (1e-3, 6e-3)]
    a = [auto.evaluate(r) for r in rows]
    c = [centred.evaluate(r) for r in rows]
    assert c[0]["overlap"] > 1e-12 and a[0]["thick"] == 1 and a[0]["overlap"] == 0.0
    assert a[0]["clearance"] == pytest.approx(c[0]["clearance"] - 1e-3, abs=1e-12)
    assert a[1]["thick"] == 0 and a[1]["overlap"] == c[1]["overlap"] == 0.0
    assert a[1]["clearance"] == c[1]["clearance"] > 0
    for k in ("liftstiff50", "liftstiff80", "mass"):  # the mechanics do not change
        assert a[0][k] == c[0][k]
    state, way = sheet_fold_path(_setting(auto), rows[0])
    panels = thick_panels(state, 1e-3, 1e-3, "offset", path=way)
    assert path_overlap([*way, state], panels).volume.max() == 0.0
    assert path_overlap([*way, state], thick_panels(state, 1e-3, 1e-3)).volume.max() > 0


def _setting(sc):
    """The SheetSetting behind a sheet scenario (its evaluator's first bound argument)."""
    return sc.evaluate_batch.args[0]


def test_sheet_mass_is_the_formula(tmp_path):
    sc = _user_sheet(tmp_path)
    row = sc.complete(SHEET_ROW)
    m, n, g = 12, 6, math.radians(60.0)
    b = 0.3 / m
    a = (0.15 - b / math.tan(g)) / n
    area = m * n * a * b * math.sin(g)  # parallelogram panels
    folds = (m - 1) * n * a + m * (n - 1) * b  # interior creases of sides a and b
    tp, tc, W = row["tpanel"], row["tcrease"], row["W"]
    mass = 900.0 * (area * tp + folds * W * (tc - tp))
    assert sc.evaluate(row)["mass"] == pytest.approx(mass, rel=1e-12)
    # uniform thickness: mass = density x area x t; a flat TMP sheet is its footprint less a
    # notch of a b / 4 at both ends of each of its m strips (the B columns are a/2 shorter)
    text = USER_SHEET.format(E=2e9, force=3.0).replace('"miura"', '"tmp"')
    text = text.replace("gamma_deg = 60.0\n", "").replace("[6]", "[3, 6]")
    tmp = read_scenario(_file(tmp_path, text, "tmp.toml"))
    row = tmp.complete({**SHEET_ROW, "n": 3.0, "tcrease": 2e-3})
    assert tmp.check(row) == []
    area = 0.3 * 0.15 - 12 * 2 * (0.15 / 3) * (0.3 / 12) / 4
    assert tmp.evaluate(row)["mass"] == pytest.approx(900.0 * area * 2e-3, rel=1e-12)


@pytest.mark.filterwarnings("ignore::holofold.geometry.solid.SolidWarning")
def test_user_sheet_shape_and_files(tmp_path):
    sc = _user_sheet(tmp_path)
    row = sc.complete(SHEET_ROW)
    p = sc.shape(row)
    assert p.n_faces == 12 * 6 and p.meta["ext"] == 0.8  # the least folded state
    assert np.ptp(p.coords[:, 0]) == pytest.approx(0.3 * 0.8 * math.sin(math.radians(60)))
    files = sc.write_files(row, tmp_path / "out")
    assert [f.path.name for f in files] == [
        "printable.stl", "printable_folded.stl", "pattern.fold", "pattern.svg", "pattern.dxf",
        "folded.stl", "folded.obj", "thick.stl",
    ]  # fmt: skip
    with open(files["surface_stl"].path, "rb") as fh:
        assert b"mm" in fh.read(80)  # the STL header states the unit
    assert all(f.path.is_file() and f.path.stat().st_size > 0 for f in files)
    # 6 mm panels folded to 0.3 overlap: every file but the thick solid, and a warning
    text = USER_SHEET.format(E=2e9, force=3.0).replace("[0.5, 0.8]", "[0.3]")
    folded = read_scenario(_file(tmp_path, text.replace('name = "awning"', _CENTRED),
                                 "folded.toml"))  # fmt: skip
    with pytest.warns(UserWarning, match="no thick.stl: the thick panels"):
        files = folded.write_files(folded.complete({**SHEET_ROW, "tpanel": 6e-3}), tmp_path / "f")
    assert [f.key for f in files] == ["fold", "svg", "dxf", "surface_stl", "surface_obj"]
    assert "no solids" in files.notes[-1]


def test_rectangular_tmp_nodes_repeat_the_geometry_formulas():
    for m, n, L, ext in [(24, 6, 0.2, 0.3), (30, 12, 0.2, 0.9), (4, 3, 1.0, 0.55)]:
        assert np.array_equal(tmp_nodes(m, n, L, ext, L), tmp_nodes(m, n, L, ext))
    X = tmp_nodes(4, 3, 0.4, 1.0, 0.2)  # flat: the footprint
    assert np.ptp(X[:, 0]) == pytest.approx(0.4) and np.ptp(X[:, 1]) == pytest.approx(0.2)
    assert np.abs(X[:, 2]).max() == 0.0


def test_sheet_checks_refuse_impossible_designs(tmp_path):
    sc = _user_sheet(tmp_path)
    assert any("tpanel" in e for e in sc.check(sc.complete({**SHEET_ROW, "tpanel": -1.0})))
    text = USER_SHEET.format(E=2e9, force=3.0).replace('"miura"', '"tmp"')
    text = text.replace("gamma_deg = 60.0\n", "").replace("[6]", "[3, 6]")
    tmp = read_scenario(_file(tmp_path, text, "t.toml"))
    assert tmp.check({**SHEET_ROW, "n": 3.0}) == []
    # n = 6: a = 0.025 m < 2 b sqrt(1 - 0.5^2) = 0.043 m, the folded tubes overlap
    errs = tmp.check({**SHEET_ROW, "n": 6.0})
    assert len(errs) == 1 and "overlap at Ext = 0.5" in errs[0], errs
    assert any("even" in e for e in tmp.check({**SHEET_ROW, "m": 13.0, "n": 3.0}))


# ---------------------------------------------------------------------- user grippers
USER_GRIPPER = shipped_text("gripper")


def _gripper(tmp_path, old, new, name):
    assert old in USER_GRIPPER
    return read_scenario(_file(tmp_path, USER_GRIPPER.replace(old, new, 1), name))


@pytest.mark.slow
def test_user_gripper_material_changes_the_right_outputs(tmp_path, gripper_rows):
    row, ref = gripper_rows["two-panel"]
    heavy = _gripper(tmp_path, "density = 1200.0", "density = 4800.0", "heavy.toml")
    assert heavy.setting["density (kg/m^3)"] == 4800.0
    out = heavy.evaluate(row)
    # density enters the mass of step A only: freqFinal halves, nothing else moves
    assert out["freqFinal"] / ref["freqFinal"] == pytest.approx(0.5, rel=1e-9)
    for c in ("finalQ", "Tmax", "stiff"):
        assert out[c] == ref[c], c
    # twice the bimorph mismatch folds twice as far per kelvin: it closes with less heat
    eager = _gripper(tmp_path, "d_alpha = 50e-6", "d_alpha = 100e-6", "eager.toml")
    out = eager.evaluate(row)
    assert out["freqFinal"] == ref["freqFinal"]
    assert out["finalQ"] < ref["finalQ"] and out["Tmax"] < ref["Tmax"]


def test_gripper_shape_and_files(tmp_path):
    sc = _shipped("gripper")
    row = dict(Pattern=3.0, L1=5e-3, L2=3e-3, t1=2e-7, t2=8e-7, tpanel=2e-5, rate=0.4, W=2e-4)
    p = sc.shape(row)
    assert np.abs(p.coords[:, 2]).max() == 0.0  # flat
    files = sc.write_files(row, tmp_path / "g")
    assert {"pattern.fold", "pattern.svg", "thick.stl"} <= {f.path.name for f in files}


# ---------------------------------------------------------------------- refusals
CANOPY = shipped_text("canopy")
GRIPPER = shipped_text("gripper")
BAD = [
    # (case, base text, old, new, words the one-line message must contain)
    ("sheet key", CANOPY, "size_y = 0.2", "size_z = 0.2", ["[sheet]", "'size_z'", "size_y"]),
    ("material key", CANOPY, "nu = 0.3", "poisson = 0.3", ["[material]", "'poisson'", "nu"]),
    ("supports key", CANOPY, 'dofs = "xyz"', 'nodes = "ends"', ["[supports]", "'nodes'", "dofs"]),
    ("solver key", CANOPY, "tol = 1e-7", "tolerance = 1e-7", ["[solver]", "'tolerance'", "tol"]),
    ("load key", CANOPY, "increments = 3", "steps = 3", ["[load] 1", "'steps'", "increments"]),
    ("feature key", CANOPY, "W = [", "Wc = [", ["[features]", "'Wc'", "tcrease"]),
    ("top key", CANOPY, 'kind = "sheet"', 'kind = "sheet"\ncolour = 1', ["'colour'", "kind"]),
    ("low >= high", CANOPY, "tpanel = [1.0e-3, 6.0e-3]", "tpanel = [6e-3, 1e-3]",
     ["[features]", "tpanel", "low must be < high"]),
    ("sheet pattern", CANOPY, "# pattern = \"miura\"", 'pattern = "kresling"',
     ["[sheet]", "pattern = 'kresling'", "allowed: miura, tmp"]),
    ("feature pattern", CANOPY, "pattern = { choices = [1, 2] }", "pattern = { choices = [1, 3] }",
     ["[features] pattern", "1 (Miura-ori), 2 (TMP)"]),
    ("extension", CANOPY, "[0.3, 0.6, 0.9]", "[0.3, 0.6, 1.5]",
     ["[sheet]", "extensions", "(0, 1]"]),
    ("extension tag", CANOPY, "[0.3, 0.6, 0.9]", "[0.3, 0.301]",
     ["[sheet]", "extensions", "same column tag 30"]),
    ("density", CANOPY, "density = 1200.0", "density = -1", ["[material]", "density", "(0, inf]"]),
    ("tmp m", CANOPY, "m = { choices = [24, 30, 36] }", "m = { choices = [24, 25] }",
     ["[features] m", "even"]),
    ("miura a", CANOPY, "gamma_deg = 70.0", "gamma_deg = 2.0",
     ["[features] m = 24", "allowed: m tan(gamma) > size_x/size_y = 1"]),
    ("gama twice", CANOPY, "W = [", "gama = [0.9, 1.2]\nW = [", ["[features]", "gama", "fixed"]),
    ("direction", CANOPY, "direction = [0, 0, -1]", "direction = [0, 0]",
     ["[load] 1", "direction", "3-vector"]),
    ("g material key", GRIPPER, "k_panel = 0.3", "k_pane = 0.3",
     ["[material]", "'k_pane'", "k_panel"]),
    ("g environment key", GRIPPER, "k_air = 0.026", "k_ai = 0.026", ["[environment]", "k_air"]),
    ("g heating key", GRIPPER, "q_load = 0.1", "power = 0.1", ["[heating]", "'power'", "q_load"]),
    ("g solver", GRIPPER, "converged = false", 'converged = "yes"',
     ["[solver]", "converged", "true or false"]),
    ("g feature key", GRIPPER, "rate = [", "ratio = [", ["[features]", "'ratio'", "rate"]),
    ("g low >= high", GRIPPER, "L1 = [3e-3, 7e-3]", "L1 = [7e-3, 7e-3]",
     ["[features]", "L1", "low must be < high"]),
    ("g pattern", GRIPPER, "choices = [1, 2, 3]", "choices = [1, 4]",
     ["[features] Pattern", "1 (Miura-based), 2 (splitted Miura), 3 (two-panel)"]),
    ("g density", GRIPPER, "density = 1200.0", "density = -5.0",
     ["[material]", "density", "(0, inf]"]),
    ("g rate", GRIPPER, "rate = [0.2, 0.6]", "rate = [0.2, 1.2]", ["[features] rate", "< 1"]),
]  # fmt: skip


@pytest.mark.parametrize("case, base, old, new, words", BAD, ids=[b[0] for b in BAD])
def test_bad_files_are_refused_in_one_line(tmp_path, case, base, old, new, words):
    assert old in base
    with pytest.raises(ScenarioFileError) as err:
        read_scenario(_file(tmp_path, base.replace(old, new, 1), "bad.toml"))
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("bad.toml"), msg
    for w in words:
        assert w in msg, (w, msg)


# ---------------------------------------------------------------------- pickling
def test_sheet_scenarios_pickle(tmp_path):
    for sc in (_user_sheet(tmp_path), _shipped("single-miura")):
        back = pickle.loads(cloudpickle.dumps(sc))
        row = sc.complete(SHEET_ROW if sc.name == "awning" else dict(SHEET_ROW, gama=1.1))
        a, b = sc.evaluate(row), back.evaluate(row)
        _same(a, b, sc.performance_names)
        assert back.setting == sc.setting and back.features == sc.features


@pytest.mark.slow
def test_gripper_scenario_pickles(gripper_rows):
    sc = _shipped("gripper")
    back = pickle.loads(cloudpickle.dumps(sc))
    row, ref = gripper_rows["two-panel"]
    _same(back.evaluate(row), ref, [c for c in sc.performance_names if c != "mass"])
    assert back.evaluate(row)["mass"] == sc.evaluate(row)["mass"] > 0
