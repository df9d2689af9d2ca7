"""The registry of scenario-file kinds (design/scenarios/kinds.py): built-in kinds, kinds
registered at run time and kinds from other packages' entry points."""

from __future__ import annotations

import importlib.metadata
import sys
import types

import pytest

from holofold.design.scenarios import Column, Scenario, ScenarioFileError, read_scenario
from holofold.design.scenarios import kinds as registry
from holofold.mechanics import CONVERGED


def _toy_from_config(doc, name, description):
    """A kind with one feature x and one column y = 2 x."""
    k = doc.sub("toy").number("factor", 2.0)
    return Scenario(
        name=name,
        description=description or "toy",
        features=(Column("x", "m", "a length", 0.0, 1.0),),
        performance=(Column("y", "m", "factor x x"),),
        check=lambda row: [],
        evaluate=lambda row: {"y": k * row["x"], "status": CONVERGED},
        kind="toy",
    )


@pytest.fixture
def clean_registry():
    with registry.KINDS.saved():  # kinds registered by a test are gone after it
        yield registry


def _write(tmp_path, text):
    p = tmp_path / "mine.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_builtin_kinds_are_listed_and_load():
    names = registry.kind_names()
    assert names[:3] == ("strip", "sheet", "gripper")
    for n in ("strip", "sheet", "gripper"):
        kind = registry.get_kind(n)
        assert kind.name == n and kind.description and callable(kind.from_config)


def test_a_registered_kind_reads_files(tmp_path, clean_registry):
    clean_registry.register_kind(registry.ScenarioKind("toy", "a toy", _toy_from_config))
    sc = read_scenario(_write(tmp_path, 'kind = "toy"\n[toy]\nfactor = 3.0\n'))
    assert sc.kind == "toy" and sc.source.endswith("mine.toml")
    assert sc.evaluate({"x": 0.5})["y"] == 1.5
    with pytest.raises(ScenarioFileError, match=r"\[toy\]: unknown key 'bad'|unknown key"):
        read_scenario(_write(tmp_path, 'kind = "toy"\nbad = 1\n'))


def test_an_unknown_kind_names_every_known_one(tmp_path, clean_registry):
    clean_registry.register_kind(registry.ScenarioKind("toy", "a toy", _toy_from_config))
    with pytest.raises(ScenarioFileError, match="allowed: strip, sheet, gripper.*toy"):
        read_scenario(_write(tmp_path, 'kind = "nope"\n'))


def test_builtin_names_cannot_be_taken(clean_registry):
    with pytest.raises(ValueError, match="built in"):
        clean_registry.register_kind(registry.ScenarioKind("sheet", "", _toy_from_config))
    with pytest.raises(ValueError, match="must be a word"):
        clean_registry.register_kind(registry.ScenarioKind("a b", "", _toy_from_config))


def test_entry_point_kinds(tmp_path, monkeypatch, clean_registry):
    """A package's entry point in holofold.scenario_kinds adds a kind; one that fails to load
    is refused in one line naming the entry point."""
    mod = types.ModuleType("holofold_toy_plugin")
    mod.from_config = _toy_from_config
    mod.DESCRIPTION = "toy kind from a plug-in"
    monkeypatch.setitem(sys.modules, "holofold_toy_plugin", mod)
    group = registry.ENTRY_POINT_GROUP
    eps = importlib.metadata.EntryPoints(
        [
            importlib.metadata.EntryPoint("toyplug", "holofold_toy_plugin", group),
            importlib.metadata.EntryPoint("broken", "holofold_no_such_module:KIND", group),
        ]
    )
    real = importlib.metadata.entry_points

    def fake(**kw):
        return eps if kw.get("group") == group else real(**kw)

    monkeypatch.setattr(importlib.metadata, "entry_points", fake)
    assert "toyplug" in registry.kind_names() and "broken" in registry.kind_names()
    kinds = registry.scenario_kinds()
    assert kinds["toyplug"].description == "toy kind from a plug-in"
    assert "broken" not in kinds
    sc = read_scenario(_write(tmp_path, 'kind = "toyplug"\n'))
    assert sc.evaluate({"x": 0.25})["y"] == 0.5
    with pytest.raises(ScenarioFileError, match="holofold_no_such_module:KIND.*cannot be loaded"):
        read_scenario(_write(tmp_path, 'kind = "broken"\n'))
