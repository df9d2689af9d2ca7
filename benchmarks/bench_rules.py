"""Speed of the random-forest rule miner (issue 6, section 6).

Prints a table of medians over ``--repeat`` runs (default 5) with the reference implementation's
figures of the issue (TreeForOrigami, 100 trees, depth 20, subset 0.5, on this kind of machine),
the targets, and the speed-up (reference / holofold):

* training the 100-tree forest on the data3 training split (1800 rows, one thread and two);
* rule extraction + scoring (all leaves of all trees, one vectorised pass);
* the same two on a 6000-row database (data3 stacked twice, the copy jittered by 1e-6
  relative, training split 3600 rows; the published 6000-row gripper file is only sampled here);
* a whole run on data3 (fit + test scoring of the rules) on 2 threads;
* the 7 x 5 x 5 grid of Fig. S8 (depth 8..32 x 20..200 trees x 5 splits) on 2 processes.

    python benchmarks/bench_rules.py [--repeat 5] [--data DIR] [--no-grid]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from _timing import median_times

from holofold.design.database.tables import read_table
from holofold.design.rules import FewRulesWarning, ForestRuleMiner
from holofold.design.rules.evaluation import grid_search, rule_scores, split_indices
from holofold.design.rules.targets import parse_target

FEATURES = ["m", "tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"]
TARGET = "Zstiff > 800 & Xstiff > 600 & error < 0.1"


def _prepare(df, seed=0):
    X = df[FEATURES]
    y = parse_target(TARGET).evaluate(df)
    train, test = split_indices(len(df), random_state=seed)
    return X, y, train, test


def _mining_time(miner, X, y, train, repeat):
    """Median time of extraction + scoring on an already trained forest."""
    Z = np.ascontiguousarray(miner._encoding.encode(X.iloc[train].to_numpy()), dtype=np.float32)
    y_pos = (y[train] == miner.classes_[1]).astype(np.intp)

    def mine():
        miner._mine(Z, y_pos, len(miner.estimators_))

    return median_times(mine, repeat)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument(
        "--data",
        default=str(Path(__file__).resolve().parents[2] / "shared" / "reference-data"),
        help="folder of the published databases",
    )
    ap.add_argument("--no-grid", action="store_true", help="skip the 7x5x5 grid")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore", FewRulesWarning)

    d3 = read_table(Path(args.data) / "data3_ShapeFit.txt")
    rng = np.random.default_rng(0)
    jitter = d3.copy()
    cont = [c for c in FEATURES if c != "m"]
    jitter[cont] = jitter[cont] * (1 + 1e-6 * rng.standard_normal((len(d3), len(cont))))
    big = pd.concat([d3, jitter], ignore_index=True)

    rows = []  # (quantity, reference s, target s or None, holofold s)
    for name, df in (("data3", d3), ("6000 rows", big)):
        X, y, train, test = _prepare(df)
        Xtr, ytr = X.iloc[train], y[train]
        for jobs in (1, 2):
            miner = ForestRuleMiner(categorical_features=["m"], random_state=0, n_jobs=jobs)
            t = median_times(lambda m=miner, a=Xtr, b=ytr: m.fit(a, b), args.repeat)
            ref = 0.9 if name == "data3" else 1.7
            rows.append((f"train 100 trees, {name}, {jobs} thread(s)", ref, None, t))
        fitted = ForestRuleMiner(categorical_features=["m"], random_state=0).fit(Xtr, ytr)
        t = _mining_time(fitted, X, y, train, args.repeat)
        ref = 1.8 if name == "data3" else 16.0
        rows.append((f"extract + score rules, {name}", ref, ref / 50, t))

    X, y, train, test = _prepare(d3)

    def whole_run():
        m = ForestRuleMiner(categorical_features=["m"], random_state=0, n_jobs=2)
        m.fit(X.iloc[train], y[train])
        rule_scores(m, X.iloc[test], y[test])

    rows.append(
        ("whole run on data3 (fit + test), 2 threads", 2.7, 0.5, median_times(whole_run, 3))
    )

    if not args.no_grid:
        t = time.perf_counter()
        runs, table = grid_search(
            X, y, miner=ForestRuleMiner(categorical_features=["m"]), seeds=range(5), n_jobs=2
        )
        tg = time.perf_counter() - t
        rows.append(("grid 7 depths x 5 tree counts x 5 splits, 2 procs", None, 60.0, (tg, None)))

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{os.cpu_count()} CPUs, load average {load:.1f} at the end (timings are wall-clock;")
    print("cpu = CPU seconds of all threads of this process, a load-independent check)\n")
    head = f"{'quantity':50s} {'reference':>9s} {'target':>8s} {'holofold':>9s} {'cpu':>7s}"
    print(f"{head} {'speed-up':>8s}")
    for q, ref, target, (t, c) in rows:
        r = f"{ref:.2f} s" if ref is not None else "-"
        g = f"{target:.3g} s" if target is not None else "-"
        sp = f"{ref / t:.0f}x" if ref is not None else "-"
        cpu = f"{c:.3f}" if c is not None else "-"
        ok = "" if target is None else ("  ok" if t <= target else "  SLOW")
        print(f"{q:50s} {r:>9s} {g:>8s} {t:>7.3f} s {cpu:>7s} {sp:>8s}{ok}")
    if not args.no_grid:
        best = table.iloc[0]
        print(
            f"\ngrid: {len(runs)} cells x splits; best mean test precision {best['mean']:.3f} at "
            f"depth {best['max_depth']}, {best['n_estimators']} trees; default cell (20, 100): "
            + "{:.3f}".format(
                table[(table.max_depth == 20) & (table.n_estimators == 100)]["mean"].iloc[0]
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
