"""``holofold evaluate``: simulate a table of designs with one of the paper's scenarios.

Reads CSV or Parquet (header = feature names of the published files, SI units) or a published
headerless ``data*_*.txt`` (column names from the ``*_FeatureName.txt`` next to it), checks every
row before simulating anything, and writes the same rows in the same order with the performance
columns and ``status`` (CSV or Parquet, by the output's extension).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import pandas as pd

from holofold.cli._parallel import add_parallel_arguments, parallel_settings
from holofold.design.runner import evaluate_designs, validate_designs
from holofold.design.scenarios import SCENARIO_NAMES, get_scenario
from holofold.mechanics.status import converged_mask, failed_mask

__all__ = ["register", "run", "read_designs", "write_results"]

_CSV = (".csv",)
_PARQUET = (".parquet", ".pq")
_TXT = (".txt",)


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "evaluate",
        help="simulate a table of designs (single Miura cell, canopy, arch)",
        description=(
            "Simulate every row of a design table with one of the paper's scenarios and write "
            "the performance columns and a status per row. Input: CSV or Parquet with the "
            "published feature names as header (SI units: metres, radians, pascals), or a "
            "published headerless data*_*.txt (names from the *_FeatureName.txt next to it)."
        ),
        epilog=_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenario", choices=SCENARIO_NAMES, help="scenario to simulate")
    p.add_argument("designs", type=Path, help="design table (.csv, .parquet or published .txt)")
    p.add_argument(
        "-o", "--output", type=Path, required=True, help="result table (.csv or .parquet)"
    )
    add_parallel_arguments(p)
    p.add_argument("--no-progress", action="store_true", help="no progress bar even on a terminal")
    return p


def _epilog() -> str:
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


def read_designs(path: Path) -> pd.DataFrame:
    """Read a design table (.csv, .parquet/.pq, or a published headerless .txt)."""
    from holofold.design.database import read_table

    path = Path(path)
    if path.suffix.lower() not in _CSV + _PARQUET + _TXT:
        raise ValueError(
            f"design table {path}: unknown extension {path.suffix!r}; allowed: .csv, .parquet, "
            ".pq, .txt"
        )
    return read_table(path)


def _check_output(path: Path) -> None:
    if path.suffix.lower() not in _CSV + _PARQUET:
        raise ValueError(
            f"output {path}: unknown extension {path.suffix!r}; allowed: .csv, .parquet, .pq"
        )
    parent = path.resolve().parent
    if not parent.is_dir():
        raise OSError(f"output folder {parent} does not exist")


def write_results(df: pd.DataFrame, path: Path) -> None:
    """Write atomically (temporary file, then rename) as CSV or Parquet."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=".holofold-", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        if path.suffix.lower() in _CSV:
            df.to_csv(tmp, index=False, float_format="%.12g")
        else:
            df.to_parquet(tmp, index=False)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def run(args) -> int:
    scenario = get_scenario(args.scenario)
    _check_output(args.output)
    workers, scheduler = parallel_settings(args)
    table = read_designs(args.designs)
    if len(table) == 0:
        raise ValueError(f"{args.designs} has no rows")
    checked = validate_designs(scenario, table)  # raises before anything is simulated
    for w in checked.warnings:
        print(f"holofold evaluate: warning: {w}", file=sys.stderr)
    res = evaluate_designs(
        scenario,
        table,
        workers=workers,
        progress=False if args.no_progress else None,
        log_warnings=False,  # printed above
        scheduler=scheduler,
    )
    write_results(res, args.output)
    ok = int(converged_mask(res["status"]).sum())
    failed = int(failed_mask(res["status"]).sum())
    print(
        f"{len(res)} design(s) evaluated with {scenario.name}: {ok} converged, "
        f"{len(res) - ok - failed} not converged, {failed} failed -> {args.output}"
    )
    return 0
