"""Scenario files: a designer's own problem in TOML, and the paper's problems shipped as such.

docs/scenarios.md §8. A file names its ``kind`` (``strip``, ``sheet``, ``gripper`` or one of
:mod:`~holofold.design.scenarios.kinds`, where other packages add theirs), the
fixed setting (curve, material, supports, loads) and the design features with their ranges or
choices. It is parsed with :mod:`tomllib` and never executed; every problem (an unknown key, a
range with low >= high, a missing file, an unknown unit, a load outside the curve) is refused
with one line naming the file, the table and the key, before anything is simulated.

:func:`load_scenario` is what every command calls: a :class:`Scenario` is returned as is, a
path to a ``.toml`` file is read, and a name is one of the paper's scenarios.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import replace
from pathlib import Path

from holofold.design.scenarios.base import Scenario
from holofold.design.scenarios.config import ScenarioFileError, Section
from holofold.design.scenarios.kinds import get_kind, kind_names
from holofold.design.scenarios.paper import get_scenario
from holofold.geometry.inputs import check_input_file

__all__ = [
    "read_scenario",
    "load_scenario",
    "shipped_scenarios",
    "shipped_text",
    "ScenarioFileError",
]

_SHIPPED = Path(__file__).with_name("shipped")


def read_scenario(path: str | os.PathLike) -> Scenario:
    """The :class:`Scenario` described by a TOML file (relative paths inside are relative to it)."""
    path = Path(path)
    try:
        check_input_file(path, "scenario file")
    except OSError as exc:
        raise ScenarioFileError(str(exc)) from None
    try:
        text = path.read_bytes().decode("utf-8")
    except OSError as exc:
        why = exc.strerror or exc
        raise ScenarioFileError(f"cannot read scenario file {str(path)!r}: {why}") from None
    except UnicodeDecodeError:
        raise ScenarioFileError(f"{path.name}: not a UTF-8 text file") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioFileError(f"{path.name}: not valid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses per level of nested arrays and tables
        raise ScenarioFileError(f"{path.name}: arrays or tables nested too deep") from None
    doc = Section(data, f"{path.name}: top level", path.resolve().parent)
    known = kind_names()
    kind = doc.choice("kind", known)
    if kind is None:
        raise doc.error(f"missing key 'kind'; allowed: {', '.join(known)}")
    name = doc.string("name", path.stem)
    if not name.strip():
        raise doc.error("name must not be empty")
    description = doc.string("description", "")
    bed = doc.string("bed", "")
    if bed:
        from holofold.geometry import Bed

        try:
            Bed.parse(bed)
        except ValueError as exc:
            raise doc.error(str(exc)) from None
    doc.where = f"{path.name}"
    try:
        reader = get_kind(kind)
    except KeyError as exc:  # a plug-in kind that does not load
        raise doc.error(str(exc.args[0])) from None
    scenario = reader.from_config(doc, name, description)
    doc.where = f"{path.name}: top level"
    doc.done()
    return replace(scenario, source=_display_path(path), bed=bed)


def _display_path(path: Path) -> str:
    """How a scenario file is named in reports: a shipped one relative to the package
    (``holofold/design/scenarios/shipped/arch.toml``, the same on every machine), another as
    given."""
    try:
        rel = path.resolve().relative_to(_SHIPPED.resolve())
    except ValueError:
        return str(path)
    return f"holofold/design/scenarios/shipped/{rel.as_posix()}"


def shipped_scenarios() -> dict[str, Path]:
    """Name -> path of the scenario files shipped with holofold (the paper's problems)."""
    return {p.stem: p for p in sorted(_SHIPPED.glob("*.toml"))}


def shipped_text(name: str) -> str:
    """The text of a shipped scenario file, ready to copy and edit."""
    files = shipped_scenarios()
    if name not in files:
        raise ValueError(f"no shipped scenario {name!r}; shipped: {', '.join(files)}")
    return files[name].read_text(encoding="utf-8")


def load_scenario(spec: Scenario | str | os.PathLike) -> Scenario:
    """A scenario from a :class:`Scenario`, a ``.toml`` path or one of the paper's names."""
    if isinstance(spec, Scenario):
        return spec
    s = os.fspath(spec)
    if s.lower().endswith(".toml"):
        return read_scenario(s)
    return get_scenario(s)
