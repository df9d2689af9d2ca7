"""The surface kind: a generalised Miura-ori fitted to a target surface (``kind = "surface"``).

docs/surface-fit.md §7. The file names the target (a mesh file in its ``units`` or a built-in
surface with its parameters, read once), the material, supports and loads as named vertex sets
of the flat pattern (:mod:`holofold.geometry.vertex_sets`; its straight creases run along y)
and the features. Load directions are in the target's frame. Every design is
fitted (:func:`holofold.fitting.fit_surface`: m x n quads over ``coverage`` of the target's
chart, starting from a Miura-ori folded to ``ext``), then its flat pattern is folded to the
fitted fold angles by the bar-and-hinge simulator and loaded
(:func:`holofold.mechanics.simulate_pattern`): the honest fold of docs/surface-fit.md §4
is part of every row.

Features (SI): ``m``, ``n`` (quads along and across the zig-zag direction, categorical),
``tpanel``, ``tcrease``, ``W`` (panel and crease thickness, crease width, m), ``ext`` (how far
the starting Miura-ori is folded, (0, 1)) and ``coverage`` (the share of the chart the pattern
covers, (0, 1]).

Columns: ``rms_error`` and ``max_error`` (m, the fitted side's distance to the target),
``fold_error`` (m, the largest distance between the simulated fold and the fit), per load
``{name}stiff`` (N/m, from the folded state), ``mass`` (kg, the flat sheet), ``overlap``
(m^3) and ``clearance`` (m) of the folded thick panels. A fit that cannot be made is a failed
row; a fold that ends farther than :data:`~holofold.mechanics.FOLD_TOLERANCE` of the target's
size from the fit is not converged.
"""

from __future__ import annotations

import math
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
    loaded_columns,
    read_supports_and_loads,
    row_part,
    row_status,
    row_thickness,
    surface_lines,
    write_row_files,
)
from holofold.fitting import (
    BUILTIN_SURFACES,
    MESH_SURFACE_TYPES,
    Placement,
    SurfaceFit,
    TargetSurface,
    builtin_surface,
    fit_surface,
    read_surface,
)
from holofold.geometry import LENGTH_UNITS, CreasePattern
from holofold.mechanics import (
    FOLD_TOLERANCE,
    PatternLoad,
    PatternSetting,
    aligned_deviation,
    simulate_pattern,
)
from holofold.mechanics.materials import Material
from holofold.mechanics.status import Status

__all__ = [
    "SURFACE_FEATURES",
    "SurfaceScenarioSetting",
    "surface_scenario",
    "evaluate_surface",
    "surface_fit_of",
    "from_config",
    "DESCRIPTION",
]

DESCRIPTION = "a generalised Miura-ori fitted to a target surface, folded, then loaded"

#: the features of a surface design, with default ranges
SURFACE_FEATURES = (
    Column("m", "-", "quads along the zig-zag direction", choices=(6.0, 8.0, 10.0)),
    Column("n", "-", "quads across the zig-zag direction", choices=(6.0, 8.0, 10.0)),
    Column("tpanel", "m", "panel thickness", 1e-3, 3e-3, display="mm"),
    Column("tcrease", "m", "crease thickness", 0.2e-3, 0.6e-3, display="mm"),
    Column("W", "m", "crease width", 1e-3, 3e-3, display="mm"),
    Column("ext", "-", "how far the starting Miura-ori is folded (1 = flat)", 0.55, 0.85),
    Column("coverage", "-", "share of the target's chart the pattern covers", 0.7, 0.95),
)
#: a surface row fits and folds a pattern: its default time limit, s
SURFACE_ROW_TIMEOUT = 600.0


@dataclass(frozen=True)
class SurfaceScenarioSetting:
    """The fixed setting of a surface scenario (SI).

    ``target`` the surface; ``source`` what it was read from; ``centre`` (u, v) m on its chart
    (None: the chart's centre); ``side`` which way the corrugation hangs; ``gamma`` the starting
    sector angle, rad; ``material``; ``supports`` vertex sets of the flat pattern held during
    the loads (``support_dofs``); ``loads``; Newton ``tol`` (m) and ``max_iter``.
    """

    target: TargetSurface
    source: str
    material: Material
    centre: tuple[float, float] | None = None
    side: str = "below"
    gamma: float = math.radians(60.0)
    supports: tuple[str, ...] = ()
    support_dofs: str = "xyz"
    loads: tuple[PatternLoad, ...] = ()
    tol: float = 1e-9
    max_iter: int = 30


def surface_columns(setting: SurfaceScenarioSetting) -> tuple[Column, ...]:
    cols = [
        Column("rms_error", "m", "RMS distance of the fitted side to the target", display="mm"),
        Column(
            "max_error", "m", "largest distance of the fitted side to the target", display="mm"
        ),  # fmt: skip
        Column(
            "fold_error",
            "m",
            "largest distance between the simulated fold and the fit",
            display="mm",
        ),  # fmt: skip
    ]
    cols += [
        Column(f"{ld.name}stiff", "N/m", f"secant stiffness under {ld.force:g} N at {ld.at}")
        for ld in setting.loads
    ]
    cols += FOLDED_COLUMNS
    return tuple(cols)


def surface_fit_of(setting: SurfaceScenarioSetting, row) -> SurfaceFit:
    """The fit of one design (raises for a design whose placement leaves the chart)."""
    u0, u1, v0, v1 = setting.target.domain
    cov = float(row["coverage"])
    c = setting.centre or ((u0 + u1) / 2, (v0 + v1) / 2)
    # the largest footprint of that share that stays on the chart around the centre
    half_u = min(c[0] - u0, u1 - c[0])
    half_v = min(c[1] - v0, v1 - c[1])
    placement = Placement(centre=c, size=(2 * cov * half_u, 2 * cov * half_v))
    return fit_surface(setting.target, (int(row["m"]), int(row["n"])), placement=placement,
                       gamma=setting.gamma, ext=float(row["ext"]), side=setting.side)  # fmt: skip


def check_surface(row) -> list[str]:
    errs = positive(row, ("tpanel", "tcrease", "W"))
    for k in ("m", "n"):
        v = row.get(k)
        if v is None or not math.isfinite(v) or v != int(v) or not 2 <= v <= 100:
            errs.append(f"{k} = {v!r} must be an integer in [2, 100]")
    e = row.get("ext")
    if e is None or not math.isfinite(e) or not 0 < e < 1:
        errs.append(f"ext = {e!r} must lie in (0, 1)")
    c = row.get("coverage")
    if c is None or not math.isfinite(c) or not 0 < c <= 1:
        errs.append(f"coverage = {c!r} must lie in (0, 1]")
    return errs


def evaluate_surface(setting: SurfaceScenarioSetting, columns: Sequence[str], row) -> dict:
    """The columns of one design and its status."""
    nan = dict.fromkeys(columns, math.nan)
    try:
        fit = surface_fit_of(setting, row)
    except ValueError as exc:
        return {**nan, "status": Status.failed(f"no fit: {exc}")}
    if not fit.ok:
        return {**nan, "rms_error": fit.rms, "max_error": fit.max,
                "status": Status.failed(f"the fit failed: {fit.message}")}  # fmt: skip
    sim = simulate_pattern(fit.pattern, _pattern_setting(setting, row, _frame(fit)))
    dev = aligned_deviation(sim.fold.coords[-1], fit.coords)
    out = {"rms_error": fit.rms, "max_error": fit.max, "fold_error": float(dev.max())}
    out.update(loaded_columns(sim))
    status = sim.status
    tol = FOLD_TOLERANCE * fit.target.size
    if out["fold_error"] > tol:
        status = Status.gather({
            "fold": status, "fit": Status.not_converged(
                f"the simulated fold ends {out['fold_error']:.3g} m from the fit (tolerance "
                f"{tol:.3g} m)")})  # fmt: skip
    return {**{c: out.get(c, math.nan) for c in columns}, "status": row_status(status)}


def _frame(fit: SurfaceFit) -> np.ndarray:
    """(3, 3) rotation from the target's frame to the simulation's: the fold holds the panel
    whose flat centroid is nearest the middle where it lies flat (``fold_pattern``'s default
    supports), so the simulated shell is the fitted one turned by this rotation."""
    p = fit.pattern
    cent = np.array([p.flat[f].mean(axis=0) for f in p.faces])
    q = p.faces[int(np.argmin(np.linalg.norm(cent - cent.mean(axis=0), axis=1)))]
    A = fit.coords[q] - fit.coords[q].mean(axis=0)
    B = np.column_stack([p.flat[q], np.zeros(len(q))])
    B = B - B.mean(axis=0)
    U, _, Vt = np.linalg.svd(A.T @ B)
    d = np.sign(np.linalg.det(U @ Vt))
    return (U @ np.diag([1.0, 1.0, d]) @ Vt).T  # x_sim = R x_target


def _pattern_setting(setting: SurfaceScenarioSetting, row, frame=None) -> PatternSetting:
    """The simulation setting of a row; ``frame`` turns the loads' directions (given in the
    target's frame) into the simulation's."""
    loads = setting.loads
    if frame is not None:
        loads = tuple(
            replace(ld, direction=tuple(float(v) for v in frame @ np.asarray(ld.direction)))
            for ld in loads
        )
    return PatternSetting(
        material=setting.material, panel_thickness=float(row["tpanel"]),
        crease_thickness=float(row["tcrease"]), crease_width=float(row["W"]), fold=1.0,
        supports=setting.supports, support_dofs=setting.support_dofs, loads=loads,
        tol=setting.tol, max_iter=setting.max_iter,
    )  # fmt: skip


def surface_shape(setting: SurfaceScenarioSetting, row) -> CreasePattern:
    """The design's fitted pattern (folded state, flat layout), m."""
    fit = surface_fit_of(setting, row)
    if not fit.ok:
        raise ValueError(f"the fit failed: {fit.message}")
    return fit.pattern


def surface_part(setting: SurfaceScenarioSetting, row):
    """The printable part: the fitted pattern's flat layout with the row's thicknesses and
    hinge width (:func:`~holofold.design.scenarios.pattern_loads.row_part`)."""
    from dataclasses import replace

    shape = surface_shape(setting, row)
    part = row_part(shape, row)
    got = row_thickness(shape, row)
    if part is None or got is None:
        return part
    return replace(part, thick=got.technique)


def surface_view(setting: SurfaceScenarioSetting, row):
    """The 3D view: flat, the fitted shell (the folded state, in the target's frame), the
    supports and loads, and the target surface's grid lines over the fitted region."""
    fit = surface_fit_of(setting, row)
    if not fit.ok:
        raise ValueError(f"the fit failed: {fit.message}")
    pat = fit.pattern
    # the chart's rectangle of the fitted footprint (surface_fit_of's placement)
    u0, u1, v0, v1 = setting.target.domain
    c = setting.centre or ((u0 + u1) / 2, (v0 + v1) / 2)
    cov = float(row["coverage"])
    hu, hv = cov * min(c[0] - u0, u1 - c[0]), cov * min(c[1] - v0, v1 - c[1])
    dom = (c[0] - hu, c[0] + hu, c[1] - hv, c[1] + hv)
    lines = surface_lines(setting.target.chart, dom)
    rms = 1e3 * fit.rms
    return crease_view(
        pat,
        fit.coords[None],
        (f"fitted, ext {float(row['ext']):.3g}",),
        setting.supports,
        setting.loads,
        curve=lines,
        curve_name="target surface",
        facts=(("fit", f"rms distance to the target {rms:.3g} mm, {pat.n_faces} panels"),),
    )


def write_surface_files(setting: SurfaceScenarioSetting, row, folder, units: str = "mm",
                        cutter=None):  # fmt: skip
    """The design's fabrication set (:func:`~holofold.geometry.write_fabrication_set`): FOLD,
    SVG, DXF, the folded shell as STL/OBJ, the thick panels and the printable part; without the
    solids (a note says why) where the panels do not allow them."""
    shape = surface_shape(setting, row)
    got = row_thickness(shape, row)
    return write_row_files(shape, folder, row, units=units, cutter=cutter,
                           thick=None if got is None else got.technique)  # fmt: skip


def surface_scenario(
    name: str,
    description: str,
    setting: SurfaceScenarioSetting,
    features: tuple[Column, ...] = SURFACE_FEATURES,
    *,
    source: str = "",
) -> Scenario:
    """The :class:`Scenario` of a surface setting (picklable for worker processes)."""
    perf = surface_columns(setting)
    t = setting.target
    words = {
        "target": f"{setting.source}: {t.name}, {1e3 * t.size:.4g} mm across",
        "side": setting.side,
        **describe_material_and_loads(
            setting.material, setting.supports, setting.support_dofs, setting.loads
        ),
    }
    cols = tuple(c.name for c in perf)
    return Scenario(
        name=name,
        description=description or f"a generalised Miura-ori fitted to {setting.source}",
        features=features,
        performance=perf,
        categorical=tuple(c.name for c in features if c.choices),
        check=check_surface,
        evaluate=partial(evaluate_surface, setting, cols),
        kind="surface",
        setting=words,
        source=source,
        **setting_hooks(setting, surface_shape, write_surface_files, surface_view, surface_part),
        row_timeout=SURFACE_ROW_TIMEOUT,
    )


# ---------------------------------------------------------------------- scenario files
def _read_target(sec: Section) -> tuple[TargetSurface, str, dict]:
    keys = ("file", "units", "builtin", "centre", "side", "gamma")
    params = {}
    builtin = sec.string("builtin", "") if sec.has("builtin") else ""
    if builtin:
        if builtin not in BUILTIN_SURFACES:
            raise sec.error(f"builtin = {builtin!r}; known: {', '.join(BUILTIN_SURFACES)}")
        _, req, opt = BUILTIN_SURFACES[builtin]
        for k in req + opt:
            if sec.has(k):
                params[k] = sec.number(k, low=0.0, low_open=True)
        keys = keys + req + opt
    for k in keys:
        sec.raw(k)
    sec.done(keys)
    if bool(builtin) == sec.has("file"):
        raise sec.error("give either file = '...' (.stl .obj .ply .off) or builtin = '...' "
                        f"({', '.join(BUILTIN_SURFACES)})")  # fmt: skip
    if not builtin:
        path = sec.path("file")
        if path.suffix.lower().lstrip(".") not in MESH_SURFACE_TYPES:
            raise sec.error(f"file = {sec.raw('file')!r}: a surface is "
                            f"{', '.join('.' + t for t in MESH_SURFACE_TYPES)}")  # fmt: skip
        units = sec.choice("units", tuple(LENGTH_UNITS), "mm")
    try:
        if builtin:
            target, source = builtin_surface(builtin, **params), builtin
        else:
            target, source = read_surface(path, units), path.name
    except ValueError as exc:
        raise sec.error(str(exc)) from None
    extra = {"side": sec.choice("side", ("below", "above"), "below")}
    if sec.has("gamma"):
        extra["gamma"] = math.radians(sec.number("gamma", low=0.0, high=90.0, low_open=True,
                                                 high_open=True))  # fmt: skip
    if sec.has("centre"):
        c = sec.raw("centre")
        if not (
            isinstance(c, list) and len(c) == 2 and all(isinstance(v, (int, float)) for v in c)
        ):
            raise sec.error(f"centre = {c!r} must be [u, v] in metres on the target's chart")
        extra["centre"] = (float(c[0]), float(c[1]))
    return target, source, extra


def from_config(doc: Section, name: str, description: str) -> Scenario:
    """The surface scenario of a parsed scenario file (``kind = "surface"``)."""
    target, source, extra = _read_target(doc.sub("surface", required=True))
    E, nu, density = read_material(doc)
    at, dofs, loads = read_supports_and_loads(doc, "'Z'")
    tol, max_iter = read_solver(doc)
    setting = SurfaceScenarioSetting(
        target=target, source=source, material=Material("file", E, nu, density),
        supports=at, support_dofs=dofs, loads=loads, tol=tol, max_iter=max_iter, **extra,
    )  # fmt: skip
    features = read_features(doc.sub("features"), SURFACE_FEATURES)
    for c in features:
        lo = min(c.choices) if c.choices else c.low
        hi = max(c.choices) if c.choices else c.high
        if c.name in ("m", "n") and not (lo >= 2 and hi * 1 == int(hi)):
            raise doc.error(f"[features] {c.name} must be integers >= 2")
        if c.name == "ext" and not (0 < lo and hi < 1):
            raise doc.error(f"[features] ext = [{lo:g}, {hi:g}] must lie in (0, 1)")
        if c.name == "coverage" and not (0 < lo and hi <= 1):
            raise doc.error(f"[features] coverage = [{lo:g}, {hi:g}] must lie in (0, 1]")
        if c.name in ("tpanel", "tcrease", "W") and not lo > 0:
            raise doc.error(f"[features] {c.name} must be > 0, got {lo:g}")
    return surface_scenario(name, description, setting, features, source=source)
