"""SVG crease patterns in Origami Simulator's convention, read into a crease pattern.

Stroke colours give the assignment: mountain red ``#ff0000``, valley blue ``#0000ff``, border
black ``#000000``, cut green ``#00ff00``, facet yellow ``#ffff00`` (``F``: stays flat),
undriven magenta ``#ff00ff`` (``U``: a passive crease); a colour within 16/255 per channel of
one of these counts as it, any other is left out with a warning naming it. The fold angle of a
mountain or valley is ``-+180 x opacity x stroke-opacity`` degrees (Origami Simulator's
encoding, 1 = a full fold); ``data-assignment`` and ``data-foldAngle`` attributes (Rabbit
Ear's and holofold's own) take precedence over the colour and the opacity.

The file is parsed by svgelements: ``<line>``, ``<polyline>``, ``<polygon>``, ``<rect>`` and
``<path>`` elements anywhere in groups (but a legend, ``<g id="legend">``, and registration
marks, ``data-role="registration"``), with every ``transform``, CSS class and style, and the
document's units and ``viewBox`` honoured (one user unit is 1/96 inch unless the document says
otherwise, so a drawing in millimetres reads in millimetres); elements hidden by ``display:
none`` are left out. The y axis is turned up, so that the pattern is not mirrored (a mirrored
pattern swaps mountains and valleys). By default (``curves="keep"``) a curve (C, Q, S, T, A
path segments) is cut by :func:`~holofold.geometry.curved.discretise`; ``curves="refuse"``
refuses curved creases (and flattens curved borders and cuts into 16 segments with a warning),
``curves="flatten"`` cuts every curve into 16. :func:`svg_drawing` returns the lines as a
:class:`~holofold.geometry.line_drawing.LineDrawing`; then
:func:`~holofold.geometry.line_drawing.pattern_from_drawing` merges end points within ``tol``,
splits crossing lines and finds the faces. The file is a path, its bytes or a binary file
object; the bounded checks (:func:`~holofold.geometry.bounded.check_svg_pattern`) run on its
bytes before svgelements parses them.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from holofold.geometry.bounded import check_svg_pattern, read_source, source_name
from holofold.geometry.curved import curve_from_svg_segment, cut_curves
from holofold.geometry.errors import FormatError, ParameterError
from holofold.geometry.line_drawing import LineDrawing, check_unit, pattern_from_drawing

__all__ = [
    "read_svg_pattern",
    "svg_drawing",
    "svg_lines",
    "SVG_COLOURS",
    "CURVE_MODES",
    "MAX_SVG_BYTES",
]

#: stroke colour (r, g, b) -> FOLD code (Origami Simulator's import convention)
SVG_COLOURS = {
    (0, 0, 0): "B",
    (255, 0, 0): "M",
    (0, 0, 255): "V",
    (0, 255, 0): "C",
    (255, 255, 0): "F",
    (255, 0, 255): "U",
}
_COLOUR_TOL = 16
#: what to do with curved lines: refuse curved creases (flatten curved borders and cuts),
#: flatten every curve into 16 segments, or keep curves (discretised by chord deviation and
#: piece length, :func:`holofold.geometry.curved.discretise`)
CURVE_MODES = ("refuse", "flatten", "keep")
#: the largest SVG file read, bytes (Origami Simulator's largest example is 0.7 MB)
MAX_SVG_BYTES = 64 * 2**20
#: metres per SVG px (1/96 inch)
PX = 0.0254 / 96.0
_CODES = {"M", "V", "B", "F", "C", "J", "U"}


def _code(colour) -> str | None:
    if colour is None or colour.value is None:
        return None
    rgb = np.array([colour.red, colour.green, colour.blue])
    for key, code in SVG_COLOURS.items():
        if np.abs(rgb - np.array(key)).max() <= _COLOUR_TOL:
            return code
    return ""


def _number(text, default: float = 1.0) -> float:
    if text is None:
        return default
    try:
        v = float(str(text).strip().rstrip("%"))
    except ValueError:
        return default
    return v / 100.0 if str(text).strip().endswith("%") else v


def _pieces(seg, n: int) -> np.ndarray:
    """``n`` straight pieces of a curved segment, (n + 1, 2) points."""
    pts = [seg.point(x) for x in np.linspace(0.0, 1.0, n + 1)]
    return np.array([[float(p.x), float(p.y)] for p in pts])


# svgelements converts absolute units to px with rounded factors (1 mm = 3.7795296 px, not
# 96 / 25.4); a px of a document sized in those units is undone with the same factor, so a
# drawing in millimetres reads back to the nanometre
_SE_PX = {"mm": 96 * 0.0393701 / 1e-3, "cm": 96 * 0.393701 / 1e-2, "in": 96 / 0.0254}


def _metres_per_px(svg, name: str = "the SVG") -> float:
    import re

    width = str(svg.values.get("width", "")).strip()
    m = re.fullmatch(r"([-+0-9.eE]+)\s*([a-zA-Z%]*)", width)
    unit = m.group(2).lower() if m else ""  # a known unit: bounded.check_svg_pattern saw to it
    if m and not 0 < _float_or_nan(m.group(1)) < math.inf:
        raise FormatError(f"{name}: width {width!r} is not a length > 0")
    box = svg.values.get("viewBox")
    if box is not None:
        vb = [_float_or_nan(v) for v in re.split(r"[\s,]+", str(box).strip())]
        if len(vb) != 4 or not np.isfinite(vb).all() or vb[2] <= 0 or vb[3] <= 0:
            raise FormatError(
                f"{name}: viewBox is not four numbers 'x y width height' with width, height > 0"
            )
    if unit in ("", "px", "pt", "pc"):  # svgelements turns pt and pc into px at 96 ppi
        return PX
    return 1.0 / _SE_PX[unit]


def _float_or_nan(text: str) -> float:
    """``float(text)``, NaN where it is not a number."""
    try:
        return float(text)
    except ValueError:
        return math.nan


def _without_legend(data: bytes):
    """The file as a stream, less a legend group (``<g id="legend">``) and registration marks
    (``data-role="registration"``): drawings, not creases (holofold's SVG writer adds them)."""
    import io

    if b'id="legend"' not in data and b'data-role="registration"' not in data:
        return io.BytesIO(data)
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(data)
    except ET.ParseError:
        return io.BytesIO(data)  # svgelements says what is wrong
    for parent in list(root.iter()):
        for child in list(parent):
            if child.get("id") == "legend" or child.get("data-role") == "registration":
                parent.remove(child)
    return io.BytesIO(ET.tostring(root))


def svg_drawing(
    source, *, curves: str = "keep", curve_chord=None, curve_length=None
) -> LineDrawing:
    """The straight lines of an SVG crease pattern (a path, bytes or a binary file object), in
    SVG px with y up, ``unit`` the metres of one px as the document's width says.

    With ``curves="keep"`` a curve is cut by :func:`~holofold.geometry.curved.discretise` with
    chord deviation ``curve_chord`` and piece length ``curve_length`` (px; defaults relative to
    the drawing's larger side, :data:`~holofold.geometry.curved.CHORD_DEFAULT`); the curves
    kept are the drawing's ``curves``.
    """
    import svgelements as se

    if curves not in CURVE_MODES:
        raise ParameterError(f"curves = {curves!r}; allowed: {', '.join(CURVE_MODES)}")
    name = source_name(source)
    data = read_source(source, MAX_SVG_BYTES, "SVG file")
    check_svg_pattern(data, name)  # counts after <use> expansion, finite numbers, root size unit
    stream = _without_legend(data)
    try:
        svg = se.SVG.parse(stream, reify=True, ppi=96.0)
    except Exception as exc:  # noqa: BLE001 - any parse failure of a user file: one line
        raise FormatError(
            f"{name}: not a readable SVG file ({type(exc).__name__}: {exc})"
        ) from None
    segs, codes, angles = [], [], []
    bad_colours: Counter = Counter()
    flattened = 0
    curved_creases = []
    kept = []
    no_stroke = 0
    for el in svg.elements():
        if not isinstance(el, se.Shape) or isinstance(el, se.Text):
            continue
        v = el.values
        if str(v.get("display", "")).strip() == "none" or str(v.get("visibility", "")).strip() in (
            "hidden",
            "collapse",
        ):
            continue
        code = v.get("data-assignment")
        if code is not None:
            code = str(code).strip().upper()
            if code not in _CODES:
                raise FormatError(
                    f"{name}: element {el.id or type(el).__name__} has data-assignment "
                    f"{code!r}; allowed: {' '.join(sorted(_CODES))}"
                )
        else:
            code = _code(el.stroke)
            if code is None:
                no_stroke += 1
                continue
            if code == "":
                bad_colours[el.stroke.hexrgb] += 1
                continue
        angle = v.get("data-foldAngle", v.get("data-foldangle"))
        if angle is not None:
            try:
                ang = float(angle)
            except ValueError:
                raise FormatError(
                    f"{name}: element {el.id or type(el).__name__} has data-foldAngle "
                    f"{angle!r}; expected degrees"
                ) from None
        else:
            op = _number(v.get("opacity")) * _number(v.get("stroke-opacity"))
            ang = {"M": -180.0, "V": 180.0}.get(code, 0.0) * min(max(op, 0.0), 1.0)
        try:
            path_el = se.Path(el)
        except Exception:  # noqa: BLE001
            if code in ("B", "C"):
                continue
            raise FormatError(
                f"{name}: element {el.id or type(el).__name__} in a crease colour ({code}) "
                "cannot be read as a path"
            ) from None
        for seg in path_el.segments():
            if isinstance(seg, se.Move):
                continue
            if isinstance(seg, (se.Line, se.Close)):
                if seg.start is None or seg.end is None:
                    continue
                pts = np.array([[seg.start.x, seg.start.y], [seg.end.x, seg.end.y]])
            else:  # a curve
                if curves == "keep":
                    cv = curve_from_svg_segment(seg, code, ang)
                    if cv is not None:
                        kept.append(cv)
                        continue
                if code in ("B", "C") or curves == "flatten":
                    pts = _pieces(seg, 16)
                    flattened += 1
                else:
                    curved_creases.append(el.id or type(el).__name__)
                    continue
            for a, b in zip(pts[:-1], pts[1:], strict=True):
                segs.append([a, b])
                codes.append(code)
                angles.append(ang)
    if kept:
        n_pieces, chord, length = cut_curves(
            kept, segs, codes, angles, chord=curve_chord, length=curve_length
        )
    if curved_creases:
        raise FormatError(
            f"{name}: {len(curved_creases)} curved crease(s) (first: {curved_creases[0]}); "
            "holofold folds straight creases: redraw them as segments, or read with "
            "curves='flatten' (--curves flatten)"
        )
    notes = []
    if bad_colours:
        listed = ", ".join(f"{c} ({n})" for c, n in bad_colours.most_common(5))
        notes.append(
            f"{sum(bad_colours.values())} line(s) of other colours left out: {listed}; crease "
            "colours: red M, blue V, black B, green C, yellow F, magenta U"
        )
    if kept:
        notes.append(
            f"{len(kept)} curve(s) kept, cut into {n_pieces} piece(s) (chord deviation "
            f"{chord:.3g} px, piece length {length:.3g} px)"
        )
    if flattened:
        notes.append(f"{flattened} curved piece(s) flattened into segments")
    if not segs:
        why = f"; {no_stroke} element(s) without a stroke" if no_stroke else ""
        raise FormatError(
            f"{name}: no crease-pattern lines (stroked in the crease colours){why}"
            + (f"; other colours: {', '.join(bad_colours)}" if bad_colours else "")
        )
    S = np.array(segs, float)
    S[..., 1] *= -1.0  # y up
    mpp = _metres_per_px(svg, name)
    return LineDrawing(S, np.array(codes, dtype="<U1"), np.array(angles, float), mpp,
                       name=name, kind="svg", notes=tuple(notes),
                       curves=tuple(c.mapped(flip_y=True) for c in kept))  # fmt: skip


def svg_lines(path, *, curves: str = "keep", curve_chord=None, curve_length=None):
    """:func:`svg_drawing` as a tuple, for callers of the earlier form: (segments (n, 2, 2) px,
    assignment (n,), fold_angle (n,) degrees, notes list, metres per px)."""
    d = svg_drawing(path, curves=curves, curve_chord=curve_chord, curve_length=curve_length)
    return (np.array(d.segments), np.array(d.assignment), np.array(d.fold_angle), list(d.notes),
            d.unit)  # fmt: skip


def read_svg_pattern(
    source, *, tol: float | None = None, unit: float | None = None, split: str = "as-needed",
    curves: str = "keep",
):  # fmt: skip
    """The crease pattern of an SVG file (a path, bytes or a binary file object; see the module
    docstring), metres.

    ``tol``: merge distance in SVG px (default 2e-3 of the drawing's larger side); ``unit``:
    metres per SVG px (default: as the document's width says; 0.0254/96 for a CSS pixel);
    ``split``: which faces to triangulate (:data:`~holofold.geometry.facets.SPLIT_MODES`);
    ``curves``: :data:`CURVE_MODES`.
    """
    if unit is not None:
        check_unit(unit)  # before the file is read
    drawing = svg_drawing(source, curves=curves)
    return pattern_from_drawing(drawing, tol=tol, unit=unit, split=split)
