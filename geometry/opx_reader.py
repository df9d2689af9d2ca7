"""ORIPA crease patterns (``.opx``, and the plain ``.cp`` line format) read into a crease pattern.

Both list lines with an ORIPA type: 1 border, 2 mountain, 3 valley; 0 and 4 are auxiliary
lines (left out). ``.opx`` is ORIPA's Java-beans XML (``oripa.OriLineProxy`` objects whose
``type``, ``x0``, ``y0``, ``x1``, ``y1`` properties default to 0 when absent, as the encoder
leaves them out); ``.cp`` has one line per crease, ``type x0 y0 x1 y1``. ORIPA draws with y
down, so y is turned up. Neither has a unit or fold angles: one drawing unit is read as a
millimetre unless ``unit`` says otherwise (ORIPA's default sheet is 400 units wide), and
mountains and valleys fold fully (-+180 degrees).

:func:`opx_drawing` and :func:`cp_drawing` return the lines as a
:class:`~holofold.geometry.line_drawing.LineDrawing` (the file a path, its bytes or a binary
file object, its lines counted before it is parsed);
:func:`~holofold.geometry.line_drawing.pattern_from_drawing` makes the crease pattern.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from holofold.geometry.bounded import check_token_count, read_source, source_name
from holofold.geometry.errors import FormatError
from holofold.geometry.line_drawing import LineDrawing, pattern_from_drawing

__all__ = [
    "read_opx_pattern",
    "read_cp_pattern",
    "opx_drawing",
    "cp_drawing",
    "ORIPA_TYPES",
    "MAX_ORIPA_BYTES",
]

#: ORIPA line type -> FOLD code (0 and 4: auxiliary lines, not read)
ORIPA_TYPES = {1: "B", 2: "M", 3: "V"}
_ANGLE = {"M": -180.0, "V": 180.0, "B": 0.0}
#: the largest ORIPA file read, bytes
MAX_ORIPA_BYTES = 64 * 2**20
#: the note of a file without a unit (dropped when the caller gives one)
_NO_UNIT = "no unit in the file: one drawing unit read as 1 mm; give unit"


def _bytes(source, token: bytes, what: str) -> tuple[bytes, str]:
    """(bytes, name) of an ORIPA file, its lines (``token``\\ s) counted first."""
    name = source_name(source)
    data = read_source(source, MAX_ORIPA_BYTES, what)
    check_token_count(data, token, what, "lines", name=name)
    return data, name


def _value(obj, prop: str, kind: type, default):
    for v in obj.iter("void"):
        if v.get("property") == prop:
            child = next(iter(v), None)
            if child is None:
                return default
            if child.text is None or not child.text.strip():
                raise FormatError(f"property {prop} is empty")
            try:
                return kind(child.text.strip())
            except ValueError:
                raise FormatError(f"property {prop} = {child.text!r} is not a number") from None
    return default


def opx_drawing(source) -> LineDrawing:
    """The lines of an ``.opx`` file (a path, bytes or a binary file object), ORIPA units with
    y up."""
    data, name = _bytes(source, b"OriLineProxy", ".opx file")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise FormatError(f"{name}: not well-formed XML ({exc})") from None

    def lines():
        for obj in root.iter("object"):
            if not str(obj.get("class", "")).endswith("OriLineProxy"):
                continue
            try:
                t = _value(obj, "type", int, 0)
                x0, y0, x1, y1 = (_value(obj, k, float, 0.0) for k in ("x0", "y0", "x1", "y1"))
            except FormatError as exc:
                raise FormatError(f"{name}: {exc}") from None
            yield t, x0, y0, x1, y1

    return _drawing(name, lines())


def cp_drawing(source) -> LineDrawing:
    """The lines of a ``.cp`` file (``type x0 y0 x1 y1`` per line; a path, bytes or a binary
    file object), y up."""
    data, name = _bytes(source, b"\n", ".cp file")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise FormatError(f"{name}: not a text file") from None

    def lines():
        for k, line in enumerate(text.splitlines(), start=1):
            parts = line.split()
            if not parts:
                continue
            try:
                t = int(parts[0])
                x0, y0, x1, y1 = (float(v) for v in parts[1:5])
            except (ValueError, IndexError):
                raise FormatError(
                    f"{name}: line {k} is not 'type x0 y0 x1 y1' (five numbers)"
                ) from None
            yield t, x0, y0, x1, y1

    return _drawing(name, lines())


def _drawing(name: str, lines) -> LineDrawing:
    """The drawing of ``lines``, (ORIPA type, x0, y0, x1, y1) with y down; lines of a type
    that is not a crease or a cut (auxiliary lines) are counted, not drawn."""
    segs, codes = [], []
    aux = 0
    for t, x0, y0, x1, y1 in lines:
        if t not in ORIPA_TYPES:
            aux += 1
            continue
        segs.append([[x0, -y0], [x1, -y1]])
        codes.append(ORIPA_TYPES[t])
    return _finish(name, segs, codes, aux)


def _finish(name, segs, codes, aux) -> LineDrawing:
    if not segs:
        raise FormatError(f"{name}: no border, mountain or valley lines")
    notes = [_NO_UNIT]
    if aux:
        notes.append(f"{aux} auxiliary line(s) (type 0 or 4) left out")
    S = np.array(segs, float)
    if not np.isfinite(S).all():
        raise FormatError(f"{name}: a line has non-finite coordinates")
    c = np.array(codes, dtype="<U1")
    return LineDrawing(S, c, np.array([_ANGLE[x] for x in codes]), 1e-3, name=name,
                       kind="oripa", notes=tuple(notes), unit_note=_NO_UNIT)  # fmt: skip


def read_opx_pattern(source, *, tol=None, unit=None, split: str = "as-needed"):
    """The crease pattern of an ORIPA ``.opx`` file (a path, bytes or a binary file object;
    see the module docstring), metres."""
    return pattern_from_drawing(opx_drawing(source), tol=tol, unit=unit, split=split)


def read_cp_pattern(source, *, tol=None, unit=None, split: str = "as-needed"):
    """The crease pattern of a ``.cp`` file (a path, bytes or a binary file object; see the
    module docstring), metres."""
    return pattern_from_drawing(cp_drawing(source), tol=tol, unit=unit, split=split)
