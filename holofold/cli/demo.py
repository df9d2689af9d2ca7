"""``holofold demo``: the whole loop on the paper's arch, end to end, in about 15 seconds."""

from __future__ import annotations

import argparse

#: the demo's default target, as ``holofold.design.DEMO_TARGET`` (a test keeps them equal);
#: written out so that ``holofold --help`` does not import the design layer
TARGET = "Zstiff > 100 & error < 0.1"


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "demo",
        help="end-to-end demo: fit a curve, simulate, build a database, mine and verify a rule",
        description=(
            "Fit a Miura strip to a half circle and export it, simulate it, build a database "
            "of arch designs, mine design rules for a target and verify the best one with "
            "fresh simulations."
        ),
    )
    p.add_argument("-o", "--output", default="holofold-demo", help="output folder")
    p.add_argument("-n", "--samples", type=int, default=200, help="designs in the database")
    p.add_argument("--verify", type=int, default=30, help="fresh designs to verify the rule")
    p.add_argument("--target", default=TARGET, help=f"target expression (default {TARGET!r})")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    return p


def run(args) -> int:
    from holofold.design import run_demo

    run_demo(
        args.output, samples=args.samples, verify=args.verify, target=args.target,
        seed=args.seed, workers=args.workers, say=lambda text: print(text, flush=True),
    )  # fmt: skip
    return 0
