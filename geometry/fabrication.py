"""A design's fabrication set: which files, under which stable keys and labels, written how.

Every kind of design (a strip, a sheet, a gripper, a crease pattern read from a file) writes the
same set, described once in :data:`FILES`: a short stable key (what ``design.json`` and the
report use), the file's name (the kind's :class:`FileNames` fill in the stems) and a label for
people. :func:`write_fabrication_set` builds every solid first (anything refused is refused
before the first file is written), then writes, and returns a :class:`FabricationSet`: the
files written, in the order of :data:`FILES`, and notes on the files left out and why.

===================  =====================================  ==================================
key                  file                                   written when
===================  =====================================  ==================================
fold                 ``{pattern}.fold``                     always
svg                  ``{pattern}.svg``                      always (a plan view without layout)
svg_front/svg_back   ``{pattern}_front.svg`` / ``_back``    a two-sided cutter job
dxf                  ``{pattern}.dxf``                      a flat layout exists
surface_stl/_obj     ``{surface}.stl`` / ``.obj``           always
thick                ``{thick}.stl``                        a panel thickness is given
printable            ``printable.stl``                      a crease thickness too
printable_folded     ``printable_folded.stl``               it can be built (else a note)
===================  =====================================  ==================================
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from holofold.geometry.cutter import CutterOptions
from holofold.geometry.cutter_preview import needs_preview
from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.export import export
from holofold.geometry.mesh import MESH_UNITS
from holofold.geometry.pattern import CreasePattern

__all__ = [
    "FabricationFile",
    "FabricationSet",
    "FileNames",
    "FILES",
    "PATTERN_NAMES",
    "STRIP_NAMES",
    "write_fabrication_set",
    "export_pattern_files",
]


@dataclass(frozen=True)
class FileNames:
    """A kind's file stems: ``pattern`` (FOLD, SVG, DXF), ``surface`` (the folded surface
    meshes), ``thick`` (the folded thick panels)."""

    pattern: str = "pattern"
    surface: str = "folded"
    thick: str = "thick"


PATTERN_NAMES = FileNames()
STRIP_NAMES = FileNames("strip", "strip", "strip_solid")

#: key -> (file name template, label template); the order is the order of the set
FILES = {
    "printable": (
        "printable.stl", "STL to print: the flat part, panels joined by hinge strips ({units})"
    ),
    "printable_folded": (
        "printable_folded.stl", "STL of the printable part folded, hinges bent ({units})"
    ),
    "fold": ("{pattern}.fold", "FOLD crease pattern: flat layout and folded state (m)"),
    "svg": ("{pattern}.svg", "SVG of the flat crease pattern, {profile} profile (mm)"),
    "svg_front": (
        "{pattern}_front.svg",
        "SVG, pass 1 (front): registration holes and mountain scores, {profile} profile (mm)",
    ),
    "svg_back": (
        "{pattern}_back.svg",
        "SVG, pass 2 (back, mirrored): valley scores and cuts, {profile} profile (mm)",
    ),
    "preview": (
        "{pattern}_preview.png",
        "PNG preview of the SVG with visible strokes (cutters read the SVG and DXF, not this)",
    ),
    "dxf": (
        "{pattern}.dxf", "DXF of the flat crease pattern, a layer per role, {profile} profile (mm)"
    ),
    "surface_stl": ("{surface}.stl", "STL of the folded surface, zero thickness ({units})"),
    "surface_obj": ("{surface}.obj", "OBJ of the folded surface, zero thickness ({units})"),
    "thick": ("{thick}.stl", "STL of the folded thick panels, loose bodies ({units})"),
}  # fmt: skip
_PLAN_LABEL = "SVG plan view (x-z) of the strip's centre and side lines: no flat layout (mm)"


@dataclass(frozen=True)
class FabricationFile:
    """One written file: its stable ``key``, ``path`` and human ``label``."""

    key: str
    path: Path
    label: str


@dataclass(frozen=True)
class FabricationSet:
    """The files written for a design, in order, and ``notes`` on files left out."""

    files: tuple[FabricationFile, ...]
    notes: tuple[str, ...] = field(default=())

    def __iter__(self) -> Iterator[FabricationFile]:
        return iter(self.files)

    def __len__(self) -> int:
        return len(self.files)

    def __getitem__(self, key: str) -> FabricationFile:
        for f in self.files:
            if f.key == key:
                return f
        raise KeyError(key)

    def __contains__(self, key: object) -> bool:
        return any(f.key == key for f in self.files)

    @property
    def paths(self) -> list[Path]:
        """The written paths, in order."""
        return [f.path for f in self.files]

    def plus(self, key: str, path: Path, label: str) -> FabricationSet:
        """This set with one more file (e.g. a kind's own table)."""
        if key in self:
            raise ValueError(f"the set already has a file {key!r}")
        return FabricationSet((*self.files, FabricationFile(key, Path(path), label)), self.notes)

    def record(self, root: str | os.PathLike | None = None) -> dict[str, dict[str, str]]:
        """``{key: {"path": ..., "label": ...}}`` with paths relative to ``root`` (for JSON)."""
        out = {}
        for f in self.files:
            p = os.path.relpath(f.path, root) if root is not None else str(f.path)
            out[f.key] = {"path": p.replace(os.sep, "/"), "label": f.label}
        return out


def write_fabrication_set(
    folded: CreasePattern,
    folder: str | os.PathLike,
    *,
    flat: CreasePattern | None = None,
    names: FileNames = PATTERN_NAMES,
    panel_thickness: float | None = None,
    crease_width: float = 0.0,
    crease_thickness: float | None = None,
    units: str = MESH_UNITS,
    cutter: CutterOptions | None = None,
    plan_view: str | None = None,
    thick: str = "centred",
    path: Sequence[CreasePattern] | None = None,
) -> FabricationSet:
    """Write a design's fabrication files into ``folder`` (created if needed).

    Parameters
    ----------
    folded : CreasePattern
        The design in its folded state (``coords``), m.
    flat : CreasePattern, optional
        The same pattern with a flat layout (counter-clockwise faces) for the FOLD, SVG, DXF and
        printable files, if ``folded`` has none of its own (a fitted strip's development).
    names : FileNames
        The kind's file stems.
    panel_thickness, crease_width, crease_thickness : float
        t_p, W and t_c, m: ``thick`` with t_p (W >= 0), ``printable`` and ``printable_folded``
        with t_c too (W > 0).
    units : str
        Unit of the mesh files (default mm).
    cutter : CutterOptions
        The SVG and DXF drawing (default: Origami Simulator's convention, one face).
    plan_view : str, optional
        SVG text written as the ``svg`` file when there is no flat layout.
    thick : str
        Thickness accommodation of the ``thick`` and printable files
        (:data:`~holofold.geometry.thick.TECHNIQUES`): "centred" (slabs on the mid-surface, the
        default), "offset" or "tapered" (:func:`~holofold.geometry.thick.thick_panels`).
    path : sequence of CreasePattern, optional
        States on the way to ``folded`` (same pattern) whose overlap is checked and whose fold
        angles bound the bevels; default a Miura sheet's rigid path from flat
        (:func:`~holofold.geometry.thick.miura_path`), else the folded state alone.
    """
    from holofold.geometry.errors import DegenerateGeometryError
    from holofold.geometry.printable import (
        folded_printable,
        folded_printable_solid,
        printable_solid,
    )
    from holofold.geometry.solid import shrunk_panels, thick_solid
    from holofold.geometry.thick import (
        TECHNIQUES,
        miura_path,
        path_overlap,
        thick_panel_mesh,
        thick_panels,
    )
    from holofold.geometry.thick_part import thick_printable
    from holofold.geometry.units import length_factor

    length_factor(units)
    cutter = CutterOptions() if cutter is None else cutter
    layout = flat if flat is not None else (folded if folded.flat is not None else None)
    W = check_range("crease_width", crease_width, 0.0, None)
    solid = part = bent = None
    notes = []
    if crease_thickness is not None:
        if panel_thickness is None or W <= 0:
            raise ParameterError(
                "a printable part needs a panel thickness and a crease width > 0 besides the "
                "crease thickness"
            )
        tc = check_range("crease_thickness", crease_thickness, 0.0, None, low_open=True)
        if layout is None:
            raise ParameterError(
                "this design has no flat layout (its development overlaps): no printable part"
            )
    if thick not in TECHNIQUES:
        known = ", ".join(TECHNIQUES)
        raise ParameterError(f"unknown thickness technique {thick!r}; known: {known}")
    if panel_thickness is not None and thick != "centred":
        t = check_range("panel_thickness", panel_thickness, 0.0, None, low_open=True)
        shrunk_panels(folded, W)
        geo = layout if layout is not None else folded  # one face orientation for both states
        if path is None:
            path = miura_path(geo, 10) if geo.meta.get("kind") == "miura" else ()
        panels = thick_panels(geo, t, W, thick, path=path)
        over = path_overlap([*path, geo], panels)
        solid = thick_panel_mesh(geo, panels)
        where = {1: "above the hinge face", -1: "below the hinge face", 0: "centred"}
        checked = f"{len(path) + 1} states of the fold path" if len(path) else "the folded state"
        worst = float(over.fraction.max())
        notes.append(
            f"{thick} panels ({where[panels.side]}), {100 * panels.kept:.3g} % of the "
            f"{1000 * t:g} mm slabs kept after the bevels; overlap over {checked}: "
            + ("none" if worst == 0 else f"up to {100 * worst:.3g} % of the panel volume")
        )
        if crease_thickness is not None:
            part = thick_printable(geo, panels, tc)
            try:
                bent = folded_printable_solid(geo, t, tc, W, panels=panels)
            except DegenerateGeometryError as exc:
                notes.append(f"no folded printable part: {exc}")
    elif panel_thickness is not None:
        t = check_range("panel_thickness", panel_thickness, 0.0, None, low_open=True)
        shrunk_panels(folded, W)  # a crease wider than a panel fails here
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            solid = thick_solid(folded, t, W)
        for w in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        overlap_said = any("thick panels intersect" in str(w.message) for w in said)
        if crease_thickness is not None:
            part = printable_solid(layout, t, tc, W)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                bent = folded_printable(folded, t, tc, W)
            for w in caught:
                notes.append(str(w.message))
                if overlap_said and "thick panels intersect" in str(w.message):
                    continue  # the same overlap, said once (thick_solid's words)
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    drawing = cutter.drawing()
    fill = {"pattern": names.pattern, "surface": names.surface, "thick": names.thick}
    words = {"units": units, "profile": cutter.profile}
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    files: list[FabricationFile] = []

    def add(key, obj, label=None, **kw):
        name, text = FILES[key]
        path = out / name.format(**fill)
        files.append(FabricationFile(key, export(obj, path, **kw), label or text.format(**words)))

    if part is not None:
        add("printable", part, units=units)
    if bent is not None:
        add("printable_folded", bent, units=units)
    fold_kw = {"crease_width": np.where(folded.interior, W, 0.0)}
    if panel_thickness is not None:
        fold_kw["panel_thickness"] = t
    if part is not None:
        fold_kw["crease_thickness"] = tc
    add("fold", layout if layout is not None else folded, **fold_kw)
    if layout is not None:
        add("svg", layout, **drawing)
        if cutter.two_sided:
            add("svg_front", layout, side="front", **drawing)
            add("svg_back", layout, side="back", **drawing)
        if needs_preview(cutter.profile):  # hairlines: the SVG looks blank in a viewer
            from holofold.geometry.cutter_preview import write_cutter_preview

            path = out / FILES["preview"][0].format(**fill)
            files.append(FabricationFile("preview", write_cutter_preview(layout, path, **drawing),
                                         FILES["preview"][1]))  # fmt: skip
        add("dxf", layout, **drawing)
    elif plan_view is not None:
        from holofold.geometry.outputs import write_text

        path = out / FILES["svg"][0].format(**fill)
        files.append(FabricationFile("svg", write_text(path, plan_view), _PLAN_LABEL))
        notes.append("no flat layout: no DXF, and the SVG is a plan view, not a crease pattern")
    add("surface_stl", folded, units=units)
    add("surface_obj", folded, units=units)
    if solid is not None:
        add("thick", solid, units=units)
    return FabricationSet(tuple(files), tuple(notes))


def export_pattern_files(
    pattern: CreasePattern,
    folder: str | os.PathLike,
    *,
    thickness: float | None = None,
    crease_width: float = 0.0,
    crease_thickness: float | None = None,
    units: str = MESH_UNITS,
    cutter: CutterOptions | None = None,
    thick: str = "centred",
) -> list[Path]:
    """The fabrication files of a sheet in ``folder``: :func:`write_fabrication_set` with the
    pattern kind's names (``pattern.fold``, ``pattern.svg``, ``pattern.dxf``, ``folded.stl``,
    ``folded.obj``, ``thick.stl`` with ``thickness``, ``printable.stl`` and
    ``printable_folded.stl`` with ``crease_thickness`` too); returns the paths written."""
    return write_fabrication_set(
        pattern, folder, panel_thickness=thickness, crease_width=crease_width,
        crease_thickness=crease_thickness, units=units, cutter=cutter, thick=thick,
    ).paths  # fmt: skip
