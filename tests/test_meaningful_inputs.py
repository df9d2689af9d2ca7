"""Inputs that must mean something (issue 23 item 5; issue 24 item 4's plausibility checks):
loads on supports, convergence at round-off, physical ranges, CSV columns, unreadable files."""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import replace

import numpy as np
import pytest

from holofold.cli import main
from holofold.design import ScenarioFileError, read_scenario, shipped_text
from holofold.fitting import (
    CurveClosedWarning,
    CurveColumnsWarning,
    CurveError,
    read_points_csv,
)


def _edited(tmp_path, name, pattern, value, count=1):
    text = re.sub(pattern, value, shipped_text(name), count=count, flags=re.M)
    assert text != shipped_text(name), pattern
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return p


def _refused(path, *words):
    with pytest.raises(ScenarioFileError) as info:
        read_scenario(path)
    msg = str(info.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg
    return msg


# ---------------------------------------------------------------- loads on supports
@pytest.mark.parametrize("at", ["0.0", "1", "0.02"])
def test_a_load_on_a_supported_node_is_refused_when_the_file_is_read(tmp_path, at):
    p = _edited(tmp_path, "arch", r"^at = .*$", f"at = {at}")
    _refused(p, "[load] 1: at = ", "puts the load on a support", "for m = 8")


def test_a_load_along_free_directions_of_a_support_is_allowed(tmp_path):
    p = _edited(tmp_path, "arch", r"^at = .*$", "at = 0.0")
    text = re.sub(r"^dofs = .*$", 'dofs = "z"', p.read_text(), count=1, flags=re.M)
    text = re.sub(r"^direction = .*$", "direction = [1, 0, 0]", text, count=1, flags=re.M)
    p.write_text(text)
    read_scenario(p)  # a load in x on nodes fixed in z only: it acts


# ---------------------------------------------------------------- convergence at round-off
def _arch_stiffness(**setting):
    from holofold.design.scenarios.arch import SETTING
    from holofold.design.scenarios.strip import StripLoad, evaluate_strip

    row = {"m": 12, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "offset": 0.2,
           "stripeWidth": 0.02, "extrude": 0.1}  # fmt: skip
    force = setting.pop("force", 5.0)
    st = replace(SETTING, loads=(StripLoad("Z", 0.5, (0, 0, -1), force, 5),), **setting)
    return evaluate_strip(st, ("Zstiff",), row)


@pytest.mark.parametrize("setting", [{"force": 1e-14}, {"force": 1e-11}, {"E": 1e25}])
def test_a_stiffness_at_round_off_is_never_converged(setting):
    out = _arch_stiffness(**dict(setting))
    assert not out["status"].converged
    assert "at round-off" in str(out["status"]) and "below the resolution" in str(out["status"])


def test_a_small_load_above_round_off_converges_to_the_linear_stiffness():
    small, normal = _arch_stiffness(force=1e-3), _arch_stiffness(force=1e-5)
    assert small["status"].converged and normal["status"].converged
    # the linear limit: within 1e-5 (round-off of 10 eps x 4 m / 2e-8 m is 4e-7)
    assert small["Zstiff"] == pytest.approx(normal["Zstiff"], rel=1e-5)
    stiff = _arch_stiffness(E=2e12)  # 1000 x E: 1000 x the stiffness, still resolved
    assert stiff["status"].converged
    assert stiff["Zstiff"] / _arch_stiffness()["Zstiff"] == pytest.approx(1015, rel=0.01)


# ---------------------------------------------------------------- physical ranges
@pytest.mark.parametrize(
    ("name", "pattern", "value", "words"),
    [("arch", r"^E = .*$", "E = 1e25", ["[material]: E = 1e+25 Pa is outside the physical"]),
     ("arch", r"^density = .*$", "density = 1e6", ["density = 1e+06 kg/m^3"]),
     ("arch", r"^force = .*$", "force = 1e300", ["[load] 1: force = 1e+300 N"]),
     ("gripper", r"^room_temperature = .*$", "room_temperature = 294",
      ["room_temperature = 294 degC", "looks like kelvin: give 20.85 (degC)"]),
     ("gripper", r"^L1 = .*$", "L1 = [4, 8]",
      ["[features]: L1 = [4, 8] m", "looks like mm: give [0.004, 0.008]"]),
     ("gripper", r"^tpanel = .*$", "tpanel = [10, 30]",
      ["tpanel = [10, 30] m", "looks like um: give [1e-05, 3e-05]"]),
     ("single-miura", r"^tpanel = .*$", "tpanel = [1, 6]", ["looks like mm: give [0.001, 0.006]"]),
     ("gripper", r"^k_air = .*$", "k_air = 26", ["k_air = 26 W/(m K)"])],
)  # fmt: skip
def test_values_outside_physical_ranges_are_refused_with_the_likely_unit(
    tmp_path, name, pattern, value, words
):
    p = _edited(tmp_path, name, pattern, value)
    _refused(p, *words, "(docs/limits.md)")


def test_the_shipped_files_and_examples_are_plausible():
    from holofold.design import shipped_scenarios

    for p in shipped_scenarios().values():
        read_scenario(p)


# ---------------------------------------------------------------- CSV points
def _csv(tmp_path, text, name="p.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_a_csv_with_three_numeric_columns_says_which_two_it_reads(tmp_path):
    p = _csv(tmp_path, "x,y,z\n0,5,0\n1,5,1\n2,5,0\n")
    with pytest.warns(CurveColumnsWarning, match=r"3 numeric columns \(x, y, z\); reading "
                      r"columns x, y as \(x, z\)"):  # fmt: skip
        flat = read_points_csv(p, check_size=False)
    assert np.ptp(flat.polyline(9)[:, 1]) == pytest.approx(0.0)  # y = 5: a flat line
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        arch = read_points_csv(p, columns=["x", "z"], check_size=False)
        assert read_points_csv(p, columns=[0, 2], check_size=False).length == arch.length
    assert flat.length == pytest.approx(2.0) and arch.length > 2.8  # through (1, 1): an arch
    with pytest.raises(CurveError, match="has no column 'q'; its columns: x, y, z"):
        read_points_csv(p, columns=["x", "q"])
    # and a scenario file takes columns = [...]
    text = re.sub(r'^builtin = .*$', f'points = "{p}"\nunits = "m"\ncolumns = ["x", "z"]',
                  shipped_text("arch"), count=1, flags=re.M)  # fmt: skip
    text = re.sub(r"^radius = .*\n", "", text, flags=re.M)
    (tmp_path / "c.toml").write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = read_scenario(tmp_path / "c.toml")
    assert "points from p.csv" in sc.setting["curve"]


def test_decimal_commas_get_a_hint_and_closed_curves_a_warning(tmp_path):
    with pytest.raises(CurveError, match=r"line 2: .*decimal commas\? write 1.5, not 1,5"):
        read_points_csv(_csv(tmp_path, "0;0\n1,5;2\n2;0\n"))
    closed = _csv(tmp_path, "0,0\n1,1\n2,0\n1,-1\n0,0\n", "closed.csv")
    with pytest.warns(CurveClosedWarning, match="closed curve .* panels collide"):
        read_points_csv(closed, check_size=False)


def test_unreadable_files_never_echo_content_and_say_what_the_path_is(tmp_path, capsys):
    secret = _csv(tmp_path, "root:$6$abcdefgh:19000:0:99999:7:::\nbin:*:19000:0:99999:7:::\n",
                  "shadow")  # fmt: skip
    with pytest.raises(CurveError) as info:
        read_points_csv(secret)
    assert "abcdefgh" not in str(info.value) and "bin" not in str(info.value)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    for path, what in ((tmp_path, "is a folder, not a file"),
                       (fifo, "is a FIFO (named pipe), not a file"),
                       ("/dev/null", "is a character device, not a file")):  # fmt: skip
        with pytest.raises(CurveError, match=re.escape(what)):
            read_points_csv(path)
        assert main(["evaluate", "arch", str(path), "-o", str(tmp_path / "o.csv")]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and what in err, err
    (tmp_path / "s.toml").write_text(shipped_text("arch").replace('builtin = "half-circle"',
                                     f'points = "{fifo}"\nunits = "m"'))  # fmt: skip
    _refused(tmp_path / "s.toml", "is a FIFO (named pipe), not a file")


def test_a_gripper_rows_time_limit_follows_its_heating_step_cap(tmp_path):
    from holofold.design import get_scenario

    assert get_scenario("gripper").row_timeout == pytest.approx(120.0)  # 60 + 0.15 x 400
    assert read_scenario(_edited(tmp_path, "gripper", r"^# step_cap = .*$",
                                 "step_cap = 100")).row_timeout == pytest.approx(75.0)  # fmt: skip
