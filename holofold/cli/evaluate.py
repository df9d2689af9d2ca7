"""``holofold evaluate``: simulate a table of designs with a scenario (a name or a .toml file).

Reads CSV or Parquet (header = feature names of the published files, SI units) or a published
headerless ``data*_*.txt`` (column names from the ``*_FeatureName.txt`` next to it), checks every
row before simulating anything, and writes the same rows in the same order with the performance
columns and ``status`` (CSV or Parquet, by the output's extension).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from holofold.cli._parallel import (
    add_parallel_arguments,
    add_row_arguments,
    parallel_settings,
    row_settings,
)
from holofold.design import SCENARIO_NAMES

__all__ = ["HELP", "DESCRIPTION", "EPILOG", "FORMATTER", "add_arguments", "run"]

_EPILOG = "<the scenarios' columns>"


class _EpilogFormatter(argparse.RawDescriptionHelpFormatter):
    """Builds the epilog (every scenario's columns) only when the help is printed: building
    the scenarios imports most of the library, which a run of the command need not pay for."""

    def add_text(self, text):
        super().add_text(_epilog() if text is _EPILOG else text)


HELP = "simulate a table of designs (single Miura cell, canopy, arch)"
DESCRIPTION = (
    "Simulate every row of a design table with one of the paper's scenarios and write "
    "the performance columns and a status per row. Input: CSV or Parquet with the "
    "published feature names as header (SI units: metres, radians, pascals), or a "
    "published headerless data*_*.txt (names from the *_FeatureName.txt next to it)."
)
EPILOG = _EPILOG
FORMATTER = _EpilogFormatter


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "scenario",
        help="scenario to simulate: " + ", ".join(SCENARIO_NAMES) + ", or a scenario file .toml",
    )
    p.add_argument("designs", type=Path, help="design table (.csv, .parquet or published .txt)")
    p.add_argument(
        "-o", "--output", type=Path, required=True, help="result table (.csv or .parquet)"
    )
    add_parallel_arguments(p)
    add_row_arguments(p)
    p.add_argument("--no-progress", action="store_true", help="no progress bar even on a terminal")


def _epilog() -> str:
    from holofold.design import get_scenario

    lines = ["columns (SI units; [paper's sampling range]):"]
    for name in SCENARIO_NAMES:
        sc = get_scenario(name)
        feats = []
        for c in sc.features:
            rng = (
                "{" + ",".join(f"{v:g}" for v in c.choices) + "}"
                if c.choices
                else f"[{c.low:g}, {c.high:g}] {c.unit}"
            )
            feats.append(f"{c.name}{'' if c.required else '?'} {rng}")
        lines.append(f"  {name}: " + "; ".join(feats))
        lines.append(f"    -> {', '.join(sc.performance_names)}, status")
    lines.append("  (? = optional, default 2e9 Pa)")
    lines.append("example: holofold evaluate arch designs.csv -o results.parquet --workers 4")
    lines.append(
        "         holofold evaluate arch designs.csv -o out.csv --scheduler tcp://host:8786"
    )
    return "\n".join(lines)


def run(args) -> int:
    from holofold.design import (
        check_table_path,
        converged_rows,
        evaluate_designs,
        failed_rows,
        load_scenario,
        read_table,
        validate_designs,
        write_table,
    )

    scenario = load_scenario(args.scenario)
    check_table_path(args.output)
    workers, scheduler = parallel_settings(args)
    on_invalid, row_timeout = row_settings(args)
    table = read_table(args.designs)
    if len(table) == 0:
        raise ValueError(f"{args.designs} has no rows")
    # --on-invalid fail: raises before anything is simulated
    checked = validate_designs(scenario, table, on_invalid)
    for w in checked.warnings:
        print(f"holofold evaluate: warning: {w}", file=sys.stderr)
    if checked.invalid:
        print(f"holofold evaluate: warning: {checked.skipped_line()}", file=sys.stderr)
    res = evaluate_designs(
        scenario,
        table,
        workers=workers,
        progress=False if args.no_progress else None,
        log_warnings=False,  # printed above
        scheduler=scheduler,
        on_invalid=on_invalid,
        row_timeout=row_timeout,
    )
    write_table(res, args.output)
    ok = int(converged_rows(res).sum())
    failed = int(failed_rows(res).sum())
    print(
        f"{len(res)} design(s) evaluated with {scenario.name}: {ok} converged, "
        f"{len(res) - ok - failed} not converged, {failed} failed -> {args.output}"
    )
    return 0
