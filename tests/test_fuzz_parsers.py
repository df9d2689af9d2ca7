"""Property-based tests: any input to the target language or the scenario-file reader gives a
result or the project's own error, never another exception (issue 15, section 6)."""

from __future__ import annotations

import string

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from holofold.design import TargetError, parse_target, read_scenario, shipped_text
from holofold.design.scenarios import ScenarioFileError

COLUMNS = ["Zstiff", "Xstiff", "error", "Zsnap"]
TOKENS = [
    "Zstiff",
    "Xstiff",
    "error",
    "Zsnap",
    "nope",
    "`a b`",
    "<",
    "<=",
    ">",
    ">=",
    "==",
    "!=",
    "&",
    "|",
    "(",
    ")",
    "+",
    "-",
    "1",
    "0.5",
    "1e3",
    ".2",
    "1e999",
    " ",
    "#",
    "`",
]


@settings(max_examples=400, deadline=None)
@given(st.lists(st.sampled_from(TOKENS), max_size=30))
def test_any_token_sequence_parses_or_raises_target_error(tokens):
    expr = " ".join(tokens)
    try:
        t = parse_target(expr, COLUMNS)
    except TargetError as exc:
        assert "\n" not in str(exc)
        return
    frame = pd.DataFrame({c: [1.0, 200.0, float("nan")] for c in COLUMNS})
    assert t.evaluate(frame).shape == (3,)
    assert t.margin(frame).shape == (3,)
    assert parse_target(str(t), COLUMNS).columns == t.columns  # rendering parses back


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet=string.printable, max_size=200))
def test_any_text_parses_or_raises_target_error(expr):
    try:
        parse_target(expr, COLUMNS)
    except TargetError:
        pass


@pytest.mark.parametrize("depth", [10, 50, 51, 500, 4000])
def test_deep_nesting_is_refused_in_one_line_not_a_recursion_error(depth):
    expr = "(" * depth + "Zstiff > 1" + ")" * depth
    if depth <= 50:
        assert parse_target(expr, COLUMNS).columns == ("Zstiff",)
    else:
        with pytest.raises(TargetError, match="nested deeper than 50"):
            parse_target(expr, COLUMNS)


def test_a_huge_expression_is_refused_before_parsing():
    with pytest.raises(TargetError, match="at most 10000"):
        parse_target(" & ".join(["Zstiff > 1"] * 5000), COLUMNS)


ARCH = shipped_text("arch")


@settings(
    max_examples=250, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.data())
def test_a_mutated_scenario_file_reads_or_raises_scenario_file_error(tmp_path, data):
    """Delete, duplicate or replace lines and characters of the shipped arch file."""
    lines = ARCH.splitlines()
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        how = data.draw(st.sampled_from(["drop", "dup", "chars", "value"]))
        if how == "drop":
            del lines[i]
        elif how == "dup":
            lines.insert(i, lines[i])
        elif how == "chars":
            lines[i] = data.draw(st.text(alphabet=string.printable, max_size=40))
        else:
            key = lines[i].split("=")[0].strip() or "x"
            value = data.draw(
                st.sampled_from(
                    [
                        "-1",
                        "0",
                        "1e400",
                        "nan",
                        "inf",
                        '"mm"',
                        "[1, 2]",
                        "[2, 1]",
                        "{choices = []}",
                        "{choices = [8, 8]}",
                        "true",
                        '"x.csv"',
                        "[0, 0, 0]",
                        "1.5",
                        "[[1]]",
                    ]
                )
            )
            lines[i] = f"{key} = {value}"
        if not lines:
            lines = [""]
    path = tmp_path / "fuzzed.toml"
    path.write_text("\n".join(lines))
    try:
        sc = read_scenario(path)
    except ScenarioFileError as exc:
        assert "\n" not in str(exc)
        return
    assert sc.performance_names and sc.feature_names
