"""A small, declarative description of a design scenario and its evaluator.

A :class:`Scenario` names the feature columns (with units and the paper's sampling ranges), the
categorical features, the performance columns, a physical-validity check and the function that
simulates one design. The runner (:mod:`~holofold.design.database.runner`) and the ``holofold
evaluate``
command work from this description only.

``evaluate(row)`` takes a mapping of feature name -> value (SI units) and returns a dict with one
entry per performance column plus ``status``, a :class:`~holofold.mechanics.status.Status`:
converged, or not converged with what did not converge (the outputs are still those the paper
defines for that case), or failed (no outputs).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import partial

__all__ = [
    "Column",
    "Scenario",
    "single_thread",
    "check_row",
    "ROW_TIMEOUTS",
    "DISPLAY_UNITS",
    "format_value",
    "setting_hooks",
    "paper_scenario",
]

#: SI unit -> the display units it may be shown in, with the factor (display value = SI value x
#: factor). A column's ``display`` must be one of its unit's entries; units not listed here are
#: shown as they are.
DISPLAY_UNITS: dict[str, dict[str, float]] = {
    "m": {"m": 1.0, "mm": 1e3, "um": 1e6},
    "rad": {"rad": 1.0, "deg": 180.0 / math.pi},
    "m^3": {"m^3": 1.0, "cm^3": 1e6, "mm^3": 1e9},
    "kg": {"kg": 1.0, "g": 1e3},
    "Pa": {"Pa": 1.0, "MPa": 1e-6, "GPa": 1e-9},
}


def _default_display(unit: str, low: float | None, high: float | None) -> str:
    """The display unit of a column that names none: degrees for angles; for a length with a
    range, um below 0.1 mm, mm up to 1 m; otherwise the SI unit itself (performance columns
    keep theirs, so values read like the targets written over them)."""
    if unit == "rad":
        return "deg"
    if unit == "m" and low is not None and high is not None:
        top = max(abs(low), abs(high))
        return "um" if top < 1e-4 else "mm" if top <= 1.0 else "m"
    return unit


def format_value(value: float, column: Column | None = None, *, digits: int = 3) -> str:
    """One value (SI) as people read it: in the column's display unit, labelled.

    ``format_value(7.792e-4, tcrease)`` is ``"0.779 mm"``; ``digits`` significant digits; a
    unitless column (``"-"``) or no column gives the number alone; infinite values read
    ``inf``. The one formatting function for values and thresholds in text, pages and charts.
    """
    v = float(value)
    if column is None:
        return _number(v, digits)
    shown = _number(v * column.display_factor, digits)
    unit = column.display_unit
    return shown if unit in ("", "-") else f"{shown} {unit}"


def single_thread():
    """Context manager limiting BLAS/OpenMP to one thread: :func:`holofold.mechanics.single_thread`
    (re-entrant, cheap when nested). Every scenario's ``evaluate`` and every solver already run
    inside it, so a script that calls them directly is as fast as the runner."""
    from holofold.mechanics.threads import single_thread as limit

    return limit()


#: default time limit per row (s) by scenario ``kind`` (measured on 20 warm rows of each
#: built-in scenario: slowest 0.02 s single Miura, 0.19 s arch, 1.3 s canopy, 2.3 s gripper of
#: 6): over 100x the slowest row and at least 60 s, 4-7x the first row of a process whose numba
#: kernels are compiled rather than loaded from their cache (9-13 s); docs/scenarios.md §1.3
ROW_TIMEOUTS = {"": 60.0, "strip": 60.0, "sheet": 300.0, "gripper": 120.0}


def _number(v: float, digits: int) -> str:
    """``digits`` significant digits, without an exponent from 1e-4 up to 1e6 (6000, not
    6e+03)."""
    text = f"{v:.{digits}g}"
    r = float(text)
    if math.isfinite(r) and 10**digits <= abs(r) < 1e6:
        return f"{r:.0f}"
    return text


@dataclass(frozen=True)
class Column:
    """One feature or performance column.

    Attributes
    ----------
    name : str
        Column name as in the published ``*_FeatureName.txt``.
    unit : str
        SI unit ("m", "rad", "Pa", "N/m", "-").
    description : str
        One line.
    low, high : float or None
        The paper's sampling range (features only); values outside merely warn.
    choices : tuple of float, optional
        Allowed values of a categorical feature (values outside warn, or fail if ``strict``).
    required : bool
        False for optional features (with ``default``).
    default : float or None
        Value used when an optional feature is missing.
    display : str
        The unit people read the column in (rules, designs, reports): one of
        :data:`DISPLAY_UNITS` of ``unit`` ("mm" for a thickness in "m", "deg" for "rad");
        ``""``: derived from the unit and range (``display_unit``). Values stay SI everywhere
        else.
    """

    name: str
    unit: str
    description: str = ""
    low: float | None = None
    high: float | None = None
    choices: tuple[float, ...] = ()
    required: bool = True
    default: float | None = None
    display: str = ""
    names: tuple[str, ...] = ()

    def level_name(self, value) -> str:
        """The name of a categorical level (``names`` aligned with ``choices``), or ""."""
        for c, n in zip(self.choices, self.names, strict=False):
            if float(c) == float(value):
                return n
        return ""

    def __post_init__(self):
        if self.names and len(self.names) != len(self.choices):
            raise ValueError(
                f"column {self.name!r}: {len(self.names)} names for {len(self.choices)} choices"
            )
        if self.display and self.display != self.unit:
            allowed = DISPLAY_UNITS.get(self.unit, {self.unit: 1.0})
            if self.display not in allowed:
                raise ValueError(
                    f"column {self.name!r}: display unit {self.display!r} is not one of "
                    f"{', '.join(allowed)} (unit {self.unit!r})"
                )

    @property
    def display_unit(self) -> str:
        """The unit the column is shown in (``display``, or derived from unit and range)."""
        return self.display or _default_display(self.unit, self.low, self.high)

    @property
    def display_factor(self) -> float:
        """Display value per SI value (1e3 for m shown in mm)."""
        return DISPLAY_UNITS.get(self.unit, {}).get(self.display_unit, 1.0)

    def to_display(self, value):
        """``value`` (SI, a number or an array) in the display unit."""
        return value * self.display_factor

    def from_display(self, value):
        """``value`` given in the display unit, in SI."""
        return value / self.display_factor

    def format(self, value: float, digits: int = 3) -> str:
        """:func:`format_value` of ``value`` (SI) in this column's display unit; a named
        categorical level with its name (``1 (offset)``)."""
        text = format_value(value, self, digits=digits)
        try:
            name = self.level_name(value) if self.names else ""
        except (TypeError, ValueError):
            name = ""
        return f"{text} ({name})" if name else text

    def out_of_range(self, value: float) -> str | None:
        """A warning text if ``value`` is outside the paper's sampling range, else None."""
        if self.choices:
            if not any(math.isclose(value, c, rel_tol=0, abs_tol=1e-12) for c in self.choices):
                allowed = ", ".join(f"{c:g}" for c in self.choices)
                return f"{self.name} = {value:g} is not one of the paper's values ({allowed})"
            return None
        if self.low is not None and self.high is not None and not (self.low <= value <= self.high):
            return (
                f"{self.name} = {value:g} {self.unit} is outside the paper's sampling range "
                f"[{self.low:g}, {self.high:g}]"
            )
        return None


@dataclass(frozen=True)
class Scenario:
    """A design scenario of the paper.

    Attributes
    ----------
    name : str
        Command-line name (``single-miura``, ``canopy``, ``arch``).
    description : str
        One paragraph.
    features : tuple of Column
        Feature columns in the published order (optional ones last).
    performance : tuple of Column
        Performance (output) columns in the published order.
    categorical : tuple of str
        Names of the categorical features.
    check : callable(row) -> list of str
        Physical validity problems of one row (empty list if valid); run before any
        simulation.
    evaluate : callable(row) -> dict
        Simulates one row; returns every performance column and ``status``. The scenario
        wraps it so that every call validates the row first (:func:`check_row`: missing,
        non-numeric or non-finite features, an angle above 2 pi rad, then ``check``), raising
        one ValueError, and so that a non-finite output is never ``converged``.
    kind : str
        ``"strip"``, ``"sheet"`` or ``"gripper"`` for scenarios of those kinds (docs/scenarios.md
        §8), else ``""``.
    setting : mapping
        The fixed setting in words and numbers (curve, material, supports, loads), for reports.
    source : str
        The scenario file it was read from, or ``""``.
    shape : callable(row) -> CreasePattern, optional
        The design's stress-free folded pattern (for pictures and files).
    write_files : callable(row, folder, units="mm", cutter=None) -> FabricationSet, optional
        Writes the design's fabrication files into ``folder`` (meshes in ``units``, the SVG and
        DXF drawn for ``cutter``, a :class:`~holofold.geometry.CutterOptions`); returns the
        :class:`~holofold.geometry.FabricationSet` (files under stable keys with labels).
    view : callable(row) -> DesignView, optional
        The design to look at in 3D, flat to folded, with supports, loads and the target
        (:class:`holofold.design.report.view.DesignView`).
    part : callable(row) -> PrintablePart, optional
        The part the design prints (its flat pattern, panel and hinge thicknesses, hinge
        width; :class:`holofold.design.loop.buildability.PrintablePart`), cut into bed-sized pieces
        when it is larger than the printer's bed.
    evaluate_batch : callable(rows) -> list of dict, optional
        Simulates several rows with the same ``batch_key`` together (their Newton solves in
        lockstep); each output is the one ``evaluate`` gives the row alone. The runner uses it
        for tables of many rows.
    batch_key : callable(row) -> hashable, optional
        Rows with equal keys have models of one size (e.g. the strip's ``m``).
    row_timeout : float, optional
        The runner's default time limit per row, seconds (a row past it is recorded as
        ``failed: timeout ...``; see :mod:`~holofold.design.database.row_limits`); None: the
        default of
        the scenario's ``kind`` (:data:`ROW_TIMEOUTS`).
    bed : str
        The printer's bed of the scenario file's ``bed`` key ("250x210", mm; ``--bed`` wins),
        or ``""`` (the default bed).
    """

    name: str
    description: str
    features: tuple[Column, ...]
    performance: tuple[Column, ...]
    check: Callable[[Mapping[str, float]], list[str]]
    evaluate: Callable[[Mapping[str, float]], dict]
    categorical: tuple[str, ...] = ()
    kind: str = ""
    setting: Mapping = field(default_factory=dict)
    source: str = ""
    shape: Callable | None = None
    write_files: Callable | None = None
    view: Callable | None = None
    part: Callable | None = None
    evaluate_batch: Callable[[list], list] | None = None
    batch_key: Callable[[Mapping[str, float]], object] | None = None
    row_timeout: float | None = None
    bed: str = ""

    def __post_init__(self):
        if self.row_timeout is None:
            object.__setattr__(self, "row_timeout", ROW_TIMEOUTS.get(self.kind, ROW_TIMEOUTS[""]))
        ev = self.evaluate
        if isinstance(ev, partial) and ev.func is _validated_evaluate:
            ev = ev.args[0]  # another scenario's wrapper: validate with this one's checks
        wrapped = partial(_validated_evaluate, ev, self.check, self.features, self.name,
                          tuple(c.name for c in self.performance))  # fmt: skip
        object.__setattr__(self, "evaluate", wrapped)

    @property
    def simulate(self) -> Callable[[Mapping[str, float]], dict]:
        """The evaluator without the row check of :attr:`evaluate`, for callers that checked
        the row already (the runner checks each row once, in
        :func:`~holofold.design.database.runner.validate_designs`, and each output once)."""
        return self.evaluate.args[0]

    @property
    def columns(self) -> dict[str, Column]:
        """name -> :class:`Column` of every feature and performance column (units, display)."""
        return {c.name: c for c in (*self.features, *self.performance)}

    @property
    def feature_names(self) -> list[str]:
        return [c.name for c in self.features]

    @property
    def required_features(self) -> list[str]:
        return [c.name for c in self.features if c.required]

    @property
    def performance_names(self) -> list[str]:
        return [c.name for c in self.performance]

    def complete(self, row: Mapping[str, float]) -> dict[str, float]:
        """The row's features as floats, optional ones filled with their defaults."""
        out = {}
        for c in self.features:
            if c.name in row and row[c.name] is not None and not _is_nan(row[c.name]):
                out[c.name] = float(row[c.name])
            elif not c.required:
                out[c.name] = c.default
            else:
                raise KeyError(c.name)
        return out

    def warnings(self, row: Mapping[str, float]) -> list[str]:
        """Values outside the paper's sampling ranges (informational only)."""
        msgs = []
        for c in self.features:
            v = row.get(c.name)
            if v is None or _is_nan(v):
                continue
            w = c.out_of_range(float(v))
            if w:
                msgs.append(w)
        return msgs


def check_row(features, check, row: Mapping, name: str = "scenario") -> list[str]:
    """Problems of one design row: a missing, non-numeric or non-finite feature, an angle
    (unit rad) above 2 pi (given in degrees?), then the scenario's own ``check``."""
    problems = []
    clean = dict(row)
    for c in features:
        v = row.get(c.name)
        if v is None or (not c.required and _is_nan(v)):
            if c.required:
                problems.append(f"{c.name} is missing")
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) and not hasattr(v, "__float__"):
            problems.append(f"{c.name} = {v!r} is not a number")
            continue
        f = float(v)
        if not math.isfinite(f):
            problems.append(f"{c.name} = {v!r} must be finite")
        elif c.unit == "rad" and abs(f) > 2 * math.pi:
            problems.append(f"{c.name} = {f:g} rad is above 2 pi: give radians, not degrees")
        clean[c.name] = f
    if not problems:
        problems = list(check(clean))
    return problems


def _validated_evaluate(evaluate, check, features, name, performance, row) -> dict:
    problems = check_row(features, check, row, name)
    if problems:
        raise ValueError(f"invalid design for scenario {name!r}: " + "; ".join(problems))
    out = evaluate(row)
    status = out.get("status")
    if status is not None and getattr(status, "converged", False):
        bad = [c for c in performance if not _finite(out.get(c))]
        if bad:
            from holofold.mechanics.status import Status

            out = {**out, "status": Status.not_converged(f"non-finite {', '.join(bad)}")}
    return out


def _finite(v) -> bool:
    try:
        return math.isfinite(float(v))
    except (TypeError, ValueError):
        return False


def _is_nan(v) -> bool:
    try:
        return math.isnan(float(v))
    except (TypeError, ValueError):
        return False


def positive(row: Mapping[str, float], names) -> list[str]:
    """Problems for the named values that are not finite and > 0."""
    out = []
    for n in names:
        v = row.get(n)
        if v is None or not math.isfinite(v) or v <= 0:
            out.append(f"{n} = {v!r} must be a finite value > 0")
    return out


def integer(row: Mapping[str, float], name: str, low: int = 1) -> list[str]:
    """Problems if ``row[name]`` is not an integer >= low."""
    v = row.get(name)
    if v is None or not math.isfinite(v) or v != round(v) or v < low:
        return [f"{name} = {v!r} must be an integer >= {low}"]
    return []


def setting_hooks(setting, shape, write_files, view, part) -> dict:
    """A kind's :class:`Scenario` hooks ``shape``, ``write_files``, ``view`` and ``part``, each
    bound to the scenario's ``setting`` (partials: picklable for worker processes)."""
    return {
        "shape": partial(shape, setting),
        "write_files": partial(write_files, setting),
        "view": partial(view, setting),
        "part": partial(part, setting),
    }


def paper_scenario(kind_scenario: Scenario, name: str, description: str, check, **fields):
    """One of the paper's scenarios on the scenario its kind makes of its setting: that
    scenario's columns, ``evaluate`` and hooks (batch, shape, view, part, files) under the
    paper's ``name``, ``description`` and ``check``; ``fields`` are the other
    :class:`Scenario` fields (``categorical``, ``row_timeout``)."""
    k = kind_scenario
    return Scenario(
        name=name,
        description=description,
        features=k.features,
        performance=k.performance,
        check=check,
        evaluate=k.evaluate,
        evaluate_batch=k.evaluate_batch,
        batch_key=k.batch_key,
        shape=k.shape,
        view=k.view,
        part=k.part,
        write_files=k.write_files,
        **fields,
    )
