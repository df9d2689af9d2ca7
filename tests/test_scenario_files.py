"""Scenario files (TOML) and the strip kind: the paper's arch as a file, a user's own strip."""

from __future__ import annotations

import math
import pickle
import tomllib

import cloudpickle
import numpy as np
import pytest

from holofold.cli import main
from holofold.design import load_scenario, read_scenario, shipped_scenarios, shipped_text
from holofold.design.scenarios import ScenarioFileError, get_scenario
from holofold.design.scenarios.strip import loaded_node, strip_model
from holofold.fitting import builtin_curve, fit_strip
from holofold.mechanics import load_along, load_group

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

ROW = {"m": 12, "offset": 0.2, "stripeWidth": 0.02, "extrude": 0.1,
       "tcrease": 8e-4, "tpanel": 2e-3, "W": 3e-3}  # fmt: skip


def _user_file(tmp_path, body: str, name: str = "mine.toml"):
    p = tmp_path / name
    p.write_text(body)
    return p


CATENARY = """
kind = "strip"
name = "catenary"
[curve]
points = "cat.csv"
units = "mm"
[material]
E = 3.0e9
density = 1000.0
[[load]]
name = "V"
at = 0.5
direction = [0, 0, -1]
force = 2.0
increments = 2
snap_displacement = 0.5
[features]
m = { choices = [8, 12] }
offset = [0.05, 0.15]
extrude = 0.1
"""


def _catenary_csv(tmp_path, scale=1000.0):
    c = builtin_curve("catenary", span=3.0, height=1.0)
    pts = c(np.linspace(0, 1, 61)) * scale
    np.savetxt(tmp_path / "cat.csv", pts, delimiter=",", header="x,z", comments="")


def test_shipped_arch_file_is_bit_identical_to_the_arch_scenario(reference_data):
    d = reference_data.load("data3_ShapeFit")
    snapping = np.flatnonzero(d["Zsnap"].to_numpy() == 1)[:2]
    idx = np.union1d(np.linspace(0, len(d) - 1, 6).astype(int), snapping)
    arch, toml = get_scenario("arch"), read_scenario(shipped_scenarios()["arch"])
    assert toml.kind == "strip" and toml.name == "arch"
    for i in idx:
        row = arch.complete(d.iloc[i].to_dict())
        a, b = arch.evaluate(row), toml.evaluate(row)
        for c in ("Zstiff", "Zsnap", "Xstiff", "error"):
            assert a[c] == b[c], (i, c)  # bit for bit
        assert str(a["status"]) == str(b["status"])
        # and both still reproduce the published row
        assert b["Zsnap"] == d["Zsnap"].iloc[i]
        assert b["error"] == pytest.approx(d["error"].iloc[i], rel=1e-6)
    assert {"closest_error", "mass"} <= set(toml.performance_names)


def test_shipped_text_reads_back_as_toml_and_names_are_listed(capsys):
    text = shipped_text("arch")
    assert tomllib.loads(text)["kind"] == "strip"
    assert main(["scenarios", "show", "arch"]) == 0
    assert capsys.readouterr().out == text
    assert main(["scenarios"]) == 0
    listing = capsys.readouterr().out
    assert "arch" in listing and "canopy" in listing and "gripper" in listing
    assert main(["scenarios", "show", "nope"]) == 2


def test_user_strip_from_a_csv_in_mm(tmp_path):
    _catenary_csv(tmp_path)
    sc = read_scenario(_user_file(tmp_path, CATENARY))
    assert sc.performance_names == [
        "Vstiff", "Vsnap", "error", "closest_error", "mass", "overlap", "clearance", "thick"
    ]  # fmt: skip
    assert sc.categorical == ("m",)
    cols = {c.name: c for c in sc.features}
    assert cols["offset"].low == 0.05 and cols["offset"].high == 0.15
    assert cols["extrude"].low == cols["extrude"].high == 0.1  # fixed
    assert cols["tpanel"].low == 1e-3  # default range kept
    curve = sc.shape.args[0].curve
    ref = builtin_curve("catenary", span=3.0, height=1.0)
    assert curve.length == pytest.approx(ref.length, rel=1e-4)  # mm read as mm
    row = {**ROW, "offset": 0.08}
    out = sc.evaluate(row)
    assert out["status"].converged and out["Vstiff"] > 0 and out["Vsnap"] == 0.0
    assert 0 < out["closest_error"] <= out["error"] * 1.5
    # the same file in metres gives the same strip
    _catenary_csv(tmp_path, scale=1.0)
    sc_m = read_scenario(_user_file(tmp_path, CATENARY.replace('"mm"', '"m"'), "m.toml"))
    assert sc_m.evaluate(row)["Vstiff"] == pytest.approx(out["Vstiff"], rel=1e-9)


def test_load_position_snaps_to_the_nearest_centre_line_vertex():
    sc = read_scenario(shipped_scenarios()["arch"])
    setting = sc.shape.args[0]
    for m in (8, 12):
        assert loaded_node(setting, m, 0.5) == m  # the apex
        assert loaded_node(setting, m, 0.25) == m // 2  # a quarter of the half circle
        assert loaded_node(setting, m, 0.0) == 0 and loaded_node(setting, m, 1.0) == 2 * m


def test_load_along_an_axis_is_the_axis_group_and_oblique_loads_project():
    a, b = load_along([3, 4], (0, 0, -2.0)), load_group([3, 4], "-z")
    assert (a.axis, a.sign, a.vector) == (b.axis, b.sign, None)
    o = load_along([1], (3.0, 0.0, 4.0))
    F = o.load(5, 10.0)
    assert np.allclose(F[1], [6.0, 0.0, 8.0]) and np.allclose(np.delete(F, 1, 0), 0)
    U = np.zeros((5, 3))
    U[1] = [1.0, 7.0, 1.0]
    assert o.displacements(U) == pytest.approx([1.4])


def test_oblique_loads_follow_the_linear_compliance(tmp_path):
    """Under a small load the compliance along a unit d is d^T C d, so the two diagonals
    (1, 0, -1) and (1, 0, 1) together give exactly C_xx + C_zz, coupling and all."""
    body = shipped_text("arch").replace("force = 5.0", "force = 1e-3")
    for name, d in (("A", "[1, 0, -1]"), ("B", "[1, 0, 1]")):
        body += f"\n[[load]]\nname = '{name}'\nat = 0.5\ndirection = {d}\nforce = 1e-3\n"
    out = read_scenario(_user_file(tmp_path, body)).evaluate(ROW)
    k = {c: out[f"{c}stiff"] for c in "ZXAB"}
    assert 1 / k["A"] + 1 / k["B"] == pytest.approx(1 / k["X"] + 1 / k["Z"], rel=1e-5)
    assert abs(1 / k["A"] - 1 / k["B"]) > 1e-6 * (1 / k["A"])  # the coupling is really there


def test_supports_choice_fixes_the_named_nodes(tmp_path):
    body = shipped_text("arch").replace('nodes = "ends"', 'nodes = "centre-ends"')
    body = body.replace('dofs = "xyz"', 'dofs = "xz"')
    sc = read_scenario(_user_file(tmp_path, body))
    s, g, _ = strip_model(sc.shape.args[0], ROW)
    fixed = np.flatnonzero(s.supports.any(axis=1))
    assert fixed.tolist() == [0, 2 * g.m]
    assert s.supports[fixed].tolist() == [[True, False, True]] * 2


def test_mass_is_density_times_the_flat_sheet_volume():
    sc = read_scenario(shipped_scenarios()["arch"])
    row = {**ROW, "tcrease": 2e-3, "tpanel": 2e-3}  # uniform sheet: mass = rho * area * t
    fit = fit_strip(builtin_curve("half-circle", radius=2.0), 12, 0.2, 0.02, 0.1, sampling="paper")
    flat = fit.flat_pattern.flat
    area = 0.0
    for f in fit.pattern.faces:
        x, y = flat[f, 0], flat[f, 1]
        area += 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert sc.evaluate(row)["mass"] == pytest.approx(1200.0 * area * 2e-3, rel=2e-3)
    thin = sc.evaluate({**row, "tcrease": 1e-3})["mass"]
    assert thin < sc.evaluate(row)["mass"]  # thinned along the hinge strips


def test_scenario_pickles_for_worker_processes():
    sc = read_scenario(shipped_scenarios()["arch"])
    back = pickle.loads(cloudpickle.dumps(sc))
    assert back.evaluate(ROW)["Zstiff"] == sc.evaluate(ROW)["Zstiff"]
    assert len(cloudpickle.dumps(sc)) < 20_000  # the curve's dense cache is not shipped


def test_load_scenario_takes_names_paths_and_objects():
    sc = get_scenario("arch")
    assert load_scenario(sc) is sc and load_scenario("arch") is sc
    assert load_scenario(str(shipped_scenarios()["arch"])).kind == "strip"
    with pytest.raises(ValueError, match="or a scenario file"):
        load_scenario("arc")


FILE_CURVE = 'points = "{}"\nunits = "{}"'
#: (id, text replaced in the shipped arch file, replacement, expected message)
BAD = [
    (
        "top",
        'kind = "strip"',
        'kind = "strip"\ncolour = "red"',
        "top level: unknown key 'colour'; allowed:",
    ),
    (
        "curve",
        "radius = 2.0",
        "radius = 2.0\ncolor = 1",
        "[curve]: unknown key 'color'; allowed: builtin",
    ),
    (
        "material",
        "nu = 0.3",
        "nu = 0.3\nYoung = 1",
        "[material]: unknown key 'Young'; allowed: E, density, nu",
    ),
    (
        "load",
        "increments = 5\nsnap",
        "speed = 3\nincrements = 5\nsnap",
        "[load] 1: unknown key 'speed'",
    ),
    (
        "at",
        "at = 0.5\ndirection = [1",
        "at = 1.5\ndirection = [1",
        "[load] 2: at = 1.5 is outside [0, 1]",
    ),
    (
        "range",
        "offset = [0.10, 0.30]",
        "offset = [0.3, 0.1]",
        "offset = [0.3, 0.1]: low must be < high",
    ),
    (
        "feature",
        "W = [",
        "thickness = [1, 2]\nW = [",
        "unknown feature 'thickness'; allowed: m, tcrease",
    ),
    (
        "unit",
        'builtin = "half-circle"',
        FILE_CURVE.format("p.csv", "furlong"),
        "units = 'furlong' is not allowed; allowed: m, cm, mm",
    ),
    (
        "file",
        'builtin = "half-circle"',
        FILE_CURVE.format("missing.csv", "mm"),
        "points = 'missing.csv': no such file",
    ),
    (
        "kind",
        'kind = "strip"',
        'kind = "tower"',
        "kind = 'tower' is not allowed; allowed: strip, sheet",
    ),
    ("density", "density = 1200.0", "density = -1", "[material]: density = -1 is outside (0, inf]"),
    ("toml", "[supports]", "[supports", "not valid TOML"),
    ("nu", "nu = 0.3", "nu = 0.5", "[material]: nu = 0.5 is outside (-1, 0.5)"),
]


@pytest.mark.parametrize("case, old, new, message", BAD, ids=[b[0] for b in BAD])
def test_bad_scenario_files_are_refused_in_one_line(tmp_path, capsys, case, old, new, message):
    base = shipped_text("arch")
    assert old in base
    body = base.replace(old, new, 1)
    if case in ("unit", "file"):
        body = body.replace("radius = 2.0", "").replace('sampling = "paper"', "")
        (tmp_path / "p.csv").write_text("0,0\n1,1\n2,0\n")
    p = _user_file(tmp_path, body)
    with pytest.raises(ScenarioFileError) as err:
        read_scenario(p)
    text = str(err.value)
    assert "\n" not in text and text.startswith("mine.toml") and message in text, text
    # the command line says the same in one line, and writes nothing
    out = tmp_path / "out.csv"
    (tmp_path / "d.csv").write_text(",".join(ROW) + "\n" + ",".join(map(str, ROW.values())))
    assert main(["evaluate", str(p), str(tmp_path / "d.csv"), "-o", str(out)]) == 2
    err_line = capsys.readouterr().err.strip()
    assert err_line.count("\n") == 0 and message in err_line and not out.exists()


def test_evaluate_command_takes_a_scenario_file(tmp_path, capsys):
    _catenary_csv(tmp_path)
    p = _user_file(tmp_path, CATENARY)
    (tmp_path / "d.csv").write_text(",".join(ROW) + "\n" + ",".join(map(str, ROW.values())))
    out = tmp_path / "res.csv"
    assert main(["evaluate", str(p), str(tmp_path / "d.csv"), "-o", str(out)]) == 0
    import pandas as pd

    res = pd.read_csv(out)
    assert list(res.columns[-11:]) == [
        "Vstiff", "Vsnap", "error", "closest_error", "mass", "overlap", "clearance", "thick",
        "status", "state", "reason",
    ]  # fmt: skip
    direct = read_scenario(p).evaluate(ROW)
    assert math.isclose(res["Vstiff"][0], direct["Vstiff"], rel_tol=1e-12)


def test_a_self_overlapping_strip_is_a_failed_row_not_a_number():
    """fit_strip refuses this strip (its panels cross); the strip kind, the paper's arch
    included, reports a failed row with the reason (it gave a 'converged' stiffness)."""
    bad = {**ROW, "m": 8, "offset": 0.05, "stripeWidth": 0.04}
    with pytest.raises(ValueError, match="self-overlapping"):
        fit_strip(builtin_curve("half-circle", radius=2.0), 8, 0.05, 0.04, 0.1, sampling="paper")
    out = read_scenario(shipped_scenarios()["arch"]).evaluate(bad)
    assert out["status"].is_failed and "self-overlapping strip" in str(out["status"])
    assert all(math.isnan(out[c]) for c in ("Zstiff", "error", "mass"))
    arch = get_scenario("arch").evaluate(bad)
    assert arch["status"].is_failed and math.isnan(arch["Zstiff"])


@pytest.mark.parametrize(
    "name, change, match",
    [("arch", {"m": 12.7}, "m = 12.7 must be an integer"), ("arch", {"m": 13}, "must be even"),
     ("arch", {"offset": -0.1}, "offset = -0.1 must be"), ("arch", {"extrude": 0}, "extrude"),
     ("arch", {"W": float("nan")}, "W = nan must be finite"), ("arch", {"tpanel": "2"}, "number"),
     ("single-miura", {"gama": 60.0}, "give radians, not degrees"),
     ("canopy", {"pattern": 3}, "pattern = 3")],
)  # fmt: skip
def test_scenario_evaluate_validates_the_row_itself(name, change, match):
    """Called from Python, evaluate refuses what the runner refuses (it ran 12.7 as 12, gave
    inf 'converged' for an angle in degrees)."""
    base = {
        "arch": ROW,
        "single-miura": {"tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "gama": 1.2},
        "canopy": {"pattern": 1, "m": 24, "n": 6, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3},
    }[name]
    with pytest.raises(ValueError, match=match) as err:
        get_scenario(name).evaluate({**base, **change})
    assert "\n" not in str(err.value) and str(err.value).startswith("invalid design")


def test_a_non_finite_output_is_never_converged():
    from holofold.design import Column, Scenario
    from holofold.mechanics import CONVERGED

    def evaluate(row):
        return {"k": math.inf, "status": CONVERGED}

    sc = Scenario("inf", "", (Column("a", "m", "", 0, 1),), (Column("k", "N/m"),),
                  check=lambda r: [], evaluate=evaluate)  # fmt: skip
    out = sc.evaluate({"a": 0.5})
    assert not out["status"].converged and "non-finite k" in str(out["status"])


def test_overlap_and_clearance_columns_say_whether_the_folded_part_can_be_built():
    sc = read_scenario(shipped_scenarios()["arch"])
    thick = {"m": 8, "tcrease": 9.4e-4, "tpanel": 5.07e-3, "W": 1.38e-3, "offset": 0.1,
             "stripeWidth": 0.0206, "extrude": 0.1417}  # fmt: skip
    a = sc.evaluate(thick)
    b = sc.evaluate({**thick, "tpanel": 1e-3, "W": 4e-3})
    assert a["overlap"] > 0 and b["overlap"] == 0.0  # thinner panels, wider hinge gaps
    assert b["clearance"] > a["clearance"]
    from holofold.geometry import printability

    s, g, _ = strip_model(sc.shape.args[0], thick)
    from holofold.geometry.pattern import CreasePattern

    direct = printability(CreasePattern.from_faces(g.nodes, list(g.faces)), 5.07e-3, 1.38e-3)
    assert a["overlap"] == direct.overlap and a["clearance"] == direct.clearance
