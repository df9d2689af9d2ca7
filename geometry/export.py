"""One entry point for writing crease patterns and meshes: :func:`export`.

The file type comes from the suffix (or ``file_type``): ``.fold`` and ``.svg`` take a
:class:`CreasePattern`; ``.stl``, ``.obj`` and ``.ply`` take a pattern (its folded surface,
:func:`geometry.mesh.folded_mesh`) or a ``trimesh.Trimesh`` (e.g. a thick solid).
"""

from __future__ import annotations

import os
from pathlib import Path

import trimesh

from holofold.geometry.fold_io import export_fold
from holofold.geometry.mesh import MESH_TYPES, export_mesh, folded_mesh
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.svg import export_svg

__all__ = ["export", "EXPORT_TYPES"]

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
    with open(path, mode) as fh:
        fh.write(data)
    return path
