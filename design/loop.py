"""The design loop: from a scenario and a target to the best design found, its files and report.

:func:`run_design` is what ``holofold design`` runs (docs/scenarios.md §9):

1. **database**: sample designs of the scenario and simulate them (resumable Parquet batches),
   a small **pilot** batch first: when no pilot design meets the target and one of its
   conditions is met by none of them, the run stops there and says what the designs reach;
2. **mine**: rules for the target (random forest), keeping distinct alternatives;
3. **verify**: simulate fresh designs inside each top rule (95 % Wilson interval);
4. **refine** (until a rule is verified or the ``budget`` of simulations is spent): sample new
   designs, half where the last round's forest votes for the target and half inside its best
   rule (or by the other strategies), add them (and the verification designs) to the database,
   re-mine and re-verify;
5. **choose** (:mod:`~holofold.design.choice`): from every simulated design, the best under the
   designer's objective inside the best verified rule of all rounds; without a qualifying rule
   the best design meeting the target; without one, the nearest, with its shortfall. A design
   whose thick panels overlap is not chosen unless ``allow_overlap``. Always an answer;
6. **files**: ``design.json``, the design's fabrication files, its fit on the printer's bed,
   pictures, a 3D view and ``report.html``.

Every simulation lands in a resumable database folder, so running the same call again
continues where it stopped and recomputes only the cheap stages (mining, choosing, files).
A larger ``samples``, ``budget``, ``rounds`` or ``verify`` extends the folder: the base sample
and each rule's verification grow by a batch; refinement and verification folders are named by the
rules they come from (a changed rule gets its own), and every design simulated in the folder
by an earlier run stays a candidate.
"""

from __future__ import annotations

import json
import math
import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.acquisition import likely_designs
from holofold.design.batches import grow
from holofold.design.buildability import DEFAULT_BED, Bed, parse_bed, part_fit
from holofold.design.choice import Answer, Candidate, choose
from holofold.design.describe import PILOT, distributions
from holofold.design.folder_lock import locks_folder
from holofold.design.mining import OneClassSplit, mine_rules
from holofold.design.objective import Objective, parse_objective
from holofold.design.rounds import Round, VerifiedRule
from holofold.design.row_status import converged_rows, failed_rows
from holofold.design.rulefile import mined_rules, write_rules
from holofold.design.rules import Condition, FewRulesWarning, Rule
from holofold.design.runner import check_workers
from holofold.design.sampling import MAX_SAMPLES, sample_designs
from holofold.design.scenarios import Scenario, load_scenario
from holofold.design.store import build_database, load_database
from holofold.design.summary import STAGES, DesignSummary, Pick, Timings
from holofold.design.tables import ColumnRoles, write_table
from holofold.design.targets import parse_target
from holofold.design.verify import as_rule, rule_key, rule_ranges, verify_rule
from holofold.geometry.outputs import write_json
from holofold.geometry.units import length_factor

__all__ = ["run_design", "DesignOutcome", "refine_designs", "choose_design", "STAGES"]

#: where refinement rounds sample (:func:`run_design`'s ``strategy``)
REFINE_STRATEGIES = ("likely", "around", "mixed")
#: a rule is verified (fresh simulations) once its estimate reaches this precision: a rule the
#: miner expects below it would not pass (90 % of its fresh designs meeting the target)
VERIFY_FROM = 0.85
#: designs simulated with none meeting the target after which the loop stops looking at random
#: (a rate below 3 / 2000 = 0.15 % at 95 % confidence: loosen the target)
RANDOM_UP_TO = 2000


@dataclass(frozen=True)
class DesignOutcome:
    """What :func:`run_design` found.

    Attributes
    ----------
    record : DesignSummary
        The typed summary (``summary`` is its JSON, the content of ``design.json``).
    table : DataFrame
        Every simulated design (database, refinement, verification and earlier rows) with
        ``origin``.
    folder : Path
        The output folder.
    """

    record: DesignSummary
    table: pd.DataFrame
    folder: Path

    @property
    def summary(self) -> dict:
        return self.record.to_json()

    @property
    def features(self) -> dict:
        return self.summary["features"]

    @property
    def performance(self) -> dict:
        return self.summary["performance"]

    @property
    def met(self) -> bool:
        """The chosen design meets the target."""
        return self.record.chosen is not None and self.record.chosen.meets


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
    table: pd.DataFrame,
    target,
    rule: Rule | Mapping | None,
    objective: Objective | None = None,
) -> tuple[int | None, dict, str]:
    """The row of ``table`` to build inside ``rule`` (None: anywhere) that meets ``target``,
    best under ``objective`` (default: the largest worst-case margin).

    Returns (index label or None, per-condition margins of that row, how it was chosen).
    Converged rows are preferred; without one inside the box, every row meeting the target
    is considered (and the returned text says so). The loop itself chooses with
    :func:`holofold.design.choice.choose`, which also weighs the rules of every round and
    whether the design can be built.
    """
    obj = objective or parse_objective(None, ())
    ok = pd.Series(~failed_rows(table), index=table.index)
    conv = pd.Series(converged_rows(table), index=table.index)
    meets = pd.Series(False, index=table.index)
    if ok.any():
        meets.loc[ok] = target.evaluate(table.loc[ok])
    inside = pd.Series(True, index=table.index)
    if rule is not None:
        inside[:] = as_rule(rule).mask(table)
    how = "inside the best verified rule"
    for pool, text in (
        (inside & meets & conv, how),
        (inside & meets, how + " (no converged design there: a non-converged row)"),
        (meets & conv, "among all simulated designs (none inside the rule meets the target)"),
    ):
        if pool.any():
            label = obj.best(table.loc[pool], target)
            margins = {k: float(v[0]) for k, v in target.margins(table.loc[[label]]).items()}
            return label, margins, text
    return None, {}, "no simulated design meets the target"


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


def _box_of(hits: pd.DataFrame, roles: ColumnRoles) -> Rule:
    """A pseudo-rule: the box spanned by the designs that meet the target (to refine around)."""
    conds = []
    for name in roles.features:
        col = hits[name].to_numpy(dtype=float)
        if name in roles.categorical:
            conds.append(Condition(name, levels=tuple(col.tolist())))
        elif col.max() > col.min():
            conds.append(
                Condition(name, gt=float(np.nextafter(col.min(), -np.inf)), le=float(col.max()))
            )
    return Rule(tuple(conds), rank=0)


def _key(*parts) -> str:
    """8 hex digits naming what a refinement's designs come from (its rules, size and seed)."""
    import hashlib

    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:8]


def _fmt(p) -> str:
    return "n/a" if p is None else f"{p:.2f}"


def _clean(v):
    if isinstance(v, (np.floating, np.integer)):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def _pilot_verdict(rows: pd.DataFrame, tgt) -> tuple[int, list[str], str | None]:
    """(designs meeting the target, conditions met by none, why to stop or None)."""
    ok = rows.loc[~failed_rows(rows)]
    if not len(ok):
        return 0, [], f"every one of the {len(rows)} pilot simulations failed"
    hits = int(tgt.evaluate(ok).sum())
    if hits:
        return hits, [], None
    margins = tgt.margins(ok)
    unmet = [c for c, m in margins.items() if not (np.nan_to_num(m, nan=-np.inf) >= 0).any()]
    if unmet:
        return 0, unmet, (f"no pilot design meets {' nor '.join(unmet)}")
    if not tgt.conjunctive:
        return 0, [], f"no pilot design meets the target {str(tgt)!r}"
    return 0, [], None  # each condition met by some, jointly by none: a rare target, go on


def _buildable_target(sc: Scenario, tgt, table: pd.DataFrame, say=lambda text: None):
    """The target with ``overlap <= OVERLAP_TOLERANCE``, when the kind computes the overlap
    (a column of NaN, as a pattern scenario without collisions gives, says nothing). When no
    design of ``table`` is buildable, the target alone (rules for a box nothing in the table
    shows to exist would only be looked for at random), said through ``say``."""
    from holofold.design.choice import OVERLAP_TOLERANCE

    ok = table.loc[~failed_rows(table)]
    ov = ok["overlap"].to_numpy(dtype=float)
    if not np.isfinite(ov).any():
        return tgt
    if not (ov <= OVERLAP_TOLERANCE).any():
        say(
            f"[mine] the thick panels of all {len(ok)} designs overlap (the least by "
            f"{np.nanmin(ov) * 1e9:.3g} mm^3): rules are mined for the target alone; the "
            "choice still keeps to designs that do not overlap (--allow-overlap admits them)"
        )
        return tgt
    return parse_target(f"({tgt}) & overlap <= {OVERLAP_TOLERANCE:g}", sc.performance_names)


def _stored_rows(folder: Path, prefix: str, covered: int) -> int:
    """Rows already simulated in the batches ``{prefix}a-b`` that continue from ``covered``."""
    from holofold.design.batches import batch_spans

    spans = batch_spans(folder, 10**9, prefix, covered)[:-1]  # the last span is the missing one
    done = [
        (a, b)
        for a, b in spans
        if (folder / f"{prefix}{a:06d}-{b:06d}" / "database.parquet").is_file()
    ]
    return sum(b - a for a, b in done)


def _on_disk(stored: int, wanted: int) -> str:
    """`` (on disk: N)`` when a batch on disk already holds some of the rows asked for."""
    k = max(0, min(stored, wanted))
    return "" if k == 0 else f" ({k} already simulated, read from disk)"


class _Ledger:
    """``runs.json``: seconds per stage of every invocation on the folder (resumed runs add)."""

    def __init__(self, out: Path):
        self.path = out / "runs.json"
        try:
            runs = json.loads(self.path.read_text(encoding="utf-8"))
            self.runs = [
                r for r in runs if isinstance(r, dict) and isinstance(r.get("stages"), dict)
            ]
        except (OSError, ValueError, TypeError):
            self.runs = []

    def timings(self, this: dict) -> Timings:
        total = dict.fromkeys(STAGES, 0.0)
        for r in self.runs:
            for k, v in r["stages"].items():
                if k in total and isinstance(v, (int, float)) and v >= 0:
                    total[k] += float(v)
        for k, v in this.items():
            total[k] += v
        return Timings(dict(this), total, len(self.runs) + 1)

    def append(self, this: dict) -> None:
        stamp = datetime.now(UTC).isoformat(timespec="seconds")
        write_json(
            self.path,
            [*self.runs, {"started": stamp, "stages": {k: round(v, 3) for k, v in this.items()}}],
        )


def _earlier_rows(sc: Scenario, roots: Sequence[Path], used: set) -> pd.DataFrame | None:
    """Rows simulated in this folder by earlier runs that this run did not read (a refinement
    of rules that have since changed, a larger sample asked before): still candidates."""
    parts = []
    for root in roots:
        if not root.is_dir():
            continue
        for d in sorted(root.rglob("designs.parquet")):
            folder = d.parent
            if folder.resolve() in used:
                continue
            try:
                info = json.loads((folder / "meta.json").read_text(encoding="utf-8"))
                if info.get("scenario") != sc.name:
                    continue
                rows = load_database(folder)
            except (OSError, ValueError, KeyError, TypeError, AttributeError):
                continue
            if all(c in rows for c in (*sc.required_features, *sc.performance_names, "status")):
                parts.append(rows.assign(origin=f"earlier: {folder.relative_to(root.parent)}"))
    return pd.concat(parts, ignore_index=True) if parts else None


@locks_folder("folder")  # one run per design folder (its databases are locked on their own)
def run_design(
    scenario: Scenario | str | os.PathLike,
    target: str,
    folder: str | os.PathLike,
    *,
    samples: int = 200,
    rounds: int | None = None,
    budget: int = 6000,
    refine: int = 50,
    verify: int = 50,
    top: int = 3,
    strategy: str = "mixed",
    until_verified: bool = True,
    db: str | os.PathLike | None = None,
    seed: int = 0,
    workers: int = 1,
    progress: bool | None = None,
    files: bool = True,
    mesh_units: str = "mm",
    cutter=None,
    objective: str | Objective | None = None,
    allow_overlap: bool = False,
    bed: str | Bed | tuple | None = None,
    pilot: int = PILOT,
    say: Callable[[str], None] = lambda text: None,
) -> DesignOutcome:
    """Run the design loop (module docstring) into ``folder``; resumable and extendable.

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
    rounds : int, optional
        Refinement rounds at most (0: mine once, as the paper did; default: as many as
        ``budget`` allows).
    budget : int
        Simulations this run may spend at most: the base database, refinement and verification
        designs (rows of a database given with ``db`` that were there before cost nothing). A
        refinement round starts only when its ``refine`` designs and one verification fit; a
        rule is verified only when its ``verify`` designs fit.
    refine : int
        New designs per refinement round.
    verify : int
        Fresh designs simulated per verified rule and round. A rule is verified when its
        estimate reaches :data:`VERIFY_FROM` (in the last round at least the best one), best
        lower estimate first.
    top : int
        Rules kept per round (distinct alternatives).
    strategy : {"mixed", "likely", "around"}
        Where a refinement round samples: ``"mixed"`` (default), half where the last round's
        forest votes for the target and half uniformly inside its best rule; ``"likely"``, all
        where the forest votes (:func:`holofold.design.acquisition.likely_designs`);
        ``"around"``, half inside the rules and half in them widened by a quarter of each range
        (:func:`refine_designs`). A round after one without a rule samples around the designs
        that meet the target, or at random while none does. Measured against each other and
        against mining once in ``benchmarks/rare_targets.md``.
    until_verified : bool
        Stop once a rule is verified: at least 90 % of its fresh designs meet the target and
        the 95 % interval's lower end is at least 0.8 (:func:`rule_verified`).
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
    objective : str or Objective, optional
        ``"margin"`` (default: the largest worst-case margin to the target), ``"min COLUMN"``
        or ``"max COLUMN"`` (any performance or feature column).
    allow_overlap : bool
        Let a design whose thick panels overlap be chosen (never by default).
    bed : "WxD" in mm, Bed or (x, y) in m
        The printer's bed the part's fit is judged on (None: the scenario's ``bed``, else
        250 x 210 mm).
    pilot : int
        Designs simulated first (0: no pilot); the run stops after them, with the columns'
        distributions, when none meets the target and a condition is met by none.
    say : callable
        Receives one line of progress per stage.
    """
    sc = load_scenario(scenario)
    tgt = parse_target(target, sc.performance_names)
    obj = parse_objective(objective, [*sc.performance_names, *sc.feature_names])
    bed = parse_bed(bed if bed is not None else (sc.bed or DEFAULT_BED))
    for name, v, low in (
        ("samples", samples, 20),
        ("rounds", 0 if rounds is None else rounds, 0),
        ("verify", verify, 1),
        ("top", top, 1),
        ("refine", refine, 1 if rounds != 0 else 0),
        ("budget", budget, 1),
        ("pilot", pilot, 0),
    ):
        if isinstance(v, bool) or int(v) != v or v < low:
            raise ValueError(f"{name} = {v!r} must be an integer >= {low}")
    if strategy not in REFINE_STRATEGIES:
        raise ValueError(
            f"strategy = {strategy!r} must be one of {', '.join(map(repr, REFINE_STRATEGIES))}"
        )
    if budget > MAX_SAMPLES:
        raise ValueError(f"budget = {budget:,} simulations; at most {MAX_SAMPLES:,} in one run")
    if budget < samples + verify:
        raise ValueError(
            f"budget = {budget:,} simulations cannot hold the {samples:,} designs of the database "
            f"and one verification of {verify:,} (at least {samples + verify:,})"
        )
    workers = check_workers(workers)
    length_factor(mesh_units)
    out = Path(folder)
    dbf = Path(db) if db is not None else out / "database"
    roles = _roles(sc)
    if not roles.features:
        raise ValueError(f"scenario {sc.name!r} varies no feature: give ranges in [features]")
    # buildable by default: rules are mined and verified for the target with panels that do not
    # overlap (the choice filters on it too); the margins and the objective use the target alone
    buildable = (
        "overlap" in sc.performance_names and not allow_overlap and "overlap" not in tgt.columns
    )
    out.mkdir(parents=True, exist_ok=True)
    ledger = _Ledger(out)
    times = dict.fromkeys(STAGES, 0.0)
    used: set = set()

    def simulate(designs: pd.DataFrame, path: Path) -> pd.DataFrame:
        # sampled designs the scenario's check refuses are failed rows, not a refused run
        used.add(path.resolve())
        return build_database(
            sc, designs, path, workers=workers, progress=progress, on_invalid="skip"
        )

    def base(start: int, count: int) -> pd.DataFrame:
        return sample_designs(sc, count, seed=seed, start=start)

    # 1. database: the pilot first
    t0 = time.perf_counter()
    parts, have = [], 0
    given = _given_database(dbf, sc)
    if given is not None:  # a database the user made (holofold generate): all its rows
        used.add(dbf.resolve())
        parts.append(given.assign(origin="database"))
        have = len(given)
    first = min(samples, pilot) if pilot else samples
    stored = _stored_rows(dbf, "base-", have)
    if have < first:
        what = f"pilot: {first - have}" if pilot else f"{samples - have}"
        say(f"[database] {what} designs of {sc.name}{_on_disk(stored, first - have)}")
    rows, _ = grow(dbf, first, base, simulate, prefix="base-", covered=have)
    parts.append(rows.assign(origin="database"))
    table = pd.concat([p for p in parts if len(p)], ignore_index=True)
    pilot_info = None
    if pilot:
        hits, unmet, stop = _pilot_verdict(table, tgt)
        pilot_info = {
            "rows": int(len(table)),
            "meeting": hits,
            "stopped": stop is not None,
            "reason": stop or "",
            "unmet": unmet,
        }
        if stop is not None:
            say(f"  pilot: {stop} ({len(table)} designs); stopping before the rest")
    times["database"] += time.perf_counter() - t0
    history: list[Round] = []
    miners: dict = {}
    mine_tgt = tgt
    if not (pilot_info and pilot_info["stopped"]):
        t0 = time.perf_counter()
        if len(table) < samples:
            more = samples - len(table)
            say(
                f"[database] {more} more designs of {sc.name}"
                f"{_on_disk(stored - len(table) + have, more)}"
            )
            rows, _ = grow(dbf, samples, base, simulate, prefix="base-", covered=len(table))
            table = pd.concat([table, rows.assign(origin="database")], ignore_index=True)
        if given is None:
            table = table.iloc[:samples]
        times["database"] += time.perf_counter() - t0
        mine_tgt = _buildable_target(sc, tgt, table, say) if buildable else tgt
        table, history, miners = _rounds(
            sc,
            mine_tgt,
            roles,
            table,
            out,
            dbf,
            simulate,
            rounds=rounds,
            budget=budget,
            free=have,
            refine=refine,
            verify=verify,
            top=top,
            strategy=strategy,
            until_verified=until_verified,
            seed=seed,
            workers=workers,
            progress=progress,
            times=times,
            used=used,
            say=say,
        )

    # 5. choose, from everything simulated in the folder
    t0 = time.perf_counter()
    earlier = _earlier_rows(sc, [dbf, out / "rounds"], used)
    everything = table if earlier is None else pd.concat([table, earlier], ignore_index=True)
    if earlier is not None:
        say(
            f"[choose] {len(earlier)} designs simulated by earlier runs in {out} join the "
            "candidates"
        )
    say(f"[choose] {obj.words}" + (", thick panels not overlapping" if buildable else ""))
    rules = [r for h in history for r in h.rules]
    answer = choose(everything, tgt, obj, rules, allow_overlap=allow_overlap)
    everything = everything.reset_index(drop=True)
    times["choose"] = time.perf_counter() - t0
    say(f"  {answer.headline}")

    summary = DesignSummary(
        scenario=_scenario_summary(sc),
        target=str(tgt),
        mined_target=str(mine_tgt),
        objective=str(obj),
        allow_overlap=bool(allow_overlap),
        answer=answer.kind,
        headline=_headline(answer, pilot_info),
        chosen=_pick(sc, everything, answer.chosen, tgt),
        alternatives=tuple(_pick(sc, everything, c, tgt) for c in answer.alternatives),
        rounds=tuple(history),
        database=_counts(everything, dbf, out),
        pilot=pilot_info,
        distributions=tuple(distributions(everything, _target_columns(sc, tgt, obj))),
    )
    write_table(everything, out / "designs.parquet")
    if files and answer.chosen is not None:
        t0 = time.perf_counter()
        what = (
            "fabrication files, "
            if sc.write_files is not None
            else f"(no fabrication files for scenario {sc.name!r}) "
        )
        say(f"[files] {what}pictures, 3D view and report.html")
        row = everything.loc[answer.chosen.label]
        rule = answer.chosen.rule
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            extra = _write_files(
                sc, row, out, rule, miners, everything, tgt, mesh_units, bed, answer.chosen, cutter
            )
        notes = list(dict.fromkeys(str(w.message) for w in caught))
        for w in notes:
            say(f"  note: {w}")
        summary = _replace(summary, warnings=tuple(notes), **extra)
        times["files"] = time.perf_counter() - t0
    summary = _replace(summary, timings=ledger.timings(times))
    write_json(out / "design.json", summary.to_json())
    ledger.append(times)
    if files:
        from holofold.design.report_page import write_report_page

        write_report_page(out, summary)
    _check_own_summary(out, summary.to_json())
    _say_chosen(say, summary, tgt, out, sc.columns)
    if summary.fabrication is not None:
        say(f"part: {summary.fabrication.line()}")
    return DesignOutcome(summary, everything, out)


def _headline(answer: Answer, pilot: Mapping | None) -> str:
    """The answer's sentence, after why the run stopped if its pilot stopped it."""
    if pilot and pilot["stopped"]:
        return (
            f"The run stopped after its pilot of {pilot['rows']} designs: "
            f"{pilot['reason']} (the designs' range is below). {answer.headline}"
        )
    return answer.headline


def _replace(summary: DesignSummary, **kw) -> DesignSummary:
    from dataclasses import replace

    return replace(summary, **kw)


def _check_own_summary(out: Path, summary: dict) -> None:
    """Before the run reports success: ``design.json`` in ``out`` is the one it wrote."""
    try:
        stored = json.loads((out / "design.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ValueError(f"{out}/design.json cannot be read back ({exc})") from None
    if stored != json.loads(json.dumps(summary)):
        raise ValueError(f"{out}/design.json is not this run's: another run wrote the folder")


def _shown(columns: Mapping, name: str, value) -> str:
    """A value of the chosen design in its column's display unit (4 digits), or n/a."""
    return "n/a" if value is None else columns[name].format(value, 4)


def _say_chosen(say, summary: DesignSummary, tgt, out: Path, columns: Mapping) -> None:
    c = summary.chosen
    if c is None:
        say(f"no design: every simulation failed; see {out}/report.html")
        return
    vp = None if c.rule is None else c.rule.precision
    feats = ", ".join(f"{k} = {_shown(columns, k, v)}" for k, v in c.features.items())
    perf = ", ".join(f"{k} = {_shown(columns, k, c.performance.get(k))}" for k in tgt.columns)
    state = "meets the target" if c.meets else "does NOT meet the target (nearest)"
    say(
        f"chosen: {feats}\n  {perf}; {state}; worst margin {c.worst_margin:.3g}; answer "
        f"{summary.answer!r}; rule verified precision {_fmt(vp)}; files in {out}/"
    )


def _target_columns(sc: Scenario, tgt, obj: Objective) -> list:
    names = list(dict.fromkeys([*tgt.columns, *([obj.column] if obj.column else [])]))
    cols = {c.name: c for c in (*sc.performance, *sc.features)}
    return [cols[n] for n in names if n in cols]


def _counts(table: pd.DataFrame, dbf: Path, out: Path) -> dict:
    by = table["origin"].astype(str)
    kind = by.str.replace(r"-\d+(-\d+)?$", "", regex=True).str.replace(
        r"^earlier: .*", "earlier", regex=True
    )
    return {
        "rows": int(len(table)),
        "failed": int(failed_rows(table).sum()),
        "by_origin": {k: int(v) for k, v in kind.value_counts(sort=False).items()},
        "path": os.path.relpath(dbf, out),
    }


def _pick(sc: Scenario, table: pd.DataFrame, c: Candidate | None, tgt) -> Pick | None:
    if c is None:
        return None
    row = table.loc[c.label]
    return Pick(
        source=c.source,
        features={f.name: _clean(float(row[f.name])) for f in sc.features if f.name in row},
        performance={k: _clean(float(row[k])) for k in sc.performance_names},
        status=str(row["status"]),
        origin=str(row["origin"]),
        margins=dict(c.margins),
        worst_margin=c.worst_margin,
        meets=c.meets,
        buildable=c.buildable,
        objective=_clean(c.score),
        rule=c.rule,
    )


def _rounds(
    sc,
    tgt,
    roles,
    table,
    out,
    dbf,
    simulate,
    *,
    rounds,
    budget,
    free,
    refine,
    verify,
    top,
    strategy,
    until_verified,
    seed,
    workers,
    progress,
    times,
    used,
    say,
):
    """Stages 2-4: mine, verify and refine until a rule is verified, ``rounds`` refinement
    rounds are done or ``budget`` simulations would be passed (the first ``free`` rows of
    ``table``, a given database's, cost nothing); returns the grown table, the rounds and each
    round's mined rules (round -> MinedRules)."""
    history: list[Round] = []
    miners: dict = {}
    boxes: list = []
    around = -1  # the last round whose few hits could not be mined: the next samples around

    def more(r: int) -> bool:
        """Another refinement round after round ``r`` is allowed and fits the budget."""
        capped = rounds is not None and r >= rounds
        return not capped and len(table) - free + refine + verify <= budget

    r = -1
    while r < 0 or more(r):
        r += 1
        of = f"{r}/{rounds}" if rounds is not None else f"{r}"
        rdir = out / "rounds" / f"round-{r}"
        if r:
            t0 = time.perf_counter()
            s = seed + 7919 * r
            if r - 1 not in miners and around == r - 1:  # too few hits to mine: around them
                say(f"[refine] round {of}: {refine} new designs around the designs "
                    "that meet the target")  # fmt: skip
                key = _key("around-hits", [rule_key(b) for b in boxes], refine, s)
                new = refine_designs(sc, boxes, refine, seed=s, start=10**6 * r)
            elif r - 1 not in miners:  # no design met the target yet: more at random
                say(f"[refine] round {of}: {refine} new designs at random (none met "
                    "the target yet)")  # fmt: skip
                key = _key("random", refine, s)
                new = sample_designs(sc, refine, seed=s, start=10**6 * r)
            elif strategy == "mixed":
                say(f"[refine] round {of}: {refine} new designs, half where the forest votes "
                    "for the target, half inside the best rule")  # fmt: skip
                key = _key("mixed", [rule_key(b) for b in boxes], len(table), refine, s)
                half = refine // 2
                vote = likely_designs(sc, miners[r - 1].miner, refine - half, seed=s,
                                      start=10**6 * r)  # fmt: skip
                inside = refine_designs(sc, boxes[:1], half, seed=s, widen=0.0,
                                        start=10**6 * r + refine - half)  # fmt: skip
                new = pd.concat([vote, inside], ignore_index=True)
            elif strategy == "likely":
                say(f"[refine] round {of}: {refine} new designs where the forest votes "
                    "for the target")  # fmt: skip
                key = _key("likely", [rule_key(b) for b in boxes], len(table), refine, s)
                new = likely_designs(sc, miners[r - 1].miner, refine, seed=s, start=10**6 * r)
            else:
                say(f"[refine] round {of}: {refine} new designs inside and around the "
                    "rules")  # fmt: skip
                key = _key([rule_key(b) for b in boxes], refine, s)
                new = refine_designs(sc, boxes, refine, seed=s, start=10**6 * r)
            res = simulate(new, dbf / f"refine-{r}-{key}")
            table = pd.concat([table, res.assign(origin=f"refine-{r}")], ignore_index=True)
            times["refine"] += time.perf_counter() - t0
        t0 = time.perf_counter()
        ok = table.loc[~failed_rows(table)]
        hits = int(tgt.evaluate(ok).sum()) if len(ok) else 0
        if hits in (0, len(ok)):  # nothing to tell apart: no rule to mine
            note = (
                f"no rule to mine: {hits} of {len(ok)} simulated designs meet "
                f"{'the target' if hits == 0 else 'the target, all of them'}"
            )
            look = hits == 0 and more(r) and 0 < len(ok) and len(table) < RANDOM_UP_TO
            if look:  # a rare target: keep looking
                note += "; the next round samples more at random"
            elif hits == 0 and len(table) >= RANDOM_UP_TO:
                note += (
                    f" (fewer than 3 in {len(table):,} at 95 % confidence): no more rounds; "
                    "loosen the target or widen the feature ranges"
                )
            say(f"[mine] round {r}: {note}")
            history.append(Round(r, len(ok), len(table) - len(ok), hits, (), note))
            times["mine"] += time.perf_counter() - t0
            if look:
                continue
            break
        say(f"[mine] round {r}: rules for {tgt} from {len(table)} designs")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", FewRulesWarning)
                mined = mine_rules(
                    table, tgt, roles=roles, seed=seed, n_rules=top, max_overlap=0.5,
                    source=str(dbf),
                )  # fmt: skip
        except OneClassSplit:  # a few hits, all held out: look around them, as with no rule
            note = f"no rule yet ({hits} of {len(ok)} designs meet the target, too few to mine)"
            times["mine"] += time.perf_counter() - t0
            history.append(Round(r, len(ok), len(table) - len(ok), hits, (), note))
            if not more(r):
                say(f"  round {r}: {note}")
                break
            boxes, around = [_box_of(ok.loc[tgt.evaluate(ok)], roles)], r
            say(f"  round {r}: {note}; the next round samples around them")
            continue
        records = mined_rules(mined.miner, mined.test_scores)[:top]
        miners[r] = mined
        if records:
            rdir.mkdir(parents=True, exist_ok=True)
            write_rules(rdir / "rules.json", records, sc.columns)
        times["mine"] += time.perf_counter() - t0
        rows, failed = int(len(mined.table)), int(mined.n_failed)
        hits = int(mined.meets.sum())
        if not records:
            if hits and more(r):  # a rare target: refine around the designs that meet it
                boxes = [_box_of(mined.table.loc[mined.meets], roles)]
                note = (
                    f"no rule yet ({hits} of {rows} designs meet the target); the next "
                    "round samples around them"
                )
            else:
                note = (
                    f"no rule reaches the miner's precision ({hits} of {rows} designs meet "
                    "the target)"
                )
            say(f"  round {r}: {note}")
            history.append(Round(r, rows, failed, hits, (), note))
            if not hits:
                break  # nothing to refine around: more rounds would sample the same
            continue
        t0 = time.perf_counter()
        worth = _worth_verifying(records, last=not more(r))
        say(f"[verify] round {r}: {len(worth)} of {len(records)} rule(s) (estimate >= "
            f"{VERIFY_FROM}), {verify} fresh designs each")  # fmt: skip
        checks: list = [None] * len(records)
        for i in worth:  # best lower estimate first; the first verified rule ends the round
            spent = len(table) - free + sum(len(v.designs) for v in checks if v)
            if spent + verify > budget:
                say(f"  round {r}: the budget of simulations leaves no room to verify more")
                break
            rec = records[i]
            vdir = rdir / "verify" / f"rule{i + 1}-{rule_key(rec)}"
            checks[i] = verify_rule(sc, rec, tgt, verify, seed=seed + 100 * r + i + 1,
                                    folder=vdir, workers=workers, progress=progress)  # fmt: skip
            used.update(p.parent.resolve() for p in vdir.rglob("designs.parquet"))
            if until_verified and rule_verified(checks[i].counts):
                break
        times["verify"] += time.perf_counter() - t0
        ranked = [
            VerifiedRule.of(rec, r, None if v is None else v.counts, sc.columns)
            for rec, v in zip(records, checks, strict=True)
        ]
        for e in ranked:
            say(
                f"  round {r} rule {e.rank}: {e.text}  (estimate {_fmt(e.estimate)}, held-out "
                f"{_fmt(e.test_precision)}, verified {_fmt(e.precision)})"
            )
        for i, v in enumerate(checks, start=1):
            if v is None:
                continue
            table = pd.concat(
                [table, v.designs.drop(columns="meets_target").assign(origin=f"verify-{r}-{i}")],
                ignore_index=True,
            )
        history.append(Round(r, rows, failed, hits, tuple(ranked)))
        boxes = records
        done = [e for e in ranked if e.verified is not None and rule_verified(e.verified)]
        if until_verified and done and more(r):
            say(f"  round {r}: rule {done[0].rank} is verified; no more rounds")
            break
        if not done and not more(r) and (rounds is None or r < rounds):
            say(f"  round {r}: the budget of {budget:,} simulations leaves no room for a round")
    return table, history, miners


def rule_verified(counts) -> bool:
    """A rule is verified: at least 90 % of its fresh designs met the target and the lower end
    of their 95 % Wilson interval is at least 0.8 (``counts``: a verification's ``Counts``)."""
    p, ci = counts.precision, counts.interval
    return p is not None and p >= 0.9 and ci[0] >= 0.8


def _worth_verifying(rules: Sequence[Rule], last: bool) -> list[int]:
    """Positions of the rules to verify, best lower estimate first: those whose estimate reaches
    :data:`VERIFY_FROM` (a rule the miner expects below it would not be verified); in the last
    round at least the best one."""

    def low(i):
        e = rules[i].estimate
        return -1.0 if e is None else e.low

    order = sorted(range(len(rules)), key=low, reverse=True)
    worth = [i for i in order if rules[i].estimate is None
             or rules[i].estimate.precision >= VERIFY_FROM]  # fmt: skip
    return worth or (order[:1] if last else [])


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
                "display_unit": c.display_unit,
                "low": c.low,
                "high": c.high,
                "choices": list(c.choices),
            }
            for c in sc.features
        ],
        "performance": [
            {
                "name": c.name,
                "unit": c.unit,
                "display_unit": c.display_unit,
                "description": c.description,
            }
            for c in sc.performance
        ],
    }


def _write_files(
    sc: Scenario,
    row,
    out: Path,
    rule: VerifiedRule | None,
    miners,
    table,
    tgt,
    mesh_units: str,
    bed: Bed,
    chosen: Candidate,
    cutter,
) -> dict:
    """The chosen design's files, pictures, 3D view and fit on the bed: the summary's
    ``files``, ``images``, ``fabrication`` and ``extras``."""
    from holofold.design.report import (
        plot_folded_design,
        plot_rule_boxes,
        plot_target_scatter,
        save_figure,
    )

    files, images, extras = {}, {}, {}
    fabrication = None
    design = {c.name: float(row[c.name]) for c in sc.features if c.name in row}
    overlap = chosen.buildable is False
    if sc.write_files is not None:
        fab = sc.write_files(design, out / "files", units=mesh_units, cutter=cutter)
        for note in fab.notes:  # the report's notes on the files (the loop records warnings)
            warnings.warn(note, UserWarning, stacklevel=2)
        for key in _FOLDED_SOLIDS if overlap else ():
            if key in fab:  # the folded part cannot exist as designed: not written
                fab[key].path.unlink(missing_ok=True)
                warnings.warn(
                    f"{fab[key].path.name} not written: the folded thick panels of this design "
                    f"overlap by {float(row['overlap']) * 1e9:.3g} mm^3, so the folded part "
                    "cannot be made as designed",
                    stacklevel=2,
                )
        files = {k: v for k, v in fab.record(out).items() if not (overlap and k in _FOLDED_SOLIDS)}
        path = next((fab[k].path for k in ("printable", "thick") if k in fab), None)
        if path is not None and path.is_file():
            part = sc.part(design) if sc.part is not None and "printable" in fab else None
            fabrication = part_fit(path, bed, units=mesh_units, root=out, part=part)
            if fabrication.segments:
                files["segments"] = {
                    "path": f"{fabrication.segments}/assembly.svg",
                    "label": f"the {fabrication.pieces} pieces to print (segments/"
                    "segment_NN.stl) and their assembly sheet (SVG)",
                }
    if sc.shape is not None:
        pat = sc.shape(design)
        creases = pat.edges[pat.interior] if hasattr(pat, "interior") else None
        fig = plot_folded_design(
            pat.coords, pat.faces, creases=creases, title=f"{sc.name}: chosen design"
        )
        save_figure(fig, out / "design.png")
        images["design"] = "design.png"
    if rule is not None and rule.round in miners:  # drawn from the table it was mined from
        mined = miners[rule.round]
        fig = plot_rule_boxes(
            mined.miner, mined.table[list(mined.features)], rule.rank - 1, columns=sc.columns
        )
        p = rule.train_precision
        fig.axes[0].set_title(
            f"{rule.label}: training precision {'n/a' if p is None else f'{p:.2f}'} "
            f"(verified {_fmt(rule.precision)})",
            fontsize=9,
        )
        fig.tight_layout()  # long feature names stay inside the picture
        save_figure(fig, out / "rule.png")
        images["rule"] = "rule.png"
    tcols = list(tgt.columns)
    if len(tcols) >= 2:
        x, y = tcols[0], tcols[1]
    else:  # the target's column against the rule's first continuous feature
        feats = [k for k in (rule.bounds if rule else {}) if k not in sc.categorical]
        x = feats[0] if feats else next(c for c in _roles(sc).features if c not in sc.categorical)
        y = tcols[0]
    ok = table.loc[~failed_rows(table)]
    fig = plot_target_scatter(ok, tgt, x, y, chosen=row, columns=sc.columns)
    save_figure(fig, out / "scatter.png")
    images["scatter"] = "scatter.png"
    if getattr(sc, "view", None) is not None:
        view = sc.view(design)
        extras["view"] = view.to_json()
        extras.update(view.facts_json())
    return {"files": files, "images": images, "fabrication": fabrication, "extras": extras}


#: fabrication-set keys of the folded thick part, which cannot exist when its panels overlap
#: (docs/scenarios.md §8.2)
_FOLDED_SOLIDS = ("thick", "printable_folded")
