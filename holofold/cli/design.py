"""``holofold design``: the whole loop on a scenario, from a target to the best design's files."""

from __future__ import annotations

import argparse
from contextlib import contextmanager
from pathlib import Path

from holofold.cli._fabrication import add_cutter_arguments, cutter_options

__all__ = ["HELP", "DESCRIPTION", "EPILOG", "FORMATTER", "add_arguments", "run"]


HELP = "design end to end: database, rules, verification, the best design and its files"
DESCRIPTION = (
    "Build (or reuse and extend) a database of the scenario, a pilot batch first (the "
    "run stops after it, saying what the designs reach, only when no pilot design "
    "meets the target and a condition is out of reach: the pilot's top tail, "
    "extrapolated, expects less than one design meeting it within --budget; a rare "
    "target goes on), "
    "mine design rules for the target, verify the best rules with fresh simulations, "
    "refine where the forest expects the target and mine again until a rule is verified "
    "or --budget simulations are spent, and choose from every simulated "
    "design the best under --objective inside the best verified rule of all rounds "
    "(without one: the best design meeting the target; without that: the nearest, with "
    "its shortfall). Designs whose thick panels overlap are not chosen unless "
    "--allow-overlap. Always writes OUT/design.json and OUT/report.html, and the "
    "design's fabrication files (FOLD, SVG, STL, OBJ, printable part) with its fit on "
    "the printer's bed. Re-running resumes; a larger -n, --budget or --verify extends "
    "the folder. Exit status 0: the chosen design meets the target; 1: no simulated "
    "design does (the nearest is shown); 2: bad input."
)
EPILOG = (
    "examples:\n"
    "  holofold scenarios show arch > my_arch.toml   # then edit curve, loads, ranges\n"
    "  holofold describe my_arch.toml                # what the designs reach\n"
    "  holofold design my_arch.toml --target 'Zstiff > 100 & error < 0.05' -o out\n"
    "  holofold design arch --target 'Zstiff > 60 & error < 0.08' -o out --rounds 2 \\\n"
    "      --objective 'min mass' --bed 250x210"
)
FORMATTER = argparse.RawDescriptionHelpFormatter


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", help="scenario name (holofold scenarios) or a scenario file .toml")
    p.add_argument("--target", required=True, help="target over the performance columns")
    p.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    p.add_argument(
        "-n", "--samples", type=int, default=200, help="designs in the base database (default 200)"
    )
    p.add_argument(
        "--objective",
        default="margin",
        help="which design meeting the target is best: 'margin' (default: the "
        "largest worst-case margin), 'min COLUMN' or 'max COLUMN' (e.g. 'min "
        "mass')",
    )
    p.add_argument(
        "--allow-overlap",
        action="store_true",
        help="let a design whose folded thick panels overlap be chosen",
    )
    p.add_argument(
        "--bed",
        default=None,
        metavar="WxD",
        help="printer bed WIDTHxDEPTH in mm the part is fitted on and, when larger, cut into "
        "pieces for (default: the scenario's bed key, else 250x210)",
    )
    p.add_argument(
        "--pilot",
        type=int,
        default=None,
        help="designs simulated first to check the target is within reach (default 50; 0: none)",
    )
    p.add_argument("--db", type=Path, help="database folder (default OUT/database)")
    p.add_argument(
        "--budget",
        type=int,
        default=6000,
        help="simulations the run may spend at most: database, refinement and verification "
        "designs (default 6000); the loop stops earlier once a rule is verified: 90 %% of its "
        "fresh designs meet the target and the 95 %% interval's lower end is at least 0.8",
    )
    p.add_argument(
        "--rounds",
        type=int,
        default=None,
        help="refinement rounds at most (default: as many as --budget allows; 0 mines once, "
        "as the paper)",
    )
    p.add_argument(
        "--refine", type=int, default=50, help="new designs per refinement round (default 50)"
    )
    p.add_argument(
        "--strategy",
        default="mixed",
        metavar="NAME",
        help="where a refinement round samples: half where the forest votes for the target and "
        "half inside the best rule (mixed, default), all where the forest votes (likely), "
        "inside and around the rules (around), or a registered strategy "
        "(holofold.design.STRATEGIES)",
    )
    p.add_argument(
        "--all-rounds",
        action="store_true",
        help="run every refinement round, also after a rule is verified",
    )
    p.add_argument(
        "--patience",
        type=int,
        default=4,
        help="once a rule is verified (at any precision), stop with the best design after this "
        "many rounds in which the best verified rule's 95 %% lower bound did not rise "
        "(default 4; 0: never)",
    )
    p.add_argument("--verify", type=int, default=50, help="fresh designs per verified rule")
    p.add_argument("--top", type=int, default=3, help="rules kept and verified per round")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    p.add_argument(
        "--units",
        choices=("mm", "m"),
        default="mm",
        help="length unit of the STL/OBJ files (default mm, as slicers read them)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    add_cutter_arguments(p)


def run(args) -> int:
    from holofold.design import (
        PILOT,
        DesignFiles,
        DesignProblem,
        Execution,
        LoopSettings,
        run_design,
    )

    problem = DesignProblem(
        args.scenario, args.target, objective=args.objective, bed=args.bed,
        allow_overlap=args.allow_overlap,
    )  # fmt: skip
    settings = LoopSettings(
        samples=args.samples, rounds=args.rounds, budget=args.budget, refine=args.refine,
        verify=args.verify, top=args.top, strategy=args.strategy,
        until_verified=not args.all_rounds, seed=args.seed,
        pilot=PILOT if args.pilot is None else args.pilot,
        patience=None if args.patience == 0 else args.patience,
    )  # fmt: skip
    execution = Execution(
        workers=args.workers, progress=False if args.no_progress else None,
        say=lambda text: print(text, flush=True),
    )  # fmt: skip
    output = DesignFiles(db=args.db, mesh_units=args.units, cutter=cutter_options(args))
    with _sigterm_as_exit():  # a run stopped by SIGTERM still counts in runs.json's total
        out = run_design(problem, folder=args.output, settings=settings, execution=execution,
                         output=output)  # fmt: skip
    return 0 if out.met else 1


@contextmanager
def _sigterm_as_exit():
    """SIGTERM raises SystemExit(143) in the main thread (the loop records the run's seconds
    before it exits); the previous handler is restored after."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, _frame):
        raise SystemExit(128 + signum)

    before = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, before)
