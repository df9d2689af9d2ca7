"""One entry point for writing crease patterns and meshes, :func:`export`, over a registry of
output formats, :data:`FORMATS`.

A :class:`Format` names its suffix, what it takes (a :class:`CreasePattern`, a mesh, or both:
a pattern is written as its folded surface, :func:`~holofold.geometry.mesh.folded_mesh`), its
unit policy and its writer. The unit policy is one of two: the format fixes its unit and says
so in the file (FOLD metres, ``frame_unit``; SVG and DXF millimetres; glTF metres, as its
specification requires), and another ``units`` is refused; or the format carries no unit (STL,
OBJ, PLY) and the caller's ``units`` is used, millimetres by default (what slicers and CAD
programs read) and named in a header or comment. A new format is one :func:`register_format`
call; an unknown suffix is refused with the list of known ones, before anything is written.
Every file is written atomically (:mod:`holofold.geometry.outputs`).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from holofold.geometry.errors import ParameterError
from holofold.geometry.mesh import MESH_UNITS
from holofold.geometry.outputs import atomic_write
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.registry import Registry

__all__ = ["Format", "FORMATS", "register_format", "export", "EXPORT_TYPES"]


@dataclass(frozen=True)
class Format:
    """An output format.

    Attributes
    ----------
    suffix : str
        Without the dot, lower case ("stl").
    takes : str
        "pattern" (a CreasePattern), "mesh" (a trimesh.Trimesh, or a pattern's folded surface).
    unit : str or None
        The unit the format fixes (a name of :data:`~holofold.geometry.units.LENGTH_UNITS`), or
        None: the caller's (default :data:`~holofold.geometry.mesh.MESH_UNITS`).
    write : callable(obj, unit, **kw) -> str or bytes
        The file's content; ``obj`` is a CreasePattern for "pattern", a trimesh.Trimesh for
        "mesh"; ``unit`` the resolved unit.
    description : str
        What the file is, for people.
    """

    suffix: str
    takes: str
    unit: str | None
    write: Callable
    description: str


def _check_format(suffix, fmt) -> Format:
    if not isinstance(fmt, Format):
        raise TypeError(f"format {suffix!r}: expected a Format, got {type(fmt).__name__}")
    if fmt.takes not in ("pattern", "mesh"):
        raise ValueError(f"format {fmt.suffix!r}: takes must be 'pattern' or 'mesh'")
    return fmt


#: suffix -> Format (a :class:`~holofold.geometry.registry.Registry`; plug-ins from the
#: entry-point group ``holofold.formats``)
FORMATS: Registry[Format] = Registry(
    "format", group="holofold.formats", check=_check_format, key=str.lower, error=ValueError
)


def register_format(fmt: Format, *, replace: bool = False) -> Format:
    """Add ``fmt`` to :data:`FORMATS` (a taken suffix only with ``replace=True``; a built-in
    one never)."""
    return FORMATS.register(fmt, fmt.suffix, replace=replace)


def _fold(obj, unit, **kw):
    from holofold.geometry.fold_io import export_fold

    return export_fold(obj, **kw)


def _svg(obj, unit, **kw):
    from holofold.geometry.svg import export_svg

    return export_svg(obj, **kw)


def _dxf(obj, unit, **kw):
    from holofold.geometry.dxf import export_dxf

    return export_dxf(obj, **kw)


def _mesh_writer(kind: str):
    """holofold's own writer of ``kind``: a pattern's folded surface or a trimesh.Trimesh,
    as arrays (:mod:`holofold.geometry.mesh_files`; no trimesh is imported for a pattern)."""

    def write(obj, unit, **kw):
        from holofold.geometry.mesh import export_mesh, folded_arrays
        from holofold.geometry.mesh_files import mesh_file

        if kw:
            raise TypeError(f".{kind} export takes no options, got {', '.join(kw)}")
        if isinstance(obj, CreasePattern):
            v, t, _ = folded_arrays(obj)
            return mesh_file(v, t, kind, unit, obj.meta.get("kind", "pattern"))
        return export_mesh(obj, kind, unit)

    return write


#: the built-in mesh formats holofold writes from a pattern's arrays (no trimesh.Trimesh built)
_ARRAY_FORMATS = ("stl", "obj", "ply")


def _is_trimesh(obj) -> bool:
    """Whether ``obj`` is a trimesh.Trimesh (without importing trimesh: where it is not
    imported, nothing can be one)."""
    tm = sys.modules.get("trimesh")
    return tm is not None and isinstance(obj, tm.Trimesh)


def _glb(obj, unit, **kw):
    import trimesh

    if kw:
        raise TypeError(f".glb export takes no options, got {', '.join(kw)}")
    return trimesh.exchange.export.export_mesh(obj, None, file_type="glb")


for _fmt in (
    Format("fold", "pattern", "m", _fold, "FOLD 1.2 crease pattern and folded state"),
    Format("svg", "pattern", "mm", _svg, "SVG of the flat crease pattern for a cutter profile"),
    Format("dxf", "pattern", "mm", _dxf, "DXF of the flat crease pattern, a layer per role"),
    Format("stl", "mesh", None, _mesh_writer("stl"), "binary STL surface"),
    Format("obj", "mesh", None, _mesh_writer("obj"), "Wavefront OBJ surface"),
    Format("ply", "mesh", None, _mesh_writer("ply"), "binary PLY surface"),
    Format("glb", "mesh", "m", _glb, "binary glTF 2.0 (metres, as glTF requires)"),
):
    FORMATS.register(_fmt, _fmt.suffix, builtin=True)

#: the built-in suffixes (:data:`FORMATS` holds any registered later too)
EXPORT_TYPES = FORMATS.builtin_names()


def export(
    obj, path: str | os.PathLike, file_type: str | None = None, *, units: str | None = None, **kw
) -> Path:
    """Write ``obj`` to ``path`` in the format of its suffix (or ``file_type``); returns the path.

    ``units`` is the length unit of a format without one (default "mm"); a format that fixes
    its unit refuses another. ``kw`` go to the format's writer. Nothing is written if the
    format, the object or the unit is wrong.
    """
    from holofold.geometry.units import length_factor

    path = Path(path)
    kind = (file_type or path.suffix).lower().lstrip(".")
    fmt = FORMATS.get(kind)
    if fmt is None:
        raise ValueError(
            f"cannot export {path.name!r}: unknown file type {kind!r}; known: " + ", ".join(FORMATS)
        )
    if fmt.takes == "pattern" and not isinstance(obj, CreasePattern):
        raise TypeError(f".{kind} export needs a CreasePattern, got {type(obj).__name__}")
    if fmt.takes == "mesh" and not (isinstance(obj, CreasePattern) or _is_trimesh(obj)):
        raise TypeError(
            f".{kind} export needs a trimesh.Trimesh or a CreasePattern, got {type(obj).__name__}"
        )
    if fmt.unit is not None and units not in (None, fmt.unit):
        raise ParameterError(
            f".{kind} files are written in {fmt.unit} (the file says so); units={units!r} "
            "applies to mesh files only (those without a unit: stl, obj, ply)"
        )
    unit = fmt.unit or (MESH_UNITS if units is None else units)
    length_factor(unit)
    if fmt.takes == "mesh" and isinstance(obj, CreasePattern) and kind not in _ARRAY_FORMATS:
        from holofold.geometry.mesh import folded_mesh

        obj = folded_mesh(obj)
    data = fmt.write(obj, unit, **kw)
    mode = "wb" if isinstance(data, bytes) else "w"

    def write(tmp):
        with open(tmp, mode) as fh:
            fh.write(data)

    return atomic_write(path, write)
