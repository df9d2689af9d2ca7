"""Target curves from files: CSV point lists and SVG drawings, in the units they are drawn in.

* :func:`read_points_csv` reads (x, z) points in ``units`` (default metres).
* :func:`read_svg_curve` reads a path of an SVG document with ``svgelements``: the document's
  ``width``/``height`` units and ``viewBox`` and every ``transform`` on the way to the path are
  applied. With ``units=None`` a document that states its size in an absolute unit (mm, cm, in,
  pt, pc, px: ``width="400mm"``) is read in that size; a document that states none (no
  ``width``, or a bare number) is read with one user unit = 1 m, as before. With ``units`` given,
  one user unit (the coordinates inside the root ``viewBox``) is one ``units``: the scenario
  files' and ``--curve-units``' meaning.

A curve whose size is implausible for an origami part read in the unit it was given in (under
1 cm or over 100 m across, :data:`PLAUSIBLE_SIZE`) gets a :class:`CurveUnitWarning` that names
its size and the unit that would make it plausible (a 400 m "arch" from a drawing in mm read as
metres, a 2 mm arch from points in metres read as mm).
"""

from __future__ import annotations

import csv
import io
import math
import re
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from holofold.fitting.curves import (
    CurveFormatError,
    PlanarCurve,
    parse_curve_spec,
    svg_path_curve,
)
from holofold.geometry.inputs import check_input_file
from holofold.geometry.units import LENGTH_UNITS, length_factor

__all__ = [
    "CurveUnitWarning",
    "CurveSelectionWarning",
    "CurveColumnsWarning",
    "CurveClosedWarning",
    "MAX_SVG_BYTES",
    "MAX_SVG_NESTING",
    "MAX_SVG_ELEMENTS",
    "MAX_SVG_POINTS",
    "MAX_CSV_POINTS",
    "PLAUSIBLE_SIZE",
    "check_curve_size",
    "read_points_csv",
    "read_svg_curve",
    "load_curve",
]

#: (smallest, largest) extent of a target curve that is plausible for an origami part, m
PLAUSIBLE_SIZE = (0.01, 100.0)

#: CSS absolute units in metres (SVG lengths; 96 px per inch)
_SVG_UNITS = {"mm": 1e-3, "cm": 1e-2, "q": 0.25e-3, "in": 0.0254, "pt": 0.0254 / 72,
              "pc": 0.0254 / 6, "px": 0.0254 / 96}  # fmt: skip
_PX = 0.0254 / 96  # svgelements reports coordinates in CSS px

#: the largest SVG file read (bytes)
MAX_SVG_BYTES = 64 * 2**20
#: the deepest element nesting read: drawings nest groups a few levels deep; svgelements
#: recurses per level and fails near 1000 (at Python's default recursion limit)
MAX_SVG_NESTING = 100
#: the most elements read after every reference (``<use href="#id">``, and any other element
#: that refers to another by ``href``) is expanded: svgelements takes about 0.2 ms per element
#: (10,000 flat paths: 1.8 s), so 20,000 is about 4 s; a 25-level ``<use>`` doubling bomb
#: (2^25 elements from 1.8 kB) is refused before it is parsed
MAX_SVG_ELEMENTS = 20_000
#: the most path points (coordinate pairs of ``d`` and ``points``) after expansion:
#: svgelements takes about 40 us per segment (100,000 in one path: 4 s)
MAX_SVG_POINTS = 200_000
#: the most rows of a points file (CSV/TXT), its size at most MAX_SVG_BYTES: the rows are parsed
#: at about 4 us each, so a 2,000,000-row file took over 10 s before it was counted
MAX_CSV_POINTS = 200_000


class CurveUnitWarning(UserWarning):
    """A curve whose size is implausible in the unit it was read in (probably the wrong unit)."""


class CurveSelectionWarning(UserWarning):
    """An SVG file with several shapes read without ``#id``: the first was taken."""


def check_curve_size(curve: PlanarCurve, unit: str, per_unit: float, where: str = "") -> None:
    """Warn (:class:`CurveUnitWarning`) if ``curve`` (m) is implausibly small or large.

    ``unit`` names the unit the file was read in and ``per_unit`` its size in metres; the
    message suggests the unit of :data:`~holofold.geometry.units.LENGTH_UNITS` that brings the
    curve nearest to 1 m.
    """
    size = float(np.ptp(curve.polyline(257), axis=0).max())
    lo, hi = PLAUSIBLE_SIZE
    if lo <= size <= hi:
        return
    raw = size / per_unit  # the size in the file's own numbers
    better = min(
        (u for u in ("m", "cm", "mm", "in") if lo <= raw * LENGTH_UNITS[u] <= hi),
        key=lambda u: abs(math.log10(raw * LENGTH_UNITS[u])),
        default=None,
    )
    hint = (
        f"; if its numbers are in {better}, it is {raw * LENGTH_UNITS[better]:.4g} m across: "
        f"give units={better!r} (holofold fit --curve-units {better})"
        if better
        else ""
    )
    warnings.warn(
        f"curve {curve.name!r}{where} is {size:.4g} m across read in {unit}, implausible for an "
        f"origami part ({lo:g}-{hi:g} m){hint}",
        CurveUnitWarning,
        stacklevel=3,
    )


def read_points_csv(
    path, units: str = "m", *, check_size: bool = True, columns: Sequence | None = None
) -> PlanarCurve:
    """Curve through the (x, z) points of a CSV file (comma, semicolon or blank separated).

    ``columns``: the two columns to read, as 0-based positions or header names (default: the
    first two; a file with more numeric columns gets a :class:`CurveColumnsWarning` naming
    the two read). Points in ``units`` (default m); a header line (any non-numeric first row)
    is skipped. Decimal commas (``1,5``) are refused with a hint; a closed curve (last point
    on the first) gets a :class:`CurveClosedWarning`. Errors never quote the file's content.
    ``check_size`` warns about an implausible size.
    """
    k = length_factor(units)
    path = _checked_input(path, "points file")
    try:
        size = path.stat().st_size
        if size > MAX_SVG_BYTES:
            raise CurveFormatError(
                f"points file {str(path)!r}: {size} bytes; at most {MAX_SVG_BYTES} are read"
            )
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise CurveFormatError(f"points file {str(path)!r} is not a UTF-8 text file") from None
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise CurveFormatError(f"cannot read points file {str(path)!r}: {why}") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise CurveFormatError(f"points file {str(path)!r} is empty")
    if len(lines) > MAX_CSV_POINTS + 1:
        raise CurveFormatError(
            f"points file {str(path)!r} has {len(lines):,} rows; at most {MAX_CSV_POINTS:,} "
            "points are read (docs/limits.md)"
        )
    try:
        delim = csv.Sniffer().sniff(lines[0], delimiters=",;\t ").delimiter
    except csv.Error:
        delim = ","
    table, header = [], None
    for n, ln in enumerate(lines):
        fields = [f.strip() for f in next(csv.reader(io.StringIO(ln), delimiter=delim))]
        fields = [f for f in fields if f]
        if delim != " " and len(fields) < 2:
            fields = ln.split()
        try:
            vals = [float(f) for f in fields]
            if len(vals) < 2:
                raise ValueError
        except ValueError:
            if n == 0:
                header = fields
                continue
            comma = any(_DECIMAL_COMMA.fullmatch(f) for f in fields)
            hint = "; decimal commas? write 1.5, not 1,5" if comma else ""
            raise CurveFormatError(
                f"{str(path)!r} line {n + 1}: expected at least two numbers x, z, got "
                f"{len(fields)} field(s) that are not all numbers{hint}"
            ) from None
        table.append(vals)
    if not table:
        raise CurveFormatError(f"points file {str(path)!r} has no numeric rows")
    width = min(len(r) for r in table)
    if max(len(r) for r in table) != width:
        raise CurveFormatError(f"points file {str(path)!r}: rows have different numbers of values")
    pick = _pick_columns(path, columns, header, width)
    rows = [[r[pick[0]], r[pick[1]]] for r in table]
    curve = PlanarCurve.from_points(np.array(rows) * k, name=path.stem, source=str(path))
    curve = PlanarCurve(curve.func, name=curve.name, kind="points",
                        params={**curve.params, "units": units, "metres_per_unit": k})  # fmt: skip
    _warn_if_closed(np.array(rows, float), path)
    if check_size:
        check_curve_size(curve, units, k, f" from {path.name}")
    return curve


def _checked_input(path, what: str) -> Path:
    """:func:`~holofold.geometry.check_input_file` as the curve error (one line)."""
    try:
        return check_input_file(path, what)
    except OSError as exc:
        raise CurveFormatError(str(exc)) from None


_DECIMAL_COMMA = re.compile(r"[-+]?\d+,\d+")


class CurveColumnsWarning(UserWarning):
    """A points file with more than two numeric columns read without ``columns``."""


class CurveClosedWarning(UserWarning):
    """A closed curve: a strip over it would collide with itself."""


def _pick_columns(path: Path, columns, header, width: int) -> tuple[int, int]:
    """The 0-based positions of the two columns to read."""
    names = header if header and len(header) == width else None
    if columns is None:
        if width > 2:
            shown = f" ({', '.join(names)})" if names else ""
            first = f"{names[0]}, {names[1]}" if names else "1 and 2"
            warnings.warn(
                f"points file {path.name} has {width} numeric columns{shown}; reading columns "
                f"{first} as (x, z): choose two with columns = [...] (names or 0-based "
                "positions)",
                CurveColumnsWarning,
                stacklevel=3,
            )
        return (0, 1)
    cols = list(columns)
    if len(cols) != 2:
        raise CurveFormatError(f"columns = {cols!r}: give the two columns to read as (x, z)")
    out = []
    for c in cols:
        if isinstance(c, str) and not c.isdigit():
            if not names or c not in names:
                known = ", ".join(names) if names else "none (no header)"
                raise CurveFormatError(
                    f"points file {path.name} has no column {c!r}; its columns: {known}"
                )
            out.append(names.index(c))
        else:
            i = int(c)
            if not 0 <= i < width:
                raise CurveFormatError(
                    f"columns = {cols!r}: {path.name} has {width} columns (0 to {width - 1})"
                )
            out.append(i)
    return out[0], out[1]


def _warn_if_closed(xz: np.ndarray, path: Path) -> None:
    size = float(np.ptp(xz, axis=0).max())
    if len(xz) > 2 and size > 0 and np.linalg.norm(xz[-1] - xz[0]) <= 1e-9 * size:
        warnings.warn(
            f"points file {path.name} describes a closed curve (its last point is its first): "
            "a strip over it closes on itself and its panels collide; fit an open arc",
            CurveClosedWarning,
            stacklevel=3,
        )


def _document_unit(svg) -> tuple[str | None, float]:
    """(unit, metres per user unit) that the root's width and viewBox declare (None, 1.0 if no
    absolute unit), from the attributes themselves (exact)."""
    raw = str(svg.values.get("width") or "").strip().lower()
    m = re.fullmatch(r"([+-]?(?:\d+\.?\d*|\.\d+)(?:e[+-]?\d+)?)\s*([a-z]*)", raw)
    if not m or m.group(2) not in _SVG_UNITS:
        return None, 1.0
    vb = svg.viewbox
    if vb is None or not vb.width:
        return m.group(2), _PX  # no viewBox: user units are CSS px
    return m.group(2), float(m.group(1)) * _SVG_UNITS[m.group(2)] / float(vb.width)


def _user_per_px(svg) -> float:
    """User units per coordinate unit of svgelements' output (which maps the viewBox to px)."""
    vb = svg.viewbox
    if vb is None or not vb.width or svg.values.get("width") is None:
        return 1.0
    return float(vb.width) / float(svg.width)


def read_svg_curve(ref, units: str | None = None, *, check_size: bool = True) -> PlanarCurve:
    """Curve from an SVG file: ``"file.svg"`` (its first ``<path>``) or ``"file.svg#path-id"``.

    Parameters
    ----------
    ref : str or Path
        The file, optionally with ``#id`` of a path (or line, polyline, ...).
    units : str, optional
        Unit of one user unit of the drawing (one of :data:`LENGTH_UNITS`). Default: the
        document's own size (``width="400mm"`` with its viewBox), or 1 m per user unit if it
        states none.
    check_size : bool
        Warn about an implausible size (:func:`check_curve_size`).

    The SVG y axis points down, so z = -y; the origin is moved to the path's first point.
    Without ``#id`` a file with several paths gives a :class:`CurveSelectionWarning` naming
    them; a path of several subpaths (M commands) is refused, not joined. Files over
    :data:`MAX_SVG_BYTES` or nested deeper than :data:`MAX_SVG_NESTING` are refused before
    parsing; every problem is one :class:`~holofold.fitting.curves.CurveFormatError` line.
    """
    from svgelements import SVG, Shape
    from svgelements import Path as SvgPath

    ref = str(ref)
    file, _, pid = ref.partition("#")
    _check_svg_structure(file)
    try:
        svg = SVG.parse(file, reify=True)
    except RecursionError:  # within MAX_SVG_NESTING, but called from a deep stack
        raise CurveFormatError(
            f"cannot read SVG file {file!r}: elements nested too deeply to read here; at most "
            f"{MAX_SVG_NESTING} levels"
        ) from None
    except Exception as exc:  # noqa: BLE001 - any parse failure is a bad file
        raise CurveFormatError(f"cannot read SVG file {file!r}: {exc}") from exc
    if pid:
        el = svg.get_element_by_id(pid)
        if not isinstance(el, Shape):
            raise CurveFormatError(f"SVG file {file!r} has no <path id={pid!r}> (or other shape)")
    else:
        shapes = [e for e in svg.elements() if isinstance(e, Shape)]
        paths = [e for e in shapes if isinstance(e, SvgPath)]
        if not shapes:
            raise CurveFormatError(f"SVG file {file!r} contains no <path> element")
        pool = paths or shapes
        el = pool[0]
        if len(pool) > 1:
            ids = [str(e.id) for e in pool if e.id]
            listed = ", ".join(ids[:5]) + (", ..." if len(ids) > 5 else "")
            warnings.warn(
                f"SVG file {file!r} has {len(pool)} {'paths' if paths else 'shapes'}"
                + (f" (ids {listed})" if ids else " (none with an id)")
                + f"; read the first{f' ({el.id!r})' if el.id else ''}: choose one with "
                f"{Path(file).name}#id",
                CurveSelectionWarning,
                stacklevel=2,
            )
    doc_unit, doc_per_user = _document_unit(svg)
    if units is None:
        label, per_user = (doc_unit, doc_per_user) if doc_unit else ("m (no unit in the file)", 1.0)
    else:
        per_user = length_factor(units)
        label = units
        if doc_unit and not math.isclose(per_user, doc_per_user, rel_tol=1e-6):
            warnings.warn(
                f"SVG file {file!r} declares one user unit = {doc_per_user * 1e3:.6g} mm "
                f"(width in {doc_unit}); read as 1 {units} as asked",
                CurveUnitWarning,
                stacklevel=2,
            )
    # svgelements maps the viewBox to CSS px: back to user units, then to metres
    scale = _user_per_px(svg) * per_user
    name = pid or Path(file).stem
    curve = svg_path_curve(SvgPath(el), name, ref, scale)
    params = {**curve.params, "units": label, "metres_per_unit": per_user}
    curve = PlanarCurve(curve.func, name=name, kind="svg", params=params)
    if check_size:
        check_curve_size(curve, label, per_user, f" from {Path(file).name}")
    return curve


def _check_svg_structure(file: str) -> None:
    """Refuse a file over :data:`MAX_SVG_BYTES` or nested deeper than :data:`MAX_SVG_NESTING`
    before svgelements (which recurses per level) parses it: one streaming pass of expat."""
    from xml.parsers import expat

    _checked_input(file, "SVG file")
    try:
        size = Path(file).stat().st_size
    except OSError as exc:
        raise CurveFormatError(f"cannot read SVG file {file!r}: {exc.strerror}") from None
    if size > MAX_SVG_BYTES:
        raise CurveFormatError(
            f"cannot read SVG file {file!r}: {size} bytes; expected at most {MAX_SVG_BYTES} "
            "(64 MiB)"
        )
    parser = expat.ParserCreate()
    depth = [0]
    # expanded size: each open element's own (elements, points) and the ids it refers to
    stack: list = [[0, 0, {}]]
    named: dict = {}  # id -> (elements, points, {referenced id: count}) of its subtree

    class Deep(Exception):
        pass

    def start(name, attrs):
        depth[0] += 1
        if depth[0] > MAX_SVG_NESTING:
            raise Deep(name)
        points = sum(len(_NUMBER.findall(attrs.get(k, ""))) // 2 for k in ("d", "points"))
        refs = {}
        href = attrs.get("xlink:href") or attrs.get("href") or ""
        if href.startswith("#"):
            refs[href[1:]] = 1
        stack.append([1, points, refs, attrs.get("id")])

    def end(name):
        depth[0] -= 1
        n, pts, refs, ident = stack.pop()
        if ident:
            named[ident] = (n, pts, refs)
        parent = stack[-1]
        parent[0] += n
        parent[1] += pts
        for k, c in refs.items():
            parent[2][k] = parent[2].get(k, 0) + c

    parser.StartElementHandler, parser.EndElementHandler = start, end
    try:
        with open(file, "rb") as fh:
            parser.ParseFile(fh)
    except Deep as exc:
        raise CurveFormatError(
            f"cannot read SVG file {file!r}: elements nested over {MAX_SVG_NESTING} deep (line "
            f"{parser.CurrentLineNumber}, <{exc}>); expected at most {MAX_SVG_NESTING} levels "
            "of groups"
        ) from None
    except expat.ExpatError as exc:
        why = expat.errors.messages[exc.code]
        raise CurveFormatError(
            f"cannot read SVG file {file!r}: not well-formed XML: {why} (line {exc.lineno}, "
            f"column {exc.offset})"
        ) from None
    except OSError as exc:
        raise CurveFormatError(f"cannot read SVG file {file!r}: {exc.strerror}") from None
    elements, points = _expanded(stack[0][0], stack[0][1], stack[0][2], named, file)
    for count, limit, what in ((elements, MAX_SVG_ELEMENTS, "elements"),
                               (points, MAX_SVG_POINTS, "path points")):  # fmt: skip
        if count > limit:
            raise CurveFormatError(
                f"cannot read SVG file {file!r}: {_size(count, limit)} {what} once its <use> "
                f"references are expanded; expected at most {limit:,} (docs/limits.md)"
            )


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _size(count: int, limit: int) -> str:
    return f"over {limit:,}" if count > 10 * limit else f"{count:,}"


def _expanded(elements: int, points: int, refs: dict, named: dict, file: str) -> tuple[int, int]:
    """(elements, points) of a subtree with every reference expanded, saturated just above the
    limits (a doubling bomb's 2^25 is never built), refusing a reference cycle."""
    cap = (10 * MAX_SVG_ELEMENTS + 1, 10 * MAX_SVG_POINTS + 1)
    memo: dict = {}

    def size(ident, seen):
        if ident in memo:
            return memo[ident]
        if ident in seen:
            raise CurveFormatError(f"cannot read SVG file {file!r}: <use> of #{ident} refers to "
                                   "itself (a reference cycle)")  # fmt: skip
        if ident not in named:
            return (0, 0)  # a dangling reference: svgelements skips it
        n, p, r = named[ident]
        out = total(n, p, r, seen | {ident})
        memo[ident] = out
        return out

    def total(n, p, r, seen):
        for k, c in r.items():
            a, b = size(k, seen)
            n, p = min(cap[0], n + c * a), min(cap[1], p + c * b)
        return n, p

    return total(elements, points, refs, frozenset())


# ---------------------------------------------------------------------- any description
def load_curve(curve, units: str | None = None, *, check_size: bool = True) -> PlanarCurve:
    """A :class:`PlanarCurve` from any accepted description.

    ``curve`` may be a PlanarCurve, a callable, an (N, 2) array, a built-in specification
    string (``"parabola:span=4,height=1"``), a CSV/TXT file of points or an SVG file
    (optionally ``file.svg#path-id``). ``units`` is the unit of a file's numbers
    (CSV default m, SVG default the document's own);
    ``check_size`` warns about a file's curve of implausible size.
    """
    if isinstance(curve, PlanarCurve):
        return curve
    if isinstance(curve, (str, Path)):
        s = str(curve)
        file = s.partition("#")[0]
        low = file.lower()
        if low.endswith(".svg"):
            return read_svg_curve(s, units, check_size=check_size)
        if low.endswith((".csv", ".txt", ".dat")) or Path(file).is_file():
            if not Path(file).is_file():
                raise CurveFormatError(f"points file {file!r} does not exist")
            return read_points_csv(file, units or "m", check_size=check_size)
        return parse_curve_spec(s)
    if callable(curve):
        return PlanarCurve.from_function(curve)
    return PlanarCurve.from_points(curve)
