"""The design loop: from a scenario and a target to one chosen, verified design and its files.

:func:`run_design` is what ``holofold design`` runs (docs/scenarios.md §9):

1. **database**: sample designs of the scenario and simulate them (resumable Parquet batches);
2. **mine**: rules for the target (random forest), keeping distinct alternatives;
3. **verify**: simulate fresh designs inside each top rule (95 % Wilson interval);
4. **refine** (``rounds`` times): sample new designs inside and around the best rules, add them
   (and the verification designs) to the database, re-mine and re-verify;
5. **choose**: among the simulated designs inside the best verified rule that meet the target,
   the one with the largest worst-case margin to the target's thresholds (each normalised by
   its threshold);
6. **files**: ``design.json``, the design's fabrication files, pictures and ``report.html``.

Every simulation lands in a resumable database folder, so running the same call again
continues where it stopped and recomputes only the cheap stages (mining, choosing, files).
"""

from __future__ import annotations

import math
import os
import re
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.folder_lock import locks_folder
from holofold.design.mining import mine_rules
from holofold.design.row_status import converged_rows, failed_rows
from holofold.design.rulefile import mined_rules, write_rules
from holofold.design.rules import Condition, FewRulesWarning, Rule
from holofold.design.runner import check_workers
from holofold.design.sampling import MAX_SAMPLES, sample_designs
from holofold.design.scenarios import Scenario, load_scenario
from holofold.design.store import build_database, load_database
from holofold.design.tables import ColumnRoles, write_table
from holofold.design.targets import parse_target
from holofold.design.verify import Verification, as_rule, rule_ranges
from holofold.geometry.outputs import write_json
from holofold.geometry.units import length_factor

__all__ = ["run_design", "DesignOutcome", "refine_designs", "choose_design", "STAGES"]

STAGES = ("database", "mine", "verify", "refine", "choose", "files")
_BASE = re.compile(r"base-(\d{6})-(\d{6})$")


@dataclass(frozen=True)
class DesignOutcome:
    """What :func:`run_design` found.

    Attributes
    ----------
    summary : dict
        The content of ``design.json`` (plus rounds, files, timings).
    table : DataFrame
        Every simulated design (database, refinement and verification rows) with ``origin``.
    folder : Path
        The output folder.
    """

    summary: dict
    table: pd.DataFrame
    folder: Path

    @property
    def features(self) -> dict:
        return self.summary["features"]

    @property
    def performance(self) -> dict:
        return self.summary["performance"]


# ---------------------------------------------------------------------- sampling
def refine_designs(
    scenario: Scenario,
    rules: Sequence[Rule | Mapping],
    n: int,
    *,
    seed: int,
    start: int = 0,
    widen: float = 0.25,
) -> pd.DataFrame:
    """``n`` new designs inside and around the boxes of ``rules`` (:class:`Rule` records or
    their JSON form; shared equally).

    Half of each rule's designs lie inside its box, half in the box widened by ``widen`` of
    each feature's range on both sides (clipped to the scenario's range), so the database also
    learns where the rule's edges really are. Categorical features keep the rule's levels.
    """
    cols = {c.name: c for c in scenario.features}
    parts = []
    k = len(rules)
    counts = [n // k + (1 if i < n % k else 0) for i in range(k)]
    for i, (rule, m) in enumerate(zip(rules, counts, strict=True)):
        inside = rule_ranges(scenario, rule)
        wide = {}
        for name, r in inside.items():
            c = cols[name]
            if isinstance(r, list):
                wide[name] = r
                continue
            pad = widen * (c.high - c.low)
            wide[name] = (max(c.low, r[0] - pad), min(c.high, r[1] + pad))
        for j, ranges in enumerate((inside, wide)):
            size = m // 2 + (m % 2 if j == 0 else 0)
            if size:
                parts.append(
                    sample_designs(scenario, size, seed=seed * 1000 + 2 * i + j, ranges=ranges)
                )
    out = pd.concat(parts, ignore_index=True)
    out["sample"] = np.arange(start, start + len(out))
    return out


# ---------------------------------------------------------------------- choosing
def choose_design(
    table: pd.DataFrame, target, rule: Rule | Mapping | None
) -> tuple[int | None, dict, str]:
    """The row of ``table`` to build: inside ``rule``, meeting ``target``, largest margin.

    Returns (index label or None, per-condition margins of that row, how it was chosen).
    Converged rows are preferred; without one inside the box, every row meeting the target
    is considered (and the returned text says so).
    """
    ok = ~failed_rows(table)
    conv = converged_rows(table)
    meets = np.zeros(len(table), bool)
    meets[ok] = target.evaluate(table.loc[ok])
    inside = as_rule(rule).mask(table) if rule is not None else np.ones(len(table), bool)
    how = "inside the best verified rule"
    for pool, text in (
        (inside & meets & conv, how),
        (inside & meets, how + " (no converged design there: a non-converged row)"),
        (meets & conv, "among all simulated designs (none inside the rule meets the target)"),
    ):
        if pool.any():
            how = text
            break
    else:
        return None, {}, "no simulated design meets the target"
    cand = table.loc[pool]
    worst = target.margin(cand)
    label = cand.index[int(np.argmax(worst))]
    margins = {k: float(v[0]) for k, v in target.margins(table.loc[[label]]).items()}
    return label, margins, how


# ---------------------------------------------------------------------- the loop
def _roles(scenario: Scenario) -> ColumnRoles:
    def varies(c) -> bool:
        if c.choices:
            return len(c.choices) > 1
        return c.low is not None and c.high is not None and c.high > c.low

    varied = [c.name for c in scenario.features if c.required and varies(c)]
    cats = tuple(c for c in scenario.categorical if c in varied)
    return ColumnRoles(tuple(varied), tuple(scenario.performance_names), cats)


def _given_database(db: Path, sc: Scenario) -> pd.DataFrame | None:
    """The rows of a database folder made by ``holofold generate`` (None if ``db`` is not one)."""
    meta = db / "meta.json"
    if not meta.is_file():
        return None
    import json

    try:
        info = json.loads(meta.read_text(encoding="utf-8"))
        name = info["scenario"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{meta}: not a holofold database description ({exc})") from None
    if name != sc.name:
        raise ValueError(f"--db {db} holds designs of scenario {name!r}, not {sc.name!r}")
    table = load_database(db)
    missing = [c for c in (*sc.required_features, *sc.performance_names) if c not in table]
    if missing:
        raise ValueError(f"--db {db} lacks the column(s) {', '.join(missing)} of {sc.name!r}")
    return table


def _base_batches(db: Path, n: int, covered: int = 0) -> list[tuple[int, int]]:
    """Row spans [start, stop) of the base sample from ``covered`` on: the existing batches,
    then what is missing."""
    spans = sorted(
        (int(m[1]), int(m[2]))
        for p in (db.iterdir() if db.is_dir() else ())
        if (m := _BASE.match(p.name))
    )
    out = []
    for a, b in spans:
        if a == covered and covered < n:
            out.append((a, b))
            covered = b
    if covered < n:
        out.append((covered, n))
    return out


def _simulate(scenario, designs, folder, workers, progress) -> pd.DataFrame:
    # sampled designs the scenario's check refuses are failed rows, not a refused run
    return build_database(
        scenario, designs, folder, workers=workers, progress=progress, on_invalid="skip"
    )


def _verify(scenario, rules, target, n, folder, seed, workers, progress):
    out = []
    for i, r in enumerate(rules, start=1):
        designs = sample_designs(scenario, n, seed=seed + i, ranges=rule_ranges(scenario, r))
        res = _simulate(scenario, designs, folder / f"rule{i}", workers, progress)
        out.append(Verification.of(res, target))
    return out


def _box_of(sc: Scenario, hits: pd.DataFrame, roles: ColumnRoles) -> Rule:
    """A pseudo-rule: the box spanned by the designs that meet the target (to refine around)."""
    conds = []
    for name in roles.features:
        col = hits[name].to_numpy(dtype=float)
        if name in roles.categorical:
            conds.append(Condition(name, levels=tuple(col.tolist())))
        elif col.max() > col.min():
            conds.append(Condition(name, gt=float(np.nextafter(col.min(), -np.inf)),
                                   le=float(col.max())))  # fmt: skip
    return Rule(tuple(conds), rank=0)


def _rule_entry(rule: Rule, v: Verification | None, columns: Mapping) -> dict:
    rec = rule.to_json(columns)
    e = {k: rec[k] for k in ("rank", "rule", "bounds", "display")}
    e |= {
        "train_precision": None if rule.train is None else rule.train.precision,
        "test_precision": None if rule.test is None else rule.test.precision,
        "test_support": None if rule.test is None else rule.test.support,
    }
    if rule.estimate is not None:
        est = rec["estimate"]
        e |= {
            "estimate": est["precision"],
            "estimate_95ci": est["interval"],
            "estimate_rows": est["rows"],
        }
    if v is not None:
        s = v.summary()
        e |= {
            "verified_precision": s["precision"],
            "verified_95ci": s["precision_95ci"],
            "verified_n": s["simulated"],
            "verified_failed": s["failed"],
        }
    return {k: (None if isinstance(x, float) and not math.isfinite(x) else x) for k, x in e.items()}


def _pick_rule(entries: list[dict]) -> int:
    def key(i):
        e = entries[i]
        vp = e.get("verified_precision")
        lo = (e.get("verified_95ci") or [-1, -1])[0]
        return (-1 if vp is None else vp, lo, e.get("test_precision") or 0.0)

    return max(range(len(entries)), key=key)


def _fmt(p) -> str:
    return "n/a" if p is None else f"{p:.2f}"


def _clean(v):
    if isinstance(v, (np.floating, np.integer)):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


@locks_folder("folder")  # one run per design folder (its databases are locked on their own)
def run_design(
    scenario: Scenario | str | os.PathLike,
    target: str,
    folder: str | os.PathLike,
    *,
    samples: int = 500,
    rounds: int = 0,
    refine: int = 100,
    verify: int = 50,
    top: int = 3,
    db: str | os.PathLike | None = None,
    seed: int = 0,
    workers: int = 1,
    progress: bool | None = None,
    files: bool = True,
    mesh_units: str = "mm",
    cutter=None,
    say: Callable[[str], None] = lambda text: None,
) -> DesignOutcome:
    """Run the design loop (module docstring) into ``folder``; resumable.

    Parameters
    ----------
    scenario : Scenario, scenario name or path of a ``.toml`` scenario file
    target : str
        Target expression over the scenario's performance columns, e.g.
        ``"Zstiff > 100 & error < 0.05"``.
    folder : path
        Output folder (``design.json``, ``report.html``, ``files/``, ``database/``, ...).
    samples : int
        Designs in the base database (>= 20).
    rounds : int
        Refinement rounds (0: mine once, as the paper did).
    refine : int
        New designs per refinement round.
    verify : int
        Fresh designs simulated per verified rule and round.
    top : int
        Rules kept and verified per round (distinct alternatives).
    db : path, optional
        Database folder to use instead of ``folder/database`` (reused and extended). A folder
        made by ``holofold generate`` (with its ``meta.json``) gives all its rows, extended with
        new batches inside it when it has fewer than ``samples``.
    seed : int
    workers : int
        Worker processes for the simulations.
    files : bool
        Write the chosen design's fabrication files, pictures and the report page.
    mesh_units : {"mm", "m"}
        Length unit of the mesh files (STL, OBJ); FOLD stays in m, SVG and DXF in mm.
    cutter : CutterOptions, optional
        How the SVG and DXF of the flat pattern are drawn (a
        :class:`~holofold.geometry.CutterOptions`; default Origami Simulator's convention).
    say : callable
        Receives one line of progress per stage.
    """
    sc = load_scenario(scenario)
    tgt = parse_target(target, sc.performance_names)
    for name, v, low in (("samples", samples, 20), ("rounds", rounds, 0), ("verify", verify, 1),
                         ("top", top, 1), ("refine", refine, 1 if rounds else 0)):  # fmt: skip
        if int(v) != v or v < low:
            raise ValueError(f"{name} = {v!r} must be an integer >= {low}")
    total = samples + rounds * refine + (rounds + 1) * top * verify
    if total > MAX_SAMPLES:
        raise ValueError(
            f"{total:,} simulations asked for (samples + rounds x refine + (rounds + 1) x top x "
            f"verify); at most {MAX_SAMPLES:,} in one run"
        )
    workers = check_workers(workers)
    length_factor(mesh_units)
    out = Path(folder)
    dbf = Path(db) if db is not None else out / "database"
    roles = _roles(sc)
    columns = sc.columns
    if not roles.features:
        raise ValueError(f"scenario {sc.name!r} varies no feature: give ranges in [features]")
    out.mkdir(parents=True, exist_ok=True)
    times = dict.fromkeys(STAGES, 0.0)

    # 1. database
    t0 = time.perf_counter()
    say(f"[database] {samples} designs of {sc.name}")
    parts, have = [], 0
    given = _given_database(dbf, sc)
    if given is not None:  # a database the user made (holofold generate): all its rows
        parts.append(given.assign(origin="database"))
        have = len(given)
    for a, b in _base_batches(dbf, max(samples, have), have):
        designs = sample_designs(sc, b - a, seed=seed, start=a)
        res = _simulate(sc, designs, dbf / f"base-{a:06d}-{b:06d}", workers, progress)
        parts.append(res.assign(origin="database"))
    table = pd.concat(parts, ignore_index=True)
    if given is None:
        table = table.iloc[:samples]
    times["database"] = time.perf_counter() - t0

    history = []
    best = None
    mined = None
    for r in range(rounds + 1):
        rdir = out / "rounds" / f"round-{r}"
        if r:
            t0 = time.perf_counter()
            say(f"[refine] round {r}/{rounds}: {refine} new designs inside and around the rules")
            new = refine_designs(sc, history[-1]["records"], refine, seed=seed + 7919 * r,
                                 start=10**6 * r)  # fmt: skip
            res = _simulate(sc, new, dbf / f"refine-{r}", workers, progress)
            table = pd.concat([table, res.assign(origin=f"refine-{r}")], ignore_index=True)
            times["refine"] += time.perf_counter() - t0
        t0 = time.perf_counter()
        say(f"[mine] round {r}: rules for {tgt} from {len(table)} designs")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FewRulesWarning)
            mined = mine_rules(table, tgt, roles=roles, seed=seed, n_rules=top, max_overlap=0.5,
                               source=str(dbf))  # fmt: skip
        records = mined_rules(mined.miner, mined.test_scores)[:top]
        if records:
            rdir.mkdir(parents=True, exist_ok=True)
            write_rules(rdir / "rules.json", records, columns)
        times["mine"] += time.perf_counter() - t0
        if not records:
            hits = int(mined.meets.sum())
            if r == rounds:
                more = "more --rounds, " if hits else ""
                raise ValueError(
                    f"no rule reaches the miner's precision for {str(tgt)!r} in round {r} "
                    f"({hits} of {len(mined.table)} designs meet it); try {more}more samples "
                    "or a looser target"
                )
            # a rare target: refine around the designs that meet it, then mine again
            box = _box_of(sc, mined.table.loc[mined.meets], roles)
            say(f"  round {r}: no rule yet ({hits} of {len(mined.table)} designs meet the "
                "target); the next round samples around them")  # fmt: skip
            history.append({"round": r, "rows": int(len(mined.table) + mined.n_failed),
                            "records": [box], "rules": [], "best": None})  # fmt: skip
            continue
        t0 = time.perf_counter()
        say(f"[verify] round {r}: {len(records)} rule(s), {verify} fresh designs each")
        checks = _verify(sc, records, tgt, verify, rdir / "verify", seed + 100 * r, workers,
                         progress)  # fmt: skip
        times["verify"] += time.perf_counter() - t0
        entries = [_rule_entry(rec, v, columns) for rec, v in zip(records, checks, strict=True)]
        for e in entries:
            est, test = _fmt(e.get("estimate")), _fmt(e["test_precision"])
            ver = _fmt(e.get("verified_precision"))
            say(f"  round {r} rule {e['rank']}: {e['rule']}  "
                f"(estimate {est}, test {test}, verified {ver})")  # fmt: skip
        for i, v in enumerate(checks, start=1):
            table = pd.concat(
                [table, v.designs.drop(columns="meets_target").assign(origin=f"verify-{r}-{i}")],
                ignore_index=True,
            )
        best = _pick_rule(entries)
        history.append({"round": r, "rows": int(len(mined.table) + mined.n_failed),
                        "records": records, "rules": entries, "best": best})  # fmt: skip

    # 5. choose
    t0 = time.perf_counter()
    say("[choose] the design with the largest worst-case margin inside the best rule")
    rule = history[-1]["rules"][best]
    label, margins, how = choose_design(table, tgt, history[-1]["records"][best])
    if label is None:
        raise ValueError(f"no simulated design meets {str(tgt)!r}; try more samples or rounds")
    row = table.loc[label]
    features = {c.name: _clean(float(row[c.name])) for c in sc.features if c.name in row}
    performance = {c: _clean(float(row[c])) for c in sc.performance_names}
    units = {c.name: c.unit for c in (*sc.features, *sc.performance)}
    times["choose"] = time.perf_counter() - t0
    summary = {
        "scenario": _scenario_summary(sc),
        "target": str(tgt),
        "features": features,
        "performance": performance,
        "status": str(row["status"]),
        "units": units,
        "rule": rule,
        "verified_precision": rule.get("verified_precision"),
        "margins": {k: _clean(v) for k, v in margins.items()},
        "worst_margin": _clean(min(margins.values())) if margins else None,
        "chosen": {"how": how, "origin": str(row["origin"])},
        "database": {
            "rows": int(len(table)),
            "failed": int(failed_rows(table).sum()),
            "path": os.path.relpath(dbf, out),
        },  # fmt: skip
        "rounds": [{k: h[k] for k in ("round", "rows", "rules", "best")} for h in history],
    }
    write_table(table, out / "designs.parquet")
    if files:
        t0 = time.perf_counter()
        what = "fabrication files, " if sc.write_files is not None else "(no fabrication files "
        what += "" if sc.write_files is not None else f"for scenario {sc.name!r}) "
        say(f"[files] {what}pictures and report.html")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            summary["files"], summary["images"] = _write_files(
                sc, row, out, mined, rule, table, tgt, mesh_units, cutter
            )
        summary["warnings"] = list(dict.fromkeys(str(w.message) for w in caught))
        for w in summary["warnings"]:
            say(f"  note: {w}")
        times["files"] = time.perf_counter() - t0
    summary["timings"] = {k: round(v, 3) for k, v in times.items()}
    write_json(out / "design.json", summary)
    if files:
        from holofold.design.report_page import write_report_page

        write_report_page(out, summary)
    _check_own_summary(out, summary)
    vp = rule.get("verified_precision")
    say(f"chosen: {', '.join(f'{k} = {_shown(columns, k, v)}' for k, v in features.items())}\n"
        f"  {', '.join(f'{k} = {_shown(columns, k, performance[k])}' for k in tgt.columns)}; "
        f"worst margin {summary['worst_margin']:.3g}; rule verified precision "
        f"{'n/a' if vp is None else f'{vp:.2f}'}; files in {out}/")  # fmt: skip
    return DesignOutcome(summary, table, out)


def _check_own_summary(out: Path, summary: dict) -> None:
    """Before the run reports success: ``design.json`` in ``out`` is the one it wrote."""
    import json

    try:
        stored = json.loads((out / "design.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ValueError(f"{out}/design.json cannot be read back ({exc})") from None
    if stored != json.loads(json.dumps(summary)):
        raise ValueError(f"{out}/design.json is not this run's: another run wrote the folder")


def _shown(columns: Mapping, name: str, value) -> str:
    """A value of the chosen design in its column's display unit (4 digits), or n/a."""
    return "n/a" if value is None else columns[name].format(value, 4)


def _scenario_summary(sc: Scenario) -> dict:
    return {
        "name": sc.name,
        "kind": sc.kind or "paper",
        "description": sc.description,
        "source": sc.source,
        "setting": {k: _clean(v) for k, v in dict(sc.setting).items()},
        "features": [
            {
                "name": c.name,
                "unit": c.unit,
                "description": c.description,
                "low": c.low,
                "high": c.high,
                "choices": list(c.choices),
            }  # fmt: skip
            for c in sc.features
        ],
        "performance": [
            {"name": c.name, "unit": c.unit, "description": c.description} for c in sc.performance
        ],
    }


def _write_files(
    sc: Scenario, row, out: Path, mined, rule: Mapping, table, tgt, mesh_units: str, cutter
):
    from holofold.design.report import (
        plot_folded_design,
        plot_rule_boxes,
        plot_target_scatter,
        save_figure,
    )

    files, images = {}, {}
    design = {c.name: float(row[c.name]) for c in sc.features if c.name in row}
    if sc.write_files is not None:
        fab = sc.write_files(design, out / "files", units=mesh_units, cutter=cutter)
        files = fab.record(out)  # stable key -> {"path", "label"}
        for note in fab.notes:  # the report's notes on the files (the loop records warnings)
            warnings.warn(note, UserWarning, stacklevel=2)
    if sc.shape is not None:
        pat = sc.shape(design)
        creases = pat.edges[pat.interior] if hasattr(pat, "interior") else None
        fig = plot_folded_design(
            pat.coords, pat.faces, creases=creases, title=f"{sc.name}: chosen design"
        )
        save_figure(fig, out / "design.png")
        images["design"] = "design.png"
    X = mined.table[list(mined.features)]
    fig = plot_rule_boxes(mined.miner, X, rule["rank"] - 1, columns=sc.columns)
    fig.tight_layout()  # long feature names stay inside the picture
    save_figure(fig, out / "rule.png")
    images["rule"] = "rule.png"
    cols = list(tgt.columns)
    if len(cols) >= 2:
        x, y = cols[0], cols[1]
    else:  # the target's column against the rule's first continuous feature
        x = next((k for k in rule["bounds"] if k not in sc.categorical), mined.features[0])
        y = cols[0]
    ok = table.loc[~failed_rows(table)]
    fig = plot_target_scatter(ok, tgt, x, y, chosen=row, columns=sc.columns)
    save_figure(fig, out / "scatter.png")
    images["scatter"] = "scatter.png"
    return files, images
