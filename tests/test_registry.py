"""One registry behaviour (geometry/registry.py) for readers, formats, pattern families,
scenario kinds, sheet families, cutter profiles and refinement strategies; and the recipes of
CONTRIBUTING.md: each extension is one new file (a plug-in module, found through its
package's entry point), no holofold file edited."""

from __future__ import annotations

import dataclasses
import re
import sys
import textwrap

import numpy as np
import pandas as pd
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


SQUARE_READER = """
    import holofold.geometry as g

    def read(path, unit=None):
        \"\"\"One square panel of side 1 (x unit, default 1 m).\"\"\"
        s = unit or 1.0
        xy = [[0, 0], [s, 0], [s, s], [0, s]]
        return g.CreasePattern.from_faces([[*p, 0.0] for p in xy], [[0, 1, 2, 3]], flat=xy)

    READER = g.PatternReader(".sq", "one square", read, ("unit",))
    """
DOUBLE_KIND = """
    from holofold.design import Column, Scenario
    from holofold.mechanics import CONVERGED

    def from_config(doc, name, description):
        k = doc.sub("double").number("factor", 2.0)
        return Scenario(name=name, description=description or "x times k",
                        features=(Column("x", "m", "a length", 0.0, 1.0),),
                        performance=(Column("y", "m", "k x"),), check=lambda row: [],
                        evaluate=lambda row: {"y": k * row["x"], "status": CONVERGED},
                        kind="double")
    """
UNIFORM_STRATEGY = """
    from holofold.design import Proposal, sample_designs

    def uniform(q):
        \"\"\"Every round at random, whatever the forest says.\"\"\"
        return Proposal(sample_designs(q.scenario, q.n, seed=q.seed, start=q.start),
                        f"uniform-{q.n}-{q.seed}", " at random (uniform strategy)")
    """


def test_recipe_a_reader(tmp_path, monkeypatch):
    _plugin(tmp_path, monkeypatch, "hf_toy_reader", SQUARE_READER, "holofold.readers",
            ".sq = :READER")  # fmt: skip
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
    _plugin(tmp_path, monkeypatch, "hf_toy_kind", DOUBLE_KIND, "holofold.scenario_kinds",
            "double = ")  # fmt: skip
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
    _plugin(tmp_path, monkeypatch, "hf_toy_strategy", UNIFORM_STRATEGY,
            "holofold.refine_strategies", "uniform = :uniform")  # fmt: skip
    assert LoopSettings(strategy="uniform").strategy == "uniform"
    assert STRATEGIES["uniform"].__doc__.startswith("Every round")


# ------------------------------------------------ the same recipes through the command line
# Each plug-in is again one new module in tmp_path (and its entry-point line); the command
# line sees it because its choices are the registries' names, read when the parser is built.
_MIURA = ["--m", "2", "--n", "2", "--gamma", "60", "--ext", "0.5", "--size", "0.1"]


def _cli(argv: list[str]) -> int:
    from holofold.cli import main

    return main([str(a) for a in argv])


def test_recipe_a_reader_through_the_cli(tmp_path, monkeypatch, capsys):
    """``holofold pattern file --path a.sq`` reads the plug-in's suffix (FOLD written back)."""
    _plugin(tmp_path, monkeypatch, "hf_cli_reader", SQUARE_READER, "holofold.readers",
            ".sq = :READER")  # fmt: skip
    (tmp_path / "a.sq").write_text("square")
    out = tmp_path / "out"
    assert _cli(["pattern", "file", "--path", tmp_path / "a.sq", "--unit", 0.5, "-o", out]) == 0
    assert "1 panels, extent 0.5 x 0.5 x 0 m" in capsys.readouterr().out
    back = g.read_pattern(out / "pattern.fold")
    assert back.n_faces == 1 and np.allclose(np.ptp(back.coords, axis=0), [0.5, 0.5, 0.0])


def test_recipe_a_pattern_family_through_the_cli(tmp_path, monkeypatch, capsys):
    """``holofold pattern my-miura`` is a sub-command of its own, with the family's options,
    and makes the same sheet as ``holofold pattern miura``."""
    _plugin(tmp_path, monkeypatch, "hf_cli_family", '''
        import dataclasses
        import holofold.geometry as g

        FAMILY = dataclasses.replace(g.get_family("miura"), name="my-miura",
                                     description="my Miura sheet")
        ''', "holofold.pattern_families", "my-miura = :FAMILY")  # fmt: skip
    from holofold.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser("pattern").parse_args(["pattern", "--help"])
    assert "my-miura" in capsys.readouterr().out
    assert _cli(["pattern", "my-miura", *_MIURA, "-o", tmp_path / "mine"]) == 0
    assert _cli(["pattern", "miura", *_MIURA, "-o", tmp_path / "ref"]) == 0
    mine, ref = (g.read_pattern(tmp_path / d / "pattern.fold") for d in ("mine", "ref"))
    assert mine.n_faces == ref.n_faces == 4
    assert np.allclose(mine.coords, ref.coords, rtol=0, atol=1e-12)


def _dash_lengths(svg: str, role: str) -> np.ndarray:
    """Lengths (mm) of the dashes of the first crease path of ``role`` in an SVG."""
    path = re.search(rf'<path d="([^"]*)"[^>]*data-role="{role}"', svg).group(1)
    pts = np.array(re.findall(r"[ML] ([-\d.]+) ([-\d.]+)", path), dtype=float).reshape(-1, 2, 2)
    return np.linalg.norm(pts[:, 1] - pts[:, 0], axis=1)


def test_recipe_a_cutter_profile_through_the_cli(tmp_path, monkeypatch):
    """``--profile my-laser`` is one of the choices; its 5 mm dashes reach the SVG (each
    dash at least 5 mm, stretched by less than a gap to fill the crease)."""
    _plugin(tmp_path, monkeypatch, "hf_cli_profile", '''
        import dataclasses
        import holofold.geometry as g

        PROFILE = dataclasses.replace(g.PROFILES["laser"], name="my-laser", dash=5.0)
        ''', "holofold.cutter_profiles", "my-laser = :PROFILE")  # fmt: skip
    for name in ("my-laser", "laser"):
        assert _cli(["pattern", "miura", *_MIURA, "--profile", name, "-o", tmp_path / name]) == 0
    mine = (tmp_path / "my-laser" / "pattern.svg").read_text()
    ref = (tmp_path / "laser" / "pattern.svg").read_text()
    assert "my-laser profile" in mine
    gap = g.get_profile("my-laser").gap
    dashes = _dash_lengths(mine, "mountain")
    assert ((dashes >= 5.0 - 1e-3) & (dashes < 5.0 + gap)).all()
    assert len(dashes) < len(_dash_lengths(ref, "mountain"))
    with pytest.raises(SystemExit):  # a profile nobody registered is no choice
        _cli(["pattern", "miura", *_MIURA, "--profile", "your-laser", "-o", tmp_path / "x"])


def test_recipe_a_scenario_kind_and_a_strategy_through_the_cli(tmp_path, monkeypatch, capsys):
    """``holofold design d.toml --strategy uniform``: a scenario kind and a refinement
    strategy, each one plug-in module, run the whole loop from the command line."""
    _plugin(tmp_path, monkeypatch, "hf_cli_kind", DOUBLE_KIND, "holofold.scenario_kinds",
            "double = ")  # fmt: skip
    _plugin(tmp_path, monkeypatch, "hf_cli_strategy", UNIFORM_STRATEGY,
            "holofold.refine_strategies", "uniform = :uniform")  # fmt: skip
    (tmp_path / "d.toml").write_text('kind = "double"\n[double]\nfactor = 3.0\n')
    out = tmp_path / "out"
    loop = ["-n", 60, "--refine", 20, "--verify", 10, "--rounds", 1, "--pilot", 0,
            "--all-rounds", "--workers", 1, "--no-progress"]  # fmt: skip
    status = _cli(["design", tmp_path / "d.toml", "--target", "y > 2.0", *loop,
                   "--strategy", "uniform", "-o", out])  # fmt: skip
    said = capsys.readouterr().out
    assert status == 0 and "round 1/1: 20 new designs at random (uniform strategy)" in said
    table = pd.read_parquet(out / "designs.parquet")
    assert (table["origin"] == "refine-1").sum() == 20
    assert np.allclose(table["y"], 3.0 * table["x"], rtol=1e-12)  # the kind's factor, read
    assert _cli(["design", tmp_path / "d.toml", "--target", "y > 2.0", "--strategy", "nearby",
                 "-o", tmp_path / "no"]) == 2  # fmt: skip
    assert "strategy = 'nearby' must be one of" in capsys.readouterr().err
    assert not (tmp_path / "no").exists()
