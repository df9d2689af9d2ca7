"""The strip kind chooses buildable thickness as the sheet and pattern kinds do (issue 34 item
3): with thick = "auto" (a scenario file's default) the first of centred, offset and tapered
panels that do not overlap in the strip's shape."""

from dataclasses import replace

import pytest

from holofold.design.database.sampling import sample_designs
from holofold.design.scenarios import arch
from holofold.design.scenarios.strip import strip_part, strip_thickness


@pytest.fixture(scope="module")
def row():
    # an arch design whose centred panels overlap (0.3 mm^3) and whose offset ones do not
    return sample_designs(arch.SCENARIO, 12, seed=3).iloc[1].to_dict()


def test_auto_takes_offset_panels_where_centred_ones_overlap(row):
    centred = strip_thickness(replace(arch.SETTING, thick="centred"), row)
    assert centred.technique == "centred" and centred.overlap > 1e-10
    auto = strip_thickness(replace(arch.SETTING, thick="auto"), row)
    assert auto.technique == "offset" and auto.overlap <= 1e-12
    assert auto.tried == ("centred", "offset") and auto.code == 1
    part = strip_part(replace(arch.SETTING, thick="auto"), row)
    assert part.thick == "offset"
    assert strip_part(replace(arch.SETTING, thick="centred"), row).thick == "centred"


def test_auto_keeps_centred_panels_that_fit(row):
    other = sample_designs(arch.SCENARIO, 12, seed=3).iloc[0].to_dict()
    got = strip_thickness(replace(arch.SETTING, thick="auto"), other)
    assert got.technique == "centred" and got.overlap == 0.0 and got.clearance > 0


def test_the_columns_say_the_technique(row):
    from holofold.design.scenarios.strip import evaluate_strip

    cols = ("Zstiff", "overlap", "clearance", "thick")
    setting = replace(arch.SETTING, thick="auto")
    out = evaluate_strip(setting, cols, row)
    assert out["thick"] == 1.0 and out["overlap"] == 0.0
    assert evaluate_strip(replace(arch.SETTING, thick="centred"), cols, row)["thick"] == 0.0
