"""``holofold demo``: the whole loop on the paper's arch, end to end, in about a minute.

1. fit a Miura strip to a half circle of radius 2 m and export it for fabrication
   (FOLD, SVG, STL, OBJ and a thick printable solid);
2. simulate that strip (vertical and horizontal stiffness, snap-through, fitting error);
3. sample N arch designs and simulate them into a resumable Parquet database;
4. mine design rules for a target from the database (random forest, held-out test);
5. verify the best rule by simulating fresh designs inside it.

Everything lands in the output folder, with ``summary.json`` describing what was done.
"""

from __future__ import annotations

import argparse

TARGET = "Zstiff > 100 & error < 0.1"
STRIP = {"m": 12, "offset": 0.2, "stripeWidth": 0.02, "extrude": 0.1}
MATERIAL = {"tcrease": 0.8e-3, "tpanel": 2e-3, "W": 3e-3}  # a printable strip: no panel overlap


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "demo",
        help="end-to-end demo: fit a curve, simulate, build a database, mine and verify a rule",
        description=__doc__.split("\n\n")[0],
    )
    p.add_argument("-o", "--output", default="holofold-demo", help="output folder")
    p.add_argument("-n", "--samples", type=int, default=200, help="designs in the database")
    p.add_argument("--verify", type=int, default=30, help="fresh designs to verify the rule")
    p.add_argument("--target", default=TARGET, help=f"target expression (default {TARGET!r})")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    return p


def _step(n: int, text: str) -> None:
    print(f"\n[{n}/5] {text}", flush=True)


def run(args) -> int:
    import json
    from pathlib import Path

    from holofold.cli import main as holofold
    from holofold.design.scenarios import get_scenario
    from holofold.design.targets import parse_target

    arch = get_scenario("arch")
    parse_target(args.target, arch.performance_names)
    if args.samples < 20:
        raise ValueError(f"--samples = {args.samples} must be >= 20 for rules to be mined")
    if args.verify < 1:
        raise ValueError(f"--verify = {args.verify} must be >= 1")
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict = {"target": args.target}

    def call(argv: list[str]) -> None:
        code = holofold(argv)
        if code:
            raise ValueError(f"step `holofold {' '.join(argv)}` failed (status {code})")

    _step(1, "fit a Miura strip to a half circle (radius 2 m) and export it")
    call(
        ["fit", "--curve", "half-circle:radius=2", "--m", str(STRIP["m"]),
         "--offset", str(STRIP["offset"]), "--strip-width", str(STRIP["stripeWidth"]),
         "--extrude", str(STRIP["extrude"]), "--panel-thickness", str(MATERIAL["tpanel"]),
         "--crease-width", str(MATERIAL["W"]), "-o", str(out / "1_fit")]
    )  # fmt: skip

    _step(2, "simulate the fitted strip (pinned feet, 5 N at the apex)")
    perf = arch.evaluate({**STRIP, **MATERIAL})
    summary["fitted_strip"] = {"design": {**STRIP, **MATERIAL}, "performance": perf}
    print(
        f"Zstiff = {perf['Zstiff']:.1f} N/m, Xstiff = {perf['Xstiff']:.1f} N/m, "
        f"snaps = {bool(perf['Zsnap'])}, fitting error = {perf['error']:.4f} m ({perf['status']})"
    )

    _step(3, f"sample {args.samples} arch designs and simulate them into a database")
    db = out / "2_database"
    call(
        ["generate", "arch", "-n", str(args.samples), "--seed", str(args.seed),
         "--workers", str(args.workers), "-o", str(db), "--csv"]
    )  # fmt: skip

    _step(4, f"mine design rules for: {args.target}")
    rules = out / "3_rules"
    rules.mkdir(exist_ok=True)
    call(
        ["mine", str(db / "database.parquet"), "--target", args.target, "--seed", str(args.seed),
         "--max-overlap", "0.5", "--json", str(rules / "rules.json"),
         "--plot", str(rules / "rules.png")]
    )  # fmt: skip
    mined = json.loads((rules / "rules.json").read_text())
    summary["rules"] = mined

    _step(5, f"verify the best rule with {args.verify} fresh simulations")
    call(
        ["verify", "arch", "--rules", str(rules / "rules.json"), "--target", args.target,
         "-n", str(args.verify), "--top", "1", "--seed", str(args.seed),
         "--workers", str(args.workers), "-o", str(out / "4_verify")]
    )  # fmt: skip
    summary["verification"] = json.loads((out / "4_verify" / "verify.json").read_text())
    (out / "summary.json").write_text(json.dumps(summary, indent=2, default=str))
    v = summary["verification"][0]
    print(
        f"\ndone: best rule '{mined[0]['rule']}' holds for {v['meeting_target']}/{v['simulated']} "
        f"fresh designs; files in {out}/ (summary.json, 1_fit/, 2_database/, 3_rules/, 4_verify/)"
    )
    return 0
