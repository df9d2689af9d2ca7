"""The pattern kind: any crease-pattern file as the design's geometry (``kind = "pattern"``).

docs/scenarios.md §8.4. The file names a crease pattern (FOLD, SVG, DXF, ORIPA; read once, when
the scenario file is read, by :func:`holofold.geometry.read_pattern`), the material, the
supports and loads as named vertex sets (:mod:`holofold.geometry.vertex_sets`) and the design
features. Every design is :func:`holofold.mechanics.simulate_pattern`: the pattern, scaled
by ``scale``, folded by rest-angle actuation to ``fold`` x its fold angles, then loaded.

Features (SI): ``tpanel``, ``tcrease``, ``W`` (panel and crease thickness, crease width, m),
``fold`` (fold fraction), ``scale`` (uniform scale of the pattern as read, and as ``[pattern]
size`` sets it).

Columns: per load ``{name}stiff`` (N/m, from the folded state), ``energy`` (J, stored by the
fold), ``mass`` (kg, the flat sheet: panels of tpanel thinned to tcrease over W along every
crease), ``overlap`` (m^3) and ``clearance`` (m) of the folded thick panels, ``reached`` (the
fold fraction reached: below ``fold`` when the fold stops short, which makes the row not
converged).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from holofold.design.scenarios.base import Column, Scenario, positive, setting_hooks
from holofold.design.scenarios.config import (
    Section,
    read_features,
    read_material,
    read_solver,
)
from holofold.design.scenarios.pattern_loads import (
    FOLDED_COLUMNS,
    crease_view,
    describe_material_and_loads,
    fold_way,
    loaded_columns,
    read_supports_and_loads,
    row_part,
    row_status,
    row_thickness,
    write_row_files,
)
from holofold.geometry import CreasePattern
from holofold.mechanics import (
    PatternLoad,
    PatternSetting,
    scaled_pattern,
    simulate_pattern,
)
from holofold.mechanics.materials import Material

__all__ = [
    "PATTERN_FEATURES",
    "PatternScenarioSetting",
    "pattern_scenario",
    "evaluate_pattern",
    "pattern_shape",
    "write_pattern_files",
    "from_config",
    "DESCRIPTION",
]

DESCRIPTION = "any crease pattern file (FOLD, SVG, DXF, ORIPA), folded, then loaded"

#: the features of a pattern design, with default ranges
PATTERN_FEATURES = (
    Column("tpanel", "m", "panel thickness", 0.5e-3, 2e-3),
    Column("tcrease", "m", "crease thickness", 0.2e-3, 0.6e-3),
    Column("W", "m", "crease width", 0.5e-3, 2e-3),
    Column("fold", "-", "fold fraction (Origami Simulator's fold percent / 100)", 0.3, 0.9),
    Column("scale", "-", "uniform scale of the pattern", 0.8, 1.2),
)
#: a pattern row may fold a large pattern: its default time limit, s
PATTERN_ROW_TIMEOUT = 900.0


@dataclass(frozen=True)
class PatternScenarioSetting:
    """The fixed setting of a pattern scenario.

    Attributes
    ----------
    pattern : CreasePattern
        As read (and sized by ``[pattern] size``), m.
    source : str
        The file it was read from.
    material : Material
    model : str
    supports : tuple of str
        Vertex sets held during the loads.
    support_dofs : str
    loads : tuple of PatternLoad
    tol, max_iter
        Newton controls of the loads.
    collisions : bool
        Compute overlap and clearance (the folded thick panels).
    family : str
        A pattern family (:func:`holofold.geometry.get_family`) that makes every row's pattern
        instead of ``pattern`` ("": the pattern as read).
    given : tuple of (str, float)
        The family's fixed parameters, in their ``given_in`` units (``[pattern]`` keys).
    family_features : tuple of str
        The family's parameters that are features (SI in the row).
    """

    pattern: CreasePattern
    source: str
    material: Material
    model: str = "concentrated"
    supports: tuple[str, ...] = ()
    support_dofs: str = "xyz"
    loads: tuple[PatternLoad, ...] = ()
    tol: float = 1e-9
    max_iter: int = 30
    collisions: bool = True
    family: str = ""
    given: tuple = ()
    family_features: tuple[str, ...] = ()


def family_columns(family) -> tuple[Column, ...]:
    """A feature column for every number parameter of a pattern family (SI; a range
    from the parameter's, where it has one)."""
    out = []
    for p in family.parameters:
        if p.unit == "text":
            continue
        lo = None if p.low is None else p.low * p.factor
        hi = None if p.high is None else p.high * p.factor
        unit = "-" if p.unit == "-" else p.unit
        out.append(Column(p.name, unit, f"{family.name}: {p.description}", lo, hi))
    return tuple(out)


def _family_given(setting: PatternScenarioSetting, row) -> dict:
    """The family's parameters of a row, in their ``given_in`` units."""
    from holofold.geometry import get_family

    params = {p.name: p for p in get_family(setting.family).parameters}
    given = dict(setting.given)
    for name in setting.family_features:
        v = float(row[name]) / params[name].factor
        given[name] = round(v) if params[name].integer and round(v) == v else v
    return given


def family_pattern(setting: PatternScenarioSetting, row) -> CreasePattern:
    """The row's pattern of the setting's family (its parameters checked), m."""
    from holofold.geometry import get_family

    p = get_family(setting.family).make(**_family_given(setting, row))
    return replace(p, meta={**p.meta, "source": setting.source})


def pattern_columns(setting: PatternScenarioSetting) -> tuple[Column, ...]:
    cols = [
        Column(
            f"{ld.name}stiff", "N/m", f"secant stiffness under {ld.force:g} N at {ld.at}, folded"
        )
        for ld in setting.loads
    ]
    cols += [
        Column("energy", "J", "elastic energy stored by the fold"),
        *FOLDED_COLUMNS,
        Column("reached", "-", "fold fraction reached"),
    ]
    return tuple(cols)


def _setting_for(setting: PatternScenarioSetting, row) -> PatternSetting:
    return PatternSetting(
        material=setting.material, panel_thickness=float(row["tpanel"]),
        crease_thickness=float(row["tcrease"]), crease_width=float(row["W"]),
        fold=float(row["fold"]), model=setting.model, supports=setting.supports,
        support_dofs=setting.support_dofs, loads=setting.loads, tol=setting.tol,
        max_iter=setting.max_iter, collisions=setting.collisions,
    )  # fmt: skip


def _pattern(setting: PatternScenarioSetting, row) -> CreasePattern:
    s = float(row["scale"])
    base = family_pattern(setting, row) if setting.family else setting.pattern
    return base if s == 1.0 else scaled_pattern(base, s)


def check_pattern(setting: PatternScenarioSetting, row) -> list[str]:
    errs = positive(row, ("tpanel", "tcrease", "W", "scale"))
    f = row.get("fold")
    if f is None or not math.isfinite(f) or not 0 <= f <= 1:
        errs.append(f"fold = {f!r} must lie in [0, 1]")
    if setting.family:
        from holofold.geometry import ParameterError, get_family

        try:
            get_family(setting.family).values(_family_given(setting, row))
        except (ParameterError, KeyError, TypeError, ValueError) as exc:
            errs.append(str(exc))
    return errs


def evaluate_pattern(setting: PatternScenarioSetting, columns: Sequence[str], row) -> dict:
    """The columns of one design and its status."""
    sim = simulate_pattern(_pattern(setting, row), _setting_for(setting, row))
    out = {**loaded_columns(sim), "energy": sim.fold.energy.total, "reached": sim.fold.reached}
    return {**{c: out[c] for c in columns}, "status": row_status(sim.status)}


def _fold(setting: PatternScenarioSetting, row):
    from holofold.mechanics.folding import fold_pattern

    s = _setting_for(setting, row)
    return fold_pattern(
        _pattern(setting, row), s.fold, panel_thickness=s.panel_thickness,
        crease_thickness=s.crease_thickness, crease_width=s.crease_width, E=s.material.E,
        nu=s.material.nu, model=s.model,
    )  # fmt: skip


def pattern_shape(setting: PatternScenarioSetting, row) -> CreasePattern:
    """The design's pattern folded as far as its fold got (flat layout kept), m."""
    return _fold(setting, row).folded()


def pattern_part(setting: PatternScenarioSetting, row):
    """The printable part: the pattern's flat layout at the row's scale, with the row's
    thicknesses and hinge width (:func:`~holofold.design.scenarios.pattern_loads.row_part`)."""
    from dataclasses import replace

    part = row_part(_pattern(setting, row), row)
    if part is None:
        return None
    fold = _fold(setting, row)
    shape, way = fold.folded(), fold_way(fold)
    got = row_thickness(shape, row, way)
    if got is None or got.technique == "centred" or shape.flat is None:
        return part
    return replace(part, pattern=shape, thick=got.technique, path=tuple(way))


def pattern_view(setting: PatternScenarioSetting, row):
    """The 3D view: flat, up to four states of the fold path, the vertex sets held and the
    loads (:func:`~holofold.design.scenarios.pattern_loads.crease_view`)."""
    fold = _fold(setting, row)
    k = len(fold.coords)
    pick = np.unique(np.linspace(0, k - 1, min(k, 4)).round().astype(int))
    pick = pick[fold.fractions[pick] > 0] if k > 1 else pick
    labels = tuple(f"fold {fold.fractions[i]:.0%}" for i in pick)
    bending = f"{fold.verdict}: {fold.note}" if fold.note else fold.verdict
    return crease_view(fold.pattern, fold.coords[pick], labels, setting.supports, setting.loads,
                       facts=(("fold", bending),))  # fmt: skip


def write_pattern_files(
    setting: PatternScenarioSetting, row, folder, units: str = "mm", cutter=None
):
    """The design's fabrication set (:func:`~holofold.geometry.write_fabrication_set`) for the
    pattern folded as far as its fold got: printable part, FOLD, SVG and DXF for ``cutter``,
    STL/OBJ and the thick solid; without the solids (a note says why) where the panels do not
    allow them."""
    fold = _fold(setting, row)
    shape, way = fold.folded(), fold_way(fold)
    got = row_thickness(shape, row, way)
    thick = None if got is None else got.technique
    return write_row_files(shape, folder, row, units=units, cutter=cutter, thick=thick,
                           path=None if got is None else [*way, shape])  # fmt: skip


def pattern_scenario(
    name: str,
    description: str,
    setting: PatternScenarioSetting,
    features: tuple[Column, ...] = PATTERN_FEATURES,
    *,
    source: str = "",
) -> Scenario:
    """The :class:`Scenario` of a pattern setting (picklable for worker processes)."""
    perf = pattern_columns(setting)
    p = setting.pattern
    size = np.ptp(p.flat if p.flat is not None else p.coords, axis=0)
    words = {
        "pattern": f"{setting.source}: {p.n_vertices} vertices, {p.n_faces} panels, "
        f"{1e3 * size[0]:.4g} x {1e3 * size[1]:.4g} mm at scale 1",
        "model": setting.model,
        **describe_material_and_loads(
            setting.material, setting.supports, setting.support_dofs, setting.loads
        ),
    }
    cols = tuple(c.name for c in perf)
    return Scenario(
        name=name,
        description=description or f"crease pattern {setting.source}, folded and loaded",
        features=features,
        performance=perf,
        check=partial(check_pattern, setting),
        evaluate=partial(evaluate_pattern, setting, cols),
        kind="pattern",
        setting=words,
        source=source,
        **setting_hooks(setting, pattern_shape, write_pattern_files, pattern_view, pattern_part),
        row_timeout=PATTERN_ROW_TIMEOUT,
    )


# ---------------------------------------------------------------------- scenario files
_PATTERN_KEYS = ("file", "size", "unit", "tol", "frame", "split", "curves", "model")


def _read_family(sec: Section, features: Section):
    """``[pattern] family = NAME`` with the family's fixed parameters as keys (in their
    ``given_in`` units); its parameters named in ``[features]`` vary by row (SI). Returns the
    family, the fixed values and the feature names."""
    from holofold.geometry import ParameterError, get_family

    name = sec.string("family")
    try:
        family = get_family(name)
    except ParameterError as exc:
        raise sec.error(f"family = {name!r}: {exc}") from None
    known = [p.name for p in family.parameters]
    fixed = {k: sec.raw(k) for k in list(sec.data) if k in known}
    sec.done(["family", "model", *known])
    varied = tuple(p.name for p in family.parameters if features.has(p.name))
    try:
        family.values(fixed)  # each fixed value checked, an unknown name refused
    except ParameterError as exc:
        raise sec.error(str(exc)) from None
    both = sorted(set(fixed) & set(varied))
    if both:
        raise sec.error(f"{both[0]} is fixed here and a feature in [features]; give it once")
    return family, fixed, varied


def _read_pattern(sec: Section) -> tuple[CreasePattern, str, str]:
    from holofold.geometry import read_pattern, reader_for

    for k in _PATTERN_KEYS:
        sec.raw(k)
    sec.done(_PATTERN_KEYS)
    if not sec.has("file"):
        raise sec.error("missing key 'file' (the crease pattern: .fold, .svg, .dxf, .opx, .cp)")
    path = sec.path("file")
    try:
        reader = reader_for(path)
    except ValueError as exc:
        raise sec.error(str(exc)) from None
    opts = {}
    for k, kind in (("unit", "number"), ("tol", "number"), ("frame", "int"), ("split", "str"),
                    ("curves", "str")):  # fmt: skip
        if not sec.has(k):
            continue
        if k not in reader.options:
            raise sec.error(f"{k}: {reader.name} files take no {k!r}")
        if kind == "number":
            opts[k] = sec.number(k, low=0.0, low_open=True)
        elif kind == "int":
            opts[k] = sec.number(k, low=0, integer=True)
        else:
            opts[k] = sec.string(k)
    model = sec.choice("model", ("concentrated", "compliant"), "concentrated")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # repairs are reported when the file is simulated
            pattern = read_pattern(path, **opts)
    except ValueError as exc:
        raise sec.error(f"file = {sec.raw('file')!r}: {exc}") from None
    if sec.has("size"):
        size = sec.number("size", low=0.0, low_open=True)
        span = float(
            np.ptp(pattern.flat if pattern.flat is not None else pattern.coords, axis=0).max()
        )
        pattern = scaled_pattern(pattern, size / span)
    return replace(pattern, meta={**pattern.meta, "source": path.name}), path.name, model


def from_config(doc: Section, name: str, description: str) -> Scenario:
    """The pattern scenario of a parsed scenario file (``kind = "pattern"``)."""
    sec, fsec = doc.sub("pattern", required=True), doc.sub("features")
    family, fixed, varied = None, {}, ()
    if sec.has("family"):
        family, fixed, varied = _read_family(sec, fsec)
        model = sec.choice("model", ("concentrated", "compliant"), "concentrated")
        cols = {c.name: c for c in family_columns(family)}
        first = {
            k: (min(fsec.raw(k)["choices"]) if isinstance(fsec.raw(k), dict)
                else min(fsec.raw(k)) if isinstance(fsec.raw(k), list) else fsec.raw(k))
            for k in varied
        }  # fmt: skip
        source = f"{family.name} family"
        probe = PatternScenarioSetting(None, source, None, family=family.name,
                                       given=tuple(fixed.items()),
                                       family_features=varied)  # fmt: skip
        try:  # the pattern at the features' low ends: vertex sets are checked on it
            pattern = family_pattern(probe, {k: first[k] for k in varied})
        except (TypeError, ValueError) as exc:
            raise fsec.error(str(exc)) from None
    else:
        pattern, source, model = _read_pattern(sec)
    E, nu, density = read_material(doc)
    at, dofs, loads = read_supports_and_loads(doc, "'press'", pattern)
    if loads and dofs == "xyz":  # a mistake of the file: refused once, not stored as rows
        from holofold.geometry.vertex_sets import parse_vertex_set

        held = {int(i) for v in at for i in parse_vertex_set(v).select(pattern)}
        if len(held) < 3:
            raise doc.error(
                f"the supports hold {len(held)} vertex(es): the pattern could turn as a whole "
                "under every load; hold at least three vertices not on one line"
            )
    tol, max_iter = read_solver(doc)
    setting = PatternScenarioSetting(
        pattern=pattern, source=source, material=Material("file", E, nu, density), model=model,
        supports=at, support_dofs=dofs, loads=loads, tol=tol, max_iter=max_iter,
        family="" if family is None else family.name, given=tuple(fixed.items()),
        family_features=varied,
    )  # fmt: skip
    extra = tuple(c for c in cols.values() if c.name in varied) if family else ()
    features = read_features(fsec, PATTERN_FEATURES + extra)
    for c in features:
        lo = min(c.choices) if c.choices else c.low
        hi = max(c.choices) if c.choices else c.high
        if c.name == "fold" and not (0 <= lo and hi <= 1):
            raise doc.error(f"[features] fold = [{lo:g}, {hi:g}] must lie in [0, 1]")
        if c.name != "fold" and c.name not in varied and not lo > 0:
            raise doc.error(f"[features] {c.name} must be > 0, got {lo:g}")
    return pattern_scenario(name, description, setting, features)
