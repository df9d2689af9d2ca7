"""ORIPA crease patterns (``.opx``, and the plain ``.cp`` line format) read into a crease pattern.

Both list lines with an ORIPA type: 1 border, 2 mountain, 3 valley; 0 and 4 are auxiliary
lines (left out). ``.opx`` is ORIPA's Java-beans XML (``oripa.OriLineProxy`` objects whose
``type``, ``x0``, ``y0``, ``x1``, ``y1`` properties default to 0 when absent, as the encoder
leaves them out); ``.cp`` has one line per crease, ``type x0 y0 x1 y1``. ORIPA draws with y
down, so y is turned up. Neither has a unit or fold angles: one drawing unit is read as a
millimetre unless ``unit`` says otherwise (ORIPA's default sheet is 400 units wide), and
mountains and valleys fold fully (-+180 degrees).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from holofold.geometry.bounded import check_token_count
from holofold.geometry.errors import FormatError, ParameterError
from holofold.geometry.line_drawing import pattern_from_lines

__all__ = ["read_opx_pattern", "read_cp_pattern", "ORIPA_TYPES", "MAX_ORIPA_BYTES"]

#: ORIPA line type -> FOLD code (0 and 4: auxiliary lines, not read)
ORIPA_TYPES = {1: "B", 2: "M", 3: "V"}
_ANGLE = {"M": -180.0, "V": 180.0, "B": 0.0}
#: the largest ORIPA file read, bytes
MAX_ORIPA_BYTES = 64 * 2**20


def _read_text(path) -> bytes:
    p = Path(path)
    size = p.stat().st_size
    if size > MAX_ORIPA_BYTES:
        raise FormatError(f"{p.name}: {size} bytes; at most {MAX_ORIPA_BYTES} (64 MiB) are read")
    return p.read_bytes()


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


def opx_lines(path):
    """(segments (n, 2, 2) ORIPA units y up, codes, angles, notes) of an ``.opx`` file."""
    name = Path(path).name
    check_token_count(path, b"OriLineProxy", ".opx file", "lines")
    try:
        root = ET.fromstring(_read_text(path))
    except ET.ParseError as exc:
        raise FormatError(f"{name}: not well-formed XML ({exc})") from None
    segs, codes = [], []
    aux = 0
    for obj in root.iter("object"):
        if not str(obj.get("class", "")).endswith("OriLineProxy"):
            continue
        try:
            t = _value(obj, "type", int, 0)
            x0, y0, x1, y1 = (_value(obj, k, float, 0.0) for k in ("x0", "y0", "x1", "y1"))
        except FormatError as exc:
            raise FormatError(f"{name}: {exc}") from None
        if t not in ORIPA_TYPES:
            aux += 1
            continue
        segs.append([[x0, -y0], [x1, -y1]])
        codes.append(ORIPA_TYPES[t])
    return _finish(name, segs, codes, aux)


def cp_lines(path):
    """(segments, codes, angles, notes) of a ``.cp`` file (``type x0 y0 x1 y1`` per line)."""
    name = Path(path).name
    check_token_count(path, b"\n", ".cp file", "lines")
    try:
        text = _read_text(path).decode("utf-8-sig")
    except UnicodeDecodeError:
        raise FormatError(f"{name}: not a text file") from None
    segs, codes = [], []
    aux = 0
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
        if t not in ORIPA_TYPES:
            aux += 1
            continue
        segs.append([[x0, -y0], [x1, -y1]])
        codes.append(ORIPA_TYPES[t])
    return _finish(name, segs, codes, aux)


def _finish(name, segs, codes, aux):
    if not segs:
        raise FormatError(f"{name}: no border, mountain or valley lines")
    notes = ["no unit in the file: one drawing unit read as 1 mm; give unit"]
    if aux:
        notes.append(f"{aux} auxiliary line(s) (type 0 or 4) left out")
    S = np.array(segs, float)
    if not np.isfinite(S).all():
        raise FormatError(f"{name}: a line has non-finite coordinates")
    c = np.array(codes, dtype="<U1")
    return S, c, np.array([_ANGLE[x] for x in codes]), notes


def _read(lines, path, tol, unit, split):
    name = Path(path).name
    S, codes, angles, notes = lines(path)
    if unit is not None:
        notes = [n for n in notes if "no unit" not in n]
        if not (isinstance(unit, int | float) and math.isfinite(unit) and unit > 0):
            raise ParameterError(f"unit = {unit!r} must be a length in metres > 0")
    return pattern_from_lines(
        S, codes, angles, name=name, unit=1e-3 if unit is None else float(unit), tol=tol,
        split=split, meta={"kind": "oripa", "source": name}, notes=notes,
    )  # fmt: skip


def read_opx_pattern(path, *, tol=None, unit=None, split: str = "as-needed"):
    """The crease pattern of an ORIPA ``.opx`` file (see the module docstring), metres."""
    return _read(opx_lines, path, tol, unit, split)


def read_cp_pattern(path, *, tol=None, unit=None, split: str = "as-needed"):
    """The crease pattern of a ``.cp`` file (see the module docstring), metres."""
    return _read(cp_lines, path, tol, unit, split)
