"""The design loop's records (design/loop/settings.py), its refinement strategies as a registry
(design/loop/strategies.py) and the loop object (design/loop/design_loop.py: DesignLoop over a
LoopState)."""

from __future__ import annotations

import ast
import inspect
from dataclasses import FrozenInstanceError
from pathlib import Path

import pandas as pd
import pytest
from test_acquisition import _loop_scenario

from holofold.design import (
    STRATEGIES,
    DesignFiles,
    DesignProblem,
    Execution,
    LoopSettings,
    Proposal,
    register_strategy,
    run_design,
    sample_designs,
)
from holofold.design.loop.strategies import design_key

DESIGN = Path(__file__).resolve().parents[1] / "design"


def _toy():
    return _loop_scenario()  # y = a + 0.01 b, a and b in [0, 1]


def test_records_check_themselves_in_one_line():
    with pytest.raises(ValueError, match="samples = 10 must be an integer >= 20"):
        LoopSettings(samples=10)
    with pytest.raises(ValueError, match="strategy = 'near' must be one of 'likely', 'around'"):
        LoopSettings(strategy="near")
    with pytest.raises(ValueError, match="cannot hold the 200 designs of the database"):
        LoopSettings(budget=220)
    with pytest.raises(ValueError, match="workers = 0 must be >= 1"):
        Execution(workers=0)
    with pytest.raises(ValueError, match="is not an address"):
        Execution(scheduler="my laptop")
    with pytest.raises(ValueError, match="row_timeout|time limit"):
        Execution(row_timeout=-1)
    assert Execution(row_timeout="none").runner() == {"workers": 1, "progress": None,
                                                      "row_timeout": "none"}  # fmt: skip
    with pytest.raises(ValueError, match="unknown length unit|furlong"):
        DesignFiles(mesh_units="furlong")
    with pytest.raises(ValueError, match="unknown column 'z'"):
        DesignProblem(_toy(), "z > 1")
    p = DesignProblem(_toy(), "y > 0.5", objective="max y", bed="300x200")
    assert p.target.columns == ("y",) and p.objective.column == "y"
    assert p.bed.width == pytest.approx(0.3) and not p.buildable  # no overlap column
    with pytest.raises(FrozenInstanceError):
        p.target = "y > 1"


def test_old_keywords_and_records_run_the_same_loop(tmp_path):
    kw = dict(samples=60, refine=20, verify=10, rounds=1, pilot=0, until_verified=False)
    old = run_design(_toy(), "y > 0.7", tmp_path / "old", workers=1, progress=False,
                     files=False, **kw)  # fmt: skip
    new = run_design(
        DesignProblem(_toy(), "y > 0.7"),
        folder=tmp_path / "new",
        settings=LoopSettings(**kw),
        execution=Execution(workers=1, progress=False),
        output=DesignFiles(files=False),
    )
    cols = ["a", "b", "y", "origin"]
    pd.testing.assert_frame_equal(old.table[cols], new.table[cols])
    a, b = old.summary, new.summary
    for s in (a, b):
        s.pop("timings"), s["database"].pop("path")
    assert a == b and len(a["rounds"]) == 2
    with pytest.raises(TypeError, match="unexpected keyword argument 'sampels'"):
        run_design(_toy(), "y > 0.7", tmp_path / "x", sampels=60)
    with pytest.raises(TypeError, match="the target is the problem's"):
        run_design(DesignProblem(_toy(), "y > 0.7"), "y > 0.1", tmp_path / "x")


def test_a_registered_strategy_is_what_the_loop_samples_by(tmp_path):
    asked = []

    def corner(q):  # every new design at a = 1 - small
        asked.append(q)
        new = sample_designs(q.scenario, q.n, seed=q.seed, start=q.start,
                             ranges={"a": (0.9, 1.0)})  # fmt: skip
        return Proposal(new, design_key("corner", q.n, q.seed), " in the corner a > 0.9")

    with STRATEGIES.saved():
        register_strategy("corner", corner)
        assert "corner" in STRATEGIES and STRATEGIES.names()[:3] == ("likely", "around", "mixed")
        with pytest.raises(ValueError, match="already registered; pass replace=True"):
            register_strategy("corner", corner)
        with pytest.raises(ValueError, match="'mixed' is built in"):
            register_strategy("mixed", corner, replace=True)
        said: list[str] = []
        out = run_design(_toy(), "y > 0.7", tmp_path / "o", samples=60, refine=20, verify=10,
                         rounds=1, pilot=0, until_verified=False, strategy="corner",
                         files=False, progress=False, say=said.append)  # fmt: skip
    new = out.table[out.table["origin"] == "refine-1"]
    assert len(new) == 20 and (new["a"] >= 0.9).all()
    assert len(asked) == 1 and asked[0].forest is not None and asked[0].rows >= 60
    assert any("20 new designs in the corner a > 0.9" in s for s in said)
    assert "corner" not in STRATEGIES  # gone with the block
    with pytest.raises(ValueError, match="must be one of 'likely', 'around', 'mixed'$"):
        LoopSettings(strategy="corner")


def _signatures(path: Path):
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            a = node.args
            n = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)
            n += (a.vararg is not None) + (a.kwarg is not None)
            if a.args and a.args[0].arg in ("self", "cls"):
                n -= 1
            yield node, n


def test_run_design_is_short_and_no_public_design_function_takes_over_12_parameters():
    params = inspect.signature(run_design).parameters
    assert len(params) <= 8
    lines, _ = inspect.getsourcelines(run_design)
    assert len(lines) <= 70
    over = {
        f"{p.relative_to(DESIGN)} {node.name}"
        for p in sorted(DESIGN.rglob("*.py"))
        for node, n in _signatures(p)
        if n > 12 and (not node.name.startswith("_") or node.name == "__init__")
    }
    # left for later (issue 35): the forest's hyperparameters (a scikit-learn estimator, item 4)
    # (generate_database passes how its rows run on to build_database)
    assert over <= {"rules/miner.py __init__"}
