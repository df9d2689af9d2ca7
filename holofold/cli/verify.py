"""``holofold verify``: simulate fresh designs inside mined rules and measure their precision."""

from __future__ import annotations

import argparse

from holofold.cli._parallel import add_parallel_arguments, parallel_settings
from holofold.design.scenarios import SCENARIO_NAMES


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "verify",
        help="simulate new designs inside each mined rule and report how many meet the target",
        description=(
            "Read the rules written by `holofold mine --json`, sample N fresh designs inside "
            "each rule's box (within the scenario's ranges), simulate them and report the "
            "fraction meeting the target, with a 95 % Wilson interval."
        ),
    )
    p.add_argument("scenario", help="scenario: " + ", ".join(SCENARIO_NAMES))
    p.add_argument("--rules", required=True, help="rules.json from `holofold mine --json`")
    p.add_argument("--target", required=True, help="target expression, as given to mine")
    p.add_argument("-n", "--samples", type=int, default=50, help="designs per rule (default 50)")
    p.add_argument("--top", type=int, default=None, help="verify only the first K rules")
    p.add_argument("--seed", type=int, default=0)
    add_parallel_arguments(p)
    p.add_argument("-o", "--output", help="folder for verify.json and the simulated designs")
    return p


def run(args) -> int:
    import json
    from contextlib import nullcontext
    from pathlib import Path

    from holofold.design.runner import dask_scheduler
    from holofold.design.scenarios import get_scenario
    from holofold.design.targets import parse_target
    from holofold.design.verify import rule_ranges, verify_rule

    scenario = get_scenario(args.scenario)
    parse_target(args.target, scenario.performance_names)
    if args.samples < 1:
        raise ValueError(f"--samples = {args.samples} must be >= 1")
    workers, scheduler = parallel_settings(args)
    try:
        rules = json.loads(Path(args.rules).read_text())
    except json.JSONDecodeError as exc:
        raise ValueError(f"{args.rules} is not valid JSON: {exc}") from None
    if not isinstance(rules, list) or not all(isinstance(r, dict) and "bounds" in r for r in rules):
        raise ValueError(f"{args.rules} is not a rules file of `holofold mine --json`")
    rules = rules[: args.top] if args.top else rules
    for r in rules:
        rule_ranges(scenario, r["bounds"])  # all rules checked before simulating
    out = Path(args.output) if args.output else None
    report = []
    # a local Dask cluster is started once for all rules
    cluster = dask_scheduler(scheduler, workers) if scheduler else nullcontext()
    with cluster as address:
        for i, r in enumerate(rules, start=1):
            v = verify_rule(
                scenario,
                r["bounds"],
                args.target,
                args.samples,
                seed=args.seed + i,
                workers=1 if address else workers,
                scheduler=address,
            )
            s = v.summary()
            lo, hi = s["precision_95ci"]
            print(
                f"rule {i}: {r.get('rule', '')}\n  fresh designs meeting the target: "
                f"{s['meeting_target']}/{s['simulated']} = {s['precision']:.3f} "
                f"(95 % CI {lo:.3f}-{hi:.3f}; {s['failed']} failed)"
            )
            report.append({"rank": i, "rule": r.get("rule"), "bounds": r["bounds"], **s})
            if out is not None:
                out.mkdir(parents=True, exist_ok=True)
                v.designs.to_csv(out / f"verify_rule{i}.csv", index=False)
    if out is not None:
        (out / "verify.json").write_text(json.dumps(report, indent=2))
    print(json.dumps([{k: d[k] for k in ("rank", "precision", "simulated")} for d in report]))
    return 0
