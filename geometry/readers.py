"""Reading crease patterns drawn in other tools: one entry point, a registry of formats by suffix.

:func:`read_pattern` reads ``.fold`` (FOLD 1.2, any frame), ``.svg`` (Origami Simulator's
colours), ``.dxf`` (layers or colours), ``.opx`` (ORIPA) and ``.cp`` (ORIPA's line list)
files into a :class:`~holofold.geometry.pattern.CreasePattern` in metres, with its flat
layout, assignments and target fold angles (degrees). Every reader refuses a file it cannot
use with one :class:`~holofold.geometry.errors.FormatError` line naming the file and the
problem, and
reports every repair it made (merged vertices, dropped lines, separated cuts, split faces) as
one :class:`PatternWarning` line each. Line drawings go through the same steps
(:func:`~holofold.geometry.line_drawing.pattern_from_lines`, the module every reader shares,
re-exported here): the planar arrangement
(:func:`~holofold.geometry.arrangement.arrange_lines`), cuts separated
(:func:`~holofold.geometry.cuts.separate_cuts`), faces split where the model needs it
(:func:`~holofold.geometry.facets.split_faces`).

Other formats are added with :func:`register_reader` (a function ``path, **options ->
CreasePattern``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from holofold.geometry.errors import FormatError, ParameterError
from holofold.geometry.line_drawing import PatternWarning, finish_pattern, pattern_from_lines
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.registry import Registry

__all__ = [
    "PatternWarning",
    "PatternReader",
    "READERS",
    "read_pattern",
    "register_reader",
    "reader_for",
    "pattern_from_lines",
    "finish_pattern",
]


@dataclass(frozen=True)
class PatternReader:
    """One file format.

    Attributes
    ----------
    suffix : str
        ``".svg"``.
    name : str
        What the format is.
    read : callable(path, **options) -> CreasePattern
    options : tuple of str
        The keyword options it takes (``tol``, ``unit``, ``frame``, ``split``, ...).
    """

    suffix: str
    name: str
    read: Callable
    options: tuple[str, ...] = ()


def _fold(path, **kw):
    from holofold.geometry.fold_reader import read_fold_pattern

    return read_fold_pattern(path, **kw)


def _svg(path, **kw):
    from holofold.geometry.svg_reader import read_svg_pattern

    return read_svg_pattern(path, **kw)


def _dxf(path, **kw):
    from holofold.geometry.dxf_reader import read_dxf_pattern

    return read_dxf_pattern(path, **kw)


def _opx(path, **kw):
    from holofold.geometry.opx_reader import read_opx_pattern

    return read_opx_pattern(path, **kw)


def _cp(path, **kw):
    from holofold.geometry.opx_reader import read_cp_pattern

    return read_cp_pattern(path, **kw)


def _check_reader(suffix, reader) -> PatternReader:
    if not isinstance(reader, PatternReader):
        raise TypeError(f"reader {suffix!r}: expected a PatternReader, got {type(reader).__name__}")
    if not str(suffix).startswith(".") or len(suffix) < 2:
        raise ValueError(f"suffix {suffix!r} must look like '.ext'")
    return reader


#: suffix -> reader (a :class:`~holofold.geometry.registry.Registry`; plug-ins from the
#: entry-point group ``holofold.readers``)
READERS: Registry[PatternReader] = Registry(
    "crease-pattern reader",
    {
        ".fold": PatternReader(".fold", "FOLD 1.2", _fold, ("frame", "unit", "split")),
        ".svg": PatternReader(
            ".svg", "SVG (Origami Simulator colours)", _svg, ("tol", "unit", "split", "curves")
        ),
        ".dxf": PatternReader(
            ".dxf", "DXF (layers or colours)", _dxf, ("tol", "unit", "split", "curves")
        ),
        ".opx": PatternReader(".opx", "ORIPA", _opx, ("tol", "unit", "split")),
        ".cp": PatternReader(".cp", "ORIPA/Oriedita lines", _cp, ("tol", "unit", "split")),
    },
    group="holofold.readers",
    check=_check_reader,
    key=str.lower,
    error=FormatError,
)


def register_reader(reader: PatternReader, *, replace: bool = False) -> PatternReader:
    """Add the reader of ``reader.suffix`` (a taken suffix only with ``replace=True``; a
    built-in one never)."""
    return READERS.register(reader, reader.suffix, replace=replace)


def reader_for(path) -> PatternReader:
    """The reader of ``path``'s suffix (one FormatError line naming the known ones)."""
    suffix = Path(path).suffix.lower()
    if suffix not in READERS:
        raise FormatError(
            f"{Path(path).name}: unknown crease-pattern format {suffix or '(no suffix)'!r}; "
            f"known: {', '.join(READERS)}"
        )
    return READERS[suffix]


def read_pattern(path: str | os.PathLike, **options) -> CreasePattern:
    """The crease pattern of a file, by its suffix (:data:`READERS`); ``options`` go to the
    format's reader (each reader names the ones it takes: ``tol`` merge distance in drawing
    units, ``unit`` metres per drawing unit, ``frame`` of a FOLD file, ``split`` one of
    :data:`~holofold.geometry.facets.SPLIT_MODES`)."""
    reader = reader_for(path)
    bad = sorted(set(options) - set(reader.options))
    if bad:
        raise ParameterError(
            f"{reader.name} files take no option {bad[0]!r}; allowed: {', '.join(reader.options)}"
        )
    p = Path(path)
    if not p.is_file():
        raise FormatError(f"{p}: no such file")
    return reader.read(p, **{k: v for k, v in options.items() if v is not None})
