"""What the design loop is asked, how it searches, how it runs and what it writes: four frozen,
validated records passed whole to :func:`~holofold.design.loop.design_loop.run_design`.

- :class:`DesignProblem`: the scenario, the target, the objective, the printer's bed and
  whether a design whose thick panels overlap may be chosen (what the user asks);
- :class:`LoopSettings`: samples, budget, refinement, verification, strategy, pilot, rounds
  (how the loop searches);
- :class:`Execution`: worker processes, Dask scheduler, progress bars, row timeout and the line
  printer ``say`` (how it runs; never changes a result);
- :class:`DesignFiles`: the database folder, whether files are written, their length unit and
  the cutter's drawing (what it writes).

Each record checks itself when made and refuses a bad value with one ``ValueError`` line naming
it. :func:`split_options` sorts the loop's old keyword arguments (``samples=``, ``workers=``,
...) into the records, so both call styles give the same records.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace

from holofold.design.database.row_limits import resolve_row_timeout
from holofold.design.database.runner import check_scheduler, check_workers
from holofold.design.database.sampling import MAX_SAMPLES
from holofold.design.loop.buildability import DEFAULT_BED, Bed, parse_bed
from holofold.design.loop.objective import Objective, parse_objective
from holofold.design.loop.strategies import STRATEGIES
from holofold.design.report.describe import PILOT
from holofold.design.rules.targets import Target, parse_target
from holofold.design.scenarios import Scenario, load_scenario
from holofold.geometry.units import length_factor

__all__ = ["DesignProblem", "LoopSettings", "Execution", "DesignFiles", "split_options", "made"]


def _quiet(text: str) -> None:
    """The default ``say``: no progress lines."""


@dataclass(frozen=True)
class DesignProblem:
    """What the designer asks.

    Attributes
    ----------
    scenario : Scenario (a name or a ``.toml`` path is loaded)
    target : Target (an expression over the scenario's performance columns is parsed)
    objective : Objective ("margin", "min COLUMN", "max COLUMN" or None are parsed)
    bed : Bed ("WxD" in mm or (x, y) in m are parsed; None: the scenario's ``bed`` if it
        has one, else :data:`~holofold.design.DEFAULT_BED`)
    allow_overlap : bool
        Let a design whose thick panels overlap be chosen (never by default).
    """

    scenario: Scenario | str | os.PathLike
    target: Target | str
    objective: Objective | str | None = None
    bed: Bed | str | tuple | None = DEFAULT_BED
    allow_overlap: bool = False

    def __post_init__(self):
        sc = load_scenario(self.scenario)
        text = self.target.expression if isinstance(self.target, Target) else self.target
        put = object.__setattr__
        put(self, "scenario", sc)
        put(self, "target", parse_target(text, sc.performance_names))
        put(self, "objective", parse_objective(self.objective, [*sc.performance_names,
                                                                *sc.feature_names]))  # fmt: skip
        bed = self.bed if self.bed is not None else getattr(sc, "bed", None) or DEFAULT_BED
        put(self, "bed", parse_bed(bed))
        put(self, "allow_overlap", bool(self.allow_overlap))

    @property
    def buildable(self) -> bool:
        """Rules are mined and verified for the target with panels that do not overlap (the
        choice keeps to them too): the kind computes ``overlap``, the target does not name it
        and overlapping designs are not allowed."""
        sc, tgt = self.scenario, self.target
        return (
            "overlap" in sc.performance_names
            and not self.allow_overlap
            and ("overlap" not in tgt.columns)
        )


@dataclass(frozen=True)
class LoopSettings:
    """How the loop searches (docs/scenarios.md §9; :func:`~holofold.design.run_design`).

    Attributes
    ----------
    samples : int
        Designs in the base database (>= 20).
    rounds : int or None
        Refinement rounds at most (0: mine once; None: as many as ``budget`` allows).
    budget : int
        Simulations the run may spend at most (>= samples + verify).
    refine : int
        New designs per refinement round.
    verify : int
        Fresh designs simulated per verified rule and round.
    top : int
        Rules kept per round.
    strategy : str
        Where a refinement round samples: a name of :data:`~holofold.design.STRATEGIES`.
    until_verified : bool
        Stop once a rule is verified.
    pilot : int
        Designs simulated first (0: no pilot).
    patience : int or None
        Refinement rounds without progress after which the run stops with the best design:
        once a rule has been verified (at any precision), rounds in which the best verified
        rule's 95 % lower bound did not rise (None: never stop for that).
    seed : int
    """

    samples: int = 200
    rounds: int | None = None
    budget: int = 6000
    refine: int = 50
    verify: int = 50
    top: int = 3
    strategy: str = "mixed"
    until_verified: bool = True
    pilot: int = PILOT
    patience: int | None = 4
    seed: int = 0

    def __post_init__(self):
        for name, v, low in (
            ("samples", self.samples, 20),
            ("rounds", 0 if self.rounds is None else self.rounds, 0),
            ("verify", self.verify, 1),
            ("top", self.top, 1),
            ("refine", self.refine, 1 if self.rounds != 0 else 0),
            ("budget", self.budget, 1),
            ("pilot", self.pilot, 0),
            ("patience", 1 if self.patience is None else self.patience, 1),
        ):
            if isinstance(v, bool) or int(v) != v or v < low:
                raise ValueError(f"{name} = {v!r} must be an integer >= {low}")
        if self.strategy not in STRATEGIES:
            raise ValueError(
                f"strategy = {self.strategy!r} must be one of {', '.join(map(repr, STRATEGIES))}"
            )
        if self.budget > MAX_SAMPLES:
            raise ValueError(
                f"budget = {self.budget:,} simulations; at most {MAX_SAMPLES:,} in one run"
            )
        if self.budget < self.samples + self.verify:
            raise ValueError(
                f"budget = {self.budget:,} simulations cannot hold the {self.samples:,} designs "
                f"of the database and one verification of {self.verify:,} (at least "
                f"{self.samples + self.verify:,})"
            )


@dataclass(frozen=True)
class Execution:
    """How the loop runs: never changes what it finds.

    Attributes
    ----------
    workers : int
        Worker processes for the simulations (-1: every core).
    progress : bool or None
        Progress bars (None: when the output is a terminal).
    scheduler : str or None
        A Dask scheduler address (:func:`~holofold.design.build_database`).
    row_timeout : float, str or None
        Seconds one row may take (:func:`~holofold.design.build_database`).
    say : callable(str)
        Receives one line of progress per stage.
    """

    workers: int = 1
    progress: bool | None = None
    scheduler: str | None = None
    row_timeout: float | str | None = None
    say: Callable[[str], None] = field(default=_quiet, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "workers", check_workers(self.workers))
        if self.scheduler is not None:
            object.__setattr__(self, "scheduler", check_scheduler(self.scheduler))
        if self.row_timeout is not None:
            resolve_row_timeout(None, self.row_timeout)  # refuses a bad limit in one line

    def runner(self) -> dict:
        """The keyword arguments of :func:`~holofold.design.build_database` and
        :func:`~holofold.design.verify_rule` that say how to run."""
        out = {"workers": self.workers, "progress": self.progress}
        if self.scheduler is not None:
            out["scheduler"] = self.scheduler
        if self.row_timeout is not None:
            out["row_timeout"] = self.row_timeout
        return out


@dataclass(frozen=True)
class DesignFiles:
    """What the loop writes besides ``design.json`` and ``designs.parquet``.

    Attributes
    ----------
    db : path or None
        Database folder to use instead of ``folder/database`` (a ``holofold generate`` folder
        gives all its rows).
    files : bool
        Write the chosen design's fabrication files, pictures and the report page.
    mesh_units : {"mm", "m"}
        Length unit of the mesh files (STL, OBJ).
    cutter : CutterOptions or None
        How the SVG and DXF of the flat pattern are drawn.
    """

    db: str | os.PathLike | None = None
    files: bool = True
    mesh_units: str = "mm"
    cutter: object = None

    def __post_init__(self):
        length_factor(self.mesh_units)


_RECORDS = (DesignProblem, LoopSettings, Execution, DesignFiles)


def split_options(options: Mapping) -> dict[type, dict]:
    """Sort keyword ``options`` by the record whose field they name: record class -> its
    fields among them. An unknown name raises ``TypeError``."""
    owner = {f.name: cls for cls in _RECORDS for f in fields(cls)}
    out: dict[type, dict] = {cls: {} for cls in _RECORDS}
    for name, value in options.items():
        if name not in owner:
            raise TypeError(f"run_design() got an unexpected keyword argument {name!r}")
        out[owner[name]][name] = value
    return out


def made(cls, given, changes: Mapping):
    """``given`` with ``changes`` (a new record of ``cls`` when ``given`` is None)."""
    if given is None:
        return cls(**changes)
    if not isinstance(given, cls):
        raise TypeError(f"expected a {cls.__name__}, got {type(given).__name__}")
    return replace(given, **changes) if changes else given
