"""The strip kind: a Miura-like strip over any planar curve (the paper's arch, generalised).

docs/scenarios.md §8. A :class:`StripSetting` fixes everything a design does not vary: the
target curve, the material, the supports and the load cases. :func:`strip_scenario` turns a
setting and the design features into a :class:`~holofold.design.scenarios.base.Scenario`
whose ``evaluate(row)`` builds the strip of :func:`holofold.fitting.strip_geometry` for the
row's ``m``, ``offset``, ``stripeWidth`` and ``extrude``, the concentrated-hinge model with
the row's ``tpanel``, ``tcrease`` and ``W``, and runs every load case from the stress-free
state (Newton-Raphson load control, the last iterate kept as in the reference).

Columns, SI units:

``{load}stiff``
    total force / |displacement of the loaded node along the load direction|, N/m;
``{load}snap``
    1 if that displacement exceeds the load's ``snap_displacement`` (loads that set one);
``error``
    the paper's index-matched fitting error, m;
``closest_error``
    mean closest-point distance of the centre line to the curve, m;
``mass``
    density x (panel area x tpanel + hinge-strip area x (tcrease - tpanel)), kg: the flat
    sheet of panel thickness, thinned to the crease thickness over a strip of width W along
    every fold line (the compliant crease the model represents);
``overlap``
    volume where the folded thick panels (thickness tpanel, pulled back W/2 from the creases)
    intersect, m^3 (0: the folded part can be built as designed);
``clearance``
    smallest gap between thick panels that share no vertex, m (negative where they run into
    each other; 1000 m when every pair shares a vertex); see
    :func:`holofold.geometry.printability`.

The paper's arch (:mod:`~holofold.design.scenarios.arch`) is this kind with the half circle of
radius 2 m, the six end nodes pinned and two 5 N loads at the apex.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache, partial

import numpy as np

from holofold.design.scenarios.base import Column, Scenario, integer, positive, setting_hooks
from holofold.design.scenarios.config import (
    Section,
    load_name,
    read_direction,
    read_dofs,
    read_features,
    read_loads,
    read_material,
    read_solver,
)
from holofold.design.scenarios.plausible import FORCE, check_plausible
from holofold.fitting import (
    BUILTIN_CURVES,
    MAX_M,
    PlanarCurve,
    builtin_curve,
    closest_point_error,
    fit_strip,
    index_matched_error,
    read_points_csv,
    read_svg_curve,
    strip_geometry,
)
from holofold.geometry import (
    LENGTH_UNITS,
    THICK_CHOICES,
    ThicknessChoice,
    choose_thickness,
    non_simple_faces,
)
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.analyses import load_along, secant_stiffness_batch
from holofold.mechanics.assembly import BatchAssembler
from holofold.mechanics.compat import PAPER
from holofold.mechanics.hinges import build_concentrated_batch
from holofold.mechanics.status import Outcome, Status
from holofold.mechanics.structure import support_mask
from holofold.mechanics.threads import single_threaded

__all__ = [
    "StripLoad",
    "StripSetting",
    "STRIP_FEATURES",
    "SUPPORTS",
    "strip_scenario",
    "strip_model",
    "strip_models",
    "strip_columns",
    "evaluate_strip",
    "evaluate_strip_batch",
    "strip_batch_key",
    "check_strip",
    "loaded_node",
    "strip_shape",
    "write_strip_files",
    "strip_view",
    "strip_part",
    "from_config",
]

#: the strip's design features with the paper's arch ranges (docs/scenarios.md §5)
STRIP_FEATURES = (
    Column("m", "-", "number of Miura units", choices=(8.0, 12.0, 16.0, 24.0)),
    Column("tcrease", "m", "crease thickness", 0.5e-3, 1.0e-3, display="mm"),
    Column("tpanel", "m", "panel thickness", 1e-3, 6e-3, display="mm"),
    Column("W", "m", "crease width", 1e-3, 4e-3, display="mm"),
    Column("offset", "m", "zigzag offset l_o of the middle vertices", 0.10, 0.30, display="mm"),
    Column("stripeWidth", "m", "side-line shift W_s", 0.01, 0.04, display="mm"),
    Column("extrude", "m", "half-width l_e of the strip", 0.05, 0.25, display="mm"),
)

#: support choices: which nodes of the strip are fixed
SUPPORTS = {
    "ends": "the first and last node of the centre line and of both side lines (6 nodes)",
    "centre-ends": "the first and last node of the centre line (2 nodes)",
    "side-ends": "the first and last node of both side lines (4 nodes)",
}


@dataclass(frozen=True)
class StripLoad:
    """One load case on a strip.

    Attributes
    ----------
    name : str
        Column prefix: the case gives ``{name}stiff`` (and ``{name}snap``).
    at : float
        Position as a fraction of the curve's arc length in [0, 1], snapped to the nearest
        centre-line vertex (0.5: the paper's apex).
    direction : (3,) float
        Direction of the force (normalised), e.g. ``(0, 0, -1)``.
    force : float
        Total force after the last increment, N (> 0).
    increments : int
        Equal load increments (>= 1).
    snap_displacement : float or None
        Displacement above which the case counts as a snap-through, m.
    """

    name: str
    at: float
    direction: tuple[float, float, float]
    force: float
    increments: int = 5
    snap_displacement: float | None = None


@dataclass(frozen=True)
class StripSetting:
    """The fixed setting of a strip scenario (everything a design does not vary).

    Attributes
    ----------
    curve : PlanarCurve
        Target curve in the x-z plane, m.
    loads : tuple of StripLoad
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio of panels and creases.
    density : float
        kg/m^3, for ``mass``.
    supports : str
        One of :data:`SUPPORTS`.
    support_dofs : str
        Fixed directions of the support nodes (any of "xyz").
    tol : float
        Newton-Raphson tolerance on ||dU||, m.
    max_iter : int
        Iteration cap per increment (the reference's: 30, i.e. 29 iterations).
    sampling : {"paper", "arclength"} or None
        Where the centre line meets the curve; None: the curve's default.
    refuse_overlap : bool
        Report a design whose panels are not simple polygons (a self-overlapping strip, which
        :func:`~holofold.fitting.fit_strip` refuses and nobody can build) as a failed row
        instead of simulating it. None of the 3000 published arch rows overlaps.
    thick : str
        Thickness accommodation of the panels ("centred", "offset", "tapered";
        :func:`~holofold.geometry.thick_panels`), or "auto": the first of them whose panels do
        not overlap in the strip's shape (:func:`strip_thickness`; a scenario file's default).
        It sets the ``overlap``, ``clearance`` and ``thick`` columns and the fabrication
        files' solids; the simulation is the same.
    curve_label : str
        How the curve was given (for reports).
    """

    curve: PlanarCurve
    loads: tuple[StripLoad, ...]
    E: float = 2e9
    nu: float = 0.3
    density: float = 1200.0
    supports: str = "ends"
    support_dofs: str = "xyz"
    tol: float = 1e-7
    max_iter: int = 30
    sampling: str | None = None
    refuse_overlap: bool = True
    curve_label: str = field(default="", compare=False)
    thick: str = field(default="centred", compare=False)

    @property
    def curve_sampling(self) -> str:
        return self.sampling or self.curve.default_sampling


#: clearance reported when no two panels are apart (every pair shares a vertex), m
_NO_NEIGHBOUR = 1e3


def strip_columns(setting: StripSetting, extras: bool = True) -> tuple[Column, ...]:
    """Performance columns of a setting: per load ``stiff`` (and ``snap``), then ``error``
    (and, with ``extras``, ``closest_error`` and ``mass``)."""
    cols = []
    for ld in setting.loads:
        cols.append(
            Column(f"{ld.name}stiff", "N/m", f"secant stiffness under {ld.force:g} N at {ld.at:g}")
        )
        if ld.snap_displacement is not None:
            cols.append(
                Column(
                    f"{ld.name}snap",
                    "-",
                    f"1 if the loaded node moves more than {ld.snap_displacement:g} m",
                )
            )
    cols.append(Column("error", "m", "mean index-matched distance of the centre line to the curve"))
    if extras:
        cols.append(Column("closest_error", "m", "mean closest-point distance to the curve"))
        cols.append(Column("mass", "kg", "mass of the strip (panels and hinge strips)"))
        cols.append(Column("overlap", "m^3", "volume where the folded thick panels intersect",
                           display="mm^3"))  # fmt: skip
        cols.append(Column("clearance", "m", "smallest gap between panels sharing no vertex",
                           display="mm"))  # fmt: skip
        cols.append(Column("thick", "-", "thickness technique of the panels: 0 centred, "
                           "1 offset, 2 tapered (with thick = 'auto' the first whose panels do "
                           "not overlap in the strip's shape)", choices=(0.0, 1.0, 2.0),
                           names=("centred", "offset", "tapered")))  # fmt: skip
    return tuple(cols)


@lru_cache(maxsize=16)
def _topology(m: int) -> CreasePattern:
    """A strip with the right faces, validated once per m (coordinates are replaced per design)."""
    g = strip_geometry(builtin_curve("half-circle", radius=2.0), m, 0.2, 0.02, 0.15)
    return CreasePattern.from_faces(g.nodes, list(g.faces))


def _strip_args(row) -> tuple[int, float, float, float]:
    """Design ``row``'s (m, offset, stripeWidth, extrude), in the order the strip takes them."""
    return int(row["m"]), float(row["offset"]), float(row["stripeWidth"]), float(row["extrude"])


def _row_geometry(setting: StripSetting, row):
    """The analytic strip of design ``row`` on the setting's curve and sampling."""
    return strip_geometry(setting.curve, *_strip_args(row), setting.curve_sampling)


def loaded_node(setting: StripSetting, m: int, at: float, t: np.ndarray | None = None) -> int:
    """Centre-line node nearest to the arc-length fraction ``at`` (node m for 0.5)."""
    if t is None:
        t = strip_geometry(setting.curve, m, 0.2, 0.02, 0.15, setting.curve_sampling).t
    if math.isclose(at, 0.5, abs_tol=1e-12):
        return int(m)  # the middle sample: exactly the apex, whatever the round-off of s(t)
    s = setting.curve.arc_length(t) / setting.curve.length
    return int(np.argmin(np.abs(s - at)))


def check_strip(setting: StripSetting, row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    errs = integer(row, "m", 2)
    if not errs and row["m"] > MAX_M:
        errs.append(f"m = {int(row['m'])} is over the limit of {MAX_M} (4m panels; docs/limits.md)")
    errs += positive(row, ("tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"))
    return errs


def strip_model(setting: StripSetting, row, *, profile=PAPER):
    """The stress-free model with its supports, its geometry and the fitting error.

    Returns
    -------
    structure : Structure
    geometry : StripGeometry
    error : float
        Index-matched fitting error, m.
    """
    return strip_models(setting, [row], profile=profile)[0]


def strip_models(setting: StripSetting, rows, *, profile=PAPER) -> list[tuple]:
    """:func:`strip_model` of several designs, the models of each ``m`` built together
    (:func:`~holofold.mechanics.hinges.build_concentrated_batch`, bit for bit the same)."""
    geoms = [_row_geometry(setting, row) for row in rows]
    out: list = [None] * len(rows)
    by_m: dict = {}
    for i, g in enumerate(geoms):
        by_m.setdefault(g.m, []).append(i)
    for m, idx in by_m.items():
        sups = []
        for i in idx:
            g = geoms[i]
            fixed = {
                "ends": g.ends,
                "centre-ends": g.centre[[0, -1]],
                "side-ends": np.concatenate([g.side_a[[0, -1]], g.side_b[[0, -1]]]),
            }[setting.supports]
            sups.append(support_mask(len(g.nodes) + len(g.faces), fixed, setting.support_dofs))
        col = lambda name, idx=idx: [float(rows[i][name]) for i in idx]  # noqa: E731
        structures = build_concentrated_batch(
            _topology(m),
            np.stack([geoms[i].nodes for i in idx]),
            crease_width=col("W"),
            crease_thickness=col("tcrease"),
            panel_thickness=col("tpanel"),
            E_panel=setting.E,
            E_crease=setting.E,
            nu_panel=setting.nu,
            nu_crease=setting.nu,
            profile=profile,
            supports=sups,
        )
        for i, s in zip(idx, structures, strict=True):
            g = geoms[i]
            out[i] = (s, g, index_matched_error(setting.curve, g.centre_line, g.t))
    return out


def _printability(pattern, tpanel: float, W: float):
    """:func:`holofold.geometry.printability`, imported on first use (it brings trimesh and
    scipy.spatial, a second of start-up for a worker that never needs them)."""
    from holofold.geometry import printability

    return printability(pattern, tpanel, W)


def _mass(setting: StripSetting, g, row) -> float:
    X, F = g.nodes, g.faces
    area = 0.5 * np.linalg.norm(np.cross(X[F[:, 2]] - X[F[:, 0]], X[F[:, 3]] - X[F[:, 1]]), axis=1)
    topo = _topology(g.m)
    e = topo.edges[topo.interior]
    fold_length = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1).sum()
    tp, tc, w = float(row["tpanel"]), float(row["tcrease"]), float(row["W"])
    return setting.density * (area.sum() * tp + fold_length * w * (tc - tp))


def evaluate_strip(setting: StripSetting, columns: Sequence[str], row) -> dict:
    """The ``columns`` of one design (see the module docstring) and a status."""
    return evaluate_strip_batch(setting, columns, [row])[0]


def _non_simple(geometries) -> list[np.ndarray]:
    """:func:`~holofold.geometry.non_simple_faces` of each strip, in one call for all (the
    check is per face: the same faces of each strip as alone)."""
    offsets = np.cumsum([0] + [len(g.nodes) for g in geometries])
    counts = np.cumsum([0] + [len(g.faces) for g in geometries])
    bad = non_simple_faces(
        np.concatenate([g.nodes for g in geometries]),
        np.concatenate(
            [np.asarray(g.faces) + o for g, o in zip(geometries, offsets, strict=False)]
        ),
    )
    return [bad[(bad >= a) & (bad < b)] - a for a, b in zip(counts[:-1], counts[1:], strict=True)]


def strip_batch_key(row) -> int:
    """Designs with the same key (their ``m``) have models of one size: one batch."""
    return int(row["m"])


@single_threaded
def evaluate_strip_batch(setting: StripSetting, columns: Sequence[str], rows) -> list[dict]:
    """:func:`evaluate_strip` of several designs of one ``m``, their Newton solves run in
    lockstep (:func:`~holofold.mechanics.analyses.secant_stiffness_batch`); each output is
    bit for bit the design's own."""
    outs: list = [None] * len(rows)
    models = []
    printable = {}
    built = strip_models(setting, rows)
    overlaps = _non_simple([g for _, g, _ in built]) if setting.refuse_overlap else None
    for i, row in enumerate(rows):
        s, g, err = built[i]
        bad = overlaps[i] if overlaps is not None else ()
        if len(bad):
            outs[i] = {
                **dict.fromkeys(columns, float("nan")),
                "status": Status.failed(
                    f"self-overlapping strip: panel {int(bad[0])} = {g.faces[bad[0]].tolist()} "
                    "is not a simple polygon (its sides cross)"
                ),
            }
            continue
        if "overlap" in columns:
            printable[i] = strip_thickness(setting, row, g)
        models.append((i, s, g, err))
    if not models:
        return outs
    structures = [s for _, s, _, _ in models]
    batch = BatchAssembler(structures)  # one pattern and reduction for every load case
    runs = {}
    for ld in setting.loads:
        groups = [load_along([loaded_node(setting, g.m, ld.at, g.t)], ld.direction)
                  for _, _, g, _ in models]  # fmt: skip
        runs[ld.name] = secant_stiffness_batch(
            structures,
            groups,
            force_per_increment=ld.force / ld.increments,
            increments=ld.increments,
            tol=setting.tol,
            max_iter=setting.max_iter,
            batch=batch,
        )
    for j, (i, _, g, err) in enumerate(models):
        out: dict = {}
        cases = {}
        for ld in setting.loads:
            r = runs[ld.name][j]
            out[f"{ld.name}stiff"] = r.stiffness
            label = f"{ld.name} case"
            if ld.snap_displacement is not None:
                snap = r.displacement > ld.snap_displacement
                out[f"{ld.name}snap"] = 1.0 if snap else 0.0
                label += " (snap-through)" if snap else ""
            cases[label] = r.result.status
        out["error"] = err
        if "closest_error" in columns:
            out["closest_error"] = closest_point_error(
                setting.curve, g.centre_line, both=False
            ).mean
        if "mass" in columns:
            out["mass"] = _mass(setting, g, rows[i])
        if i in printable:
            got = printable[i]
            out["overlap"], out["clearance"], out["thick"] = got.overlap, got.clearance, got.code
        out = {c: out[c] for c in columns}
        out["status"] = Status.gather(cases, worst=Outcome.NOT_CONVERGED)
        outs[i] = out
    return outs


def strip_shape(setting: StripSetting, row) -> CreasePattern:
    """The design's stress-free strip (3-D pattern in the x-z plane, m)."""
    return _fit(setting, row).pattern


def _fit(setting: StripSetting, row):
    return fit_strip(setting.curve, *_strip_args(row), sampling=setting.curve_sampling)


def strip_view(setting: StripSetting, row):
    """The design from its flat development to the strip over the curve, with the supported
    nodes, the loads and the target curve (:class:`~holofold.design.report.view.DesignView`)."""
    from holofold.design.report.view import DesignView, Load

    fit = _fit(setting, row)
    pat = fit.flat_pattern if fit.flat is not None else fit.pattern
    g = _row_geometry(setting, row)
    ends = {
        "ends": g.ends,
        "centre-ends": g.centre[[0, -1]],
        "side-ends": np.concatenate([g.side_a[[0, -1]], g.side_b[[0, -1]]]),
    }
    fixed = ends[setting.supports]
    frames, labels = [pat.coords], ["folded over the curve"]
    if fit.flat is not None:
        flat = np.column_stack([fit.flat, np.zeros(len(fit.flat))])
        frames, labels = [flat, pat.coords], ["flat, as printed", "folded over the curve"]
    loads = tuple(
        Load(loaded_node(setting, g.m, ld.at, g.t), ld.direction, f"{ld.name}: {ld.force:g} N")
        for ld in setting.loads
    )
    c = setting.curve(np.linspace(0.0, 1.0, 200))
    curve = np.column_stack([c[:, 0], np.zeros(len(c)), c[:, 1]])
    e = pat.edges
    return DesignView(
        frames=np.stack(frames), labels=tuple(labels), faces=[list(f) for f in pat.faces],
        edges=e, kinds="".join(str(a)[0] for a in pat.assignment), supports=fixed, loads=loads,
        curve=curve,
        facts=(("supports", f"{SUPPORTS[setting.supports]}, fixed in {setting.support_dofs}"),),
    )  # fmt: skip


def strip_thickness(setting: StripSetting, row, geometry=None):
    """The design's thick panels in the strip's shape
    (:class:`~holofold.geometry.ThicknessChoice`): centred panels, or with
    ``setting.thick`` another technique or "auto" (the first of centred, offset and tapered
    whose panels do not overlap: :func:`~holofold.geometry.choose_thickness` on the
    strip's flat development and shape). ``geometry``: the design's strip, if built. A strip is
    not folded from flat in the model, so only its final shape is checked."""

    tp, w = float(row["tpanel"]), float(row["W"])
    fit = None
    if geometry is None:
        fit = _fit(setting, row)
        geometry = fit.geometry
    p = _printability(CreasePattern.from_faces(geometry.nodes, list(geometry.faces)), tp, w)
    centred = ThicknessChoice("centred", float(p.overlap),
                              float(min(p.clearance, _NO_NEIGHBOUR)), ("centred",))  # fmt: skip
    clear = centred.overlap <= 1e-12 and not centred.clearance < 0
    if setting.thick == "centred" or (setting.thick == "auto" and clear):
        return centred
    flat = (fit or _fit(setting, row)).flat_pattern
    if flat is None:  # no valid development: nothing but centred panels to judge
        return centred
    got = choose_thickness(flat, tp, w, thick=setting.thick, no_neighbour=_NO_NEIGHBOUR)
    if got.technique == "centred":  # none folds clear: centred, as measured on the strip
        return ThicknessChoice("centred", centred.overlap, centred.clearance, got.tried)
    return got


def strip_part(setting: StripSetting, row):
    """The printable part: the strip's flat development, printed with panels of ``tpanel``
    joined by hinge strips of ``tcrease`` and width ``W``
    (:class:`~holofold.design.loop.buildability.PrintablePart`; None if the development
    overlaps)."""
    from holofold.design.loop.buildability import PrintablePart

    fit = _fit(setting, row)
    if fit.flat is None:
        return None
    got = strip_thickness(setting, row)
    return PrintablePart(
        fit.flat_pattern, float(row["tpanel"]), float(row["tcrease"]), float(row["W"]),
        thick=got.technique,
    )  # fmt: skip


def write_strip_files(setting: StripSetting, row, folder, units: str = "mm", cutter=None):
    """The design's fabrication set (:func:`~holofold.fitting.write_strip_set`): the printable
    part (flat panels of ``tpanel`` joined by hinge strips of ``tcrease`` and width ``W``) flat and
    folded, FOLD, SVG and DXF for ``cutter`` (a :class:`~holofold.geometry.CutterOptions`), STL/OBJ
    of the folded strip and its thick panels. Meshes in ``units``.
    """
    from holofold.fitting import write_strip_set  # trimesh: only for files

    return write_strip_set(
        _fit(setting, row),
        folder,
        panel_thickness=float(row["tpanel"]),
        crease_width=float(row["W"]),
        crease_thickness=float(row["tcrease"]),
        units=units,
        cutter=cutter,
        thick=strip_thickness(setting, row).technique,
    )


def strip_scenario(
    name: str,
    description: str,
    setting: StripSetting,
    features: tuple[Column, ...] = STRIP_FEATURES,
    *,
    extras: bool = True,
    source: str = "",
) -> Scenario:
    """The :class:`Scenario` of a strip setting (picklable for worker processes)."""
    perf = strip_columns(setting, extras)
    words = {
        "curve": setting.curve_label or setting.curve.name,
        "curve length (m)": setting.curve.length,
        "E (Pa)": setting.E,
        "nu": setting.nu,
        "density (kg/m^3)": setting.density,
        "supports": f"{SUPPORTS[setting.supports]}, fixed in {setting.support_dofs}",
    }
    for ld in setting.loads:
        d = ", ".join(f"{v:g}" for v in ld.direction)
        snap = "" if ld.snap_displacement is None else f", snap above {ld.snap_displacement:g} m"
        words[f"load {ld.name}"] = (
            f"{ld.force:g} N along ({d}) at {ld.at:g} of the arc length, "
            f"{ld.increments} increments{snap}"
        )
    return Scenario(
        name=name,
        description=description,
        features=features,
        performance=perf,
        check=partial(check_strip, setting),
        evaluate=partial(evaluate_strip, setting, tuple(c.name for c in perf)),
        evaluate_batch=partial(evaluate_strip_batch, setting, tuple(c.name for c in perf)),
        batch_key=strip_batch_key,
        categorical=tuple(c.name for c in features if c.choices),
        kind="strip",
        setting=words,
        source=source,
        **setting_hooks(setting, strip_shape, write_strip_files, strip_view, strip_part),
    )


# ---------------------------------------------------------------------- scenario files
def _read_curve(sec: Section) -> tuple[PlanarCurve, str, str | None]:
    """The ``[curve]`` table: a built-in with its parameters, or a points/SVG file in units."""
    given = [k for k in ("builtin", "points", "svg") if sec.has(k)]
    if len(given) != 1:
        raise sec.error("give exactly one of builtin = ..., points = ..., svg = ...")
    sampling = sec.choice("sampling", ("paper", "arclength"))
    try:
        if given[0] == "builtin":
            key = sec.choice("builtin", tuple(sorted(BUILTIN_CURVES)))
            params = {
                k: sec.number(k) for k in BUILTIN_CURVES[key][1] if sec.has(k)
            }  # only the built-in's own parameters; anything else is refused below
            sec.done(["builtin", "sampling", *BUILTIN_CURVES[key][1]])
            curve = builtin_curve(key, **params)
            label = key + "".join(f", {k} = {v:g}" for k, v in params.items())
            return curve, label, sampling
        unit = sec.choice("units", tuple(LENGTH_UNITS))
        if unit is None and given[0] == "points":
            raise sec.error("units = ... is required for a points file; allowed: "
                            + ", ".join(LENGTH_UNITS))  # fmt: skip
        file = sec.path(given[0])
        if given[0] == "points":
            columns = sec.raw("columns")
            if columns is not None and not (
                isinstance(columns, list) and len(columns) == 2
                and all(isinstance(c, str | int) and not isinstance(c, bool) for c in columns)
            ):  # fmt: skip
                raise sec.error(f"columns = {columns!r} must be two column names or positions")
            curve = read_points_csv(file, units=unit, columns=columns)
        else:  # without units: the drawing's own (width/height units and viewBox)
            frag = sec.raw("svg").partition("#")[2]
            curve = read_svg_curve(f"{file}#{frag}" if frag else file, units=unit)
        keys = ["svg"] if given[0] == "svg" else ["points", "columns"]
        sec.done([*keys, "units", "sampling"])
        shown = unit or "the drawing's units"
        return curve, f"{given[0]} from {file.name} ({shown})", sampling
    except ValueError as exc:
        if str(exc).startswith(sec.where):
            raise
        raise sec.error(str(exc)) from None


def _read_load(sec: Section, names: set) -> StripLoad:
    load = StripLoad(
        name=load_name(sec, names, "'Z' or 'tip'"),
        at=sec.number("at", low=0.0, high=1.0) if sec.has("at") else _missing(sec, "at"),
        direction=read_direction(sec),
        force=sec.number("force", low=0.0, low_open=True) if sec.has("force")
        else _missing(sec, "force"),
        increments=sec.number("increments", 5, low=1, high=1000, integer=True),
        snap_displacement=sec.number("snap_displacement", low=0.0, low_open=True),
    )  # fmt: skip
    sec.done(["name", "at", "direction", "force", "increments", "snap_displacement"])
    check_plausible(sec, "force", load.force, *FORCE)
    return load


def _missing(sec: Section, key: str):
    raise sec.error(f"missing key {key!r}")


def from_config(doc: Section, name: str, description: str) -> Scenario:
    """The strip scenario of a parsed scenario file (``kind = "strip"``)."""
    curve, label, sampling = _read_curve(doc.sub("curve", required=True))
    E, nu, density = read_material(doc)
    sup = doc.sub("supports")
    supports = sup.choice("nodes", tuple(SUPPORTS), "ends")
    dofs = read_dofs(sup)
    sup.done()
    tol, max_iter = read_solver(doc)
    loads = read_loads(doc, _read_load)
    setting = StripSetting(
        curve=curve,
        loads=tuple(loads),
        E=E,
        nu=nu,
        density=density,
        supports=supports,
        support_dofs=dofs,
        tol=tol,
        max_iter=max_iter,
        sampling=sampling,
        curve_label=label,
        thick=doc.choice("thick", THICK_CHOICES, "auto"),
    )
    features = read_features(doc.sub("features"), STRIP_FEATURES, kind="strip")
    for c in features:
        if c.name != "m":
            continue
        levels = c.choices or (c.low, c.high)
        if not all(v >= 2 and v == int(v) for v in levels):
            raise doc.error(f"[features] m must be integers >= 2, got {levels}")
        if max(levels) > MAX_M:
            raise doc.error(f"[features] m = {levels}: at most {MAX_M} (4m panels; docs/limits.md)")
    _check_loads_off_supports(doc, setting, features)
    return strip_scenario(name, description, setting, features)


def _check_loads_off_supports(doc: Section, setting: StripSetting, features) -> None:
    """Refuse a load whose node is a support fixed along the load (for the smallest ``m``,
    the coarsest snapping, and every ``m`` of a list of choices): it would carry nothing and
    every row would give a non-finite or meaningless stiffness."""
    if setting.supports == "side-ends":
        return  # the loads act on the centre line
    m = next(c for c in features if c.name == "m")
    levels = sorted({int(v) for v in m.choices}) if m.choices else [int(m.low)]
    axes = ["xyz".index(a) for a in setting.support_dofs]
    for k, ld in enumerate(setting.loads, start=1):
        if not any(ld.direction[a] for a in axes):
            continue  # along free directions only
        for level in levels:
            g = strip_geometry(setting.curve, level, 0.2, 0.02, 0.15, setting.curve_sampling)
            node = loaded_node(setting, level, ld.at, g.t)
            if node in (int(g.centre[0]), int(g.centre[-1])):
                raise doc.error(
                    f"[load] {k}: at = {ld.at:g} puts the load on a support (the end node "
                    f"{node} of the centre line for m = {level}, fixed in "
                    f"{setting.support_dofs!r}): it would carry nothing; move it inside the "
                    "arc, away from the supported ends"
                )
