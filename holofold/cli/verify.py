"""``holofold verify``: simulate fresh designs inside mined rules and measure their precision."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from holofold.cli._parallel import (
    add_parallel_arguments,
    add_row_arguments,
    parallel_settings,
    row_settings,
)
from holofold.design import SCENARIO_NAMES

HELP = "simulate new designs inside each mined rule and report how many meet the target"
DESCRIPTION = (
    "Read the rules written by `holofold mine --json`, sample N fresh designs inside "
    "each rule's box (within the scenario's ranges), simulate them and report the "
    "fraction meeting the target, with a 95 % Wilson interval. With -o the designs are "
    "simulated into resumable databases OUT/rule{i}-{key}/ (the design loop's own "
    "verification): an interrupted run resumes, and a larger -n adds designs."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "scenario", help="scenario: " + ", ".join(SCENARIO_NAMES) + ", or a scenario file .toml"
    )
    p.add_argument("--rules", required=True, help="rules.json from `holofold mine --json`")
    p.add_argument("--target", required=True, help="target expression, as given to mine")
    p.add_argument("-n", "--samples", type=int, default=50, help="designs per rule (default 50)")
    p.add_argument("--top", type=int, default=None, help="verify only the first K rules")
    p.add_argument("--seed", type=int, default=0)
    add_parallel_arguments(p)
    add_row_arguments(p, on_invalid="skip")
    p.add_argument("-o", "--output",
                   help="folder for verify.json, the simulated designs and their resumable "
                        "databases")  # fmt: skip


def run(args) -> int:
    import json

    from holofold.design import load_scenario, read_rules, verify_rules, write_verification

    workers, scheduler = parallel_settings(args)
    on_invalid, row_timeout = row_settings(args)
    if args.top is not None and args.top < 1:
        raise ValueError(f"--top = {args.top} must be >= 1")
    if args.output is not None:  # before any simulation: a folder that can be written
        from holofold.geometry import check_output_folder

        if Path(args.output).exists() and not Path(args.output).is_dir():
            raise ValueError(f"--output {args.output!r} exists and is not a folder")
        check_output_folder(args.output, "--output")
    rules = read_rules(args.rules)[: args.top]
    scenario = load_scenario(args.scenario)
    results = verify_rules(
        scenario, rules, args.target, args.samples,
        seed=args.seed, workers=workers, scheduler=scheduler,
        on_invalid=on_invalid, row_timeout=row_timeout, folder=args.output,
    )  # fmt: skip
    for i, (r, v) in enumerate(zip(rules, results, strict=True), start=1):
        print(f"rule {i}: {r.text(scenario.columns)}\n  {v.describe()}")
        shown = _shown(r)
        if shown:
            print(f"  {shown}")
    if args.output is not None:
        write_verification(args.output, rules, results, scenario.columns)
    print(json.dumps([{"rank": i, **{k: v.summary()[k] for k in ("precision", "simulated")}}
                      for i, v in enumerate(results, start=1)]))  # fmt: skip
    return 0


def _shown(rule) -> str:
    """What `holofold mine` said of the rule (its estimate and held-out precision), if the
    rules file carries it: '' otherwise."""
    parts = []
    e = rule.estimate
    if e is not None:
        text = f"estimate {e.precision:.3f}"
        if math.isfinite(e.low) and math.isfinite(e.high):
            text += f" (95 % interval {e.low:.3f}-{e.high:.3f})"
        parts.append(text)
    if rule.test is not None:
        parts.append(f"held-out precision {rule.test.precision:.3f}")
    return "mined with: " + ", ".join(parts) if parts else ""
