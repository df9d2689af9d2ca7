"""Pattern families: every crease-pattern generator behind one protocol, in a registry.

A :class:`PatternFamily` is a named generator with its :class:`Parameter` list (name, unit, the
unit people give it in, a range), a ``build`` that checks the values and makes the
:class:`~holofold.geometry.pattern.CreasePattern` (folded, with its flat layout), and named vertex
sets (:mod:`~holofold.geometry.vertex_sets`) for supports and loads. Families with a topology
shared by a whole class of designs (the sheets) also give ``faces(values)`` and
``nodes(values)`` so that models of many designs reuse one topology.

Built in: ``miura`` and ``tmp`` (sheets), ``gripper`` (the paper's three grippers), ``file``
(any crease-pattern file, :func:`~holofold.geometry.readers.read_pattern`), ``curved-pleat``
(:mod:`~holofold.geometry.curved_pleat`). Other layers and
packages add families through the entry-point group :data:`ENTRY_POINT_GROUP`
(``holofold.pattern_families``; holofold's own ``strip``, the Miura strip over a curve, lives in
the fitting layer and comes this way) or :func:`register_family`. ``holofold pattern`` offers
every family of the registry, its options made from the parameters.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import MAX_PANELS, CreasePattern
from holofold.geometry.registry import Registry

__all__ = [
    "Parameter",
    "PatternFamily",
    "ENTRY_POINT_GROUP",
    "FAMILIES",
    "pattern_families",
    "family_names",
    "get_family",
    "register_family",
    "check_panels",
]

#: the entry-point group other packages (and holofold's fitting layer) add families in
ENTRY_POINT_GROUP = "holofold.pattern_families"


@dataclass(frozen=True)
class Parameter:
    """One parameter of a family.

    Attributes
    ----------
    name : str
        Keyword of the family's ``build`` (and the ``--name`` option of ``holofold pattern``).
    unit : str
        SI unit of the value ``build`` receives (``m``, ``rad``, ``-``) or ``text``.
    description : str
    given_in : str
        The unit people give it in (``deg`` for an angle in ``rad``); ``""``: the SI unit.
    low, high : float or None
        Allowed range in ``given_in`` units (inclusive unless ``open_low``/``open_high``).
    required : bool
    integer : bool
    open_low, open_high : bool
    """

    name: str
    unit: str
    description: str
    given_in: str = ""
    low: float | None = None
    high: float | None = None
    required: bool = False
    integer: bool = False
    open_low: bool = False
    open_high: bool = False

    @property
    def factor(self) -> float:
        """SI value per given value (pi/180 for degrees)."""
        return math.pi / 180.0 if self.given_in == "deg" and self.unit == "rad" else 1.0

    def value(self, given, label: str):
        """The SI value of ``given`` (checked against the range), or None."""
        if given is None:
            if self.required:
                raise ParameterError(f"{label} is required ({self.description})")
            return None
        if self.unit == "text":
            return str(given)
        if self.integer:
            if isinstance(given, bool) or int(given) != given:
                raise ParameterError(f"{label} = {given!r} must be an integer")
            v = int(given)
            if self.low is not None and v < self.low:
                raise ParameterError(
                    f"{label} = {given!r} is outside the allowed range [{self.low:g}, inf)"
                )
            return v
        v = check_range(label, given, self.low, self.high, low_open=self.open_low,
                        high_open=self.open_high)  # fmt: skip
        return v * self.factor


@dataclass(frozen=True)
class PatternFamily:
    """A crease-pattern generator (see the module docstring).

    Attributes
    ----------
    name : str
    description : str
    parameters : tuple of Parameter
    build : callable(values: dict, label) -> CreasePattern
        ``values`` SI values by parameter name (None where not given); ``label(name)`` the name
        to use in messages (``--gamma`` at the command line).
    node_sets : mapping of str -> str
        Named vertex sets of the family's patterns (e.g. ``fixed`` and ``loaded``).
    faces : callable(values) -> list of (k,) int, optional
        The topology, from the integer parameters only.
    nodes : callable(values) -> (nv, 3) float, optional
        The folded vertex coordinates of a design, m.
    describe : callable(values) -> str, optional
        A short label of a design (``miura 4x4 at ext 0.6``).
    """

    name: str
    description: str
    parameters: tuple[Parameter, ...]
    build: Callable
    node_sets: Mapping[str, str] = field(default_factory=dict)
    faces: Callable | None = None
    nodes: Callable | None = None
    describe: Callable | None = None

    def values(self, given: Mapping, label: Callable[[str], str] = str) -> dict:
        """SI values of ``given`` (by parameter name), each checked; unknown names refused."""
        known = {p.name for p in self.parameters}
        extra = sorted(k for k, v in given.items() if v is not None and k not in known)
        if extra:
            raise ParameterError(
                f"{self.name} patterns take no {label(extra[0])}; allowed: "
                + ", ".join(label(p.name) for p in self.parameters)
            )
        return {p.name: p.value(given.get(p.name), label(p.name)) for p in self.parameters}

    def make(self, label: Callable[[str], str] = str, **given) -> CreasePattern:
        """The pattern of the given values (in the parameters' ``given_in`` units)."""
        return self.build(self.values(given, label), label)


def check_panels(m: int, n: int, label: Callable[[str], str] = str) -> None:
    """Refuse more than :data:`~holofold.geometry.pattern.MAX_PANELS` panels."""
    if m > 0 and n > 0 and m * n > MAX_PANELS:
        raise ParameterError(
            f"{label('m')} {m} x {label('n')} {n} = {m * n} panels; at most {MAX_PANELS} "
            "(a 100 x 100 sheet takes 2 s; use the Python API for larger ones)"
        )


# ------------------------------------------------------------------ built-in families
_SHEET = (
    Parameter("m", "-", "panels along x", low=1, required=True, integer=True),
    Parameter("n", "-", "panels along y", low=1, required=True, integer=True),
    Parameter(
        "ext", "-", "extension ratio in (0, 1]", low=0.0, high=1.0, open_low=True, required=True
    ),  # fmt: skip
)
_SHEET_SETS = {"fixed": "side:-x", "loaded": "side:+x"}


def _miura_build(v: dict, label) -> CreasePattern:
    from holofold.geometry.miura import miura_sheet

    check_panels(v["m"], v["n"], label)
    if v["gamma"] is None:
        raise ParameterError(f"{label('gamma')} is required for a Miura sheet (degrees in (0, 90))")
    if v["size"] is None and (v["a"] is None or v["b"] is None):
        raise ParameterError(
            f"give {label('size')}, or both {label('a')} and {label('b')}, for a Miura sheet"
        )
    return miura_sheet(v["m"], v["n"], a=v["a"], b=v["b"], gamma=v["gamma"], ext=v["ext"],
                       size=v["size"])  # fmt: skip


def _miura_nodes(v: dict):
    from holofold.geometry.miura import miura_nodes

    return miura_nodes(v["m"], v["n"], v["a"], v["b"], v["gamma"], v["ext"])


def _miura_faces(v: dict):
    from holofold.geometry.miura import miura_faces

    return miura_faces(v["m"], v["n"])


def _tmp_build(v: dict, label) -> CreasePattern:
    from holofold.geometry.tmp import tmp_sheet

    check_panels(v["m"], v["n"], label)
    if v["size"] is None:
        raise ParameterError(f"{label('size')} (sheet size L, m) is required for a TMP sheet")
    return tmp_sheet(v["m"], v["n"], v["size"], v["ext"])


def _tmp_nodes(v: dict):
    from holofold.geometry.tmp import tmp_nodes

    return tmp_nodes(v["m"], v["n"], v["size"], v["ext"], v.get("size_y"))


def _tmp_faces(v: dict):
    from holofold.geometry.tmp import tmp_faces

    return tmp_faces(v["m"], v["n"])


def _sheet_label(kind):
    return lambda v: f"{kind} {v['m']}x{v['n']} at ext {v['ext']:g}"


def _gripper_build(v: dict, label) -> CreasePattern:
    from holofold.geometry.gripper import gripper_pattern

    return gripper_pattern(v["kind"], v["L1"], v["L2"], v["rate"], v["range"]).pattern


def _file_build(v: dict, label) -> CreasePattern:
    from holofold.geometry.readers import read_pattern

    opts = {k: v[k] for k in ("unit", "tol") if v[k] is not None}
    return read_pattern(v["path"], **opts)


_BUILTIN = (
    PatternFamily(
        "miura", "Miura-ori sheet folded to an extension",
        (*_SHEET,
         Parameter("gamma", "rad", "sector angle", "deg", 0.0, 90.0, open_low=True,
                   open_high=True),
         Parameter("a", "m", "panel side a (along y)", low=0.0, open_low=True),
         Parameter("b", "m", "panel side b (the zig-zag side)", low=0.0, open_low=True),
         Parameter("size", "m", "sheet size L: b = L/m, a = (L - b cot gamma)/n", low=0.0,
                   open_low=True)),
        _miura_build, _SHEET_SETS, _miura_faces, _miura_nodes, _sheet_label("miura"),
    ),
    PatternFamily(
        "tmp", "Tachi-Miura polyhedron sheet folded to an extension",
        (Parameter("m", "-", "panels along x (even)", low=1, required=True, integer=True),
         Parameter("n", "-", "panels along y (a multiple of 3)", low=1, required=True,
                   integer=True),
         _SHEET[2],
         Parameter("size", "m", "sheet size L", low=0.0, open_low=True)),
        _tmp_build, _SHEET_SETS, _tmp_faces, _tmp_nodes, _sheet_label("tmp"),
    ),
    PatternFamily(
        "gripper", "the paper's electro-thermal grippers, flat",
        (Parameter("kind", "-", "1 Miura-based, 2 splitted Miura, 3 two-panel", low=1,
                   required=True, integer=True),
         Parameter("L1", "m", "arm length", low=0.0, open_low=True, required=True),
         Parameter("L2", "m", "arm width", low=0.0, open_low=True, required=True),
         Parameter("rate", "-", "crease-length rate in (0, 1)", low=0.0, high=1.0,
                   open_low=True, open_high=True, required=True),
         Parameter("range", "m", "gap between the arm roots (default the pattern's)", low=0.0,
                   open_low=True)),
        _gripper_build, {},
        describe=lambda v: f"gripper {v['kind']}",
    ),
    PatternFamily(
        "file", "a crease pattern read from a file (FOLD, SVG, DXF, ORIPA)",
        (Parameter("path", "text", "the file", required=True),
         Parameter("unit", "m", "metres per drawing unit (default: the file's)", low=0.0,
                   open_low=True),
         Parameter("tol", "-", "merge distance of a drawing, drawing units", low=0.0,
                   open_low=True)),
        _file_build, {"boundary": "boundary"},
        describe=lambda v: f"file {v['path']}",
    ),
)  # fmt: skip


def _curved_pleat_build(v: dict, label) -> CreasePattern:
    from holofold.geometry.curved_pleat import build_family

    return build_family(v, label)


def _curved_pleat_describe(v: dict) -> str:
    from holofold.geometry.curved_pleat import describe

    return describe(v)


_CURVED_PLEAT = PatternFamily(
    "curved-pleat",
    "concentric circular creases on an annulus sector, meshed along the radial rulings",
    (Parameter("inner_radius", "m", "radius of the inner rim (0.1)", low=0.0, open_low=True),
     Parameter("pleat_width", "m", "distance between creases (0.02)", low=0.0, open_low=True),
     Parameter("creases", "-", "number of circular creases, valley first (3)", low=1,
               integer=True),
     Parameter("sector", "rad", "sector angle (90 deg)", "deg", 0.0, 360.0, open_low=True,
               open_high=True),
     Parameter("fold_angle", "rad", "fold angle of every crease (60 deg)", "deg", 0.0, 179.0),
     Parameter("pieces", "-", "pieces of every arc (one per 11.25 deg of sector)", low=2,
               integer=True),
     Parameter("across", "-", "rings of quads across each pleat (1)", low=1, integer=True)),
    _curved_pleat_build, {"fixed": "side:-y"},
    describe=_curved_pleat_describe,
)  # fmt: skip


def _check_family(name, fam) -> PatternFamily:
    if not isinstance(fam, PatternFamily):
        raise TypeError(f"expected a PatternFamily, got {type(fam).__name__}")
    return fam


#: name -> family (a :class:`~holofold.geometry.registry.Registry`; plug-ins from the
#: entry-point group :data:`ENTRY_POINT_GROUP`)
FAMILIES: Registry[PatternFamily] = Registry(
    "pattern family",
    {f.name: f for f in (*_BUILTIN, _CURVED_PLEAT)},
    group=ENTRY_POINT_GROUP,
    check=_check_family,
    error=ParameterError,
)


def family_names() -> tuple[str, ...]:
    """Every family: built-in and registered, then from entry points."""
    return FAMILIES.names()


def get_family(name: str) -> PatternFamily:
    """The family called ``name`` (one ParameterError line naming the known ones)."""
    return FAMILIES[name]


def pattern_families() -> dict[str, PatternFamily]:
    """name -> family of every family that loads."""
    return FAMILIES.loaded()


def register_family(family: PatternFamily, *, replace: bool = False) -> PatternFamily:
    """Add a family at run time; a built-in name cannot be taken, a registered one only with
    ``replace=True``."""
    if not isinstance(family, PatternFamily):
        raise TypeError(f"expected a PatternFamily, got {type(family).__name__}")
    return FAMILIES.register(family, replace=replace)
