"""Simulate a user's crease pattern: fold it towards its fold angles, then load it.

:func:`simulate_pattern` takes any :class:`~holofold.geometry.pattern.CreasePattern` (read
from FOLD, SVG, DXF or ORIPA by :func:`holofold.geometry.read_pattern`) and a
:class:`PatternSetting` (material, section, fold fraction, supports and loads by named vertex
sets, :mod:`holofold.geometry.vertex_sets`) and returns a :class:`PatternSimulation`:

1. the fold by rest-angle actuation (:func:`holofold.mechanics.fold_pattern`) towards
   ``fold`` x the pattern's fold angles, with its verdict;
2. every load from the folded state (Newton-Raphson load control from that equilibrium, the
   supports replacing the fold's), its secant stiffness (N/m) and status;
3. the energy and the largest strain and bend of every panel in the folded state, the mass, and
   whether the folded thick panels run into each other (overlap, clearance:
   :func:`holofold.geometry.printability`);
4. one honest status line: the verdict, how far it folded, any snap, collision or load that did
   not converge.

:func:`write_simulation` writes the files: ``folded.fold`` (the crease pattern as key frame,
the fold path as frames), ``folded.stl`` and ``folded.obj`` (the last state, mm),
``panels.csv`` (energy, strain, bend per panel), ``simulation.json`` and ``picture.png``.
"""

from __future__ import annotations

import csv
import math
import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from holofold.geometry import CreasePattern, ParameterError, check_range, choose_thickness
from holofold.geometry.errors import EnvironmentFault
from holofold.geometry.physical import check_sheet
from holofold.geometry.vertex_sets import VertexSet, parse_vertex_set
from holofold.mechanics.contact import INSTALL as CONTACT_INSTALL
from holofold.mechanics.contact import has_ipctk
from holofold.mechanics.folding import MODELS, FoldResult, crease_classes, fold_pattern
from holofold.mechanics.materials import Material, get_material
from holofold.mechanics.status import Status

__all__ = [
    "PatternLoad",
    "PatternSetting",
    "LoadOutcome",
    "PatternSimulation",
    "simulate_pattern",
    "write_simulation",
    "plot_simulation",
    "pattern_mass",
    "check_physical",
    "scaled_pattern",
]


@dataclass(frozen=True)
class PatternLoad:
    """A force shared by a set of vertices, applied to the folded pattern.

    Attributes
    ----------
    name : str
        Label (a column prefix in scenario files).
    at : VertexSet
        The loaded vertices (each takes an equal share).
    direction : (3,) float
        Direction of the force (normalised).
    force : float
        Total force after the last increment, N.
    increments : int
        Equal load increments.
    """

    name: str
    at: VertexSet
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    force: float = 1.0
    increments: int = 5

    def __post_init__(self):
        object.__setattr__(self, "at", parse_vertex_set(self.at))
        d = np.asarray(self.direction, float)
        if d.shape != (3,) or not np.isfinite(d).all() or not d.any():
            raise ParameterError(
                f"load {self.name}: direction {self.direction!r} must be a non-zero 3-vector"
            )
        object.__setattr__(self, "direction", tuple(float(x) for x in d))
        check_range(f"load {self.name}: force", self.force, 0.0, None, low_open=True)
        if int(self.increments) != self.increments or self.increments < 1:
            raise ParameterError(f"load {self.name}: increments must be an integer >= 1")


@dataclass(frozen=True)
class PatternSetting:
    """What a pattern is simulated with (SI units).

    Attributes
    ----------
    material : Material
    panel_thickness, crease_thickness, crease_width : float
        m.
    fold : float
        Fold fraction in [0, 1] (Origami Simulator's fold percent / 100).
    model : str
        ``concentrated`` or ``compliant``.
    supports : tuple of VertexSet
        Vertices held during the loads (their ``support_dofs``); the fold holds one panel.
    support_dofs : str
        Fixed directions of the support vertices, some of ``"xyz"``.
    loads : tuple of PatternLoad
    tol : float
        Newton tolerance of the loads on ||dU||, m.
    max_iter : int
        Newton iteration cap per increment.
    max_step_deg : float
        Largest rest-angle change per fold step, degrees.
    collisions : bool
        Check the folded thick panels for collisions.
    contact : bool or "auto"
        Barrier contact between the thick panels while folding
        (:mod:`holofold.mechanics.contact`, needs ``holofold[contact]``): the layers are held a
        panel thickness apart, and the fold stops where they cannot go on. ``"auto"``
        (default): on where IPC Toolkit is installed, else off (the intersection check still
        stops a fold at its last clean state; :attr:`contact_on` says which); True: on,
        refused before any work without IPC Toolkit; False: off.
    thick : str
        The thickness technique of the panels checked (``"centred"``, ``"offset"``,
        ``"tapered"``) or ``"auto"`` (default): the first of them that folds without overlap
        (:func:`holofold.geometry.choose_thickness`, over up to four states of the
        fold path).
    """

    material: Material = field(default_factory=lambda: get_material("pp"))
    panel_thickness: float = 1e-3
    crease_thickness: float = 0.3e-3
    crease_width: float = 1e-3
    fold: float = 1.0
    model: str = "concentrated"
    supports: tuple = ()
    support_dofs: str = "xyz"
    loads: tuple = ()
    tol: float = 1e-9
    max_iter: int = 30
    max_step_deg: float = 3.0
    collisions: bool = True
    thick: str = "auto"
    contact: bool | str = "auto"

    def __post_init__(self):
        if isinstance(self.material, str):
            object.__setattr__(self, "material", get_material(self.material))
        for k in ("panel_thickness", "crease_thickness", "crease_width"):
            check_range(k, getattr(self, k), 0.0, None, low_open=True)
        check_range("fold", self.fold, 0.0, 1.0)
        if self.model not in MODELS:
            raise ParameterError(f"model = {self.model!r}; allowed: {', '.join(MODELS)}")
        object.__setattr__(self, "supports", tuple(parse_vertex_set(s) for s in self.supports))
        dofs = self.support_dofs
        if not dofs or set(dofs) - set("xyz") or len(set(dofs)) != len(dofs):
            raise ParameterError(f"support_dofs = {dofs!r} must be some of 'x', 'y', 'z'")
        names = [ld.name for ld in self.loads]
        if len(set(names)) != len(names):
            raise ParameterError(f"load names must differ: {names}")
        if self.loads and not self.supports:
            raise ParameterError("loads need supports: give the vertices that hold the pattern")
        if not (self.contact is True or self.contact is False or self.contact == "auto"):
            raise ParameterError(f"contact = {self.contact!r}; allowed: 'auto', True, False")
        if self.contact is True and not has_ipctk():  # before any work
            raise EnvironmentFault(CONTACT_INSTALL)

    @property
    def contact_on(self) -> bool:
        """Whether the fold runs with barrier contact (``contact`` "auto": where installed)."""
        return has_ipctk() if self.contact == "auto" else bool(self.contact)


@dataclass(frozen=True)
class LoadOutcome:
    """The result of one load on the folded pattern.

    Attributes
    ----------
    name : str
    stiffness : float
        Total force / mean displacement of the loaded vertices along the force, N/m.
    displacement : float
        That mean displacement, m.
    status : Status
    """

    name: str
    stiffness: float
    displacement: float
    status: Status


@dataclass(frozen=True, eq=False)
class PatternSimulation:
    """A simulated pattern (see the module docstring)."""

    pattern: CreasePattern
    setting: PatternSetting
    fold: FoldResult
    loads: tuple[LoadOutcome, ...]
    mass: float
    overlap: float | None
    clearance: float | None
    closest: tuple[int, int] | None
    seconds: float
    thick: str = "centred"

    @property
    def folded(self) -> CreasePattern:
        """The pattern in its last folded state."""
        return self.fold.folded()

    @property
    def collision(self) -> bool:
        """Thick panels that share no vertex run into each other in the folded state (centred
        panels: a negative clearance; offset and tapered ones: any overlap along the path)."""
        if self.thick != "centred":
            return bool(self.overlap is not None and self.overlap > 1e-12)
        return bool(self.clearance is not None and self.clearance < 0)

    @property
    def panel_bending(self) -> float:
        """The largest bend of a panel in the last state, degrees: |fold angle| over the
        panels' own lines (F and J edges inside the sheet: a facet or a triangulation line)."""
        p = self.fold.pattern
        inside = np.isin(p.assignment, ("F", "J")) & p.interior
        if not inside.any():
            return 0.0
        return float(np.abs(np.asarray(self.fold.fold_angles[-1], float)[inside]).max())

    @property
    def status(self) -> Status:
        """Converged when the fold reached its fraction and every load converged."""
        parts = {"fold": self.fold.status, **{f"load {o.name}": o.status for o in self.loads}}
        return Status.gather(parts)

    def status_line(self) -> str:
        """One line: verdict, fraction reached, snaps, collision, loads."""
        f = self.fold
        text = f"{f.verdict}: reached {100 * f.reached:.0f} % of {100 * f.requested:.0f} % "
        text += f"(fold progress {100 * f.progress:.0f} %); {f.note}"
        bend = self.panel_bending
        if bend > 5.0:
            text += (
                f"; panels bend by up to {bend:.0f} deg across their facet lines (the pattern "
                "does not fold with flat panels)"
            )
        if self.thick != "centred":
            text += (
                f"; {self.thick} panels fold without collision"
                if not self.collision
                else f"; {self.thick} panels overlap by {1e9 * self.overlap:.3g} mm^3"
            )
        elif self.clearance is not None and self.clearance < 0:
            a, b = self.closest or (-1, -1)
            text += (
                f"; collision: thick panels {a} and {b} run into each other (clearance "
                f"{1e3 * self.clearance:.3g} mm)"
            )
        elif self.overlap:
            text += (
                f"; thick panels overlap by {1e9 * self.overlap:.3g} mm^3 at their creases "
                "(thickness not accommodated)"
            )
        elif self.overlap is not None:
            text += "; no collision"
        for o in self.loads:
            state = "" if o.status.converged else f" ({o.status.outcome.value})"
            text += f"; {o.name} {o.stiffness:.4g} N/m{state}"
        return text


def scaled_pattern(pattern: CreasePattern, factor: float) -> CreasePattern:
    """``pattern`` with every length multiplied by ``factor`` (its curved creases too)."""
    check_range("scale factor", factor, 0.0, None, low_open=True)
    flat = None if pattern.flat is None else pattern.flat * factor
    curves = tuple(c.mapped(factor) for c in pattern.curves)
    return replace(pattern, coords=pattern.coords * factor, flat=flat, curves=curves)


def pattern_mass(pattern: CreasePattern, setting: PatternSetting) -> float:
    """density x (panel area x tpanel + crease length x W x (tcrease - tpanel)), kg, of the flat
    sheet: panels of the panel thickness, thinned to the crease thickness over a strip of the
    crease width along every crease (facets, F and J, are not thinned)."""
    xy = pattern.flat if pattern.flat is not None else pattern.coords[:, :2]
    area = 0.0
    for f in pattern.faces:
        p = xy[f]
        area += 0.5 * abs(
            np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1])
        )
    cls = crease_classes(pattern)
    creases = (cls == 0) | (cls == 2)
    e = pattern.edges[creases]
    length = float(np.linalg.norm(xy[e[:, 1]] - xy[e[:, 0]], axis=1).sum())
    s = setting
    return float(
        s.material.density
        * (
            area * s.panel_thickness
            + length * s.crease_width * (s.crease_thickness - s.panel_thickness)
        )
    )


def check_physical(pattern: CreasePattern, setting: PatternSetting) -> None:
    """Refuse, in one line, a sheet that cannot exist (geometry.physical.check_sheet: extent,
    thicknesses, creases wider than the panels between them allow) or a mass that is not
    positive. Raises :class:`ParameterError`."""
    s = setting
    check_sheet(pattern, panel_thickness=s.panel_thickness, crease_thickness=s.crease_thickness,
                crease_width=s.crease_width)  # fmt: skip
    m = pattern_mass(pattern, s)
    if not m > 0:
        raise ParameterError(
            f"the sheet would weigh {m * 1e3:.4g} g: its crease strips "
            f"({s.crease_width * 1e3:.4g} mm wide) take more than its panels; give a narrower "
            "crease width"
        )


def simulate_pattern(pattern: CreasePattern, setting: PatternSetting) -> PatternSimulation:
    """Fold ``pattern`` and load it as ``setting`` says (see the module docstring)."""
    from holofold.mechanics.analyses import load_along, secant_stiffness

    t0 = time.perf_counter()
    s = setting
    # vertex sets first: a bad set is refused before anything is computed
    sup_ids = [v.select(pattern) for v in s.supports]
    load_ids = [ld.at.select(pattern) for ld in s.loads]
    check_physical(pattern, s)
    fold = fold_pattern(
        pattern, s.fold, panel_thickness=s.panel_thickness, crease_thickness=s.crease_thickness,
        crease_width=s.crease_width, E=s.material.E, nu=s.material.nu, model=s.model,
        max_step_deg=s.max_step_deg, contact=s.contact_on,
    )  # fmt: skip
    outcomes = []
    if s.loads:
        held = np.unique(np.concatenate(sup_ids))
        _check_supports(pattern, fold.coords[-1], held, s.support_dofs)
        st = fold.structure.with_rest_angles(fold.rest)
        st = st.fixed(st.vertex_nodes(held), s.support_dofs)
        U0 = fold.U[-1]
        for ld, ids in zip(s.loads, load_ids, strict=True):
            free_ids = np.setdiff1d(ids, held) if s.support_dofs == "xyz" else ids
            if not free_ids.size:
                raise ParameterError(f"load {ld.name}: every vertex of {ld.at} is a support")
            group = load_along(st.vertex_nodes(free_ids), ld.direction)
            try:
                res = secant_stiffness(
                    st, group, force_per_increment=ld.force / ld.increments,
                    increments=ld.increments, tol=s.tol, max_iter=s.max_iter, U0=U0,
                )  # fmt: skip
                outcomes.append(
                    LoadOutcome(ld.name, res.stiffness, res.displacement, res.result.status)
                )
            except (ArithmeticError, RuntimeError, ValueError) as exc:
                outcomes.append(
                    LoadOutcome(ld.name, math.nan, math.nan, Status.from_exception(exc))
                )
    overlap = clearance = closest = None
    thick = "centred"
    if s.collisions:
        from holofold.geometry import printability

        try:
            pr = printability(fold.folded(), s.panel_thickness, s.crease_width)
            overlap, clearance, closest = pr.overlap, pr.clearance, pr.closest
        except ValueError:  # panels too small for the crease width: no thick panels
            pass
        clash = overlap is not None and (overlap > 1e-12 or (clearance or 0.0) < 0)
        if overlap is not None and (s.thick not in ("auto", "centred")
                                    or (s.thick == "auto" and clash)):  # fmt: skip
            k = len(fold.coords)
            way = [fold.folded(int(i)) for i in np.unique(np.linspace(0, k - 1, 5).round())[1:-1]]
            try:
                got = choose_thickness(fold.folded(), s.panel_thickness, s.crease_width,
                                       path=way, thick=s.thick, no_neighbour=math.inf)  # fmt: skip
                overlap, clearance, thick = got.overlap, got.clearance, got.technique
            except ValueError:
                pass
    return PatternSimulation(
        pattern=pattern, setting=s, fold=fold, loads=tuple(outcomes),
        mass=pattern_mass(pattern, s), overlap=overlap, clearance=clearance, closest=closest,
        seconds=time.perf_counter() - t0, thick=thick,
    )  # fmt: skip


def _check_supports(pattern: CreasePattern, X: np.ndarray, held: np.ndarray, dofs: str) -> None:
    """Refuse supports that leave the folded pattern (vertices ``X``) free to turn as a rigid
    body: every connected piece needs three held vertices not on one line, all three
    directions fixed (with fewer directions the solve says whether it converged)."""
    if dofs != "xyz":
        return
    xy = X
    from holofold.mechanics.folding import _components

    label = _components(pattern)
    vert_piece = np.full(pattern.n_vertices, -1)
    for k, f in enumerate(pattern.faces):
        vert_piece[f] = label[k]
    size = float(np.ptp(xy, axis=0).max())
    for c in np.unique(label):
        ids = held[vert_piece[held] == c]
        P = xy[ids] - xy[ids].mean(axis=0) if ids.size else np.zeros((0, 3))
        rank_ok = ids.size >= 3 and np.linalg.svd(P, compute_uv=False)[1] > 1e-6 * size
        if not rank_ok:
            where = (
                "the pattern" if len(np.unique(label)) == 1 else f"piece {int(c)} of the pattern"
            )
            raise ParameterError(
                f"the supports hold {ids.size} vertex(es) of {where}"
                + (", on one line in the folded state" if ids.size >= 3 else "")
                + ": it can still turn as a whole; hold at least three vertices not on one line "
                "(e.g. near:X,Y,4, or two sides)"
            )


def _summary(sim: PatternSimulation) -> dict:
    s, f = sim.setting, sim.fold
    m = s.material
    return {
        "status": str(sim.status),
        "status_line": sim.status_line(),
        "pattern": {
            "source": sim.pattern.meta.get("source", ""),
            "vertices": sim.pattern.n_vertices,
            "edges": sim.pattern.n_edges,
            "panels": sim.pattern.n_faces,
            "size_m": [
                float(x)
                for x in np.ptp(
                    sim.pattern.flat if sim.pattern.flat is not None else sim.pattern.coords, axis=0
                )
            ],  # fmt: skip
        },
        "setting": {
            "material": {"name": m.name, "E_Pa": m.E, "nu": m.nu, "density_kg_m3": m.density},
            "panel_thickness_m": s.panel_thickness,
            "crease_thickness_m": s.crease_thickness,
            "crease_width_m": s.crease_width,
            "fold_fraction": s.fold,
            "model": s.model,
            "supports": [str(v) for v in s.supports],
            "support_dofs": s.support_dofs,
            "contact": s.contact_on,
        },
        "fold": {
            "verdict": f.verdict,
            "note": f.note,
            "requested": f.requested,
            "reached": f.reached,
            "progress": f.progress,
            "steps": len(f.fractions) - 1,
            "snaps_at": [float(x) for x in f.snaps],
            "wrong_at": _num(f.wrong_at),
            "touch_at": _num(f.touch_at),
            "touch_faces": list(f.touch_where) if f.touch_where[0] >= 0 else None,
            "energy_J": f.energy.total,
            "largest_panel_strain": float(f.energy.panel_strain.max(initial=0.0)),
            "largest_triangle_strain": float(f.energy.triangle_strain.max(initial=0.0)),
            "largest_panel_bend_deg": float(np.degrees(f.energy.panel_bend.max(initial=0.0))),
        },
        "loads": [
            {
                "name": o.name,
                "stiffness_N_m": _num(o.stiffness),
                "displacement_m": _num(o.displacement),
                "status": str(o.status),
                "at": str(ld.at),
                "direction": list(ld.direction),
                "force_N": ld.force,
                "increments": ld.increments,
            }
            for o, ld in zip(sim.loads, s.loads, strict=True)
        ],  # fmt: skip
        "mass_kg": sim.mass,
        "overlap_m3": sim.overlap,
        "thick": sim.thick,
        "panel_bending_deg": sim.panel_bending,
        "clearance_m": _num(sim.clearance) if sim.clearance is not None else None,
        "seconds": sim.seconds,
    }


def _num(x):
    return float(x) if x is not None and math.isfinite(x) else None


def write_simulation(sim: PatternSimulation, folder, units: str = "mm") -> list[Path]:
    """The files of a simulation in ``folder`` (created): ``folded.fold``, ``folded.stl``,
    ``folded.obj`` (meshes in ``units``), ``panels.csv``, ``simulation.json`` and
    ``picture.png``; returns their paths. Everything is built before the first is written."""
    from holofold.geometry import atomic_write, export, write_json, write_text
    from holofold.geometry.fold_frames import export_fold_path

    f = sim.fold
    s = sim.setting
    fold_text = export_fold_path(
        f.pattern, f.coords, f.fractions, f.fold_angles,
        crease_width=np.where(f.pattern.interior, s.crease_width, 0.0),
        crease_thickness=np.where(f.pattern.interior, s.crease_thickness, 0.0),
        panel_thickness=s.panel_thickness,
        title=str(sim.pattern.meta.get("source", "pattern")),
    )  # fmt: skip
    summary = _summary(sim)
    folded = sim.folded
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    written = [write_text(out / "folded.fold", fold_text)]
    written.append(export(folded, out / "folded.stl", units=units))
    written.append(export(folded, out / "folded.obj", units=units))
    e = f.energy

    def rows(tmp):
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["panel", "energy_J", "largest_strain", "largest_bend_deg"])
            for k in range(sim.pattern.n_faces):
                w.writerow([k, f"{e.panel_energy[k]:.6g}", f"{e.panel_strain[k]:.6g}",
                            f"{math.degrees(e.panel_bend[k]):.6g}"])  # fmt: skip

    written.append(atomic_write(out / "panels.csv", rows))
    written.append(write_json(out / "simulation.json", summary))
    written.append(plot_simulation(sim, out / "picture.png"))
    return written


_COLOURS = {"M": "#e41a1c", "V": "#1f5fd6", "B": "#000000", "C": "#2ca02c", "F": "#d4b000",
            "J": "#d4b000", "U": "#c51bc5"}  # fmt: skip


def plot_simulation(sim: PatternSimulation, path: str | os.PathLike) -> Path:
    """A picture: the crease pattern as read, and the folded state (an orthographic view, the
    panels sorted by depth) coloured by how far each panel bends, with the status line as the
    title; PNG, drawn with Pillow (:mod:`holofold.mechanics._picture`: no matplotlib, 0.4 s of
    import and 1 s of layout less per run)."""
    from holofold.geometry import atomic_write
    from holofold.mechanics._picture import simulation_picture

    p = sim.fold.pattern
    xy = p.flat if p.flat is not None else p.coords[:, :2]

    def save(tmp):
        simulation_picture(
            tmp, flat_xy=xy * 1e3, edges=p.edges, assignment=p.assignment, colours=_COLOURS,
            folded=sim.fold.coords[-1] * 1e3, faces=p.faces,
            bend_deg=np.degrees(sim.fold.energy.panel_bend), reached=sim.fold.reached,
            title=sim.status_line(),
        )  # fmt: skip

    return atomic_write(Path(path), save)
