"""Issue 23 item 7: every built-in scenario writes the fabrication files its shipped file does."""

from __future__ import annotations

import pytest

from holofold.design import get_scenario, load_scenario, sample_designs, shipped_scenarios


@pytest.mark.parametrize(
    "name", ["arch", pytest.param("canopy", marks=pytest.mark.slow), "single-miura", "gripper"]
)
def test_a_built_in_name_writes_the_files_of_its_shipped_file(name, tmp_path):
    builtin = get_scenario(name)
    shipped = load_scenario(shipped_scenarios()[name])
    assert builtin.write_files is not None and builtin.shape is not None
    row = sample_designs(builtin, 1, seed=3).iloc[0].to_dict()
    row |= {c.name: min(c.choices) for c in builtin.features if c.choices}  # the smallest
    a = builtin.write_files(row, tmp_path / "builtin", units="mm")
    b = shipped.write_files(row, tmp_path / "shipped", units="mm")
    assert [(f.key, f.path.name) for f in a] == [(f.key, f.path.name) for f in b]
    assert len(a) >= 5 and all(p.is_file() and p.stat().st_size > 0 for p in a.paths)
    # the same design gives the same files, byte for byte, by either route
    for f in a:
        assert f.path.read_bytes() == (tmp_path / "shipped" / f.path.name).read_bytes(), f.key
    assert builtin.shape(row).coords.shape == shipped.shape(row).coords.shape
