"""The registry of scenario-file kinds: ``kind = "strip"``, ``"sheet"``, ``"gripper"``,
``"pattern"``, ``"surface"`` and any kind another package adds.

A kind is a :class:`ScenarioKind`: a name, one line of description and
``from_config(doc, name, description) -> Scenario``, which reads the file's tables through
:class:`~holofold.design.scenarios.config.Section` (refusing every problem in one line) and
returns the :class:`~holofold.design.scenarios.base.Scenario`. :func:`read_scenario` looks the
file's ``kind`` up here.

Built-in kinds are named by module (imported only when used). Other packages add kinds in two
ways:

* an entry point in the group :data:`ENTRY_POINT_GROUP` (``holofold.scenario_kinds``) whose name
  is the kind and whose object is a :class:`ScenarioKind` or a module with ``from_config``
  (and an optional ``DESCRIPTION``); in a ``pyproject.toml``::

      [project.entry-points."holofold.scenario_kinds"]
      surface = "mypackage.surface_kind:KIND"

* :func:`register_kind` at run time (a script, a test).

A kind's name is what users write in their files; a name taken by a built-in kind cannot be
taken again.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType

from holofold.geometry import Registry

__all__ = [
    "ScenarioKind",
    "ENTRY_POINT_GROUP",
    "KINDS",
    "BUILTIN_KINDS",
    "scenario_kinds",
    "get_kind",
    "kind_names",
    "register_kind",
]

#: the entry-point group other packages add scenario kinds in
ENTRY_POINT_GROUP = "holofold.scenario_kinds"


@dataclass(frozen=True)
class ScenarioKind:
    """One kind of scenario file.

    Attributes
    ----------
    name : str
        What a file's ``kind`` says.
    description : str
        One line for listings.
    from_config : callable(doc, name, description) -> Scenario
        Reads the file (``doc`` a :class:`~holofold.design.scenarios.config.Section` of the
        top level; the caller refuses unknown top-level keys afterwards).
    """

    name: str
    description: str
    from_config: Callable


#: built-in kind -> (module with ``from_config``, description)
BUILTIN_KINDS = {
    "strip": ("holofold.design.scenarios.strip", "a Miura strip over any planar curve"),
    "sheet": ("holofold.design.scenarios.sheet", "Miura-ori and TMP sheets of any footprint"),
    "gripper": (
        "holofold.design.scenarios.gripper_kind",
        "the electro-thermal grippers with your material",
    ),
    "pattern": (
        "holofold.design.scenarios.pattern_kind",
        "any crease pattern file (FOLD, SVG, DXF, ORIPA), folded, then loaded",
    ),
    "surface": (
        "holofold.design.scenarios.surface_kind",
        "a generalised Miura-ori fitted to a target surface, folded, then loaded",
    ),
}


def _from_module(name: str, module: ModuleType, description: str | None = None) -> ScenarioKind:
    if not callable(getattr(module, "from_config", None)):
        raise TypeError(f"scenario kind {name!r}: module {module.__name__} has no from_config")
    text = description or getattr(module, "DESCRIPTION", "") or ""
    return ScenarioKind(name, text, module.from_config)


def _as_kind(name: str, obj) -> ScenarioKind:
    if isinstance(obj, ScenarioKind):
        return obj
    if isinstance(obj, ModuleType):
        return _from_module(name, obj)
    if callable(obj):
        return ScenarioKind(name, getattr(obj, "__doc__", "") or "", obj)
    raise TypeError(
        f"scenario kind {name!r}: expected a ScenarioKind, a module with from_config or a "
        f"function, got {type(obj).__name__}"
    )


def _check_kind(name, obj) -> ScenarioKind:
    if not name or not str(name).replace("-", "_").isidentifier():
        raise ValueError(f"scenario kind name {name!r} must be a word such as 'surface'")
    return _as_kind(name, obj)


def _builtin(name: str, module: str, text: str):
    return lambda: _from_module(name, importlib.import_module(module), text)


#: name -> kind (a :class:`~holofold.geometry.Registry`: built-in kinds imported when used,
#: registered ones, then plug-ins of :data:`ENTRY_POINT_GROUP`)
KINDS: Registry[ScenarioKind] = Registry(
    "scenario kind", group=ENTRY_POINT_GROUP, check=_check_kind, error=KeyError
)
for _name, (_module, _text) in BUILTIN_KINDS.items():
    KINDS.register_lazy(_name, _builtin(_name, _module, _text))


def kind_names() -> tuple[str, ...]:
    """Every kind a file may name: built-in, registered, then from entry points."""
    return KINDS.names()


def get_kind(name: str) -> ScenarioKind:
    """The kind called ``name`` (raises ``KeyError`` naming the known kinds)."""
    return KINDS[name]


def scenario_kinds() -> dict[str, ScenarioKind]:
    """name -> kind of every kind that loads (a plug-in that fails to load is left out)."""
    return KINDS.loaded()


def register_kind(
    kind: ScenarioKind | ModuleType, name: str | None = None, *, replace: bool = False
) -> ScenarioKind:
    """Add a kind at run time (a :class:`ScenarioKind`, or a module with ``from_config``
    registered under ``name``); returns it. A built-in name cannot be replaced, a registered
    one only with ``replace=True``."""
    if isinstance(kind, ModuleType):
        if not name:
            raise ValueError("register_kind(module, name): give the kind's name")
        kind = _from_module(name, kind)
    elif not isinstance(kind, ScenarioKind):
        raise TypeError(f"expected a ScenarioKind or a module, got {type(kind).__name__}")
    return KINDS.register(kind, replace=replace)
