"""The design loop: from a scenario and a target to the best design found, its files and report.

:func:`run_design` is what ``holofold design`` runs (docs/scenarios.md §9):

1. **database**: sample designs of the scenario and simulate them (resumable Parquet batches),
   a small **pilot** batch first: when no pilot design meets the target and one of its
   conditions is out of reach (the pilot's tail, extrapolated, expects less than one design
   meeting it within the budget), the run stops there and says what the designs reach;
2. **mine**: rules for the target (random forest), keeping distinct alternatives;
3. **verify**: simulate fresh designs inside each top rule (95 % Wilson interval);
4. **refine** (until a rule is verified or the ``budget`` of simulations is spent): sample new
   designs, half where the last round's forest votes for the target and half inside its best
   rule (or by the other strategies), add them (and the verification designs) to the database,
   re-mine and re-verify;
5. **choose** (:mod:`~holofold.design.loop.choice`): from every simulated design, the best under the
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
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.database.batches import grow
from holofold.design.database.folder_lock import folder_lock
from holofold.design.database.row_status import converged_rows, failed_rows
from holofold.design.database.sampling import sample_designs
from holofold.design.database.store import build_database, load_database
from holofold.design.database.tables import ColumnRoles, write_table
from holofold.design.loop.buildability import Bed, part_fit
from holofold.design.loop.choice import Answer, Candidate, choose
from holofold.design.loop.objective import Objective, parse_objective
from holofold.design.loop.rounds import RULE_BAR, Round, VerifiedRule
from holofold.design.loop.settings import (
    DesignFiles,
    DesignProblem,
    Execution,
    LoopSettings,
    made,
    split_options,
)
from holofold.design.loop.strategies import (
    STRATEGIES,
    RefineRequest,
    around_hits,
    at_random,
    refine_designs,
)
from holofold.design.loop.summary import STAGES, DesignSummary, Pick, Timings
from holofold.design.report.describe import distributions
from holofold.design.rules import Condition, FewRulesWarning, Rule
from holofold.design.rules.mining import OneClassSplit, mine_rules
from holofold.design.rules.rulefile import mined_rules, write_rules
from holofold.design.rules.targets import parse_target
from holofold.design.rules.verify import as_rule, rule_key, verify_rule
from holofold.design.scenarios import Scenario
from holofold.geometry.outputs import write_json

__all__ = [
    "run_design",
    "DesignLoop",
    "LoopState",
    "DesignOutcome",
    "refine_designs",
    "choose_design",
    "STAGES",
]
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
    :func:`holofold.design.loop.choice.choose`, which also weighs the rules of every round and
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


def _fmt(p) -> str:
    return "n/a" if p is None else f"{p:.2f}"


def _clean(v):
    if isinstance(v, (np.floating, np.integer)):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def _pilot_verdict(rows: pd.DataFrame, tgt, budget: int) -> tuple[int, list[str], str | None]:
    """(designs meeting the target, conditions out of reach, why to stop or None).

    A condition no pilot design meets is out of reach when the pilot's top tail,
    extrapolated (:meth:`Target.reach`), expects fewer than one design meeting it in the
    run's ``budget`` of simulations; a condition that is merely rare (or met by some designs)
    never stops the run. With ``|``, the run stops only when every condition is out of reach.
    """
    ok = rows.loc[~failed_rows(rows)]
    if not len(ok):
        return 0, [], f"every one of the {len(rows)} pilot simulations failed"
    hits = int(tgt.evaluate(ok).sum())
    if hits:
        return hits, [], None
    reach = tgt.reach(ok)
    far = [r for r in reach if r.meeting == 0 and r.rarity * budget < 1.0]
    if not far or (not tgt.conjunctive and len(far) < len(tgt.conditions)):
        return 0, [], None  # rare, not out of reach: go on
    why = []
    for r in far:
        q5, q50, q95 = np.nanquantile(ok[r.column].to_numpy(float), [0.05, 0.5, 0.95])
        odds = f"1 in {1 / r.rarity:.2g}" if r.rarity > 0 else "none"
        why.append(
            f"{r.condition} (the pilot's 5 / 50 / 95 % are {q5:.4g} / {q50:.4g} / {q95:.4g}, its "
            f"best {r.best:.4g}; its top quarter extrapolates to {odds} designs, fewer than one "
            f"in the budget of {budget})"
        )
    return 0, [r.condition for r in far], "no pilot design meets " + " nor ".join(why)


def _buildable_target(sc: Scenario, tgt, table: pd.DataFrame, say=lambda text: None):
    """The target with ``overlap <= OVERLAP_TOLERANCE``, when the kind computes the overlap
    (a column of NaN, as a pattern scenario without collisions gives, says nothing). When no
    design of ``table`` is buildable, the target alone (rules for a box nothing in the table
    shows to exist would only be looked for at random), said through ``say``."""
    from holofold.design.loop.choice import OVERLAP_TOLERANCE

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
    from holofold.design.database.batches import batch_spans

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

    def append(self, this: dict, *, interrupted: bool = False) -> None:
        """Add this invocation's seconds per stage; ``interrupted`` for a run stopped by a
        signal before it wrote its answer (its seconds still count in the total)."""
        stamp = datetime.now(UTC).isoformat(timespec="seconds")
        run = {"started": stamp, "stages": {k: round(v, 3) for k, v in this.items()}}
        if interrupted:
            run["interrupted"] = True
        write_json(self.path, [*self.runs, run])
        self.runs.append(run)


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


def run_design(
    problem: DesignProblem | Scenario | str | os.PathLike,
    target: str | None = None,
    folder: str | os.PathLike | None = None,
    *,
    settings: LoopSettings | None = None,
    execution: Execution | None = None,
    output: DesignFiles | None = None,
    **options,
) -> DesignOutcome:
    """Run the design loop (module docstring) into ``folder``; resumable and extendable.

    Parameters
    ----------
    problem : DesignProblem, or the scenario (a Scenario, its name or a ``.toml`` path)
        What is asked (:class:`~holofold.design.DesignProblem`: scenario, target, objective,
        bed, ``allow_overlap``). Given a scenario, ``target`` is its target expression, e.g.
        ``"Zstiff > 100 & error < 0.05"``.
    target : str, optional
        With a scenario: the target expression over its performance columns.
    folder : path
        Output folder (``design.json``, ``report.html``, ``files/``, ``database/``, ...); one run
        at a time holds it.
    settings : LoopSettings, optional
        How the loop searches (samples, budget, refine, verify, strategy, pilot, rounds, top,
        until_verified, seed; :class:`~holofold.design.LoopSettings` gives each its meaning).
    execution : Execution, optional
        How it runs (workers, progress, scheduler, row_timeout, ``say`` for the progress lines).
    output : DesignFiles, optional
        What it writes (db, files, mesh_units, cutter).
    **options
        Any field of the four records by name (the loop's former keyword arguments:
        ``samples=200``, ``workers=2``, ``objective="min mass"``, ``files=False``, ...); each
        replaces the field of the record given, or of the default one.

    The rows of a database given with ``db`` that were there before cost nothing against the
    budget. Every simulation lands in a resumable folder: the same call again continues.
    """
    if folder is None:
        raise TypeError("run_design() needs the output folder")
    with folder_lock(folder):  # a run refused before it writes leaves no folder behind
        by = split_options(options)
        if isinstance(problem, DesignProblem):
            if target is not None:
                raise TypeError("run_design(problem, ...): the target is the problem's")
            problem = made(DesignProblem, problem, by[DesignProblem])
        else:
            problem = DesignProblem(problem, target, **by[DesignProblem])
        loop = DesignLoop(
            problem,
            made(LoopSettings, settings, by[LoopSettings]),
            made(Execution, execution, by[Execution]),
            made(DesignFiles, output, by[DesignFiles]),
            Path(folder),
        )
        return loop.run()


@dataclass
class LoopState:
    """What one :class:`DesignLoop` has found so far (its steps read and grow it; none is
    handed on).

    ``table`` every design simulated by the run (with ``origin``); ``free`` its first rows that
    came from a given database (no cost against the budget); ``history`` the rounds;
    ``miners`` round -> MinedRules; ``boxes`` the rules (or the box of the designs meeting the
    target) the next refinement samples by; ``around`` the last round whose few hits could not
    be mined; ``times`` seconds per stage; ``used`` the folders this run read;
    ``pilot`` the pilot's verdict; ``mine_target`` the target rules are mined for;
    ``stalled`` why the search stopped for want of progress ("" when it did not).
    """

    table: pd.DataFrame | None = None
    free: int = 0
    history: list = field(default_factory=list)
    miners: dict = field(default_factory=dict)
    boxes: list = field(default_factory=list)
    around: int = -1
    times: dict = field(default_factory=lambda: dict.fromkeys(STAGES, 0.0))
    used: set = field(default_factory=set)
    pilot: dict | None = None
    mine_target: object = None
    stalled: str = ""


class DesignLoop:
    """The loop over one folder: :meth:`database`, then rounds of :meth:`refine`,
    :meth:`mine` and :meth:`verify` (:meth:`search`), then :meth:`choose` and :meth:`write`,
    each a step over :attr:`state` (a :class:`LoopState`)."""

    def __init__(self, problem: DesignProblem, settings: LoopSettings, execution: Execution,
                 output: DesignFiles, folder: Path):  # fmt: skip
        self.problem, self.settings, self.execution, self.output = (
            problem, settings, execution, output
        )  # fmt: skip
        self.sc, self.say, self.out = problem.scenario, execution.say, Path(folder)
        self.dbf = Path(output.db) if output.db is not None else self.out / "database"
        self.roles = _roles(self.sc)
        if not self.roles.features:
            raise ValueError(
                f"scenario {self.sc.name!r} varies no feature: give ranges in [features]"
            )
        self.state = LoopState(mine_target=problem.target)

    def run(self) -> DesignOutcome:
        self.out.mkdir(parents=True, exist_ok=True)
        ledger = _Ledger(self.out)
        try:
            if self.database():
                self.search()
            answer, everything = self.choose()
        except (KeyboardInterrupt, SystemExit):  # Ctrl-C, or SIGTERM turned into SystemExit
            ledger.append(self.state.times, interrupted=True)  # still in the time total
            raise
        return self.write(answer, everything, ledger)

    # ------------------------------------------------------------------ helpers
    @contextmanager
    def _timed(self, stage: str):
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.state.times[stage] += time.perf_counter() - t0

    def _simulate(self, designs: pd.DataFrame, path: Path) -> pd.DataFrame:
        # sampled designs the scenario's check refuses are failed rows, not a refused run
        self.state.used.add(path.resolve())
        return build_database(self.sc, designs, path, on_invalid="skip",
                              **self.execution.runner())  # fmt: skip

    def _base(self, start: int, count: int) -> pd.DataFrame:
        return sample_designs(self.sc, count, seed=self.settings.seed, start=start)

    def _round_dir(self, r: int) -> Path:
        return self.out / "rounds" / f"round-{r}"

    def more(self, r: int) -> bool:
        """Another refinement round after round ``r`` is allowed and fits the budget."""
        s = self.settings
        capped = s.rounds is not None and r >= s.rounds
        spent = len(self.state.table) - self.state.free
        return not capped and spent + s.refine + s.verify <= s.budget

    # ------------------------------------------------------------------ 1. database
    def database(self) -> bool:
        """The pilot, then the rest of the base sample; False when the pilot stops the run."""
        s, st, say = self.settings, self.state, self.say
        with self._timed("database"):
            parts, have = [], 0
            given = _given_database(self.dbf, self.sc)
            if given is not None:  # a database the user made (holofold generate): all its rows
                st.used.add(self.dbf.resolve())
                parts.append(given.assign(origin="database"))
                have = len(given)
            st.free = have
            first = min(s.samples, s.pilot) if s.pilot else s.samples
            stored = _stored_rows(self.dbf, "base-", have)
            if have < first:
                what = f"pilot: {first - have}" if s.pilot else f"{s.samples - have}"
                say(f"[database] {what} designs of {self.sc.name}{_on_disk(stored, first - have)}")
            rows, _ = grow(self.dbf, first, self._base, self._simulate, prefix="base-",
                           covered=have)  # fmt: skip
            parts.append(rows.assign(origin="database"))
            st.table = pd.concat([p for p in parts if len(p)], ignore_index=True)
            if s.pilot:
                st.pilot = _pilot_info(st.table, self.problem.target, s.budget, say)
        if st.pilot and st.pilot["stopped"]:
            return False
        with self._timed("database"):
            if len(st.table) < s.samples:
                more = s.samples - len(st.table)
                on_disk = _on_disk(stored - len(st.table) + have, more)
                say(f"[database] {more} more designs of {self.sc.name}{on_disk}")
                rows, _ = grow(self.dbf, s.samples, self._base, self._simulate, prefix="base-",
                               covered=len(st.table))  # fmt: skip
                st.table = pd.concat([st.table, rows.assign(origin="database")],
                                     ignore_index=True)  # fmt: skip
            if given is None:
                st.table = st.table.iloc[: s.samples]
        if self.problem.buildable:
            st.mine_target = _buildable_target(self.sc, self.problem.target, st.table, say)
        return True

    # ------------------------------------------------------------------ 2-4. rounds
    def search(self) -> None:
        """Mine, verify and refine until a rule is verified, ``rounds`` refinement rounds are
        done or the budget would be passed."""
        r = -1
        while r < 0 or self.more(r):
            r += 1
            if r:
                self.refine(r)
            step = self.mine(r)
            if step is True:
                continue
            if step is False or self.verify(r, step):
                break

    def refine(self, r: int) -> None:
        """New designs for round ``r``: by the settings' strategy after a round with rules,
        around the designs meeting the target after one whose few hits could not be mined, at
        random while none meets it."""
        s, st = self.settings, self.state
        with self._timed("refine"):
            last = st.miners.get(r - 1)
            if last is None:
                how = around_hits if st.around == r - 1 else at_random
            else:
                how = STRATEGIES[s.strategy]
            ask = RefineRequest(self.sc, s.refine, s.seed + 7919 * r, 10**6 * r,
                                tuple(st.boxes), last and last.miner, len(st.table))  # fmt: skip
            new = how(ask)
            words = new.words
            if last is not None and st.around == r - 1:  # no rule: the box of the hits
                words = words.replace("inside the best rule", "around the designs meeting it")
                words = words.replace("inside and around the rules", "around the designs "
                                      "meeting the target")  # fmt: skip
            if how is at_random and str(st.mine_target) != str(self.problem.target):
                # designs may meet the target itself: none did with panels that fold clear
                words = " at random (none met the target with thick panels that do not overlap yet)"
            of = f"{r}/{s.rounds}" if s.rounds is not None else f"{r}"
            self.say(f"[refine] round {of}: {s.refine} new designs{words}")
            res = self._simulate(new.designs, self.dbf / f"refine-{r}-{new.key}")
            st.table = pd.concat([st.table, res.assign(origin=f"refine-{r}")], ignore_index=True)

    def mine(self, r: int) -> list | bool:
        """Rules for the target from every design so far: the rules to verify, or True to go
        on to the next round without any, False to stop."""
        s, st, say, tgt = self.settings, self.state, self.say, self.state.mine_target
        with self._timed("mine"):
            ok = st.table.loc[~failed_rows(st.table)]
            hits = int(tgt.evaluate(ok).sum()) if len(ok) else 0
            if hits in (0, len(ok)):  # nothing to tell apart: no rule to mine
                return self._nothing_to_mine(r, ok, hits)
            say(f"[mine] round {r}: rules for {tgt} from {len(st.table)} designs")
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", FewRulesWarning)
                    mined = mine_rules(st.table, tgt, roles=self.roles, seed=s.seed,
                                       n_rules=s.top, max_overlap=0.5,
                                       source=str(self.dbf))  # fmt: skip
            except OneClassSplit:  # a few hits, all held out: look around them, as with no rule
                note = f"no rule yet ({self._met(ok, hits)}: too few to mine)"
                st.history.append(Round(r, len(ok), len(st.table) - len(ok), hits, (), note))
                if not self.more(r):
                    say(f"  round {r}: {note}")
                    return False
                st.boxes, st.around = [_box_of(ok.loc[tgt.evaluate(ok)], self.roles)], r
                say(f"  round {r}: {note}; the next round samples around them")
                return True
            records = mined_rules(mined.miner, mined.test_scores)[: s.top]
            st.miners[r] = mined
            if records:
                self._round_dir(r).mkdir(parents=True, exist_ok=True)
                write_rules(self._round_dir(r) / "rules.json", records, self.sc.columns)
        return records or self._no_rule(r, mined)

    def _met(self, ok: pd.DataFrame, hits: int, what: str = "designs") -> str:
        """'k of n designs meet the target', and when rules are mined for the target with
        buildable panels, how many meet the target itself: the two counts, never one for
        the other."""
        st, target = self.state, self.problem.target
        if str(st.mine_target) == str(target) or not len(ok):
            return f"{hits} of {len(ok)} {what} meet the target"
        raw = int(target.evaluate(ok).sum())
        return (
            f"{raw} of {len(ok)} {what} meet the target, {hits} of them with thick panels "
            "that do not overlap"
        )

    def _nothing_to_mine(self, r: int, ok: pd.DataFrame, hits: int) -> bool:
        st, n = self.state, len(self.state.table)
        note = f"no rule to mine: {self._met(ok, hits, 'simulated designs')}" + (
            ", all of them" if hits else ""
        )
        look = hits == 0 and self.more(r) and 0 < len(ok) and n < RANDOM_UP_TO
        if look:  # a rare target: keep looking
            note += "; the next round samples more at random"
        elif hits == 0 and n >= RANDOM_UP_TO:
            note += (
                f" (fewer than 3 in {n:,} at 95 % confidence): no more rounds; "
                "loosen the target or widen the feature ranges"
            )
        self.say(f"[mine] round {r}: {note}")
        st.history.append(Round(r, len(ok), n - len(ok), hits, (), note))
        return look

    def _no_rule(self, r: int, mined) -> bool:
        rows, failed, hits = int(len(mined.table)), int(mined.n_failed), int(mined.meets.sum())
        ok = mined.table  # the rows mined: failed ones already left out
        if hits and self.more(r):  # a rare target: refine around the designs that meet it
            self.state.boxes = [_box_of(mined.table.loc[mined.meets], self.roles)]
            self.state.around = r  # the boxes are theirs, not rules
            note = f"no rule yet ({self._met(ok, hits)}); the next round samples around them"
        else:
            note = f"no rule reaches the miner's precision ({self._met(ok, hits)})"
        self.say(f"  round {r}: {note}")
        self.state.history.append(Round(r, rows, failed, hits, (), note))
        return bool(hits)  # nothing to refine around: more rounds would sample the same

    def verify(self, r: int, records: list) -> bool:
        """Fresh designs inside the rules worth it, best first; True when the loop stops."""
        s, st, say = self.settings, self.state, self.say
        with self._timed("verify"):
            checks = self._checks(r, records)
        ranked = [
            VerifiedRule.of(rec, r, None if v is None else v.counts, self.sc.columns)
            for rec, v in zip(records, checks, strict=True)
        ]
        for e in ranked:
            say(
                f"  round {r} rule {e.rank}: {e.text}  (estimate {_fmt(e.estimate)}, held-out "
                f"{_fmt(e.test_precision)}, verified {_fmt(e.precision)})"
            )
        for i, v in enumerate(checks, start=1):
            if v is not None:
                rows = v.designs.drop(columns="meets_target").assign(origin=f"verify-{r}-{i}")
                st.table = pd.concat([st.table, rows], ignore_index=True)
        mined = st.miners[r]
        st.history.append(Round(r, int(len(mined.table)), int(mined.n_failed),
                                int(mined.meets.sum()), tuple(ranked)))  # fmt: skip
        st.boxes = records
        done = [e for e in ranked if e.verified is not None and rule_verified(e.verified)]
        if s.until_verified and done and self.more(r):
            say(f"  round {r}: rule {done[0].rank} is verified; no more rounds")
            return True
        stalled = self._stalled(r)
        if stalled and self.more(r):
            say(f"  round {r}: {stalled}; no more rounds")
            st.stalled = stalled
            return True
        if not done and not self.more(r) and (s.rounds is None or r < s.rounds):
            say(f"  round {r}: the budget of {s.budget:,} simulations leaves no room for a round")
        return False

    def _stalled(self, r: int) -> str:
        """Why the search stops for want of progress ("" to go on): a rule has been verified,
        and the best 95 % lower bound of a verified rule has not risen in the last
        ``patience`` rounds."""
        s, hist = self.settings, self.state.history
        if s.patience is None or not s.until_verified:
            return ""
        best, since, where = -1.0, None, None
        for h in hist:
            for e in h.rules:
                lo = None if e.interval is None else e.interval[0]
                if lo is not None and lo > best + 1e-12:
                    best, since, where = lo, h.index, e
        if where is None or r - since < s.patience:
            return ""
        return (
            f"the best verified rule ({where.label}: {_fmt(where.precision)} verified, 95 % "
            f"interval from {_fmt(best)}) has not improved in {r - since} rounds (--patience "
            f"{s.patience}); the target may lie at the edge of what these designs reach"
        )

    def _checks(self, r: int, records: list) -> list:
        """Each rule's verification (None: not verified), within the budget."""
        s, st = self.settings, self.state
        worth = _worth_verifying(records, last=not self.more(r))
        self.say(f"[verify] round {r}: {len(worth)} of {len(records)} rule(s) (estimate >= "
                 f"{VERIFY_FROM}), {s.verify} fresh designs each")  # fmt: skip
        checks: list = [None] * len(records)
        for i in worth:  # best lower estimate first; the first verified rule ends the round
            spent = len(st.table) - st.free + sum(len(v.designs) for v in checks if v)
            if spent + s.verify > s.budget:
                self.say(f"  round {r}: the budget of simulations leaves no room to verify more")
                break
            vdir = self._round_dir(r) / "verify" / f"rule{i + 1}-{rule_key(records[i])}"
            checks[i] = verify_rule(self.sc, records[i], st.mine_target, s.verify,
                                    seed=s.seed + 100 * r + i + 1, folder=vdir,
                                    **self.execution.runner())  # fmt: skip
            st.used.update(p.parent.resolve() for p in vdir.rglob("designs.parquet"))
            if s.until_verified and rule_verified(checks[i].counts):
                break
        return checks

    # ------------------------------------------------------------------ 5. choose
    def choose(self) -> tuple[Answer, pd.DataFrame]:
        """From everything simulated in the folder (earlier runs too): the answer and the
        table it indexes."""
        p, st, say = self.problem, self.state, self.say
        with self._timed("choose"):
            earlier = _earlier_rows(self.sc, [self.dbf, self.out / "rounds"], st.used)
            everything = st.table
            if earlier is not None:
                everything = pd.concat([st.table, earlier], ignore_index=True)
                say(f"[choose] {len(earlier)} designs simulated by earlier runs in {self.out} "
                    "join the candidates")  # fmt: skip
            buildable = ", thick panels not overlapping" if p.buildable else ""
            say(f"[choose] {p.objective.words}{buildable}")
            rules = [r for h in st.history for r in h.rules]
            answer = choose(everything, p.target, p.objective, rules,
                            allow_overlap=p.allow_overlap)  # fmt: skip
            everything = everything.reset_index(drop=True)
        say(f"  {answer.headline}")
        return answer, everything

    # ------------------------------------------------------------------ 6. files
    def write(self, answer: Answer, everything: pd.DataFrame, ledger: _Ledger) -> DesignOutcome:
        """``design.json``, ``designs.parquet``, the chosen design's files and the report."""
        p, st, sc, out = self.problem, self.state, self.sc, self.out
        pick = partial(_pick, sc, everything, tgt=p.target)
        summary = DesignSummary(
            scenario=_scenario_summary(sc),
            target=str(p.target),
            mined_target=str(st.mine_target),
            objective=str(p.objective),
            allow_overlap=p.allow_overlap,
            answer=answer.kind,
            headline=_headline(answer, st.pilot, st.stalled),
            chosen=pick(answer.chosen),
            alternatives=tuple(pick(c) for c in answer.alternatives),
            rounds=tuple(st.history),
            database=_counts(everything, self.dbf, out),
            pilot=st.pilot,
            distributions=tuple(distributions(everything, _target_columns(sc, p.target,
                                                                          p.objective))),
        )  # fmt: skip
        write_table(everything, out / "designs.parquet")
        if self.output.files and answer.chosen is not None:
            with self._timed("files"):
                summary = self._files(summary, answer, everything)
        summary = _replace(summary, timings=ledger.timings(st.times))
        write_json(out / "design.json", summary.to_json())
        ledger.append(st.times)
        if self.output.files:
            from holofold.design.report.page import write_report_page

            write_report_page(out, summary)
        _check_own_summary(out, summary.to_json())
        _say_chosen(self.say, summary, p.target, out, sc.columns)
        if summary.fabrication is not None:
            self.say(f"part: {summary.fabrication.line()}")
        return DesignOutcome(summary, everything, out)

    def _files(self, summary: DesignSummary, answer: Answer, everything) -> DesignSummary:
        sc, f = self.sc, self.output
        what = (
            "fabrication files, "
            if sc.write_files is not None
            else f"(no fabrication files for scenario {sc.name!r}) "
        )
        self.say(f"[files] {what}pictures, 3D view and report.html")
        row = everything.loc[answer.chosen.label]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            extra = _write_files(sc, row, self.out, answer.chosen.rule, self.state.miners,
                                 everything, self.problem.target, f.mesh_units, self.problem.bed,
                                 answer.chosen, f.cutter)  # fmt: skip
        notes = list(dict.fromkeys(str(w.message) for w in caught))
        for w in notes:
            self.say(f"  note: {w}")
        return _replace(summary, warnings=tuple(notes), **extra)


def _pilot_info(table: pd.DataFrame, tgt, budget: int, say) -> dict:
    """The pilot's verdict for the summary (and the line saying why it stops the run, or that
    a target none of its designs meets is rare, not out of reach)."""
    hits, unmet, stop = _pilot_verdict(table, tgt, budget)
    if stop is not None:
        say(f"  pilot: {stop} ({len(table)} designs); stopping before the rest")
    elif not hits and len(table):
        say(f"  pilot: none of {len(table)} designs meets the target, but it is not out of reach "
            "(rare: the run goes on)")  # fmt: skip
    return {
        "rows": int(len(table)),
        "meeting": hits,
        "stopped": stop is not None,
        "reason": stop or "",
        "unmet": unmet,
    }


def _headline(answer: Answer, pilot: Mapping | None, stalled: str = "") -> str:
    """The answer's sentence, after why the run stopped if its pilot stopped it or its search
    made no progress."""
    if stalled:
        return f"The search stopped early: {stalled}. {answer.headline}"
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
    below = "" if c.rule is None or c.rule.meets_bar else f" (below the {RULE_BAR[0]:g} bar)"
    feats = ", ".join(f"{k} = {_shown(columns, k, v)}" for k, v in c.features.items())
    perf = ", ".join(f"{k} = {_shown(columns, k, c.performance.get(k))}" for k in tgt.columns)
    state = "meets the target" if c.meets else "does NOT meet the target (nearest)"
    fab = summary.fabrication
    if c.meets and fab is not None and not (fab.film or fab.fits or fab.pieces):
        # the part line below says why; a bare 'meets the target' contradicted it
        state += f", but its part cannot be printed on the {fab.bed_text} bed"
    say(
        f"chosen: {feats}\n  {perf}; {state}; worst margin {c.worst_margin:.3g}; answer "
        f"{summary.answer!r}; rule verified precision {_fmt(vp)}{below}; files in {out}/"
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


def rule_verified(counts) -> bool:
    """A rule is verified: at least 90 % of its fresh designs met the target and the lower end
    of their 95 % Wilson interval is at least 0.8 (``counts``: a verification's ``Counts``)."""
    p, ci = counts.precision, counts.interval
    return p is not None and p >= RULE_BAR[0] and ci[0] >= RULE_BAR[1]


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
                **({"names": list(c.names)} if c.names else {}),
            }
            for c in sc.features
        ],
        "performance": [
            {
                "name": c.name,
                "unit": c.unit,
                "display_unit": c.display_unit,
                "description": c.description,
                **({"choices": list(c.choices), "names": list(c.names)} if c.names else {}),
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
    from holofold.design.rules.report import (
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
