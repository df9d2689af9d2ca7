"""What the crease-pattern kinds share: supports and loads at vertex sets, their columns, files.

The ``pattern`` and ``surface`` kinds (:mod:`~holofold.design.scenarios.pattern_kind`,
:mod:`~holofold.design.scenarios.surface_kind`) fold a crease pattern and load it with
:func:`~holofold.mechanics.simulate_pattern`: their ``[supports]`` and ``[[load]]``
tables name vertex sets (:mod:`holofold.geometry.vertex_sets`), their rows get a stiffness per
load, the mass, ``overlap`` and ``clearance`` of the same simulation, and their files (as the
sheet kind's) are the fabrication set, without the solids where the thick panels cannot be made.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from holofold.design.scenarios.base import Column
from holofold.design.scenarios.config import (
    Section,
    load_name,
    read_direction,
    read_dofs,
    read_loads,
)
from holofold.geometry import THICK_CODES, CreasePattern, choose_thickness
from holofold.geometry.vertex_sets import parse_vertex_set
from holofold.mechanics import PatternLoad, PatternSimulation
from holofold.mechanics.materials import Material
from holofold.mechanics.status import Status

__all__ = [
    "read_supports_and_loads",
    "describe_material_and_loads",
    "loaded_columns",
    "row_status",
    "write_row_files",
    "row_part",
    "crease_view",
    "surface_lines",
    "THICK_COLUMN",
    "FOLDED_COLUMNS",
    "row_thickness",
    "fold_way",
]

_LOAD_KEYS = ("name", "at", "direction", "force", "increments")


def _read_load(sec: Section, names: set, example: str) -> PatternLoad:
    for k in _LOAD_KEYS:
        sec.raw(k)
    sec.done(list(_LOAD_KEYS))
    name = load_name(sec, names, example)
    at = sec.string("at")
    if not at:
        raise sec.error("missing key 'at' (a vertex set such as 'near:50%,50%,4')")
    if not sec.has("force"):
        raise sec.error("missing key 'force' (total force, N)")
    try:
        return PatternLoad(
            name=name, at=parse_vertex_set(at), direction=read_direction(sec),
            force=sec.number("force", low=0.0, low_open=True),
            increments=sec.number("increments", 5, low=1, high=1000, integer=True),
        )  # fmt: skip
    except ValueError as exc:
        raise sec.error(str(exc)) from None


def read_supports_and_loads(
    doc: Section, example: str, pattern: CreasePattern | None = None
) -> tuple[tuple[str, ...], str, tuple[PatternLoad, ...]]:
    """The ``[supports]`` table (``at``: a vertex set or a list of them, ``dofs``) and the
    ``[[load]]`` tables of a scenario file: (vertex sets held, their DOFs, loads). Every vertex
    set is parsed, and selected on ``pattern`` where the pattern is known before the design;
    loads need supports. ``example`` is a load name for the error that asks for one."""
    sup = doc.sub("supports")
    at = sup.raw("at", [])
    if isinstance(at, str):
        at = [at]
    if not isinstance(at, list) or not all(isinstance(a, str) for a in at):
        raise sup.error(f"at = {at!r} must be a vertex set or a list of them")
    for a in at:
        try:
            held = parse_vertex_set(a)
            if pattern is not None:
                held.select(pattern)
        except ValueError as exc:
            raise sup.error(str(exc)) from None
    dofs = read_dofs(sup)
    sup.done()
    loads = []
    if doc.has("load"):
        loads = read_loads(doc, lambda s, names: _read_load(s, names, example))
    if pattern is not None:
        for ld in loads:
            try:
                ld.at.select(pattern)
            except ValueError as exc:
                raise doc.error(f"[load] {ld.name}: {exc}") from None
    if loads and not at:
        raise sup.error("loads need supports: at = ['side:-x', 'side:+x'] (vertex sets held)")
    return tuple(at), dofs, tuple(loads)


def describe_material_and_loads(
    material: Material, supports: tuple[str, ...], dofs: str, loads: tuple[PatternLoad, ...]
) -> dict:
    """The report's lines for the material, the supports and every load."""
    words = {
        "E (Pa)": material.E,
        "nu": material.nu,
        "density (kg/m^3)": material.density,
        "supports": ", ".join(supports) + f" fixed in {dofs}" if supports else "none (no loads)",
    }
    for ld in loads:
        words[f"load {ld.name}"] = (
            f"{ld.force:g} N along ({', '.join(f'{v:g}' for v in ld.direction)}) shared by "
            f"{ld.at}, {ld.increments} increments, from the folded state"
        )
    return words


def loaded_columns(sim: PatternSimulation) -> dict[str, float]:
    """``{name}stiff`` (N/m) of every load, ``mass`` (kg), ``overlap`` (m^3, NaN where not
    computed), ``clearance`` (m, at most 1000) and ``thick`` (the technique's code) of one
    simulated design."""
    out = {f"{o.name}stiff": o.stiffness for o in sim.loads}
    out["mass"] = sim.mass
    out["overlap"] = math.nan if sim.overlap is None else sim.overlap
    out["clearance"] = math.nan if sim.clearance is None else min(sim.clearance, 1e3)
    out["thick"] = float(THICK_CODES[sim.thick])
    return out


#: the ``thick`` column of the crease-pattern kinds
THICK_COLUMN = Column(
    "thick", "-", "thickness technique of the folded panels: 0 centred, 1 offset, 2 tapered "
    "(the first that folds without collision)", choices=(0.0, 1.0, 2.0),
    names=("centred", "offset", "tapered"),
)  # fmt: skip

#: the columns :func:`loaded_columns` gives after the stiffnesses: mass, overlap, clearance, thick
FOLDED_COLUMNS = (
    Column("mass", "kg", "mass of the flat sheet (panels and thinned creases)"),
    Column("overlap", "m^3", "intersection volume of the folded thick panels"),
    Column("clearance", "m", "smallest gap between folded thick panels sharing no vertex"),
    THICK_COLUMN,
)


def row_thickness(state: CreasePattern, row, path=()):
    """The row's thick panels in ``state`` (:func:`~holofold.design.loop.buildability.
    choose_thickness` with ``thick = "auto"``, over ``path``)."""

    try:
        return choose_thickness(state, float(row["tpanel"]), float(row["W"]), path=tuple(path))
    except ValueError:
        return None


def fold_way(fold, states: int = 3) -> list:
    """Up to ``states`` states of a fold path between its start and end."""
    k = len(fold.coords)
    return [fold.folded(int(i)) for i in np.unique(np.linspace(0, k - 1, states + 2).round())[1:-1]]


def row_status(status: Status) -> Status:
    """A design row's status: a failed simulation counts as not converged (the row is kept,
    its reasons with it)."""
    if not status.converged and status.is_failed:
        return Status.not_converged(*status.reasons)
    return status


def write_row_files(shape: CreasePattern, folder, row, *, units: str = "mm", cutter=None,
                    thick=None, fallback=ValueError, what: str = "no solids",
                    path=None):  # fmt: skip
    """The fabrication set (:func:`~holofold.geometry.write_fabrication_set`) of a design's
    folded ``shape`` with the row's ``tpanel``, ``tcrease`` and ``W`` (m); where the solids
    cannot be made (``fallback``, raised by the writer), every file but the solids with a note
    saying why, and a warning starting with ``what``."""
    from holofold.geometry import FabricationSet, write_fabrication_set  # trimesh: only for files

    W = float(row["W"])
    extra = {} if thick is None else {"thick": thick}
    if path is not None:
        extra["path"] = path
    try:
        return write_fabrication_set(
            shape, folder, panel_thickness=float(row["tpanel"]), crease_width=W,
            crease_thickness=float(row["tcrease"]), units=units, cutter=cutter, **extra,
        )  # fmt: skip
    except fallback as exc:
        warnings.warn(f"{what}: {exc}", stacklevel=3)
        got = write_fabrication_set(shape, folder, crease_width=W, units=units, cutter=cutter)
        return FabricationSet(got.files, (*got.notes, f"no solids: {exc}"))


def row_part(pattern: CreasePattern, row):
    """The printable part of a design whose crease pattern is ``pattern`` (its flat layout;
    a pattern read flat is its own layout), printed with the row's ``tpanel``, ``tcrease`` and
    ``W`` (:class:`~holofold.design.loop.buildability.PrintablePart`); None without a flat
    layout."""
    from dataclasses import replace

    from holofold.design.loop.buildability import PrintablePart

    if pattern.flat is None:
        z = pattern.coords[:, 2]
        if float(np.ptp(z)) > 1e-9 * max(float(np.ptp(pattern.coords, axis=0).max()), 1e-12):
            return None
        pattern = replace(pattern, flat=pattern.coords[:, :2].copy())
    return PrintablePart(pattern, float(row["tpanel"]), float(row["tcrease"]), float(row["W"]))


def _flat_frame(pattern: CreasePattern) -> np.ndarray:
    if pattern.flat is not None:
        return np.column_stack([pattern.flat, np.zeros(pattern.n_vertices)])
    return np.asarray(pattern.coords, float)


def crease_view(
    pattern: CreasePattern,
    states: np.ndarray,
    labels: tuple[str, ...],
    supports: tuple[str, ...],
    loads: tuple[PatternLoad, ...],
    *,
    curve: np.ndarray | None = None,
    curve_name: str = "target curve",
    facts: tuple[tuple[str, str], ...] = (),
):
    """The 3D view (:class:`~holofold.design.report.view.DesignView`) of a crease-pattern design:
    the flat layout, then ``states`` (k, nv, 3) m with their ``labels``; the vertex sets held
    and the loads (one arrow per loaded vertex) selected on ``pattern``; ``curve`` (P, 3) m the
    target drawn over every state."""
    from holofold.design.report.view import DesignView, Load

    frames = np.concatenate([_flat_frame(pattern)[None], np.asarray(states, float)])
    held = (
        np.unique(np.concatenate([parse_vertex_set(a).select(pattern) for a in supports]))
        if supports
        else np.zeros(0, int)
    )
    arrows = tuple(
        Load(int(v), tuple(float(x) for x in ld.direction), f"{ld.name}: {ld.force:g} N shared")
        for ld in loads
        for v in ld.at.select(pattern)
    )
    return DesignView(
        frames=frames, labels=("flat", *labels), faces=[list(f) for f in pattern.faces],
        edges=pattern.edges, kinds="".join(str(a)[0] for a in pattern.assignment),
        supports=held, loads=arrows, curve=curve, curve_name=curve_name, facts=facts,
    )  # fmt: skip


def surface_lines(chart, domain, lines: int = 9, samples: int = 25) -> np.ndarray:
    """One polyline (P, 3) m over a charted surface: ``lines`` u-lines then ``lines`` v-lines
    of the ``domain`` (u0, u1, v0, v1), run back and forth so that the pen never lifts
    (the viewer draws a target as one line). ``chart(u, v)`` -> (points, normals)."""
    u0, u1, v0, v1 = domain
    us, vs = np.linspace(u0, u1, lines), np.linspace(v0, v1, lines)
    ts_u, ts_v = np.linspace(v0, v1, samples), np.linspace(u0, u1, samples)
    uu, vv = [], []
    for k, u in enumerate(us):
        t = ts_u if k % 2 == 0 else ts_u[::-1]
        uu.append(np.full(samples, u))
        vv.append(t)
    for k, v in enumerate(vs[::-1] if lines % 2 else vs):
        t = ts_v[::-1] if lines % 2 else ts_v
        t = t if k % 2 == 0 else t[::-1]
        uu.append(t)
        vv.append(np.full(samples, v))
    pts, _ = chart(np.concatenate(uu), np.concatenate(vv))
    return np.asarray(pts, float)
