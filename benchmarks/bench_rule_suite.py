"""The rule miner on a suite of targets nobody tuned it for (issue 13).

One command builds (or reuses) the suite's databases, runs every method on every target over
``--splits`` train/test splits (forest seed = split seed), prints the comparison table, and
verifies the default's top rules with fresh simulations (calibration, with a plot)::

    python benchmarks/bench_rule_suite.py [--cache DIR] [--splits 5] [--jobs 2]
        [--calibration-splits 3] [--verify-n SPEC] [--no-calibration] [--methods a,b,...]

Everything is cached under ``--cache`` (default ``~/.cache/holofold-suite``): the generated
databases (see ``suite_data.py``), one JSON per (target, split, forest) with the top rules of
every method that shares that forest, and one JSON per verified rule. A cached result is
reused while ``design/rules.py`` is unchanged (its hash is part of the key), so a rerun only
prints (a few seconds). On 2 shared cores: ~25 min to build the generated databases once
(each resumable; ``python benchmarks/suite_data.py`` builds them alone), ~20 min for the
comparison of all 17 methods (``--methods paper,default`` takes ~3 min) and ~15 min for the
verification (``--no-calibration`` skips it); each stage is cached, so an interrupted run
resumes where it stopped.

Methods: ``paper`` is Zhu & Filipov's (training precision, F-beta, leaf boxes as found);
``default`` is ForestRuleMiner's defaults; the others change one thing each (see ``METHODS``).
``gboost`` (gradient boosting, no rule) is there for context. Targets whose database has a
twin of the same simulator (``suite_data.EXTERNAL``) are also scored on that twin's thousands of
rows (the second table), a low-noise check of the first.

Comparison (top rule of each method on the test rows of each split):

* ``prec``, ``recall``, ``support``: means over (target, split) pairs where the method found a
  rule (``no rule`` counts the others);
* ``win``: share of targets whose mean test precision over splits beats the paper's method's
  (ties count half);
* ``diff [95 % CI]``: mean over targets of the per-target mean paired difference to the paper's
  method (same split, both with a rule), with a t interval over targets (the splits of one
  target are not independent);
* ``lose>.05``: share of targets where the method is worse than the paper's by more than 0.05.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from scipy import stats as sstats
from suite_data import CACHE, EXTERNAL, ROOT, load_databases, suite_targets

from holofold.design import rules_to_records, verify_rule
from holofold.design.rules import FewRulesWarning, ForestRuleMiner
from holofold.design.rules.evaluation import rule_scores, split_indices

PAPER = "paper"
DEFAULT = "default"  #: ForestRuleMiner's defaults: the method whose rules are verified
_OLD = dict(beta=0.2, tighten=False, simplify="none")
#: name -> (forest parameters, selection parameters, what it is); unset parameters are the
#: miner's defaults (scoring="train", ranking="fbeta", beta=0.2, tighten=True, idle conditions
#: dropped)
METHODS = {
    PAPER: ({}, dict(tighten=False, simplify="none"), "Zhu & Filipov: train precision, F-beta"),
    DEFAULT: ({}, {}, "the paper's ranking, bounds tightened"),
    "oob-lcb": ({}, dict(scoring="oob", ranking="lcb", **_OLD), "the old default"),
    "train-lcb": ({}, dict(ranking="lcb", **_OLD), "Wilson bound of train precision"),
    "lcb.05-tight": (
        {},
        dict(ranking="lcb", beta=0.05),
        "Wilson bound, beta 0.05, tightened",
    ),
    "lcb.05": ({}, dict(ranking="lcb", beta=0.05, tighten=False), "Wilson bound, beta 0.05"),
    "est": ({}, dict(scoring="estimate", **_OLD), "shrunk OOB estimate, F-beta"),
    "est-lcb": ({}, dict(scoring="estimate", ranking="lcb", **_OLD), "its lower bound"),
    "est-lcb-k0": (
        {},
        dict(scoring="estimate", ranking="lcb", prior_strength=0.0, **_OLD),
        "distinct OOB rows, no shrinkage",
    ),
    "est-lcb-k10": (
        {},
        dict(scoring="estimate", ranking="lcb", prior_strength=10.0, **_OLD),
        "shrunk to the base rate (10 rows)",
    ),
    "simplified": ({}, dict(simplify="estimate"), "default + conditions dropped (OOB)"),
    "leaf5": (dict(min_samples_leaf=5), {}, "default, leaves >= 5 rows"),
    "paper-leaf5": (
        dict(min_samples_leaf=5),
        dict(tighten=False, simplify="none"),
        "paper, leaves >= 5",
    ),
    "prune3e-3": (dict(ccp_alpha=3e-3), {}, "default, ccp_alpha 3e-3"),
    "depth8": (dict(max_depth=8), {}, "default, depth 8"),
    "depth12": (dict(max_depth=12), {}, "default, depth 12"),
    "trees300": (dict(n_estimators=300), {}, "default, 300 trees"),
}
BASELINE = "gboost"  # gradient boosting on the same splits: a non-rule classifier, for context
N_RULES = 3
CALIBRATION_DBS = ("data0", "data3", "gen-arch", "data1", "gen-canopy")


def _code_hash() -> str:
    src = (ROOT / "design" / "rules.py").read_bytes()
    return hashlib.sha256(src).hexdigest()[:10]


def _key(*parts) -> str:
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:12]


def _atomic_json(path: Path, data) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(data))
    tmp.replace(path)


# ---------------------------------------------------------------------------------------------
# runs
# ---------------------------------------------------------------------------------------------


def _top(miner, records, Xte, yte, ext=None) -> dict:
    if not len(miner.rules_):
        return {"n_rules": 0}
    sc = rule_scores(miner, Xte, yte)
    r = miner.rules_.iloc[0]
    both = miner.rule_estimates(sc).iloc[0]
    out = {
        "estimate_all": float(both["estimate"]),
        "estimate_all_low": float(both["estimate_low"]),
        "estimate_all_high": float(both["estimate_high"]),
        "estimate_all_support": int(both["estimate_support"]),
    }
    if ext is not None:
        es = rule_scores(miner, *ext)
        out["ext_precision"] = float(es["precision"].iloc[0])
        out["ext_support"] = int(es["support"].iloc[0])
    return {
        **out,
        "n_rules": len(miner.rules_),
        "rule": r["rule"],
        "bounds": records[0]["bounds"],
        "train_precision": float(r["precision"]),
        "train_support": int(r["support"]),
        "estimate": float(r["estimate"]),
        "estimate_low": float(r["estimate_low"]),
        "estimate_high": float(r["estimate_high"]),
        "estimate_support": int(r["estimate_support"]),
        "test_precision": float(sc["precision"].iloc[0]),
        "test_recall": float(sc["recall"].iloc[0]),
        "test_support": int(sc["support"].iloc[0]),
        "test_precision_all": sc["precision"].tolist(),
        "n_conditions": len(records[0]["bounds"]),
    }


def _forest_task(db, target, split, forest, methods, ext_db=None) -> dict:
    """One forest on one split; the top rule of every method that shares it."""
    X = db.table[list(db.features)]
    ext = None if ext_db is None else (ext_db.table[list(db.features)], target.labels(ext_db))
    y = target.labels(db)
    train, test = split_indices(len(y), random_state=split)
    Xtr, ytr, Xte, yte = X.iloc[train], y[train], X.iloc[test], y[test]
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        t0 = time.perf_counter()
        base = ForestRuleMiner(
            **forest,
            categorical_features=list(db.categorical) or None,
            n_rules=N_RULES,
            random_state=split,
            n_jobs=1,
        ).fit(Xtr, ytr)
        fit_time = time.perf_counter() - t0
        for name, sel in methods.items():
            t0 = time.perf_counter()
            m = base.with_selection(Xtr, ytr, **sel)
            records = rules_to_records(m)
            out[name] = {**_top(m, records, Xte, yte, ext), "time": time.perf_counter() - t0}
    return {"fit_time": fit_time, "methods": out}


def _baseline_task(db, target, split) -> dict:
    from sklearn.ensemble import GradientBoostingClassifier
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    X = pd.get_dummies(db.table[list(db.features)], columns=list(db.categorical), dtype=float)
    y = target.labels(db)
    train, test = split_indices(len(y), random_state=split)
    # standardised first: scikit-learn's trees cannot split features closer than 1e-7 (SI)
    model = make_pipeline(StandardScaler(), GradientBoostingClassifier(random_state=split))
    model.fit(X.iloc[train], y[train])
    pred = model.predict(X.iloc[test])
    yte = y[test]
    n_pred = int(pred.sum())
    hit = int((pred & yte).sum())
    if not n_pred:
        return {"n_rules": 0}
    return {
        "n_rules": 1,
        "test_precision": hit / n_pred,
        "test_recall": hit / max(int(yte.sum()), 1),
        "test_support": n_pred,
    }


def run_suite(dbs, targets, splits, methods, cache: Path, jobs: int) -> pd.DataFrame:
    """One row per (target, split, method) with the top rule's numbers (cached)."""
    code = _code_hash()
    groups: dict = {}
    for name in methods:
        forest, sel, _ = METHODS[name]
        groups.setdefault(json.dumps(forest, sort_keys=True), {})[name] = sel
    tasks = []
    for t in targets:
        db = dbs[t.database]
        tkey = _key(t.database, t.expression, len(db.table), EXTERNAL.get(t.database) in dbs)
        for s in splits:
            for fkey, sel in groups.items():
                path = cache / "runs" / f"{t.key}-{tkey}" / f"s{s}-{_key(code, fkey, sel)}.json"
                tasks.append((t, s, "forest", json.loads(fkey), sel, path))
            path = cache / "runs" / f"{t.key}-{tkey}" / f"s{s}-{BASELINE}.json"
            tasks.append((t, s, BASELINE, None, None, path))
    todo = [task for task in tasks if not task[-1].is_file()]
    print(f"{len(tasks)} runs, {len(tasks) - len(todo)} cached, {len(todo)} to do", flush=True)

    def work(t, s, kind, forest, sel, path):
        db = dbs[t.database]
        if kind == BASELINE:
            res = {"methods": {BASELINE: _baseline_task(db, t, s)}}
        else:
            res = _forest_task(db, t, s, forest, sel, dbs.get(EXTERNAL.get(t.database)))
        _atomic_json(path, res)

    t0 = time.perf_counter()
    Parallel(n_jobs=jobs, verbose=0)(delayed(work)(*task) for task in todo)
    if todo:
        print(f"ran {len(todo)} in {time.perf_counter() - t0:.0f} s", flush=True)
    rows = []
    for t, s, _, _, _, path in tasks:
        res = json.loads(path.read_text())
        for name, r in res["methods"].items():
            if name in methods or name == BASELINE:
                rows.append(
                    {
                        "target": t.key,
                        "database": t.database,
                        "kind": t.kind,
                        "split": s,
                        "method": name,
                        **r,
                    }
                )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------
# comparison
# ---------------------------------------------------------------------------------------------


def paired(runs: pd.DataFrame, method: str, ref: str = PAPER, col="test_precision") -> dict:
    """Paired comparison of ``method`` with ``ref`` over targets (see the module docstring)."""
    if col not in runs:
        return {}
    a = runs[runs.method == method].set_index(["target", "split"])[col]
    b = runs[runs.method == ref].set_index(["target", "split"])[col]
    both = pd.concat([a.rename("a"), b.rename("b")], axis=1).dropna()
    per = both.groupby(level="target").mean()
    d = (per["a"] - per["b"]).to_numpy()
    n = d.size
    if n < 2:
        return {"diff": float("nan"), "lo": float("nan"), "hi": float("nan"), "win": float("nan")}
    half = sstats.t.ppf(0.975, n - 1) * d.std(ddof=1) / math.sqrt(n)
    win = float(np.mean((d > 1e-12) + 0.5 * (np.abs(d) <= 1e-12)))
    return {
        "diff": float(d.mean()),
        "lo": float(d.mean() - half),
        "hi": float(d.mean() + half),
        "win": win,
        "lose": float(np.mean(d < -0.05)),
        "n_targets": n,
    }


def comparison_table(runs: pd.DataFrame, methods) -> pd.DataFrame:
    out = []
    for name in [*methods, BASELINE]:
        r = runs[runs.method == name]
        ok = r[r.n_rules > 0]
        row = {
            "method": name,
            "prec": ok.test_precision.mean(),
            "recall": ok.test_recall.mean(),
            "support": ok.test_support.mean(),
            "no rule": int((r.n_rules == 0).sum()),
        }
        if "estimate" in ok and name != BASELINE:
            row["est-test"] = (ok.estimate - ok.test_precision).mean()
        row.update(paired(runs, name) if name != PAPER else {})
        if "ext_precision" in ok and name != BASELINE:
            e = ok.dropna(subset=["ext_precision"])
            row["ext"] = e.ext_precision.mean()
            row["ext_support"] = e.ext_support.mean()
            row["|est-ext|"] = (e.estimate - e.ext_precision).abs().mean()
            row["est-ext"] = (e.estimate - e.ext_precision).mean()
            row["|all-ext|"] = (e.estimate_all - e.ext_precision).abs().mean()
            if name != PAPER:
                p = paired(runs, name, col="ext_precision")
                row.update({f"ext_{k}": v for k, v in p.items()})
        out.append(row)
    return pd.DataFrame(out)


def _paired_cells(r, prefix: str = "") -> str:
    """The win, difference [95 % CI] and lose>.05 cells of a method's row (dashes for the
    paper's method, the reference of the pairing)."""
    if r.method == PAPER:
        return f"{'-':>5s} {'-':>24s} {'-':>8s}"
    g = {k: r[f"{prefix}{k}"] for k in ("win", "diff", "lo", "hi", "lose")}
    ci = f"{g['diff']:+.3f} [{g['lo']:+.3f}, {g['hi']:+.3f}]"
    return f"{g['win']:5.2f} {ci:>24s} {g['lose']:8.2f}"


def print_external(table: pd.DataFrame) -> None:
    if "ext" not in table:
        return
    print(
        f"\nthe same top rules on fresh rows of the same simulator ({', '.join(EXTERNAL)} -> "
        f"{', '.join(EXTERNAL.values())}; thousands of rows, so far less noise)\n"
    )
    head = (
        f"{'method':14s} {'prec':>6s} {'supp':>7s} {'est-ext':>8s} {'|est-ext|':>9s} "
        f"{'|all-ext|':>9s} {'win':>5s} {'diff [95 % CI]':>24s} {'lose>.05':>8s}"
    )
    print(head)
    print("-" * len(head))
    for _, r in table.iterrows():
        if pd.isna(r.get("ext", np.nan)):
            continue
        cmp = _paired_cells(r, "ext_")
        print(
            f"{r.method:14s} {r.ext:6.3f} {r.ext_support:7.1f} {r['est-ext']:+8.3f} "
            f"{r['|est-ext|']:9.3f} {r['|all-ext|']:9.3f} {cmp}"
        )


def print_table(table: pd.DataFrame, n_targets: int, n_splits: int) -> None:
    print(
        f"\ntop-rule test precision, {n_targets} targets x {n_splits} splits "
        f"(paired with '{PAPER}' by target and split; CI: t interval over targets)\n"
    )
    head = (
        f"{'method':14s} {'prec':>6s} {'recall':>6s} {'supp':>6s} {'norule':>6s} "
        f"{'est-test':>8s} {'win':>5s} {'diff [95 % CI]':>24s} {'lose>.05':>8s}  what"
    )
    print(head)
    print("-" * len(head))
    for _, r in table.iterrows():
        what = METHODS[r.method][2] if r.method in METHODS else "gradient boosting (no rule)"
        est = "" if pd.isna(r.get("est-test", np.nan)) else f"{r['est-test']:+.3f}"
        cmp = _paired_cells(r)
        print(
            f"{r.method:14s} {r.prec:6.3f} {r.recall:6.3f} {r.support:6.1f} {int(r['no rule']):6d} "
            f"{est:>8s} {cmp}  {what}"
        )


def kind_table(runs: pd.DataFrame, methods) -> None:
    kinds = ["single", "range", "two", "three", "categorical"]
    print("\nmean top-rule test precision by kind of target (targets in brackets)")
    n = runs.drop_duplicates("target").kind.value_counts()
    print(f"{'method':14s} " + " ".join(f"{k + f' ({n.get(k, 0)})':>16s}" for k in kinds))
    for name in [*methods, BASELINE]:
        r = runs[(runs.method == name) & (runs.n_rules > 0)]
        vals = [r[r.kind == k].test_precision.mean() for k in kinds]
        print(f"{name:14s} " + " ".join(f"{v:16.3f}" for v in vals))


# ---------------------------------------------------------------------------------------------
# calibration: the shown estimate against fresh simulations
# ---------------------------------------------------------------------------------------------


#: fresh designs per verified rule, by scenario: each scenario's verification costs about the
#: same time, and the binomial noise of the verified precision (sd at p = 0.85: 0.015, 0.021,
#: 0.029) stays well under the 0.05 it is compared with
VERIFY_N = {"single-miura": 600, "arch": 300, "canopy": 150}


def verify_counts(spec: str) -> dict:
    """``"150"`` (every scenario) or ``"arch=300,canopy=150,..."`` -> {scenario: n}."""
    if "=" not in spec:
        return dict.fromkeys(VERIFY_N, int(spec))
    out = dict(VERIFY_N)
    for part in spec.split(","):
        name, _, n = part.partition("=")
        if name.strip() not in VERIFY_N:
            known = ", ".join(VERIFY_N)
            raise ValueError(f"--verify-n: unknown scenario {name!r} (one of {known})")
        out[name.strip()] = int(n)
    return out


def calibrate(dbs, targets, runs, method, splits, counts, cache: Path, jobs: int) -> pd.DataFrame:
    """Verify the top rule of ``method`` on the simulated scenarios (cached); ``counts``:
    fresh designs per rule by scenario."""
    tasks = []
    by = {t.key: t for t in targets}
    for _, r in runs[(runs.method == method) & (runs.n_rules > 0)].iterrows():
        t = by[r.target]
        if r.split not in splits or t.database not in CALIBRATION_DBS:
            continue
        scenario = dbs[t.database].scenario
        seed = 1000 + int(r.split)
        n = counts[scenario]
        path = cache / "verify" / f"{_key(scenario, r.bounds, t.expression, n, seed)}.json"
        tasks.append((t, r, scenario, seed, n, path))
    todo = [x for x in tasks if not x[-1].is_file()]
    each = ", ".join(f"{k} {v}" for k, v in counts.items())
    print(f"\nverification: {len(tasks)} rules, {len(todo)} to simulate (designs each: {each})")

    def work(t, r, scenario, seed, n, path):
        v = verify_rule(scenario, r.bounds, t.expression, n, seed=seed, progress=False)
        _atomic_json(path, v.summary())

    t0 = time.perf_counter()
    Parallel(n_jobs=jobs)(delayed(work)(*x) for x in todo)
    if todo:
        print(f"simulated in {time.perf_counter() - t0:.0f} s")
    rows = []
    for t, r, scenario, _, _, path in tasks:
        v = json.loads(path.read_text())
        if v["precision"] is None:
            continue
        rows.append(
            {
                "target": t.key,
                "database": t.database,
                "scenario": scenario,
                "split": r.split,
                "estimate": r.estimate,
                "estimate_low": r.estimate_low,
                "estimate_high": r.estimate_high,
                "estimate_all": r.estimate_all,
                "estimate_all_low": r.estimate_all_low,
                "estimate_all_high": r.estimate_all_high,
                "train": r.train_precision,
                "test": r.test_precision,
                "verified": v["precision"],
                "verified_low": v["precision_95ci"][0],
                "verified_high": v["precision_95ci"][1],
                "simulated": v["simulated"],
            }
        )
    return pd.DataFrame(rows)


def print_calibration(cal: pd.DataFrame) -> None:
    if cal.empty:
        print("no verified rule")
        return
    print(
        "\ncalibration of the top rules: mean |shown - verified| (verified: fresh simulations "
        "inside the rule; estimate: training split only; + held-out: with the test rows, what "
        "`holofold mine` shows; noise: the part of it the verification's own binomial noise "
        "explains, mean sqrt(2/pi p(1-p)/n))"
    )
    print(
        f"{'scenario':14s} {'rules':>5s} {'estimate':>9s} {'+held-out':>9s} {'held-out':>9s} "
        f"{'train':>7s} {'noise':>7s} {'bias':>7s} {'bias+ho':>7s} {'in 95 %':>7s} "
        f"{'in 95 %+ho':>10s}"
    )
    for name, g in [*cal.groupby("scenario"), ("all", cal)]:
        e = (g.estimate - g.verified).abs().mean()
        ea = (g.estimate_all - g.verified).abs().mean()
        te = (g.test - g.verified).abs().mean()
        tr = (g.train - g.verified).abs().mean()
        cover = ((g.verified >= g.estimate_low) & (g.verified <= g.estimate_high)).mean()
        cover_a = ((g.verified >= g.estimate_all_low) & (g.verified <= g.estimate_all_high)).mean()
        bias, bias_a = (g.estimate - g.verified).mean(), (g.estimate_all - g.verified).mean()
        noise = np.sqrt(2 / np.pi * g.verified * (1 - g.verified) / g.simulated).mean()
        print(
            f"{name:14s} {len(g):5d} {e:9.3f} {ea:9.3f} {te:9.3f} {tr:7.3f} {noise:7.3f} "
            f"{bias:+7.3f} {bias_a:+7.3f} {cover:7.2f} {cover_a:10.2f}"
        )
    mae = (cal.estimate_all - cal.verified).abs().mean()
    verdict = "meets" if mae <= 0.05 else "misses"
    print(
        f"shown estimate: mean |shown - verified| = {mae:.4f} over {len(cal)} rules "
        f"({verdict} <= 0.05)"
    )


def plot_calibration(cal: pd.DataFrame, path: Path) -> None:
    """Shown precision against verified precision, one panel per way of showing it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = (
        ("estimate_all", "estimate with the held-out rows\n(what `holofold mine` shows)"),
        ("estimate", "estimate from the training split"),
        ("train", "training precision (what the paper shows)"),
    )
    fig, axes = plt.subplots(1, 3, figsize=(14, 5.4), sharey=True, layout="constrained")
    lo = min(cal[[c for c, _ in panels]].min().min(), cal.verified.min(), 0.5) - 0.03
    for ax, (col, label) in zip(axes, panels, strict=True):
        for sc, g in cal.groupby("scenario"):
            xerr = None
            if col != "train":
                xerr = [g[col] - g[f"{col}_low"], g[f"{col}_high"] - g[col]]
            ax.errorbar(
                g[col], g.verified, xerr=xerr,
                yerr=[g.verified - g.verified_low, g.verified_high - g.verified],
                fmt="o", ms=4, lw=0.5, alpha=0.75, label=f"{sc} ({len(g)})",
            )  # fmt: skip
        ax.plot([0, 1], [0, 1], color="0.4", lw=1, ls="--")
        mae = (cal[col] - cal.verified).abs().mean()
        ax.set_title(f"{label}\nmean |x - verified| = {mae:.3f}", fontsize=9)
        ax.set_xlabel("shown precision")
        ax.set_xlim(lo, 1.02)
        ax.set_ylim(lo, 1.02)
        ax.set_aspect("equal")
    axes[0].set_ylabel("verified precision (fresh simulations, 95 % interval)")
    axes[0].legend(fontsize=7, loc="lower right")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cache", type=Path, default=CACHE, help="folder of cached results")
    ap.add_argument("--splits", type=int, default=5, help="splits (and forest seeds) 0..K-1")
    ap.add_argument("--jobs", type=int, default=2, help="processes")
    ap.add_argument("--methods", help="comma-separated subset of the methods")
    ap.add_argument("--calibration-splits", type=int, default=3)
    ap.add_argument(
        "--verify-n", default=",".join(f"{k}={v}" for k, v in VERIFY_N.items()),
        help="fresh designs per verified rule: n, or scenario=n,... (default: %(default)s)",
    )  # fmt: skip
    ap.add_argument("--no-calibration", action="store_true")
    ap.add_argument("--no-build", action="store_true", help="use only databases already built")
    ap.add_argument("--plot", type=Path, help="calibration plot (default: CACHE/calibration.png)")
    args = ap.parse_args(argv)
    methods = list(METHODS) if not args.methods else args.methods.split(",")
    if PAPER not in methods:
        methods.insert(0, PAPER)
    for m in methods:
        if m not in METHODS:
            ap.error(f"unknown method {m!r}; methods: {', '.join(METHODS)}")

    t0 = time.perf_counter()
    dbs = load_databases(args.cache, build=not args.no_build, workers=args.jobs)
    targets = suite_targets(dbs)
    print(f"{len(targets)} targets on {len(dbs)} databases:")
    for t in targets:
        y = t.labels(dbs[t.database])
        print(f"  {t.key} {t.database:11s} {t.kind:11s} {100 * y.mean():5.1f} %  {t.expression}")
    runs = run_suite(dbs, targets, range(args.splits), methods, args.cache, args.jobs)
    table = comparison_table(runs, methods)
    print_table(table, len(targets), args.splits)
    print_external(table)
    kind_table(runs, methods)
    runs.to_csv(args.cache / "runs.csv", index=False)
    if not args.no_calibration and DEFAULT in methods:
        cal = calibrate(
            dbs, targets, runs, DEFAULT, range(args.calibration_splits),
            verify_counts(args.verify_n), args.cache, args.jobs,
        )  # fmt: skip
        print_calibration(cal)
        plot = args.plot or args.cache / "calibration.png"
        if not cal.empty:
            plot_calibration(cal, plot)
            cal.to_csv(args.cache / "calibration.csv", index=False)
            print(f"wrote {plot}")
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
