"""Display units: every scenario column is shown in the unit people read (mm, um, degrees)."""

from __future__ import annotations

import math

import pytest

from holofold.design import (
    DISPLAY_UNITS,
    SCENARIO_NAMES,
    Column,
    format_value,
    get_scenario,
    read_table,
    table_columns,
)


@pytest.mark.parametrize("name", SCENARIO_NAMES)
def test_every_feature_of_a_shipped_scenario_has_a_display_unit(name):
    sc = get_scenario(name)
    for c in (*sc.features, *sc.performance):
        assert c.display_unit in DISPLAY_UNITS.get(c.unit, {c.unit: 1.0}), c
        if c.unit == "m" and c.low is not None:  # lengths people read in mm or um
            assert c.display_unit in ("mm", "um"), c
            assert 0.1 <= c.to_display(c.high) < 1000, c  # a readable number
        if c.unit == "rad":
            assert c.display_unit == "deg"
        assert c.from_display(c.to_display(0.123)) == pytest.approx(0.123, rel=1e-15)


def test_display_units_of_the_paper_scenarios():
    grip = {c.name: c.display_unit for c in get_scenario("gripper").features}
    assert grip == {"Pattern": "-", "L1": "mm", "L2": "mm", "t1": "um", "t2": "um",
                    "tpanel": "um", "rate": "-", "W": "um"}  # fmt: skip
    arch = {c.name: c.display_unit for c in get_scenario("arch").features}
    assert {arch[k] for k in ("tcrease", "tpanel", "W", "offset", "extrude")} == {"mm"}
    perf = {c.name: c.display_unit for c in get_scenario("gripper").performance}
    assert perf == {"freqFinal": "rad/s", "finalQ": "W", "Tmax": "degC", "stiff": "N/m"}


def test_format_value_reads_in_the_display_unit():
    tcrease = Column("tcrease", "m", low=5e-4, high=1e-3)
    assert tcrease.display_unit == "mm"
    assert format_value(7.792e-4, tcrease) == "0.779 mm"
    assert tcrease.format(2.174e-3) == "2.17 mm"
    gama = Column("gama", "rad", low=0.87, high=1.4)
    assert format_value(math.radians(65.8), gama) == "65.8 deg"
    t1 = Column("t1", "m", low=1.5e-7, high=2.5e-7)
    assert format_value(1.9e-7, t1) == "0.19 um"
    assert format_value(6000.4, Column("k", "N/m")) == "6000 N/m"  # no exponent
    assert format_value(0.5, Column("rate", "-")) == "0.5"
    assert format_value(0.123456) == "0.123"
    assert format_value(math.inf, tcrease) == "inf mm"
    assert format_value(7.792e-4, tcrease, digits=4) == "0.7792 mm"


def test_a_display_unit_that_does_not_fit_the_unit_is_refused():
    with pytest.raises(ValueError, match="display unit 'deg' is not one of m, mm, um"):
        Column("W", "m", display="deg")
    assert Column("x", "N/m", display="N/m").display_factor == 1.0


def test_table_columns_of_published_databases(reference_data):
    path = reference_data.path("data2_TwoPanel_sample")
    t = read_table(path)
    cols = table_columns(t.columns, path)
    assert cols["t1"].display_unit == "um" and cols["L1"].display_unit == "mm"
    assert cols["t1"].format(t["t1"].iloc[0]) == "0.217 um"
    arch = table_columns(read_table(reference_data.path("data3_ShapeFit")).columns)
    assert arch["tcrease"].display_unit == "mm" and arch["Zstiff"].display_unit == "N/m"
    assert table_columns(["a", "b"]) == {}
