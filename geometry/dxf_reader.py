"""DXF crease patterns (CAD, laser software) read into a crease pattern, with ezdxf.

The layer of an entity gives its assignment (:data:`LAYER_CODES`: the layers holofold's DXF
writer uses, ``BOUNDARY``, ``CUT``, ``SCORE_M``, ``SCORE_V``, ``SCORE_F``, ``SCORE_U``, and the
usual names ``MOUNTAIN``, ``VALLEY``, ``BORDER``, ``OUTLINE``, ``FACET``, ``UNDRIVEN``, ``M``,
``V``, ... in any case); an entity on another layer is assigned by its colour as in Origami
Simulator's SVG convention (AutoCAD colour index 1 red mountain, 5 blue valley, 7 black/white
border, 3 green cut, 2 yellow facet, 6 magenta undriven, or the same true colours; ``BYLAYER``
resolved). ``REGISTRATION`` and layers of no known name or colour are left out with a warning
naming them. A DXF has no fold angle: mountains and valleys fold fully (-+180 degrees) unless
the entity is transparent, where the angle is 180 x (1 - transparency) (the opacity rule of
Origami Simulator's SVG).

Entities: ``LINE``, ``LWPOLYLINE`` and ``POLYLINE`` (straight pieces; bulges are arcs),
``ARC``, ``CIRCLE``, ``ELLIPSE``, ``SPLINE`` and polyline bulges (curves: by default,
``curves="keep"``, kept as :class:`~holofold.geometry.curved.Curve` (arcs; a spline's Bezier
pieces; the Bezier curves ezdxf makes of bulges) and cut by
:func:`~holofold.geometry.curved.discretise` as the SVG reader cuts its curves (the drawing's
``curves``); a rational or higher-degree spline, or a curve out of the drawing's plane, by
ezdxf's adaptive flattening to 1e-3 of its extent, as ``"flatten"`` does every curve;
``"refuse"`` refuses curved creases) and ``INSERT`` (block references, exploded
with their transformation). Units from ``$INSUNITS`` (unitless drawings are read as
millimetres, with a warning); ``unit`` (metres per drawing unit) overrides.

:func:`dxf_drawing` returns the lines as a :class:`~holofold.geometry.line_drawing.LineDrawing`
(the file a path, its bytes or a binary file object; the bounded checks of
:func:`~holofold.geometry.bounded.check_dxf_pattern` run on its bytes before ezdxf parses them);
:func:`~holofold.geometry.line_drawing.pattern_from_drawing` makes the crease pattern.
"""

from __future__ import annotations

import io
import math
from collections import Counter

import numpy as np

from holofold.geometry.bounded import check_dxf_pattern, read_source, source_name
from holofold.geometry.curved import Curve, cut_curves
from holofold.geometry.errors import EnvironmentFault, FormatError, ParameterError
from holofold.geometry.line_drawing import LineDrawing, pattern_from_drawing

__all__ = [
    "read_dxf_pattern",
    "dxf_drawing",
    "dxf_lines",
    "LAYER_CODES",
    "ACI_CODES",
    "MAX_DXF_BYTES",
]

#: layer name (upper case) -> FOLD code; holofold's writer uses the first of each group
LAYER_CODES = {
    **dict.fromkeys(("BOUNDARY", "BORDER", "OUTLINE", "B"), "B"),
    **dict.fromkeys(("CUT", "CUTS", "C"), "C"),
    **dict.fromkeys(("SCORE_M", "MOUNTAIN", "MOUNTAINS", "M"), "M"),
    **dict.fromkeys(("SCORE_V", "VALLEY", "VALLEYS", "V"), "V"),
    **dict.fromkeys(("SCORE_F", "FLAT", "FACET", "FACETS", "F"), "F"),
    **dict.fromkeys(("JOIN", "J"), "J"),
    **dict.fromkeys(("SCORE_U", "UNDRIVEN", "UNASSIGNED", "HINGE", "U"), "U"),
}
#: layers that are never crease lines
IGNORED_LAYERS = ("REGISTRATION", "DEFPOINTS")
#: AutoCAD colour index -> FOLD code
ACI_CODES = {1: "M", 5: "V", 7: "B", 3: "C", 2: "F", 6: "U"}
_RGB_CODES = {(255, 0, 0): "M", (0, 0, 255): "V", (0, 0, 0): "B", (255, 255, 255): "B",
              (0, 255, 0): "C", (255, 255, 0): "F", (255, 0, 255): "U"}  # fmt: skip
#: the largest DXF file read, bytes
MAX_DXF_BYTES = 64 * 2**20
_CURVES = ("ARC", "CIRCLE", "ELLIPSE", "SPLINE")


def _code(entity, doc) -> str | None:
    layer = str(entity.dxf.get("layer", "0"))
    key = layer.strip().upper()
    if key in IGNORED_LAYERS:
        return None
    if key in LAYER_CODES:
        return LAYER_CODES[key]
    rgb = entity.rgb if entity.dxf.hasattr("true_color") else None
    if rgb is None:
        aci = entity.dxf.get("color", 256)
        if aci == 256:  # BYLAYER
            try:
                lay = doc.layers.get(layer)
                aci = lay.color
                if lay.has_dxf_attrib("true_color"):
                    rgb = lay.rgb
            except Exception:  # noqa: BLE001 - an undefined layer: no colour
                return ""
        if rgb is None:
            return ACI_CODES.get(abs(int(aci)), "")
    return _RGB_CODES.get(tuple(int(c) for c in rgb), "")


def _angle(code: str, entity) -> float:
    if code not in ("M", "V"):
        return 0.0
    t = 0.0
    try:
        if entity.dxf.hasattr("transparency"):
            t = float(entity.transparency)
    except Exception:  # noqa: BLE001
        t = 0.0
    return (-180.0 if code == "M" else 180.0) * (1.0 - min(max(t, 0.0), 1.0))


def _entities(space, depth: int = 0):
    for e in space:
        if e.dxftype() == "INSERT" and depth < 16:
            try:
                yield from _entities(e.virtual_entities(), depth + 1)
            except Exception:  # noqa: BLE001 - a broken block: skip it
                continue
        else:
            yield e


def _load(ezdxf, data: bytes, name: str):
    """The ezdxf document of a DXF file's bytes, as ``ezdxf.readfile`` loads a file: binary DXF
    by its sentinel, else text in the encoding the header names (undecodable bytes kept)."""
    from ezdxf.document import Drawing
    from ezdxf.filemanagement import dxf_stream_info
    from ezdxf.lldxf.tagger import binary_tags_loader
    from ezdxf.lldxf.validator import is_dxf_stream

    if data[:22] == b"AutoCAD Binary DXF\r\n\x1a\x00":
        return Drawing.load(binary_tags_loader(data, errors="surrogateescape"))
    if not is_dxf_stream(io.TextIOWrapper(io.BytesIO(data), errors="ignore")):
        raise OSError(f"File '{name}' is not a DXF file.")
    info = dxf_stream_info(io.TextIOWrapper(io.BytesIO(data), "utf-8", errors="ignore"))
    text = io.TextIOWrapper(io.BytesIO(data), encoding=info.encoding, errors="surrogateescape")
    return ezdxf.read(text)


def dxf_drawing(source, *, curves: str = "keep") -> LineDrawing:
    """The straight lines of a DXF crease pattern (a path, bytes or a binary file object), in
    drawing units, ``unit`` the metres of one as ``$INSUNITS`` says (millimetres, with a note,
    when it says none)."""
    try:
        import ezdxf
        from ezdxf import path as ezpath
        from ezdxf import units as ezunits
    except ImportError as exc:  # a dependency of holofold: the environment is broken
        raise EnvironmentFault(f"ezdxf cannot be imported ({exc}); pip install ezdxf") from None
    if curves not in ("refuse", "flatten", "keep"):
        raise ParameterError(f"curves = {curves!r}; allowed: refuse, flatten, keep")
    name = source_name(source)
    data = read_source(source, MAX_DXF_BYTES, "DXF file")
    check_dxf_pattern(data, name)  # lines and block INSERT expansion, before ezdxf loads it
    try:
        doc = _load(ezdxf, data, name)
    except (OSError, ezdxf.DXFError) as exc:
        why = " ".join(str(exc).split())[:200]  # one line
        raise FormatError(f"{name}: not a readable DXF file ({why})") from None
    except Exception as exc:  # noqa: BLE001 - a malformed file: one line
        raise FormatError(
            f"{name}: not a readable DXF file ({type(exc).__name__}: "
            f"{' '.join(str(exc).split())[:200]})"
        ) from None
    notes = []
    insunits = int(doc.header.get("$INSUNITS", 0) or 0)
    if insunits == 0:
        unit = 1e-3
        notes.append("the drawing states no unit ($INSUNITS 0): read as millimetres; give unit")
    else:
        try:
            unit = float(ezunits.conversion_factor(insunits, ezunits.M))
        except Exception:  # noqa: BLE001 - an unknown unit code
            unit = 1e-3
            notes.append(f"unknown $INSUNITS {insunits}: read as millimetres; give unit")
    segs, codes, angles = [], [], []
    skipped: Counter = Counter()
    curved_creases = 0
    flattened = 0
    kept: list = []
    ents = list(_entities(doc.modelspace()))
    pts_all = []

    def add(pieces, code, ang):
        """Each polyline of ``pieces`` as segments of assignment ``code`` and angle ``ang``."""
        for P in pieces:
            pts_all.append(P)
            for a, b in zip(P[:-1], P[1:], strict=True):
                segs.append([a, b])
                codes.append(code)
                angles.append(ang)

    for e in ents:
        t = e.dxftype()
        if t not in ("LINE", "LWPOLYLINE", "POLYLINE", *_CURVES):
            continue
        code = _code(e, doc)
        if code is None:
            continue
        if code == "":
            skipped[str(e.dxf.get("layer", "0"))] += 1
            continue
        ang = _angle(code, e)
        if t == "LINE":
            a, b = e.dxf.start, e.dxf.end
            pieces = [np.array([[a.x, a.y], [b.x, b.y]])]
        else:
            try:
                p = ezpath.make_path(e)
            except Exception:  # noqa: BLE001 - an entity ezdxf cannot trace
                skipped[f"{t} on {e.dxf.get('layer', '0')}"] += 1
                continue
            curved = t in _CURVES or p.has_curves
            if curved and code not in ("B", "C") and curves == "refuse":
                curved_creases += 1
                continue
            if curved and curves == "keep":
                got = _kept_curves(e, p, code, ang)
                if got is not None:  # curves, and the straight pieces between them
                    kept += got[0]
                    add(got[1], code, ang)
                    continue
            pieces = []
            for sub in p.sub_paths():
                if sub.has_curves:
                    flattened += 1
                    ext = max(
                        1e-12,
                        float(
                            np.ptp(
                                np.array([(v.x, v.y) for v in sub.control_vertices()]), axis=0
                            ).max()
                        ),
                    )
                    vs = list(sub.flattening(distance=1e-3 * ext))
                else:
                    vs = [v for v in sub.control_vertices()]
                P = np.array([[v.x, v.y] for v in vs])
                if len(P) >= 2:
                    pieces.append(P)
        add(pieces, code, ang)
    if curved_creases:
        raise FormatError(
            f"{name}: {curved_creases} curved crease(s); holofold folds straight creases: draw "
            "them as lines, or read with curves='flatten' (--curves flatten)"
        )
    if skipped:
        listed = ", ".join(f"{k} ({n})" for k, n in skipped.most_common(5))
        notes.append(
            f"{sum(skipped.values())} entit(ies) on layers of no crease name or colour left out: "
            f"{listed}; layers: BOUNDARY, CUT, SCORE_M, SCORE_V, SCORE_F, SCORE_U (or colours)"
        )
    if flattened:
        notes.append(f"{flattened} curved piece(s) flattened into segments")
    if kept:
        n_pieces, chord, length = cut_curves(kept, segs, codes, angles)
        notes.append(
            f"{len(kept)} curve(s) kept, cut into {n_pieces} piece(s) (chord deviation "
            f"{chord:.3g}, piece length {length:.3g} drawing units)"
        )
    if not segs:
        raise FormatError(
            f"{name}: no crease-pattern lines (LINE/LWPOLYLINE/POLYLINE on crease layers or in "
            "crease colours)"
        )
    unit_note = next((n for n in notes if "$INSUNITS" in n), "")
    return LineDrawing(np.array(segs, float), np.array(codes, dtype="<U1"), np.array(angles),
                       unit, name=name, kind="dxf", notes=tuple(notes), curves=tuple(kept),
                       unit_note=unit_note)  # fmt: skip


def _kept_curves(e, p, code: str, ang: float):
    """(curves, straight polylines) of a curved entity, drawing units: ``ARC``, ``CIRCLE`` and
    ``ELLIPSE`` as arcs, a non-rational ``SPLINE`` of degree <= 3 as its Bezier pieces, a
    polyline as its lines and the Bezier curves ezdxf makes of its bulges; None where the
    entity is not flat in the drawing's plane or is a rational or higher-degree spline (then
    it is flattened as before)."""
    t = e.dxftype()
    ex = e.dxf.get("extrusion", (0.0, 0.0, 1.0))
    if t in _CURVES and not (abs(ex[0]) < 1e-12 and abs(ex[1]) < 1e-12 and ex[2] > 0):
        return None  # mirrored or tilted (OCS): ezdxf's flattening handles it
    if t in ("ARC", "CIRCLE"):
        c, r = e.dxf.center, float(e.dxf.radius)
        if t == "CIRCLE":
            a0, sweep = 0.0, 2 * math.pi
        else:
            a0 = math.radians(e.dxf.start_angle)
            sweep = math.radians((e.dxf.end_angle - e.dxf.start_angle) % 360.0) or 2 * math.pi
        arc = Curve("arc", code, ang, centre=(c.x, c.y), radii=(r, r), start=a0, sweep=sweep)
        return [arc], []
    if t == "ELLIPSE":
        c, m = e.dxf.center, e.dxf.major_axis
        rx = math.hypot(m.x, m.y)
        s0, s1 = float(e.dxf.start_param), float(e.dxf.end_param)
        sweep = (s1 - s0) % (2 * math.pi) or 2 * math.pi
        arc = Curve("arc", code, ang, centre=(c.x, c.y), radii=(rx, rx * float(e.dxf.ratio)),
                    rotation=math.atan2(m.y, m.x), start=s0, sweep=sweep)  # fmt: skip
        return [arc], []
    if t == "SPLINE":
        try:
            bs = e.construction_tool()
        except Exception:  # noqa: BLE001 - a spline ezdxf cannot build: flatten it
            return None
        if bs.is_rational or bs.degree > 3:
            return None
        out = [
            Curve("bezier", code, ang, points=tuple((float(v.x), float(v.y)) for v in cps))
            for cps in bs.bezier_decomposition()
        ]
        return out, []
    # a polyline with bulges: lines stay lines, ezdxf's Bezier curves of the bulges are kept
    from ezdxf.path import Command

    curves_out, lines, cur = [], [], [(p.start.x, p.start.y)]
    start = p.start
    for cmd in p.commands():
        end = (cmd.end.x, cmd.end.y)
        if cmd.type == Command.LINE_TO:
            cur.append(end)
        elif cmd.type == Command.MOVE_TO:
            if len(cur) >= 2:
                lines.append(np.array(cur))
            cur = [end]
        else:
            if len(cur) >= 2:
                lines.append(np.array(cur))
            ctrl = [cmd.ctrl] if cmd.type == Command.CURVE3_TO else [cmd.ctrl1, cmd.ctrl2]
            pts = ((start.x, start.y), *((v.x, v.y) for v in ctrl), end)
            curves_out.append(Curve("bezier", code, ang, points=tuple(map(tuple, pts))))
            cur = [end]
        start = cmd.end
    if len(cur) >= 2:
        lines.append(np.array(cur))
    return curves_out, lines


def dxf_lines(path, *, curves: str = "keep"):
    """:func:`dxf_drawing` as a tuple, for callers of the earlier form: (segments (n, 2, 2) in
    drawing units, codes, fold angles in degrees, metres per drawing unit, notes list)."""
    d = dxf_drawing(path, curves=curves)
    return (np.array(d.segments), np.array(d.assignment), np.array(d.fold_angle), d.unit,
            list(d.notes))  # fmt: skip


def read_dxf_pattern(source, *, tol: float | None = None, unit: float | None = None,
                     split: str = "as-needed", curves: str = "keep"):  # fmt: skip
    """The crease pattern of a DXF file (a path, bytes or a binary file object; see the module
    docstring), metres."""
    drawing = dxf_drawing(source, curves=curves)
    return pattern_from_drawing(drawing, tol=tol, unit=unit, split=split)
