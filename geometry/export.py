"""One entry point for writing crease patterns and meshes: :func:`export`; and the set of
fabrication files of a pattern: :func:`export_pattern_files`.

The file type comes from the suffix (or ``file_type``): ``.fold`` and ``.svg`` take a
:class:`CreasePattern`; ``.stl``, ``.obj`` and ``.ply`` take a pattern (its folded surface,
:func:`~holofold.geometry.mesh.folded_mesh`) or a ``trimesh.Trimesh`` (e.g. a thick solid).
Every file is written atomically (:mod:`holofold.geometry.outputs`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import trimesh

from holofold.geometry.errors import check_range
from holofold.geometry.fold_io import export_fold
from holofold.geometry.mesh import MESH_TYPES, export_mesh, folded_mesh
from holofold.geometry.outputs import atomic_write
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.solid import shrunk_panels, thick_solid
from holofold.geometry.svg import export_svg

__all__ = ["export", "export_pattern_files", "EXPORT_TYPES"]

EXPORT_TYPES = ("fold", "svg", *MESH_TYPES)


def export(obj, path: str | os.PathLike, file_type: str | None = None, **kw) -> Path:
    """Write ``obj`` to ``path``; returns the path. ``kw`` go to the format's writer."""
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
        data = export_fold(obj, **kw) if kind == "fold" else export_svg(obj, **kw)
    else:
        mesh = obj if isinstance(obj, trimesh.Trimesh) else folded_mesh(obj)
        data = export_mesh(mesh, kind)
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
) -> list[Path]:
    """The fabrication files of a sheet, in ``folder`` (created if needed).

    ``pattern.fold`` (flat crease pattern + folded frame, with the crease width),
    ``pattern.svg`` (cut/score layers), ``folded.stl`` / ``folded.obj`` (folded surface) and,
    with ``thickness`` (m), ``thick.stl`` (panels of that thickness with hinge gaps
    ``crease_width``, m). Everything is built, and can fail, before the first file is written.
    """
    W = check_range("crease_width", crease_width, 0.0, None)
    solid = None
    if thickness is not None:
        t = check_range("thickness", thickness, 0.0, None, low_open=True)
        shrunk_panels(pattern, W)  # a crease wider than a panel fails here
        solid = thick_solid(pattern, t, W)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    written = [
        export(pattern, out / "pattern.fold", crease_width=np.where(pattern.interior, W, 0.0)),
        export(pattern, out / "pattern.svg"),
        export(pattern, out / "folded.stl"),
        export(pattern, out / "folded.obj"),
    ]
    if solid is not None:
        written.append(export(solid, out / "thick.stl"))
    return written
