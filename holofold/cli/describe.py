"""``holofold describe``: what a scenario's designs reach, column by column, before a target."""

from __future__ import annotations

import argparse

__all__ = ["HELP", "DESCRIPTION", "EPILOG", "FORMATTER", "add_arguments", "run"]


HELP = "each performance column's distribution (quantiles, units): pick a reachable target"
DESCRIPTION = (
    "Print each performance column's distribution (min, 5 %, quartiles, 95 %, max, in "
    "the column's unit) over a database folder's simulated designs, or over a small "
    "pilot sample of a scenario (a name or a .toml file) simulated now. Use it to write "
    "a target the designs can reach before running `holofold design`."
)
EPILOG = (
    "examples:\n"
    "  holofold describe examples/my_arch.toml          # a pilot of 50 designs\n"
    "  holofold describe arch -n 200 --workers 2\n"
    "  holofold describe out/database                   # a database already simulated"
)
FORMATTER = argparse.RawDescriptionHelpFormatter


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("source", help="scenario name, scenario file .toml, or a database folder")
    p.add_argument(
        "-n", "--samples", type=int, default=None, help="pilot designs for a scenario (default 50)"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")
    p.add_argument("-o", "--output", help="keep the pilot's database in this folder")
    p.add_argument("--json", action="store_true", help="print the distributions as JSON")


def run(args) -> int:
    import json

    from holofold.design import PILOT, check_workers, describe_source, distributions_text

    check_workers(args.workers)
    n = PILOT if args.samples is None else args.samples
    dists, where = describe_source(
        args.source, n=n, seed=args.seed, workers=args.workers, folder=args.output
    )
    if args.json:
        print(json.dumps([d.to_json() for d in dists], indent=2))
    else:
        print(distributions_text(dists, f"{where}:"))
    return 0
