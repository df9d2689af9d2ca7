"""``holofold generate``: sample designs of a scenario and simulate them into a database."""

from __future__ import annotations

import argparse

from holofold.cli._parallel import (
    add_parallel_arguments,
    add_row_arguments,
    parallel_settings,
    row_settings,
)
from holofold.design import SCENARIO_NAMES

HELP = "sample designs and simulate them into a resumable Parquet database"
DESCRIPTION = (
    "Sample N designs of a scenario inside the paper's ranges (or yours) and simulate "
    "them into FOLDER (chunked Parquet; re-running the same command resumes an "
    "interrupted run without losing or duplicating rows)."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "scenario", help="scenario: " + ", ".join(SCENARIO_NAMES) + ", or a scenario file .toml"
    )
    p.add_argument("-n", "--samples", type=int, required=True, help="number of designs")
    p.add_argument("-o", "--output", required=True, help="database folder")
    p.add_argument("--seed", type=int, default=0, help="sampling seed (default 0)")
    p.add_argument("--method", default="random", choices=["random", "lhs", "sobol"])
    p.add_argument(
        "--range",
        action="append",
        default=[],
        metavar="NAME=LOW:HIGH",
        help="override a feature's range (SI units), or NAME=A,B,C for categorical choices "
        "(NAME=LOW:HIGH on a categorical feature keeps its choices in [LOW, HIGH])",
    )
    add_parallel_arguments(p)
    add_row_arguments(p, on_invalid="skip")
    p.add_argument("--chunk-size", type=int, default=100, help="rows per result chunk")
    p.add_argument("--csv", action="store_true", help="also write database.csv")
    p.add_argument(
        "--retry-failed",
        action="store_true",
        help="simulate the stored failed rows again (a resume always simulates again the rows "
        "whose stored failure was the environment's, not the design's)",
    )


def _parse_ranges(items):
    out = {}
    for it in items:
        name, sep, val = it.partition("=")
        if not sep or not name:
            raise ValueError(f"--range {it!r}: expected NAME=LOW:HIGH or NAME=A,B,C")
        try:
            if ":" in val:
                lo, hi = (float(v) for v in val.split(":", 1))
                out[name.strip()] = (lo, hi)
            else:
                out[name.strip()] = [float(v) for v in val.split(",")]
        except ValueError:
            raise ValueError(f"--range {it!r}: values must be numbers") from None
    return out


def run(args) -> int:
    from pathlib import Path

    from holofold.design import failed_rows, generate_database

    workers, scheduler = parallel_settings(args)
    on_invalid, row_timeout = row_settings(args)
    db = generate_database(
        args.scenario, args.samples, args.output,
        seed=args.seed, method=args.method, ranges=_parse_ranges(args.range),
        chunk_size=args.chunk_size, workers=workers, scheduler=scheduler, csv=args.csv,
        on_invalid=on_invalid, row_timeout=row_timeout, retry_failed=args.retry_failed,
    )  # fmt: skip
    failed = int(failed_rows(db).sum())
    where = Path(args.output) / "database.parquet"
    print(f"{args.scenario}: {len(db)} designs in {where} ({failed} failed)")
    return 0
