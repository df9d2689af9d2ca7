"""DXF crease patterns with named layers, for CAD and laser software (written with ezdxf).

The flat layout in millimetres (``$INSUNITS`` = 4, y up as the pattern has it), one ``LINE``
per drawn segment on the layer of its role (a kept curve, :attr:`CreasePattern.curves
<holofold.geometry.pattern.CreasePattern>`, as one ``ARC``, ``ELLIPSE`` or ``SPLINE`` in
place of its straight pieces: :func:`add_curve`) (:data:`DXF_LAYERS`; the outline is cut, so it goes
on ``CUT`` with the cuts, and ``BOUNDARY`` stays empty for other software's use): ``CUT``,
``SCORE_M`` (mountains), ``SCORE_V`` (valleys), ``SCORE_F`` (flat creases), ``SCORE_U``
(unassigned), ``REGISTRATION``. Each layer has the profile's colour (as a true colour and the
nearest AutoCAD colour index, which laser software maps by) and a lineweight of the profile's
stroke width. Creases are drawn as the cutter profile says
(:func:`~holofold.geometry.cutter.cutter_drawing`): whole lines, vertex to vertex, with the
``origami-simulator`` profile (a reader rebuilds the crease graph from them), dashes with gaps
at the vertices with ``laser``. Every ``LINE`` carries no text; the fold angle of a crease is
not in a DXF (use the FOLD file). The header's dates and GUIDs are fixed (ezdxf's
``write_fixed_meta_data_for_testing``, set only while writing) and its CLASS entries are
registered in sorted order (ezdxf takes them from a ``set``), so a design always gives the same
bytes, in every process.
"""

from __future__ import annotations

import io
import math

import numpy as np

from holofold.geometry.cutter import (
    DEFAULT_PROFILE,
    ROLES,
    CutterProfile,
    cutter_drawing,
    get_profile,
    hole_points,
)
from holofold.geometry.pattern import CreasePattern

__all__ = ["DXF_LAYERS", "export_dxf", "add_curve"]

#: role -> DXF layer name (readers map these back to FOLD assignments B, C, M, V, F, U)
DXF_LAYERS = {
    "boundary": "BOUNDARY",
    "cut": "CUT",
    "mountain": "SCORE_M",
    "valley": "SCORE_V",
    "flat": "SCORE_F",
    "unassigned": "SCORE_U",
    "registration": "REGISTRATION",
}

# AutoCAD colour index of the pure colours the profiles use
_ACI = {
    (255, 0, 0): 1,
    (255, 255, 0): 2,
    (0, 255, 0): 3,
    (0, 255, 255): 4,
    (0, 0, 255): 5,
    (255, 0, 255): 6,
    (0, 0, 0): 7,  # black / white by background
    (255, 255, 255): 7,
}
# DXF lineweights, 1/100 mm
_LINEWEIGHTS = (0, 5, 9, 13, 15, 18, 20, 25, 30, 35, 40, 50, 53, 60, 70, 80, 90, 100)


def _rgb(colour: str) -> tuple[int, int, int]:
    c = colour.lstrip("#")
    return int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)


def export_dxf(
    pattern: CreasePattern,
    *,
    profile: str | CutterProfile = DEFAULT_PROFILE,
    dash: float | None = None,
    gap: float | None = None,
    vertex_gap: float | None = None,
    margin_mm: float = 5.0,
) -> str:
    """DXF text (R2010) of the flat crease pattern for a cutter ``profile``, mm (see module)."""
    import ezdxf

    prof = get_profile(profile)
    draw = cutter_drawing(
        pattern, prof, dash=dash, gap=gap, vertex_gap=vertex_gap, margin=margin_mm
    )
    # fixed dates, GUIDs and ezdxf markers (created and written): a design gives the same bytes
    fixed = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        return _dxf_text(ezdxf, prof, draw)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = fixed


def _dxf_text(ezdxf, prof: CutterProfile, draw) -> str:
    doc = ezdxf.new("R2010", units=4)  # 4: millimetres
    doc.header["$MEASUREMENT"] = 1  # metric
    msp = doc.modelspace()
    for role in ROLES:
        st = prof.strokes[role]
        rgb = _rgb(st.colour)
        lw = min(_LINEWEIGHTS, key=lambda w: abs(w - 100 * st.width))
        layer = doc.layers.add(DXF_LAYERS[role], color=_ACI.get(rgb, 7))
        layer.rgb = rgb
        layer.dxf.lineweight = lw
    flip = np.array([1.0, -1.0])
    shift = np.array([0.0, draw.height])
    on_curves = draw.curve_edges
    for role, segs in draw.lines.items():
        # the outline is cut: on CUT, which the laser and cutter software cut (a reader takes
        # a cut on the outline for the border it is)
        name = DXF_LAYERS["cut" if role == "boundary" else role]
        if on_curves:
            segs = segs[~np.isin(draw.edges[role], list(on_curves))]
        for a, b in segs * flip + shift:
            msp.add_line(tuple(a), tuple(b), dxfattribs={"layer": name})
        for parts, _ in draw.curves.get(role, ()):
            for cv in parts:
                add_curve(msp, cv.mapped(1.0, shift, flip_y=True), name)
    for c in draw.holes:
        pts = hole_points(c, draw.hole_radius) * flip + shift
        msp.add_lwpolyline(pts[:-1].tolist(), close=True, dxfattribs={"layer": "REGISTRATION"})
    _fix_class_order(doc)
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue()


def add_curve(msp, cv, layer: str) -> None:
    """One curve (drawing units, y up) into a modelspace: a circular arc as ``ARC``, an
    elliptical one as ``ELLIPSE`` (DXF arcs run counter-clockwise: a clockwise one is written
    from its end), a Bezier of degree 2 or 3 as a clamped ``SPLINE`` with its control points
    (the Bezier itself), of degree 1 as ``LINE``."""
    at = {"layer": layer}
    if cv.kind == "bezier":
        P = [tuple(map(float, p)) for p in cv.points]
        if len(P) == 2:
            msp.add_line(P[0], P[1], dxfattribs=at)
        else:
            msp.add_open_spline(P, degree=len(P) - 1, dxfattribs=at)
        return
    rx, ry = cv.radii
    a0, a1 = cv.start, cv.start + cv.sweep
    if a1 < a0:
        a0, a1 = a1, a0
    if math.isclose(rx, ry, rel_tol=1e-12):
        rot = math.degrees(cv.rotation)
        msp.add_arc(
            tuple(cv.centre), rx, rot + math.degrees(a0), rot + math.degrees(a1), dxfattribs=at
        )
        return
    c, s = math.cos(cv.rotation), math.sin(cv.rotation)
    if rx >= ry:
        major, ratio = (rx * c, rx * s), ry / rx
    else:  # the major axis along the curve's y: parameters a quarter turn back
        major, ratio = (-ry * s, ry * c), rx / ry
        a0, a1 = a0 - math.pi / 2, a1 - math.pi / 2
    msp.add_ellipse(tuple(cv.centre), major, ratio, a0, a1, dxfattribs=at)


def _fix_class_order(doc) -> None:
    """Register the CLASS entries of the entity types in use in sorted order.

    ``Drawing.write`` adds them in the order of a ``set`` of type names, which follows the
    string hash of the process (``PYTHONHASHSEED``): ``LAYOUT`` and ``ACDBPLACEHOLDER`` swapped
    in about 1 process in 4. Classes already registered keep their place, so the CLASSES
    section, and the file, is the same in every process.
    """
    doc.commit_pending_changes()
    for dxftype in sorted(doc.entitydb.dxf_types_in_use()):
        doc.classes.add_class(dxftype)
