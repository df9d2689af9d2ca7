"""``holofold design``: the whole loop on a scenario, from a target to a verified design's files."""

from __future__ import annotations

import argparse
from pathlib import Path

from holofold.cli._fabrication import add_cutter_arguments, cutter_options

__all__ = ["register", "run"]


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "design",
        help="design end to end: database, rules, verification, a chosen design and its files",
        description=(
            "Build (or reuse and extend) a database of the scenario, mine design rules for the "
            "target, verify the best rules with fresh simulations, optionally refine the "
            "database around them for --rounds rounds, choose the simulated design with the "
            "largest margin to the target inside the best verified rule, and write "
            "OUT/design.json, its fabrication files (FOLD, SVG, STL, OBJ, printable solid), "
            "pictures and OUT/report.html. Re-running the same command resumes."
        ),
        epilog=(
            "examples:\n"
            "  holofold scenarios show arch > my_arch.toml   # then edit curve, loads, ranges\n"
            "  holofold design my_arch.toml --target 'Zstiff > 100 & error < 0.05' -o out\n"
            "  holofold design arch --target 'Zstiff > 60 & error < 0.08' -o out --rounds 2"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenario", help="scenario name (holofold scenarios) or a scenario file .toml")
    p.add_argument("--target", required=True, help="target over the performance columns")
    p.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    p.add_argument("-n", "--samples", type=int, default=500, help="designs in the base database")
    p.add_argument("--db", type=Path, help="database folder (default OUT/database)")
    p.add_argument("--rounds", type=int, default=0, help="refinement rounds (default 0)")
    p.add_argument("--refine", type=int, default=100, help="new designs per refinement round")
    p.add_argument("--verify", type=int, default=50, help="fresh designs per verified rule")
    p.add_argument("--top", type=int, default=3, help="rules kept and verified per round")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    p.add_argument(
        "--units", choices=("mm", "m"), default="mm",
        help="length unit of the STL/OBJ files (default mm, as slicers read them)",
    )  # fmt: skip
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    add_cutter_arguments(p)
    return p


def run(args) -> int:
    from holofold.design import run_design

    cutter = cutter_options(args)
    run_design(
        args.scenario, args.target, args.output, samples=args.samples, rounds=args.rounds,
        refine=args.refine, verify=args.verify, top=args.top, db=args.db, seed=args.seed,
        workers=args.workers, progress=False if args.no_progress else None, mesh_units=args.units,
        cutter=cutter, say=lambda text: print(text, flush=True),
    )  # fmt: skip
    return 0
