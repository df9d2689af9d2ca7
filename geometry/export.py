"""One entry point for writing crease patterns and meshes: :func:`export`; and the set of
fabrication files of a pattern: :func:`export_pattern_files`.

The file type comes from the suffix (or ``file_type``): ``.fold`` and ``.svg`` take a
:class:`CreasePattern`; ``.stl``, ``.obj`` and ``.ply`` take a pattern (its folded surface,
:func:`~holofold.geometry.mesh.folded_mesh`) or a ``trimesh.Trimesh`` (e.g. a thick solid).
Units: meshes are written in millimetres unless ``units`` says otherwise (slicers and CAD read
STL/OBJ/PLY as mm), FOLD in metres (``frame_unit`` "m"), SVG in millimetres (``width`` and
``height`` say so). Every file is written atomically (:mod:`holofold.geometry.outputs`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import trimesh

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.fold_io import export_fold
from holofold.geometry.mesh import MESH_TYPES, MESH_UNITS, export_mesh, folded_mesh
from holofold.geometry.outputs import atomic_write
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.solid import shrunk_panels, thick_solid
from holofold.geometry.svg import export_svg

__all__ = ["export", "export_pattern_files", "EXPORT_TYPES"]

EXPORT_TYPES = ("fold", "svg", *MESH_TYPES)


def export(
    obj, path: str | os.PathLike, file_type: str | None = None, *, units: str | None = None, **kw
) -> Path:
    """Write ``obj`` to ``path``; returns the path. ``kw`` go to the format's writer.

    ``units`` (a name of :data:`~holofold.geometry.units.LENGTH_UNITS`) is the length unit of a
    mesh file (default "mm"); FOLD (metres) and SVG (millimetres) state their own unit and
    refuse another.
    """
    path = Path(path)
    kind = (file_type or path.suffix).lower().lstrip(".")
    if kind not in EXPORT_TYPES:
        raise ValueError(
            f"cannot export {path.name!r}: unknown file type {kind!r}; known: "
            + ", ".join(EXPORT_TYPES)
        )
    if kind in ("fold", "svg"):
        if not isinstance(obj, CreasePattern):
            raise TypeError(f".{kind} export needs a CreasePattern, got {type(obj).__name__}")
        own = "m" if kind == "fold" else "mm"
        if units not in (None, own):
            raise ParameterError(
                f".{kind} files are written in {own} (the file says so); units={units!r} "
                "applies to mesh files only"
            )
        data = export_fold(obj, **kw) if kind == "fold" else export_svg(obj, **kw)
    else:
        mesh = obj if isinstance(obj, trimesh.Trimesh) else folded_mesh(obj)
        data = export_mesh(mesh, kind, MESH_UNITS if units is None else units)
    mode = "wb" if isinstance(data, bytes) else "w"

    def write(tmp):
        with open(tmp, mode) as fh:
            fh.write(data)

    return atomic_write(path, write)


def export_pattern_files(
    pattern: CreasePattern,
    folder: str | os.PathLike,
    *,
    thickness: float | None = None,
    crease_width: float = 0.0,
    crease_thickness: float | None = None,
    units: str = MESH_UNITS,
) -> list[Path]:
    """The fabrication files of a sheet, in ``folder`` (created if needed).

    ``pattern.fold`` (flat crease pattern + folded frame, with the crease width, m),
    ``pattern.svg`` (cut/score layers, mm), ``folded.stl`` / ``folded.obj`` (folded surface)
    and, with ``thickness`` (m), ``thick.stl`` (the folded panels of that thickness with hinge
    gaps ``crease_width``, m, as loose bodies) and, with ``crease_thickness`` too (m),
    ``printable.stl``: the flat part to print, panels joined by hinge strips of that thickness
    and width ``crease_width`` (:func:`~holofold.geometry.printable.printable_solid`), and
    ``printable_folded.stl``, the same part folded with its hinges bent
    (:func:`~holofold.geometry.printable.folded_printable_solid`; left out, with a warning,
    where the hinges are thicker than the panels). Meshes in ``units`` (default mm).
    Everything is built, and can fail, before the first file is written.
    """
    from holofold.geometry.printable import folded_printable, printable_solid
    from holofold.geometry.units import length_factor

    length_factor(units)
    W = check_range("crease_width", crease_width, 0.0, None)
    solid = part = bent = None
    if crease_thickness is not None:
        if thickness is None or W <= 0:
            raise ParameterError(
                "a printable part needs a panel thickness and a crease width > 0 besides the "
                "crease thickness"
            )
        tc = check_range("crease_thickness", crease_thickness, 0.0, None, low_open=True)
    if thickness is not None:
        t = check_range("thickness", thickness, 0.0, None, low_open=True)
        shrunk_panels(pattern, W)  # a crease wider than a panel fails here
        solid = thick_solid(pattern, t, W)
        if crease_thickness is not None:
            part = printable_solid(pattern, t, tc, W)
            bent = folded_printable(pattern, t, tc, W)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    written = [
        export(pattern, out / "pattern.fold", crease_width=np.where(pattern.interior, W, 0.0)),
        export(pattern, out / "pattern.svg"),
        export(pattern, out / "folded.stl", units=units),
        export(pattern, out / "folded.obj", units=units),
    ]
    if solid is not None:
        written.append(export(solid, out / "thick.stl", units=units))
    if part is not None:
        written.append(export(part, out / "printable.stl", units=units))
    if bent is not None:
        written.append(export(bent, out / "printable_folded.stl", units=units))
    return written
