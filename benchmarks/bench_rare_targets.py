"""Rare targets with fewer simulations: how many simulations each strategy needs before its best
rule reaches a verified precision of 0.9 (Wilson 95 % lower bound 0.8).

A rule counts as verified when ``VERIFY`` fresh designs drawn uniformly inside it (and inside the
scenario's ranges) are simulated and at least 90 % of them meet the target with the two-sided
95 % Wilson interval's lower end at 0.8 or more (46 of 50). Every simulated design counts: the
database, refinement designs and verification designs. Verification stops early once a rule can
no longer pass (that does not make passing easier).

Strategies (seeded; the same seed gives the same designs):

* ``one-shot``: the paper's method. A random database of N designs, rules mined once
  (``tighten=False, simplify="none"``, the top rule by F0.2 of its training precision), the top
  rule verified; N = 250, 500, 1000, 2000, 4000, 6000 in turn (each database extends the
  previous one), so the count is the first N that passes plus every verification tried on the
  way.
* ``one-shot-holofold``: the same with holofold's miner (tightened, distinct rules), the rule
  of the best estimate verified: what the miner alone changes.
* ``rounds``: today's design loop (``holofold design`` defaults): 500 random designs, the top 3
  distinct rules verified with 50 designs each, then rounds of 100 designs inside and around
  the rules (or around the designs meeting the target when there is no rule yet).
* ``loop-mixed``, ``loop-likely`` and ``loop-around``: the design loop itself (``run_design`` with
  its defaults, rounds until a rule is verified or its budget of 6000 simulations is spent;
  ``allow_overlap=True`` so that it mines the target as given, like the others), sampling half
  where the forest votes for the target and half inside the best rule (``strategy="mixed"``,
  the default), all where the forest votes (``"likely"``) or inside and around the rules
  (``"around"``).
* ``likelihood``: forest-likelihood sampling. 200 random designs; each round the rule miner is
  fitted on every simulated design, 50 new designs are drawn from 20,000 random candidates
  with probability proportional to the square of the forest's vote for the target (where the
  forest says the target is likely), and the rule with the best lower estimate
  (``Rule.estimate.low``) is verified when its estimate reaches 0.85 (one rule per round, never
  the same box twice; its verification designs join the database).

Run it niced; simulations are cached under ``benchmarks/.cache/rare`` (gitignored), so a second
run re-mines without simulating. ``--quick`` runs the cheap scenarios only.

    nice -n 19 python benchmarks/bench_rare_targets.py [--quick] [--seeds 2] [--first-seed 0]
    python benchmarks/bench_rare_targets.py --table    # the tables of every saved run
"""

from __future__ import annotations

import argparse
import hashlib
import math
import os
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design import (
    FewRulesWarning,
    ForestRuleMiner,
    evaluate_designs,
    load_scenario,
    mined_rules,
    parse_target,
    rule_ranges,
    sample_designs,
)
from holofold.design.database.row_status import failed_rows
from holofold.design.loop.design_loop import _box_of, _roles, refine_designs

HERE = Path(__file__).resolve().parent
CACHE = HERE / ".cache" / "rare"
VERIFY = 50  #: fresh designs per verified rule
BUDGET = 6000  #: simulations after which a strategy gives up
LOOP_BUDGET = None  #: the design loop's budget (None: run_design's default)
#: one-shot's databases in turn (each extends the previous one), up to the budget
ONE_SHOT_SIZES = (250, 500, 1000, 2000, 4000, BUDGET)


@dataclass(frozen=True)
class Case:
    """A target on a scenario (a shipped name or a scenario file)."""

    label: str
    scenario: str
    target: str
    window: bool = False
    quick: bool = True


CASES = (
    Case("miura-soft", "single-miura", "axialstiff60 < 3000"),
    Case(
        "miura-window",
        "single-miura",
        "10000 < axialstiff30 < 10400 & axialstiff90 > 400000",
        window=True,
    ),
    Case("arch-stiff", "arch", "Zstiff > 2500"),
    Case("arch-snap", "arch", "Zsnap == 1 & error < 0.08"),
    Case("arch-window", "arch", "900 < Xstiff < 1300 & error < 0.11", window=True),
    Case(
        "sheet-window",
        str(HERE / "scenarios" / "pa12_sheet.toml"),
        "3000 < axialstiff50 < 4000 & bendstiff80 > 3000",
        window=True,
    ),
    Case("canopy-stiff", "canopy", "bendstiff90 > 35000", quick=False),
    Case("gripper-stiff", "gripper", "stiff > 0.005", quick=False),
)


def wilson_low(k: int, n: int, z: float = 1.959964) -> float:
    if n == 0:
        return 0.0
    p = k / n
    centre = p + z * z / (2 * n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return (centre - half) / (1 + z * z / n)


def passes(k: int, n: int) -> bool:
    return n > 0 and k / n >= 0.9 and wilson_low(k, n) >= 0.8


#: the least number of the VERIFY designs that must meet the target
K_MIN = next(k for k in range(VERIFY + 1) if passes(k, VERIFY))


class Simulator:
    """Simulates designs of one scenario, with a cache on disk keyed by the feature values."""

    def __init__(self, scenario, workers: int):
        self.sc = load_scenario(scenario)
        self.workers = workers
        name = hashlib.sha1(str(scenario).encode()).hexdigest()[:8]
        self.path = CACHE / f"{self.sc.name}-{name}.parquet"
        self.features = self.sc.feature_names
        self.cols = [*self.features, *self.sc.performance_names, "status"]
        self.cache = pd.read_parquet(self.path) if self.path.is_file() else pd.DataFrame()
        self.index = dict(zip(self._keys(self.cache), range(len(self.cache)), strict=True))
        self.new = 0

    def _keys(self, frame) -> list[str]:
        if not len(frame):
            return []
        vals = frame.reindex(columns=self.features).to_numpy(dtype=float)
        return [",".join(map(repr, row)) for row in vals.tolist()]

    def __call__(self, designs: pd.DataFrame) -> pd.DataFrame:
        designs = designs.reset_index(drop=True)
        keys = self._keys(designs)
        todo = [i for i, k in enumerate(keys) if k not in self.index]
        if todo:
            res = evaluate_designs(self.sc, designs.iloc[todo], workers=self.workers,
                                   progress=False, on_invalid="skip")  # fmt: skip
            res = res.reindex(columns=[c for c in res.columns if c != "sample"])
            res["status"] = res["status"].astype(str)
            start = len(self.cache)
            self.cache = pd.concat([self.cache, res], ignore_index=True)
            for j, i in enumerate(todo):
                self.index[keys[i]] = start + j
            self.new += len(todo)
            if len(todo) >= 20 or self.new % 100 < len(todo):
                self.save()
        rows = self.cache.iloc[[self.index[k] for k in keys]].reset_index(drop=True)
        return rows

    def save(self):
        """Write the cache, merged with what other runs wrote meanwhile (by feature values)."""
        CACHE.mkdir(parents=True, exist_ok=True)
        frame = self.cache
        if self.path.is_file():
            try:
                disk = pd.read_parquet(self.path)
            except (OSError, ValueError):
                disk = None
            if disk is not None and len(disk):
                known = set(self.index)
                extra = [k not in known for k in self._keys(disk)]
                frame = pd.concat([frame, disk.loc[extra]], ignore_index=True)
        tmp = self.path.with_suffix(f".{os.getpid()}.tmp")
        frame.to_parquet(tmp, index=False)
        tmp.replace(self.path)


@dataclass
class Run:
    """What a strategy did on one case and seed."""

    sims: int = 0
    passed: bool = False
    rule: str = ""
    verified: tuple = ()
    rounds: int = 0
    log: list = field(default_factory=list)


class Context:
    def __init__(self, case: Case, sim: Simulator, seed: int):
        self.case, self.sim, self.seed = case, sim, seed
        self.sc = sim.sc
        self.target = parse_target(case.target, self.sc.performance_names)
        self.roles = _roles(self.sc)
        self.run = Run()

    def simulate(self, designs: pd.DataFrame) -> pd.DataFrame:
        self.run.sims += len(designs)
        return self.sim(designs)

    def ok(self, table: pd.DataFrame) -> tuple[pd.DataFrame, np.ndarray]:
        good = table.loc[~failed_rows(table)].reset_index(drop=True)
        return good, np.asarray(self.target.evaluate(good), bool)

    def verify(self, rule, seed: int) -> tuple[bool, pd.DataFrame]:
        """Verify ``rule`` with VERIFY fresh designs, stopping once it cannot pass."""
        designs = sample_designs(self.sc, VERIFY, seed=seed, ranges=rule_ranges(self.sc, rule))
        parts, k, n = [], 0, 0
        for a in range(0, VERIFY, 10):
            res = self.simulate(designs.iloc[a : a + 10])
            parts.append(res)
            good, meets = self.ok(res)
            k += int(meets.sum())
            n += len(res)  # a failed simulation counts as a miss
            if n - k > VERIFY - K_MIN:
                break
        ok = n == VERIFY and k >= K_MIN
        self.run.verified += ((k, n),)
        self.run.log.append(f"verify {rule.text(self.sc.columns)}: {k}/{n}")
        if ok:
            self.run.passed, self.run.rule = True, rule.text(self.sc.columns)
        return ok, pd.concat(parts, ignore_index=True)

    def miner(self, **kw) -> ForestRuleMiner:
        cats = list(self.roles.categorical) or None
        return ForestRuleMiner(categorical_features=cats, random_state=self.seed, **kw)

    def fit(self, table, **kw):
        good, y = self.ok(table)
        if y.all() or not y.any():
            return None, good, y
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            m = self.miner(**kw).fit(good[list(self.roles.features)], y)
        return m, good, y


def one_shot(ctx: Context, paper: bool = True) -> Run:
    table = pd.DataFrame()
    have = 0
    kw = dict(tighten=False, simplify="none", n_rules=1, max_overlap=None) if paper else {}
    for k, n in enumerate(ONE_SHOT_SIZES):
        designs = sample_designs(ctx.sc, n - have, seed=ctx.seed, start=have)
        table = pd.concat([table, ctx.simulate(designs)], ignore_index=True)
        have = n
        m, _, _ = ctx.fit(table, **kw)
        ctx.run.rounds = k + 1
        if m is None or not len(m.rules_):
            continue
        rules = mined_rules(m)
        best = rules[0] if paper else max(rules, key=lambda x: x.estimate.precision)
        ok, _ = ctx.verify(best, seed=ctx.seed * 1000 + 17 + k)
        if ok:
            break
    return ctx.run


def one_shot_holofold(ctx: Context) -> Run:
    """One-shot with holofold's miner (tightened, distinct rules; the best estimate verified)."""
    return one_shot(ctx, paper=False)


def rounds(ctx: Context, samples=500, refine=100, top=3) -> Run:
    table = ctx.simulate(sample_designs(ctx.sc, samples, seed=ctx.seed))
    r = 0
    while ctx.run.sims < BUDGET:
        m, good, y = ctx.fit(table, n_rules=top)
        rules = mined_rules(m)[:top] if m is not None else []
        ctx.run.rounds = r + 1
        if rules:
            for i, rule in enumerate(rules, start=1):
                ok, res = ctx.verify(rule, seed=ctx.seed + 100 * r + i)
                table = pd.concat([table, res], ignore_index=True)
                if ok:
                    return ctx.run
            around = rules
        elif y.any():
            around = [_box_of(good.loc[y], ctx.roles)]
        else:
            around = None
        if around is None:
            new = sample_designs(ctx.sc, refine, seed=ctx.seed + 7919 * (r + 1), start=samples)
        else:
            new = refine_designs(ctx.sc, around, refine, seed=ctx.seed + 7919 * (r + 1),
                                 start=10**6 * (r + 1))  # fmt: skip
        table = pd.concat([table, ctx.simulate(new.drop(columns="sample"))], ignore_index=True)
        r += 1
    return ctx.run


def likelihood(ctx: Context, start=200, batch=50, candidates=20000, gate=0.85) -> Run:
    """Forest-likelihood sampling with one verification at a time.

    Each round the miner is fitted on every simulated design; ``batch`` new designs are drawn
    from ``candidates`` random ones with probability proportional to the square of the forest's
    vote for the target; the rule with the best lower estimate (``estimate.low``) is verified
    when its estimate reaches ``gate``, and the verification designs join the database (where
    the rule fails, the next trees learn it).
    """
    table = ctx.simulate(sample_designs(ctx.sc, start, seed=ctx.seed))
    r = 0
    rng = np.random.default_rng(ctx.seed)
    tried = set()
    while ctx.run.sims < BUDGET:
        m, good, y = ctx.fit(table, n_rules=5)
        ctx.run.rounds = r + 1
        rules = [x for x in (mined_rules(m) if m is not None else []) if x.to_json()["bounds"]]
        fresh = [x for x in rules if repr(x.conditions) not in tried]
        if fresh:
            best = max(fresh, key=lambda x: x.estimate.low)
            if best.estimate.precision >= gate:
                tried.add(repr(best.conditions))
                ok, res = ctx.verify(best, seed=ctx.seed + 100 * r + 1)
                table = pd.concat([table, res], ignore_index=True)
                if ok:
                    return ctx.run
        pool = sample_designs(ctx.sc, candidates, seed=ctx.seed + 104729 * (r + 1))
        if m is None:
            pick = rng.choice(candidates, batch, replace=False)
        else:
            p = m.forest_probability(pool[list(ctx.roles.features)]) ** 2 + 1e-12
            pick = rng.choice(candidates, batch, replace=False, p=p / p.sum())
        new = pool.iloc[pick].drop(columns="sample")
        table = pd.concat([table, ctx.simulate(new)], ignore_index=True)
        r += 1
    return ctx.run


def loop(ctx: Context, **kw) -> Run:
    """The design loop itself (``run_design`` with its defaults: rounds until a rule is
    verified or its budget of simulations is spent; ``--loop-budget`` replaces the budget), its
    simulations routed through the cache."""
    import tempfile

    import holofold.design.loop.design_loop as design_loop
    import holofold.design.rules.verify as design_verify

    real = design_loop.build_database, design_verify.build_database

    def cached(scenario, designs, path, **kw):  # the loop's and the verifier's simulations
        res = ctx.simulate(designs.drop(columns="sample", errors="ignore"))
        return res.assign(sample=designs["sample"].to_numpy())

    # allow_overlap: the loop mines the target as given, as the other strategies do (by default
    # it mines "target and thick panels not overlapping" where the scenario has an overlap
    # column: on the PA12 sheet every design meeting the window overlaps, a target of its own)
    params = dict(files=False, seed=ctx.seed, progress=False, workers=1, pilot=0,
                  allow_overlap=True)  # fmt: skip
    if LOOP_BUDGET:
        params["budget"] = LOOP_BUDGET
    params.update(kw)
    design_loop.build_database = design_verify.build_database = cached
    try:
        with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = design_loop.run_design(ctx.sc, ctx.case.target, folder, **params)
    except ValueError as exc:  # no design meets the target, or no rule in the last round
        ctx.run.log.append(str(exc))
        return ctx.run
    finally:
        design_loop.build_database, design_verify.build_database = real
    rounds = out.summary["rounds"]
    ctx.run.rounds = len(rounds)
    verified = [e for h in out.record.rounds for e in h.rules if e.verified is not None]
    ctx.run.verified = tuple((e.verified.meeting, e.verified.simulated) for e in verified)
    done = [e for e in verified if design_loop.rule_verified(e.verified)]
    if done:
        ctx.run.passed, ctx.run.rule = True, done[0].text
    return ctx.run


def loop_likely(ctx: Context) -> Run:
    """The design loop sampling where the forest votes for the target."""
    return loop(ctx, strategy="likely")


def loop_around(ctx: Context) -> Run:
    """The design loop sampling around the rules (today's refinement), until verified."""
    return loop(ctx, strategy="around")


def loop_mixed(ctx: Context) -> Run:
    """The design loop sampling half where the forest votes, half inside the best rule."""
    return loop(ctx, strategy="mixed")


STRATEGIES = {
    "one-shot": one_shot,
    "one-shot-holofold": one_shot_holofold,
    "rounds": rounds,
    "likelihood": likelihood,
    "loop-mixed": loop_mixed,
    "loop-likely": loop_likely,
    "loop-around": loop_around,
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="the cheap scenarios only")
    ap.add_argument("--seeds", type=int, default=2, help="seeds per case and strategy")
    ap.add_argument("--first-seed", type=int, default=0, help="the first seed (default 0)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cases", default=None, help="comma-separated case labels")
    ap.add_argument("--strategies", default=",".join(STRATEGIES))
    ap.add_argument("--rarity", type=int, default=4000,
                    help="random designs on which each target's rarity is measured")  # fmt: skip
    ap.add_argument("--loop-budget", type=int, default=None,
                    help="the design loop's budget (default: run_design's)")  # fmt: skip
    ap.add_argument("--table", action="store_true", help="print the table of the saved results")
    args = ap.parse_args(argv)
    global LOOP_BUDGET
    LOOP_BUDGET = args.loop_budget
    out = CACHE / "results.csv"
    if args.table:
        print(table(pd.read_csv(out)))
        return 0
    cases = [c for c in CASES if (c.quick or not args.quick)]
    if args.cases:
        want = set(args.cases.split(","))
        cases = [c for c in cases if c.label in want]
    strategies = args.strategies.split(",")
    rows = []
    for case in cases:
        sim = Simulator(case.scenario, args.workers)
        # the target's rarity on the first random designs (the one-shot databases, seed 0)
        base = sim(sample_designs(sim.sc, args.rarity, seed=0))
        good = base.loc[~failed_rows(base)]
        rate = float(np.mean(parse_target(case.target, sim.sc.performance_names).evaluate(good)))
        print(f"# {case.label}: {case.target} on {sim.sc.name}: met by {100 * rate:.2f} % of "
              f"{len(good)} random designs", flush=True)  # fmt: skip
        for name in strategies:
            for seed in range(args.first_seed, args.first_seed + args.seeds):
                t0 = time.perf_counter()
                ctx = Context(case, sim, seed)
                run = STRATEGIES[name](ctx)
                sim.save()
                rows.append({"case": case.label, "rarity": rate, "rarity_n": len(good),
                             "strategy": name, "seed": seed,
                             "sims": run.sims if run.passed else np.nan, "spent": run.sims,
                             "passed": run.passed, "rounds": run.rounds,
                             "verified": " ".join(f"{k}/{n}" for k, n in run.verified),
                             "rule": run.rule, "seconds": time.perf_counter() - t0})  # fmt: skip
                save(rows[-1:], out)
                print(f"{case.label:14s} {name:10s} seed {seed}: "
                      f"{'passed' if run.passed else 'gave up'} after {run.sims} sims, "
                      f"{run.rounds} rounds; {rows[-1]['verified']}; {run.rule}",
                      flush=True)  # fmt: skip
    print(table(pd.DataFrame(rows)))
    return 0


def save(rows: list[dict], out: Path) -> None:
    """Merge ``rows`` into the results file: rows of other cases, strategies or seeds stay;
    these replace their own."""
    frame = pd.DataFrame(rows)
    if out.is_file():
        old = pd.read_csv(out)
        key = ["case", "strategy", "seed"]
        mine = old.set_index(key).index.isin(frame.set_index(key).index)
        frame = pd.concat([old.loc[~mine], frame], ignore_index=True)
    tmp = out.with_suffix(f".{os.getpid()}.tmp")
    frame.to_csv(tmp, index=False)
    tmp.replace(out)


def table(frame: pd.DataFrame) -> str:
    """Markdown: strategy x case, the mean simulations to a verified rule over the seeds (a run
    that never verified counted at what it spent, marked >, passed/seeds in brackets), then the
    ratio to one-shot with every run that never verified counted at the budget (``BUDGET``), so
    a strategy that gives up early gains nothing by it."""
    cases = [c.label for c in CASES if c.label in set(frame["case"])]
    strategies = [s for s in STRATEGIES if s in set(frame["strategy"])]
    spent, charged, cells = {}, {}, {}
    for s in strategies:
        for c in cases:
            sub = frame[(frame["strategy"] == s) & (frame["case"] == c)]
            if not len(sub):
                continue
            ok = sub["passed"].to_numpy(bool)
            used = sub["spent"].to_numpy(float)
            spent[(s, c)] = float(np.mean(used))
            charged[(s, c)] = float(np.mean(np.where(ok, used, BUDGET)))
            mark = "" if ok.all() else ">"
            cells[(s, c)] = f"{mark}{spent[(s, c)]:.0f} ({int(ok.sum())}/{len(sub)})"
    head = "| strategy | " + " | ".join(cases) + " |"
    lines = ["Simulations to a verified rule (mean over seeds; > : a run never verified, "
             "counted at what it spent)", "", head, "|" + "---|" * (len(cases) + 1)]  # fmt: skip
    for s in strategies:
        lines.append(f"| {s} | " + " | ".join(cells.get((s, c), "") for c in cases) + " |")
    if "rarity_n" not in frame:
        frame = frame.assign(rarity_n=np.nan)
    rar = []
    for c in cases:  # measured on the most random designs
        sub = frame[frame["case"] == c].sort_values("rarity_n", ascending=False)
        n = sub["rarity_n"].iloc[0]
        rar.append(f"{100 * sub['rarity'].iloc[0]:.2f} %" + ("" if n != n else f" of {n:.0f}"))
    rar = " | ".join(rar)
    lines.append(f"| (met by) | {rar} |")
    ref = "one-shot"
    if ref in strategies:
        lines += ["", f"Ratio to one-shot, every run that never verified counted at the budget, "
                  f"{BUDGET}", "", head[:-1] + "| mean of ratios | ratio of totals |",
                  "|" + "---|" * (len(cases) + 3)]  # fmt: skip
        for s in strategies:
            both = [c for c in cases if (s, c) in charged and (ref, c) in charged]
            ratio = {c: charged[(s, c)] / charged[(ref, c)] for c in both}
            total = sum(charged[(s, c)] for c in both) / sum(charged[(ref, c)] for c in both)
            row = [f"{ratio[c]:.2f}" if c in ratio else "" for c in cases]
            lines.append(f"| {s} | " + " | ".join(row) +
                         f" | {np.mean(list(ratio.values())):.2f} | {total:.2f} |")  # fmt: skip
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
