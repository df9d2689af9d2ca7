"""Re-simulate the published gripper rows (data2, 3 x 200 samples) and compare.

Usage (from the repository root)::

    python validation/reproduce_gripper.py                    # all 600 rows
    python validation/reproduce_gripper.py --rows 20 --workers 2
    python validation/reproduce_gripper.py --save out/gripper.csv
    python validation/reproduce_gripper.py --random 50       # fresh designs
    python validation/reproduce_gripper.py --patterns 3 --perturb 1e-15 \
        --compare out/gripper.csv          # round-off sensitivity of each row vs an earlier run
    python validation/reproduce_gripper.py --patterns 3 --ensemble 8 \
        --ensemble-arccos --save out/ens.csv --plot out/ens.png   # published vs 8 variants
    python validation/reproduce_gripper.py --from-csv out/ens.csv  # report again
    python validation/reproduce_gripper.py --converged      # tight Newton solves

For each pattern and performance column it prints the median, 90th and 99th percentile and
maximum of |ours - published| / |published|, the closure-step agreement (the published finalQ
decoded to its heating step by ``compat.gripper_closing_step``) and, for every pattern,
the quartiles of finalQ, Tmax and stiff of ours and the published rows (the acceptance view for
the Miura-based pattern, whose closure the spec did not expect to reproduce). ``--random N``
instead simulates N fresh designs per pattern drawn as the paper did (4.1, with the re-draw
rules) and reports how many fail to close. The reference folder is ``../shared/reference-data``
next to the repository, ``$HOLOFOLD_REFERENCE_DATA`` or ``--data``.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
from reproduce import load, reference_folder
from reproduce import stats_line as reproduce_stats_line

from holofold.design.scenarios.gripper import QLOAD, GripperOptions, simulate
from holofold.geometry.gripper import DEFAULT_RANGE
from holofold.mechanics.compat import gripper_closing_step

STEMS = {1: "data2_MiuraBased_sample", 2: "data2_SplittedMiura_sample", 3: "data2_TwoPanel_sample"}
NAMES = {1: "Miura-based", 2: "splitted Miura", 3: "two-panel"}
FEATURES = ["Pattern", "L1", "L2", "t1", "t2", "tpanel", "rate", "W"]
OUTPUTS = ["freqFinal", "finalQ", "Tmax", "stiff"]
DEFAULT = GripperOptions()


def with_arccos(options: GripperOptions, arccos: bool) -> GripperOptions:
    """``options`` with the reference's arccos dihedral angle switched on or off."""
    return replace(options, profile=replace(options.profile, arccos_dihedral=arccos))


def published_step(P: int, ref: pd.DataFrame) -> np.ndarray:
    """The closing heating step of each published row of ``ref`` (pattern ``P``), decoded from
    its finalQ (whole numbers)."""
    L1, L2 = ref["L1"].to_numpy(), ref["L2"].to_numpy()
    return gripper_closing_step(P, L1, L2, ref["finalQ"], DEFAULT_RANGE[P], rate=QLOAD)


def emit(text: str = "") -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def _run(row: dict, perturb: float = 0.0, options: GripperOptions = DEFAULT) -> dict:
    t = time.perf_counter()
    if perturb:
        row = row | {"L1": row["L1"] * (1.0 + perturb)}
    try:
        r = simulate(row, options)
        out = r.as_row() | {"status": str(r.status), "step": r.closing_step or np.nan}
    except Exception as exc:  # noqa: BLE001 - report and go on
        out = {c: np.nan for c in OUTPUTS} | {"status": f"failed: {exc}", "step": np.nan}
    out["seconds"] = time.perf_counter() - t
    return out


def run_rows(
    rows: list[dict], workers: int, perturb: float | np.ndarray = 0.0, options=DEFAULT
) -> list[dict]:
    """Simulate ``rows``; ``perturb`` (relative L1 change) and ``options`` are one for all
    rows or a sequence with one per row."""
    n = len(rows)
    perturb = np.broadcast_to(np.asarray(perturb, float), (n,))
    options = [options] * n if isinstance(options, GripperOptions) else list(options)
    jobs = list(zip(rows, perturb, options, strict=True))
    if workers == 1:
        return [_run(*job) for job in jobs]
    from joblib import Parallel, delayed

    return list(Parallel(n_jobs=workers, batch_size=1)(delayed(_run)(*job) for job in jobs))


def run_ensemble(rows: list[dict], members, workers: int) -> list[pd.DataFrame]:
    """One run of every row per member ``(relative L1 shift, options)`` (all in one pool)."""
    members = list(members)
    n = len(rows)
    out = pd.DataFrame(
        run_rows(
            [r for _ in members for r in rows],
            workers,
            np.repeat([m[0] for m in members], n),
            [m[1] for m in members for _ in rows],
        )
    )
    return [out.iloc[k * n : (k + 1) * n].reset_index(drop=True) for k in range(len(members))]


def exchangeability(values: np.ndarray, published: np.ndarray, rtol: float, seed: int = 0) -> dict:
    """Is the published value statistically just one more member of our ensemble?

    ``values`` (n, K): K runs of each of n rows that differ only by round-off-level details;
    ``published`` (n,). Two values *agree* when they are within ``rtol`` (relative). If the
    published numbers come from the same algorithm and only such details differ, the published
    value is exchangeable with the members, so (a) it agrees with a member as often as two
    members agree with each other, and (b) its rank among the K + 1 values (exact ties broken
    at random; a tolerance would make ties intransitive and the rank non-uniform) is uniform on
    0..K -- checked with a chi-square test (``p_rank``). Rows where all K members agree are the
    *stable* rows; on them the published value should agree too. ``pair_median`` and
    ``pair_p90`` are the median and 90th percentile of |a - b| / |b| over rows and pairs of
    members: the agreement a run can expect with another run.
    """
    from scipy.stats import chi2

    v = np.asarray(values, float)
    p = np.asarray(published, float)
    ok = np.isfinite(v).all(axis=1) & np.isfinite(p)
    v, p = v[ok], p[ok]
    n, K = v.shape

    def agree(a, b):
        return np.abs(a - b) <= rtol * np.abs(b)

    pub = np.mean([agree(v[:, k], p).mean() for k in range(K)])
    mem = np.mean([agree(v[:, i], v[:, j]).mean() for i in range(K) for j in range(K) if i != j])
    ties = v == p[:, None]
    below = v < p[:, None]
    rng = np.random.default_rng(seed)
    rank = below.sum(1) + rng.integers(0, ties.sum(1) + 1)
    hist = np.bincount(rank, minlength=K + 1)
    expect = n / (K + 1)
    p_rank = float(chi2.sf(((hist - expect) ** 2 / expect).sum(), K))
    stable = agree(v, v[:, :1]).all(axis=1)
    inside = agree(v, p[:, None]).any(1) | ((v.min(1) < p) & (p < v.max(1)))
    pairs = [np.abs(v[:, i] - v[:, j]) / np.abs(v[:, j]) for i in range(K) for j in range(K)]
    pairs = np.concatenate([d for k, d in enumerate(pairs) if k // K != k % K] or [np.nan])
    return dict(
        n=n,
        members=K,
        agree_published=pub,
        agree_members=mem,
        rank_hist=hist,
        p_rank=p_rank,
        stable=int(stable.sum()),
        stable_agree=float(agree(v[stable, 0], p[stable]).mean()) if stable.any() else np.nan,
        inside=float(inside.mean()),
        pair_median=float(np.median(pairs)),
        pair_p90=float(np.percentile(pairs, 90)),
    )


def ensemble_report(
    P: int, ref: pd.DataFrame, steps: np.ndarray, stiff: np.ndarray, groups: dict
) -> None:
    """Published values against an ensemble: ``steps``, ``stiff`` (n, K) member results of the
    n rows of ``ref``; ``groups`` maps a label to the member columns to test together."""
    pub_step = np.rint(published_step(P, ref))
    pub_stiff = ref["stiff"].to_numpy(float)
    for name, cols in groups.items():
        emit(f"  members {name} ({len(cols)} runs per row):")
        for label, vals, pub, rtol in (
            ("closing step", steps[:, cols], pub_step, 0.0),
            ("stiff (1e-3)", stiff[:, cols], pub_stiff, 1e-3),
            ("stiff (1e-2)", stiff[:, cols], pub_stiff, 1e-2),
        ):
            x = exchangeability(vals, pub, rtol)
            emit(
                f"    {label:<13} agreement published-member {x['agree_published']:.3f} vs "
                f"member-member {x['agree_members']:.3f};  published inside the ensemble on "
                f"{100 * x['inside']:.1f} % of {x['n']} rows"
            )
            emit(
                f"    {'':<13} rank of published among {len(cols) + 1}: "
                f"{x['rank_hist'].tolist()} (chi-square p = {x['p_rank']:.2g});  rows where all "
                f"runs agree: {x['stable']}, published agrees there on "
                f"{100 * x['stable_agree']:.1f} %"
            )
        x = exchangeability(stiff[:, cols], pub_stiff, 1e-3)
        e = np.abs(stiff[:, cols] - pub_stiff[:, None]) / pub_stiff[:, None]
        e = e[np.isfinite(e).all(axis=1)]
        emit(
            f"    stiff, |a - b| / |b|: member vs member median {x['pair_median']:.2e}, p90 "
            f"{x['pair_p90']:.2e};  member vs published median {np.median(e):.2e}, p90 "
            f"{np.percentile(e, 90):.2e}"
        )


def ensemble_arrays(table: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, dict]:
    """(steps, stiff, groups) of a saved ``--ensemble`` run (columns ``step``, ``stiff``,
    ``step_m1``, ``stiff_m1``, ``angle_m1``, ...; member 0 is the plain run)."""
    ks = sorted(int(c[7:]) for c in table.columns if c.startswith("stiff_m"))
    if not ks:
        raise ValueError("no ensemble columns (stiff_m1, ...): save a run made with --ensemble")
    steps = table[["step"] + [f"step_m{k}" for k in ks]].to_numpy(float)
    stiff = table[["stiff"] + [f"stiff_m{k}" for k in ks]].to_numpy(float)
    angle = ["atan2"] + [str(table[f"angle_m{k}"].iloc[0]) for k in ks]
    groups = {"all": list(range(len(angle)))}
    if len(set(angle)) > 1:
        for a in sorted(set(angle)):
            groups[f"with the {a} angle"] = [i for i, b in enumerate(angle) if b == a]
    return steps, stiff, groups


def sensitivity(P: int, ref: pd.DataFrame, ours: pd.DataFrame, other: pd.DataFrame) -> None:
    """Compare with an earlier run (``--compare``), e.g. one with ``--perturb 1e-15``.

    Rows whose closing step or stiffness moves under a round-off-level change of the input are
    numerically chaotic (their Newton iterations end far from equilibrium along soft modes, so
    the result depends on the last bits of every linear solve); the agreement with the
    published values is then reported separately on the robust rows.
    """
    same_step = ours["step"].to_numpy() == other["step"].to_numpy()
    ds = np.abs(ours["stiff"].to_numpy() / other["stiff"].to_numpy() - 1)
    robust = same_step & (ds < 1e-4)
    emit(
        f"  sensitivity vs --compare run: closing step changed on {(~same_step).sum()} rows; "
        f"stiff change median {np.nanmedian(ds):.2e}, p90 {np.nanpercentile(ds, 90):.2e}; "
        f"robust rows (same step, stiff within 1e-4): {robust.sum()} / {len(ref)}"
    )
    pub_step = published_step(P, ref)
    same = np.abs(ours["step"].to_numpy() - pub_step) < 1e-6
    emit(
        f"  robust rows: same closing step as published {(same & robust).sum()} / "
        f"{robust.sum()};  non-robust rows: {(same & ~robust).sum()} / {(~robust).sum()}"
    )
    for c in ("Tmax", "stiff"):
        e = np.abs(ours[c].to_numpy() - ref[c].to_numpy()) / np.abs(ref[c].to_numpy())
        emit(stats_line(c + " rob.", e[robust & same]))
        emit(stats_line(c + " n-r.", e[~robust & same]))


def stats_line(label: str, e: np.ndarray) -> str:
    """:func:`reproduce.stats_line` in this script's narrower columns."""
    return reproduce_stats_line(label, e, width=10, count_width=4)


def quartiles(x) -> str:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return "(none)"
    q = np.percentile(x, [25, 50, 75])
    return f"q25 {q[0]:.4g}  median {q[1]:.4g}  q75 {q[2]:.4g}  (n={x.size})"


def report(P: int, ref: pd.DataFrame, ours: pd.DataFrame) -> None:
    emit(f"== pattern {P} ({NAMES[P]}): {len(ref)} rows")
    closed = ours["step"].notna().to_numpy()
    pub_step = published_step(P, ref)
    same = closed & (np.abs(ours["step"].to_numpy() - pub_step) < 1e-6)
    emit(
        f"  closed {closed.sum()} / {len(ref)};  same closing step as published: "
        f"{same.sum()} / {len(ref)} ({100 * same.mean():.1f} %)"
    )
    d = ours["step"].to_numpy() - pub_step
    if closed.any():
        dd = d[closed]
        emit(
            f"  step difference (ours - published) on closed rows: min {np.nanmin(dd):+.1f}, "
            f"max {np.nanmax(dd):+.1f}, |diff| <= 1: {(np.abs(dd) <= 1).sum()}"
        )
    emit("  relative error |ours - published| / published (all closed rows):")
    for c in OUTPUTS:
        e = np.abs(ours[c].to_numpy() - ref[c].to_numpy()) / np.abs(ref[c].to_numpy())
        emit(stats_line(c, e))
    if same.any() and same.sum() < closed.sum():
        emit("  ... restricted to rows closing at the published step:")
        for c in ("Tmax", "stiff"):
            e = np.abs(ours[c].to_numpy() - ref[c].to_numpy()) / np.abs(ref[c].to_numpy())
            emit(stats_line(c, e[same]))
    emit("  distributions (ours | published):")
    for c in ("finalQ", "Tmax", "stiff"):
        emit(f"    {c:<7} ours      {quartiles(ours[c])}")
        emit(f"    {'':<7} published {quartiles(ref[c])}")
    sec = ours["seconds"].to_numpy()
    emit(f"  seconds per row: median {np.median(sec):.2f}, max {sec.max():.2f}")
    emit("  status: " + status_summary(ours["status"]))


def status_summary(status: pd.Series) -> str:
    """Counts of the kinds of status (converged, unconverged heating / prying runs, failures)."""
    kinds = {
        "converged": status == "converged",
        "some heating steps above tolerance": status.str.contains("heating steps"),
        "prying run above tolerance": status.str.contains("prying-stiffness"),
        "no closure": status == "failed: no closure",
        "early closure": status.str.contains("early closure"),
        "other failures": status.str.startswith("failed")
        & (status != "failed: no closure")
        & ~status.str.contains("early closure"),
    }
    return "; ".join(f"{k} {int(v.sum())}" for k, v in kinds.items() if v.any())


def random_designs(P: int, n: int, rng: np.random.Generator) -> list[dict]:
    """Designs drawn as in the paper (uniform ranges, re-draw rules for rate)."""
    rows = []
    for _ in range(n):
        L1 = rng.uniform(3e-3, 7e-3)
        L2 = rng.uniform(2e-3, 4e-3)
        W = rng.uniform(100e-6, 300e-6)
        rate = rng.uniform(0.2, 0.6)
        for _try in range(10):
            if P == 1 and (1 - rate) * L1 - L2 / 2 < 0:
                rate = rng.uniform(0.2, 0.6)
            elif P == 2 and not (1 - rate) * L1 > L2 / 2 + 1.5 * W:
                rate = rng.uniform(0.2, 0.6)
            else:
                break
        rows.append(
            dict(
                Pattern=float(P),
                L1=L1,
                L2=L2,
                t1=rng.uniform(0.15e-6, 0.25e-6),
                t2=rng.uniform(0.6e-6, 1.0e-6),
                tpanel=rng.uniform(10e-6, 30e-6),
                rate=rate,
                W=W,
            )
        )
    return rows


def plot_ensemble(table: pd.DataFrame, path) -> list[int]:
    """Picture of the published stiffness against the ensemble, one panel per pattern.

    ``table``: a ``--save`` CSV of an ``--ensemble`` run. Rows are sorted by the ensemble's
    spread; each row is a grey bar from the smallest to the largest member and a dot for the
    published value, all relative to the ensemble median (rows with a member that did not close
    are left out). Returns the patterns drawn.
    """
    from matplotlib.figure import Figure

    missing = {"Pattern", "stiff_published"} - set(table.columns)
    if missing:
        raise ValueError(f"not a --save CSV of reproduce_gripper.py: no {sorted(missing)}")
    arrays = {int(P): ensemble_arrays(d) for P, d in table.groupby("Pattern")}
    angles = {len(g) for _, _, g in arrays.values()}
    what = "; half with the reference's arccos angle" if angles != {1} else ""
    fig = Figure(figsize=(11, 3.6 * len(arrays)))
    axes = fig.subplots(len(arrays), 1, squeeze=False)[:, 0]
    for ax, (P, (_, v, _)) in zip(axes, arrays.items(), strict=True):
        d = table[table["Pattern"] == P]
        pub = d["stiff_published"].to_numpy(float)
        ok = np.isfinite(v).all(axis=1) & np.isfinite(pub)
        v, pub = v[ok], pub[ok]
        med = np.median(v, axis=1)
        rel = v / med[:, None] - 1
        order = np.argsort(rel.max(1) - rel.min(1), kind="stable")
        x = np.arange(len(order))
        ax.vlines(x, rel[order].min(1), rel[order].max(1), color="0.6", lw=2.5, label="ensemble")
        ax.plot(x, (pub / med - 1)[order], "o", ms=3.5, color="C3", label="published")
        ax.set_yscale("symlog", linthresh=1e-4)
        ax.axhspan(-1e-3, 1e-3, color="C2", alpha=0.12, lw=0, label="within 1e-3")
        ax.set_xlim(-1, len(order))
        ax.set_ylabel("stiff / ensemble median - 1")
        ax.set_title(
            f"{NAMES[P]}: prying stiffness of {len(order)} published rows against "
            f"{v.shape[1]} holofold runs each\n(L1 x (1 + k 1e-15){what})",
            fontsize=10,
        )
        ax.legend(loc="upper left", fontsize=8, ncol=3)
    axes[-1].set_xlabel("rows, sorted by the spread of the ensemble")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return list(arrays)


def analyse_saved(table: pd.DataFrame) -> None:
    """Print the ensemble report of a saved ``--ensemble`` run (``--from-csv``)."""
    for P, d in table.groupby("Pattern"):
        ref = d.rename(columns={"finalQ_published": "finalQ_pub", "stiff_published": "stiff_pub"})
        ref = ref.assign(finalQ=ref["finalQ_pub"], stiff=ref["stiff_pub"]).reset_index(drop=True)
        emit(f"== pattern {int(P)} ({NAMES[int(P)]}): {len(d)} rows (saved run)")
        ensemble_report(int(P), ref, *ensemble_arrays(d))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--patterns", nargs="*", type=int, default=[1, 2, 3], choices=[1, 2, 3])
    ap.add_argument("--rows", type=int, default=None, help="only the first N rows per pattern")
    ap.add_argument("--workers", type=int, default=1, help="worker processes (joblib)")
    ap.add_argument("--data", default=None, help="reference-data folder")
    ap.add_argument("--save", default=None, help="write all per-row results to this CSV")
    ap.add_argument("--random", type=int, default=0, help="N fresh random designs per pattern")
    ap.add_argument("--seed", type=int, default=2022)
    ap.add_argument(
        "--perturb",
        type=float,
        default=0.0,
        help="multiply every L1 by (1 + PERTURB), e.g. 1e-15, to expose round-off sensitivity",
    )
    ap.add_argument(
        "--compare", default=None, help="per-row CSV of an earlier --save run to compare with"
    )
    ap.add_argument(
        "--ensemble",
        type=int,
        default=0,
        metavar="K",
        help="run every row K times in all, run k with L1 x (1 + k 1e-15), and test whether "
        "the published values are exchangeable with these round-off-level variants",
    )
    ap.add_argument(
        "--ensemble-arccos",
        action="store_true",
        help="odd ensemble members also use the reference's arccos dihedral angle",
    )
    ap.add_argument(
        "--converged",
        action="store_true",
        help="run every Newton solve to a tight tolerance (GripperOptions(converged=True))",
    )
    ap.add_argument(
        "--plot",
        default=None,
        metavar="PNG",
        help="with --ensemble or --from-csv: draw the published stiffness against the ensemble",
    )
    ap.add_argument(
        "--from-csv",
        default=None,
        metavar="CSV",
        help="report (and --plot) a saved --ensemble run instead of simulating",
    )
    args = ap.parse_args(argv)
    if args.ensemble < 0 or args.ensemble == 1:
        ap.error(f"--ensemble {args.ensemble}: needs K >= 2 runs per row")
    if args.random and (args.ensemble or args.plot):
        ap.error("--ensemble and --plot apply to the published rows, not to --random designs")
    if args.plot and not (args.ensemble or args.from_csv):
        ap.error("--plot needs --ensemble K (or --from-csv CSV)")
    if args.ensemble_arccos and not args.ensemble:
        ap.error("--ensemble-arccos needs --ensemble K")
    if args.from_csv:
        try:
            table = pd.read_csv(args.from_csv)
            analyse_saved(table)
            if args.plot:
                plot_ensemble(table, args.plot)
                emit(f"picture written to {args.plot}")
        except (OSError, ValueError, KeyError) as exc:
            ap.error(f"--from-csv {args.from_csv}: {exc}")
        return 0
    options = GripperOptions(converged=args.converged)
    frames = []
    if args.random:
        rng = np.random.default_rng(args.seed)
        for P in args.patterns:
            rows = random_designs(P, args.random, rng)
            res = pd.DataFrame(run_rows(rows, args.workers, 0.0, options))
            fail = (res["status"] == "failed: no closure").sum()
            other = res["status"].str.startswith("failed").sum() - fail
            emit(
                f"== pattern {P} ({NAMES[P]}): {len(rows)} fresh designs, no closure within the "
                f"cap: {fail} ({100 * fail / len(rows):.0f} %), other failures: {other}; "
                f"median {res['seconds'].median():.2f} s per design"
            )
            emit(f"   closing step quartiles: {quartiles(res['step'])}")
            frames.append(pd.concat([pd.DataFrame(rows), res], axis=1))
    else:
        folder = reference_folder(args.data)
        for P in args.patterns:
            ref = load(folder, STEMS[P])
            if args.rows:
                ref = ref.iloc[: args.rows]
            rows = ref[FEATURES].to_dict("records")
            t = time.perf_counter()
            ours = pd.DataFrame(run_rows(rows, args.workers, args.perturb, options))
            emit(f"(pattern {P}: {time.perf_counter() - t:.0f} s wall)")
            report(P, ref.reset_index(drop=True), ours)
            if args.compare:
                old = pd.read_csv(args.compare)
                old = old[old["Pattern"] == P].reset_index(drop=True).iloc[: len(ours)]
                if len(old) == len(ours):
                    sensitivity(P, ref.reset_index(drop=True), ours, old)
                else:
                    emit(f"  --compare: {len(old)} rows of pattern {P} there, not {len(ours)}")
            extra = []
            if args.ensemble > 1:
                t = time.perf_counter()
                k = np.arange(1, args.ensemble)
                arccos = args.ensemble_arccos & (k % 2 == 1)
                spec = [
                    (args.perturb + 1e-15 * kk, with_arccos(options, bool(a)))
                    for kk, a in zip(k, arccos, strict=True)
                ]
                members = run_ensemble(rows, spec, args.workers)
                emit(f"(ensemble: {time.perf_counter() - t:.0f} s wall)")
                extra = [
                    m[["step", "stiff"]]
                    .add_suffix(f"_m{kk}")
                    .assign(**{f"angle_m{kk}": "arccos" if a else "atan2"})
                    for kk, a, m in zip(k, arccos, members, strict=True)
                ]
                emit(
                    f"  ensemble: member k = 0..{args.ensemble - 1} with L1 x (1 + k 1e-15)"
                    + (", odd k with the reference's arccos angle" if args.ensemble_arccos else "")
                )
                saved = pd.concat([ours, *extra], axis=1)
                ensemble_report(P, ref.reset_index(drop=True), *ensemble_arrays(saved))
            pub = ref.add_suffix("_published")
            frames.append(
                pd.concat(
                    [ref[FEATURES], ours, *extra, pub[[o + "_published" for o in OUTPUTS]]], axis=1
                )
            )
    if args.save and frames:
        Path(args.save).parent.mkdir(parents=True, exist_ok=True)
        pd.concat(frames, ignore_index=True).to_csv(args.save, index=False)
        emit(f"per-row results written to {args.save}")
    if args.plot and frames and args.ensemble > 1:
        plot_ensemble(pd.concat(frames, ignore_index=True), args.plot)
        emit(f"picture written to {args.plot}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
