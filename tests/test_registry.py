"""One registry behaviour (geometry/registry.py) for readers, formats, pattern families,
scenario kinds, sheet families, cutter profiles and refinement strategies; and the recipes of
CONTRIBUTING.md: each extension is one new file (a plug-in module, found through its
package's entry point), no holofold file edited."""

from __future__ import annotations

import dataclasses
import sys
import textwrap

import numpy as np
import pytest

import holofold.geometry as g
from holofold.design import STRATEGIES, LoopSettings, read_scenario
from holofold.design.scenarios import KINDS, load_scenario, shipped_text
from holofold.design.scenarios.sheet import PATTERNS
from holofold.design.scenarios.sheet_families import (
    MIURA_SHEET,
    SHEET_FAMILIES,
    register_sheet_family,
)
from holofold.geometry import FAMILIES, FORMATS, PROFILES, READERS, Registry


def test_one_behaviour():
    reg = Registry("widget", {"a": 1}, error=LookupError)
    reg.register(2, "b")
    assert reg.names() == ("a", "b") and reg["b"] == 2 and dict(reg) == {"a": 1, "b": 2}
    with pytest.raises(ValueError, match="widget 'a' is built in"):
        reg.register(3, "a", replace=True)
    with pytest.raises(ValueError, match="widget 'b' is already registered; pass replace=True"):
        reg.register(3, "b")
    assert reg.register(3, "b", replace=True) == 3 and reg["b"] == 3
    with pytest.raises(LookupError, match="unknown widget 'c'; known: a, b"):
        reg["c"]
    assert reg.get("c") is None and "c" not in reg and reg.get([1]) is None  # unhashable
    with reg.saved():
        reg.register(4, "d")
        assert "d" in reg
    assert "d" not in reg and reg.names() == ("a", "b")


@pytest.mark.parametrize(
    ("registry", "builtin"),
    [
        (READERS, ".svg"),
        (FORMATS, "stl"),
        (FAMILIES, "miura"),
        (KINDS, "sheet"),
        (SHEET_FAMILIES, 1),
        (PROFILES, "laser"),
        (STRATEGIES, "mixed"),
    ],
)
def test_every_registry_protects_its_builtins(registry, builtin):
    assert isinstance(registry, Registry) and builtin in registry.builtin_names()
    with pytest.raises(ValueError, match="is built in"):
        registry.register(registry[builtin], builtin, replace=True)


def test_a_taken_reader_suffix_is_refused_unless_replaced():
    mine = g.PatternReader(".toy", "toy", lambda path, **kw: None)
    with READERS.saved():
        g.register_reader(mine)
        with pytest.raises(ValueError, match="'.toy' is already registered"):
            g.register_reader(mine)
        assert g.register_reader(dataclasses.replace(mine, name="toy 2"), replace=True)
        assert READERS[".TOY"].name == "toy 2"  # suffixes in any case
    assert ".toy" not in READERS


def test_a_sheet_family_registered_later_is_named_by_scenario_files(tmp_path):
    """A third sheet family appears in PATTERNS (live, not frozen at import) and a scenario
    file's [sheet] pattern can name it."""
    fam = dataclasses.replace(FAMILIES["miura"], name="miura-again")
    sheet = dataclasses.replace(MIURA_SHEET, code=3, name="miura-again", label="Miura again")
    toml = shipped_text("single-miura").replace('pattern = "miura"', 'pattern = "miura-again"')
    (tmp_path / "mine.toml").write_text(toml.replace('name = "single-miura"', 'name = "mine"'))
    with FAMILIES.saved(), SHEET_FAMILIES.saved():
        g.register_family(fam)
        register_sheet_family(sheet)
        assert PATTERNS["miura-again"] == 3 and 3 in SHEET_FAMILIES
        sc = read_scenario(tmp_path / "mine.toml")
        ref = load_scenario("single-miura")
        row = {"tcrease": 0.7e-3, "tpanel": 3e-3, "W": 2e-3, "gama": 1.1}
        a, b = sc.evaluate(row), ref.evaluate(row)
        assert np.isclose(a["axialstiff60"], b["axialstiff60"], rtol=1e-9)
    assert "miura-again" not in PATTERNS


# ---------------------------------------------------------------------- CONTRIBUTING recipes
def _plugin(tmp_path, monkeypatch, module: str, source: str, group: str, entry: str) -> None:
    """Install a one-file plug-in: ``module.py`` (the new file) and the entry-point line that
    its package's ``pyproject.toml`` declares (here the metadata pip would write); ``entry``
    is ``name = object``."""
    (tmp_path / f"{module}.py").write_text(textwrap.dedent(source), encoding="utf-8")
    info = tmp_path / f"{module}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: 0.1\n")
    name, obj = (w.strip() for w in entry.split("="))
    (info / "entry_points.txt").write_text(f"[{group}]\n{name} = {module}{obj}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, module, raising=False)


def test_recipe_a_reader(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_reader", '''
        import holofold.geometry as g

        def read(path, unit=None):
            """One square panel of side 1 (x unit, default 1 m)."""
            s = unit or 1.0
            xy = [[0, 0], [s, 0], [s, s], [0, s]]
            return g.CreasePattern.from_faces([[*p, 0.0] for p in xy], [[0, 1, 2, 3]], flat=xy)

        READER = g.PatternReader(".sq", "one square", read, ("unit",))
        ''', "holofold.readers", ".sq = :READER")  # fmt: skip
    (tmp_path / "a.sq").write_text("square")
    pat = g.read_pattern(tmp_path / "a.sq", unit=0.5)
    assert ".sq" in READERS and pat.n_faces == 1 and np.ptp(pat.coords[:, 0]) == 0.5


def test_recipe_a_format(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_format", '''
        import holofold.geometry as g

        def write(pattern, unit, **kw):
            return f"{pattern.n_vertices} vertices, {pattern.n_faces} faces\\n"

        FORMAT = g.Format("count", "pattern", "m", write, "vertex and face counts")
        ''', "holofold.formats", "count = :FORMAT")  # fmt: skip
    path = g.export(g.miura_sheet(2, 2, size=0.1, gamma=1.0, ext=0.6), tmp_path / "m.count")
    assert path.read_text() == "9 vertices, 4 faces\n" and "count" in FORMATS


def test_recipe_a_pattern_family(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_family", '''
        import dataclasses
        import holofold.geometry as g

        FAMILY = dataclasses.replace(g.get_family("miura"), name="my-miura")
        ''', "holofold.pattern_families", "my-miura = :FAMILY")  # fmt: skip
    fam = g.get_family("my-miura")
    assert fam.make(m=2, n=2, gamma=60.0, ext=0.5, size=0.1).n_faces == 4
    assert "my-miura" in g.family_names()


def test_recipe_a_scenario_kind(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_kind", '''
        from holofold.design import Column, Scenario
        from holofold.mechanics import CONVERGED

        def from_config(doc, name, description):
            k = doc.sub("double").number("factor", 2.0)
            return Scenario(name=name, description=description or "x times k",
                            features=(Column("x", "m", "a length", 0.0, 1.0),),
                            performance=(Column("y", "m", "k x"),), check=lambda row: [],
                            evaluate=lambda row: {"y": k * row["x"], "status": CONVERGED},
                            kind="double")
        ''', "holofold.scenario_kinds", "double = ")  # fmt: skip
    (tmp_path / "d.toml").write_text('kind = "double"\n[double]\nfactor = 3.0\n')
    assert read_scenario(tmp_path / "d.toml").evaluate({"x": 0.5})["y"] == 1.5


def test_recipe_a_cutter_profile(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_profile", '''
        import dataclasses
        import holofold.geometry as g

        PROFILE = dataclasses.replace(g.PROFILES["laser"], name="my-laser", dash=5.0)
        ''', "holofold.cutter_profiles", "my-laser = :PROFILE")  # fmt: skip
    assert g.CutterOptions("my-laser").profile == "my-laser"
    assert g.get_profile("my-laser").dash == 5.0 and "my-laser" in PROFILES


def test_recipe_a_refinement_strategy(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_strategy", '''
        from holofold.design import Proposal, sample_designs

        def uniform(q):
            """Every round at random, whatever the forest says."""
            return Proposal(sample_designs(q.scenario, q.n, seed=q.seed, start=q.start),
                            f"uniform-{q.n}-{q.seed}", " at random (uniform strategy)")
        ''', "holofold.refine_strategies", "uniform = :uniform")  # fmt: skip
    assert LoopSettings(strategy="uniform").strategy == "uniform"
    assert STRATEGIES["uniform"].__doc__.startswith("Every round")
