"""Reading crease patterns drawn in other tools: one entry point, a registry of formats by suffix.

:func:`read_pattern` reads ``.fold`` (FOLD 1.2, any frame), ``.svg`` (Origami Simulator's
colours), ``.dxf`` (layers or colours), ``.opx`` (ORIPA) and ``.cp`` (ORIPA's line list)
files into a :class:`~holofold.geometry.pattern.CreasePattern` in metres, with its flat
layout, assignments and target fold angles (degrees). Every reader refuses a file it cannot
use with one :class:`~holofold.geometry.errors.FormatError` line naming the file and the
problem, and
reports every repair it made (merged vertices, dropped lines, separated cuts, split faces) as
one :class:`PatternWarning` line each. A file is a path, its bytes or a binary file object
(a source: bytes and file objects name their format with ``suffix``, or a file object by its
name); the bounded checks of :mod:`~holofold.geometry.bounded` run on the bytes before a
library parses them. Each line reader (SVG, DXF, ORIPA) returns one
:class:`~holofold.geometry.line_drawing.LineDrawing`, and every drawing goes through one
pipeline (:func:`~holofold.geometry.line_drawing.pattern_from_drawing`, re-exported here): the
planar arrangement (:func:`~holofold.geometry.arrangement.arrange_lines`), cuts separated
(:func:`~holofold.geometry.cuts.separate_cuts`), faces split where the model needs it
(:func:`~holofold.geometry.facets.split_faces`).

This module is the registry only: it imports the reader modules, none of which imports it. Other
formats are added with :func:`register_reader` (a function ``source, **options ->
CreasePattern``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from holofold.geometry.bounded import source_name
from holofold.geometry.dxf_reader import read_dxf_pattern
from holofold.geometry.errors import FormatError, ParameterError
from holofold.geometry.fold_reader import read_fold_pattern
from holofold.geometry.line_drawing import (
    LineDrawing,
    PatternWarning,
    finish_pattern,
    pattern_from_drawing,
    pattern_from_lines,
)
from holofold.geometry.opx_reader import read_cp_pattern, read_opx_pattern
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.registry import Registry
from holofold.geometry.svg_reader import read_svg_pattern

__all__ = [
    "PatternWarning",
    "LineDrawing",
    "pattern_from_drawing",
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
    read : callable(source, **options) -> CreasePattern
        ``source``: a :class:`~pathlib.Path`, bytes or a binary file object
        (:func:`~holofold.geometry.bounded.read_source` gives its bytes, ``source_name`` its
        name in messages).
    options : tuple of str
        The keyword options it takes (``tol``, ``unit``, ``frame``, ``split``, ...).
    """

    suffix: str
    name: str
    read: Callable
    options: tuple[str, ...] = ()


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
        ".fold": PatternReader(".fold", "FOLD 1.2", read_fold_pattern, ("frame", "unit", "split")),
        ".svg": PatternReader(
            ".svg",
            "SVG (Origami Simulator colours)",
            read_svg_pattern,
            ("tol", "unit", "split", "curves"),
        ),
        ".dxf": PatternReader(
            ".dxf", "DXF (layers or colours)", read_dxf_pattern, ("tol", "unit", "split", "curves")
        ),
        ".opx": PatternReader(".opx", "ORIPA", read_opx_pattern, ("tol", "unit", "split")),
        ".cp": PatternReader(
            ".cp", "ORIPA/Oriedita lines", read_cp_pattern, ("tol", "unit", "split")
        ),
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


def _is_path(source) -> bool:
    return isinstance(source, str | os.PathLike)


def reader_for(path, suffix: str | None = None) -> PatternReader:
    """The reader of ``suffix`` (``".svg"``), else of ``path``'s suffix (a path or a file
    object's name; one FormatError line naming the known ones)."""
    if suffix is None:
        named = path if _is_path(path) else getattr(path, "name", None)
        suffix = Path(named).suffix if isinstance(named, str | os.PathLike) else ""
    suffix = str(suffix).lower()
    if suffix not in READERS:
        raise FormatError(
            f"{source_name(path)}: unknown crease-pattern format {suffix or '(no suffix)'!r}; "
            f"known: {', '.join(READERS)}"
        )
    return READERS[suffix]


def read_pattern(
    source: str | os.PathLike | bytes | BinaryIO, *, suffix: str | None = None, **options
) -> CreasePattern:
    """The crease pattern of a file, by its suffix (:data:`READERS`); ``source`` a path, the
    file's bytes or a binary file object (``suffix``, ``".svg"``, names the format of bytes
    and of a file object without a name). ``options`` go to the format's reader (each reader
    names the ones it takes: ``tol`` merge distance in drawing units, ``unit`` metres per
    drawing unit, ``frame`` of a FOLD file, ``split`` one of
    :data:`~holofold.geometry.facets.SPLIT_MODES`)."""
    reader = reader_for(source, suffix)
    bad = sorted(set(options) - set(reader.options))
    if bad:
        raise ParameterError(
            f"{reader.name} files take no option {bad[0]!r}; allowed: {', '.join(reader.options)}"
        )
    if _is_path(source):
        source = Path(source)
        if not source.is_file():
            raise FormatError(f"{source}: no such file")
    return reader.read(source, **{k: v for k, v in options.items() if v is not None})
