"""Reading the tables of a scenario file: checked values, one clear line per problem.

A scenario file (docs/scenarios.md §8) is TOML, parsed with :mod:`tomllib` and never executed.
Each kind (:mod:`~holofold.design.scenarios.strip`, ``sheet``, ``gripper``) reads its tables
with these helpers, so every refusal has the same form::

    my_arch.toml: [load] 2: at = 1.5 is outside [0, 1]

naming the file, the table, the key and the allowed values, before anything is simulated.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from holofold.design.scenarios.base import Column
from holofold.design.scenarios.plausible import MATERIAL, check_lengths, check_plausible

__all__ = [
    "ScenarioFileError",
    "Section",
    "read_features",
    "read_material",
    "read_dofs",
    "read_solver",
    "read_loads",
    "read_direction",
    "load_name",
]


class ScenarioFileError(ValueError):
    """A scenario file that cannot be used (the message names file, table and key)."""


@dataclass
class Section:
    """One table of a scenario file, read key by key; :meth:`done` refuses unknown keys.

    Attributes
    ----------
    data : mapping
        The table as parsed.
    where : str
        ``"file.toml: [table]"``, the prefix of every message.
    base : Path
        Folder of the file (relative paths are relative to it).
    """

    data: Mapping
    where: str
    base: Path
    _used: set | None = None

    def __post_init__(self):
        if not isinstance(self.data, Mapping):
            raise ScenarioFileError(f"{self.where} must be a table, got {self.data!r}")
        self._used = set()

    def error(self, text: str) -> ScenarioFileError:
        return ScenarioFileError(f"{self.where}: {text}")

    def sub(self, key: str, required: bool = False) -> Section:
        """The sub-table ``key`` (an empty one if absent and not ``required``)."""
        if key not in self.data and required:
            raise self.error(f"missing table [{key}]")
        self._used.add(key)
        head = self.where.rsplit(":", 1)[0]
        return Section(self.data.get(key, {}), f"{head}: [{key}]", self.base)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None):
        self._used.add(key)
        return self.data.get(key, default)

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        low: float | None = None,
        high: float | None = None,
        low_open: bool = False,
        integer: bool = False,
    ) -> float | None:
        """A finite number in [low, high] (``(low, ...`` if ``low_open``), or ``default``."""
        self._used.add(key)
        if key not in self.data:
            if default is None:
                return None
            return default
        v = self.data[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise self.error(f"{key} = {v!r} must be a finite number")
        if integer and v != int(v):
            raise self.error(f"{key} = {v!r} must be an integer")
        too_low = low is not None and (v <= low if low_open else v < low)
        if too_low or (high is not None and v > high):
            lo = "(" if low_open else "["
            a = "-inf" if low is None else f"{low:g}"
            b = "inf" if high is None else f"{high:g}"
            rng = f"{lo}{a}, {b}]"
            raise self.error(f"{key} = {v!r} is outside {rng}")
        return int(v) if integer else float(v)

    def choice(self, key: str, allowed: Sequence[str], default: str | None = None) -> str | None:
        """A string among ``allowed`` (or ``default`` if absent)."""
        self._used.add(key)
        if key not in self.data:
            return default
        v = self.data[key]
        if v not in allowed:
            raise self.error(f"{key} = {v!r} is not allowed; allowed: {', '.join(allowed)}")
        return v

    def string(self, key: str, default: str | None = None) -> str | None:
        self._used.add(key)
        v = self.data.get(key, default)
        if v is not None and not isinstance(v, str):
            raise self.error(f"{key} = {v!r} must be a string")
        return v

    def path(self, key: str) -> Path:
        """An existing file named by ``key``, relative to the scenario file's folder."""
        from holofold.geometry.inputs import path_kind

        v = self.string(key)
        file = v.partition("#")[0]
        p = Path(file) if Path(file).is_absolute() else self.base / file
        kind = path_kind(p)
        if kind == "missing":
            raise self.error(f"{key} = {v!r}: no such file {str(p)!r}")
        if kind != "a file":
            raise self.error(f"{key} = {v!r}: {str(p)!r} is {kind}, not a file")
        return p

    def done(self, allowed: Sequence[str] | None = None) -> None:
        """Refuse any key that was not read (naming it and the allowed keys)."""
        unknown = [k for k in self.data if k not in self._used]
        if unknown:
            names = sorted(self._used if allowed is None else allowed)
            raise self.error(f"unknown key {unknown[0]!r}; allowed: {', '.join(names)}")


def read_features(
    section: Section, defaults: Sequence[Column], kind: str | None = None
) -> tuple[Column, ...]:
    """The design features of a ``[features]`` table over the kind's ``defaults``.

    ``name = [low, high]`` sets a continuous range, ``name = {choices = [...]}`` the levels of a
    categorical feature, ``name = value`` fixes it (a range of one value); a feature not named
    keeps its default. Returns the columns in the defaults' order. With ``kind``, the lengths
    given are checked against the kind's physical ranges
    (:mod:`~holofold.design.scenarios.plausible`: metres that look like millimetres are
    refused, naming the values in metres).
    """
    by_name = {c.name: c for c in defaults}
    out = dict(by_name)
    for name, spec in section.data.items():
        if name not in by_name:
            raise section.error(f"unknown feature {name!r}; allowed: {', '.join(by_name)}")
        section._used.add(name)
        base = by_name[name]
        where = f"{name} = {spec!r}"
        if isinstance(spec, Mapping):
            if set(spec) != {"choices"}:
                raise section.error(f"{where}: a table here must be {{choices = [...]}}")
            levels = spec["choices"]
            if (
                not isinstance(levels, list)
                or not levels
                or not all(_finite(v) for v in levels)
                or len(set(levels)) != len(levels)
            ):
                raise section.error(f"{where}: choices must be distinct finite numbers")
            out[name] = replace(base, low=None, high=None, choices=tuple(float(v) for v in levels))
        elif isinstance(spec, list):
            if len(spec) != 2 or not all(_finite(v) for v in spec):
                raise section.error(f"{where}: a range is [low, high] of two finite numbers")
            lo, hi = (float(v) for v in spec)
            if not lo < hi:
                raise section.error(f"{where}: low must be < high (fix a value as {name} = v)")
            if base.choices:
                raise section.error(f"{where}: {name} is categorical; give {{choices = [...]}}")
            out[name] = replace(base, low=lo, high=hi, choices=())
        elif _finite(spec):
            v = float(spec)
            if base.choices:
                out[name] = replace(base, low=None, high=None, choices=(v,))
            else:
                out[name] = replace(base, low=v, high=v, choices=())
        else:
            raise section.error(f"{where}: give [low, high], {{choices = [...]}} or a number")
        if kind is not None:
            c = out[name]
            check_lengths(section, kind, {name: c.choices or sorted({c.low, c.high})})
    return tuple(out[c.name] for c in defaults)


def _finite(v) -> bool:
    return not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v)


def read_material(doc: Section) -> tuple[float, float, float]:
    """``[material]``: E (Pa, > 0), nu (in (-1, 0.5)) and density (kg/m^3, > 0).

    Defaults: the paper's 2 GPa and 0.3, and 1200 kg/m^3.
    """
    mat = doc.sub("material")
    E = mat.number("E", 2e9, low=0.0, low_open=True)
    nu = mat.number("nu", 0.3, low=-1.0, high=0.5, low_open=True)
    if nu == 0.5:
        raise mat.error("nu = 0.5 is outside (-1, 0.5): an incompressible material has no model")
    density = mat.number("density", 1200.0, low=0.0, low_open=True)
    for key, value in (("E", E), ("density", density)):
        check_plausible(mat, key, value, *MATERIAL[key])
    mat.done()
    return E, nu, density


def read_dofs(sec: Section, default: str = "xyz") -> str:
    """``dofs``: the fixed directions of the support nodes, some of ``"xyz"``."""
    dofs = sec.string("dofs", default)
    if not dofs or set(dofs) - set("xyz") or len(set(dofs)) != len(dofs):
        raise sec.error(f"dofs = {dofs!r} must be some of 'x', 'y', 'z' (e.g. 'xyz')")
    return dofs


def read_solver(doc: Section) -> tuple[float, int]:
    """``[solver]``: Newton-Raphson ``tol`` (m, 1e-7) and ``max_iter`` (30, the reference's)."""
    sol = doc.sub("solver")
    tol = sol.number("tol", 1e-7, low=0.0, low_open=True)
    max_iter = sol.number("max_iter", 30, low=2, high=1000, integer=True)
    sol.done()
    return tol, max_iter


def read_loads(doc: Section, read_one) -> list:
    """The ``[[load]]`` tables, each read by ``read_one(section, names_so_far)``; >= 1."""
    raw = doc.raw("load", [])
    if not isinstance(raw, list) or not raw:
        raise doc.error("at least one [[load]] table is needed")
    loads, names = [], set()
    head = doc.where.rsplit(":", 1)[0]
    for k, t in enumerate(raw, start=1):
        ld = read_one(Section(t, f"{head}: [load] {k}", doc.base), names)
        names.add(ld.name)
        loads.append(ld)
    return loads


def load_name(sec: Section, names: set, example: str) -> str:
    """A load's ``name``: a column prefix (an identifier) not used by another load."""
    name = sec.string("name")
    if not name or not name.isidentifier():
        raise sec.error(f"name = {name!r} must be a column prefix such as {example}")
    if name in names:
        raise sec.error(f"name = {name!r} is used by another load")
    return name


def read_direction(sec: Section) -> tuple[float, float, float]:
    """A load's ``direction``: a finite non-zero 3-vector."""
    d = sec.raw("direction")
    if not isinstance(d, list) or len(d) != 3 or not all(_finite(v) for v in d) or not any(d):
        raise sec.error(f"direction = {d!r} must be a non-zero 3-vector [x, y, z]")
    return tuple(float(v) for v in d)
