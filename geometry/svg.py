"""SVG crease patterns for Origami Simulator, laser cutters, Cricut-type cutters and plotters.

:func:`export_svg` draws the flat layout for a cutter profile (:mod:`holofold.geometry.cutter`).
The default, ``origami-simulator``, follows Origami Simulator's import convention: mountain red
``#ff0000``, valley blue ``#0000ff``, border black, flat and join (facet) yellow ``#ffff00``,
cut green ``#00ff00``, unassigned magenta ``#ff00ff``; ``stroke-opacity`` = |fold angle| / 180
for M and V, but at least ``min_opacity`` (default 0.3, so that shallow creases stay visible; 1
when a crease's fold angle is 0, i.e. a flat pattern whose M/V is known but not its target
angle). Origami Simulator reads fold angles from the opacity: the exact angle of every line is
its ``data-foldAngle`` (and the FOLD file's), and ``min_opacity=0`` writes the plain encoding. A
legend (mountain, valley, cut, boundary, as short ``<path>`` samples with labels,
``<g id="legend">``) sits above the pattern, outside it; ``legend=False`` leaves it out. Lines
are grouped: ``<g id="cut">`` holds border and cut lines, ``<g id="score">`` the creases, one
``<line>`` per edge. The ``laser`` and ``cricut`` profiles draw one ``<path>`` per edge (its
dashes as subpaths) in an Inkscape layer per role, with no text.

Coordinates are in millimetres (``width``/``height`` in mm, ``viewBox`` in mm), and the y axis is
flipped (SVG's y points down) so that the drawing is not mirrored: a mirrored crease pattern
swaps M and V (the back face of a two-pass job is mirrored on purpose). :func:`load_svg` reads
the origami-simulator files back (with :mod:`xml.etree`, nothing evaluated).
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from holofold.geometry.cutter import (
    DEFAULT_PROFILE,
    ROLES,
    CutterProfile,
    cutter_drawing,
    get_profile,
    hole_points,
)
from holofold.geometry.errors import FormatError, ParameterError, check_range
from holofold.geometry.pattern import CreasePattern

__all__ = ["COLOURS", "export_svg", "polylines_svg", "load_svg", "SvgLines", "curve_path"]

COLOURS = {
    "M": "#ff0000",
    "V": "#0000ff",
    "B": "#000000",
    "F": "#ffff00",
    "J": "#ffff00",
    "C": "#00ff00",
    "U": "#ff00ff",
}
_CUT = ("B", "C")
_SVG_NS = "http://www.w3.org/2000/svg"


_LEGEND = (("M", "mountain"), ("V", "valley"), ("C", "cut"), ("B", "boundary"))


def _legend(
    x0: float, y0: float, font_mm: float, stroke_mm: float, min_opacity: float
) -> tuple[str, float, float]:
    """The legend group at (x0, y0) (mm), with its width and height."""
    col = 36.0 * font_mm / 3.0
    row = 1.6 * font_mm
    items = []
    for k, (code, label) in enumerate(_LEGEND):
        x, y = x0 + (k % 2) * col, y0 + (k // 2) * row + font_mm
        items.append(
            f'<path d="M {x:.3f} {y - font_mm / 3:.3f} h {2.5 * font_mm:.3f}" '
            f'stroke="{COLOURS[code]}" stroke-width="{2 * stroke_mm}"/>'
            f'<text x="{x + 3.2 * font_mm:.3f}" y="{y:.3f}">{label}</text>'
        )
    text = f"opacity |fold angle| / 180, at least {min_opacity:g}; mm"
    note = (
        f'<text x="{x0:.3f}" y="{y0 + 2 * row + font_mm:.3f}" font-size="{0.8 * font_mm:.3g}">'
        f"{text}</text>"
    )
    body = (
        f'<g id="legend" fill="none" font-family="sans-serif" font-size="{font_mm:.3g}">\n  '
        + "\n  ".join(items)
        + f"\n  {note}\n</g>"
    )
    width = max(2 * col, 0.8 * font_mm * 0.55 * len(text))
    return body.replace("<text", '<text fill="#000000"'), width, 3 * row


def export_svg(
    pattern: CreasePattern,
    *,
    profile: str | CutterProfile = DEFAULT_PROFILE,
    margin_mm: float = 5.0,
    stroke_mm: float | None = None,
    show_facets: bool = False,
    min_opacity: float = 0.3,
    legend: bool | None = None,
    dash: float | None = None,
    gap: float | None = None,
    vertex_gap: float | None = None,
    side: str = "both",
) -> str:
    """SVG text of the flat crease pattern for a cutter ``profile`` (metres in, mm out).

    ``origami-simulator`` (default): ``<line>`` elements as the module docstring says;
    ``show_facets`` also draws ``J`` edges (triangulation lines, left out by default because they
    are neither cut nor folded), ``min_opacity`` in [0, 1] keeps shallow creases visible,
    ``legend`` (default the profile's) adds the legend above the pattern, ``stroke_mm``
    overrides the profile's width. ``laser`` / ``cricut``: one ``<path>`` per line (its dashes
    as subpaths) in a layer per role (Inkscape layers, ``<g id=...>``), no text; ``dash``,
    ``gap`` and ``vertex_gap`` (mm) override the profile's crease drawing and ``side`` ("front"
    or "back") draws one face of a two-pass job (:func:`~holofold.geometry.cutter.
    cutter_drawing`).
    """
    prof = get_profile(profile)
    min_opacity = check_range("min_opacity", min_opacity, 0.0, 1.0)
    legend = prof.legend if legend is None else bool(legend)
    if legend and not prof.legend:
        raise ParameterError(
            f"the {prof.name} profile has no text: a cutter would cut or engrave a legend"
        )
    width = {r: prof.strokes[r].width if stroke_mm is None else stroke_mm for r in ROLES}
    top = 0.0
    if legend:
        key, key_w, key_h = _legend(margin_mm, margin_mm, 3.0, width["mountain"], min_opacity)
        top = key_h + margin_mm
    draw = cutter_drawing(
        pattern, prof, dash=dash, gap=gap, vertex_gap=vertex_gap, side=side,
        margin=margin_mm, top=top,
    )  # fmt: skip
    w, h = draw.width, draw.height
    if legend:
        w = max(w, key_w + 2 * margin_mm)
    if prof.opacity:
        body = [key] if legend else []
        body += _simulator_groups(pattern, draw, width, min_opacity, show_facets)
        head = f'<svg xmlns="{_SVG_NS}" '
        title = f"holofold crease pattern ({pattern.meta.get('kind', 'pattern')})"
    else:
        body = _cutter_layers(draw, width)
        head = f'<svg xmlns="{_SVG_NS}" xmlns:inkscape="{_INKSCAPE_NS}" '
        face = {"both": "", "front": ", front face", "back": ", back face (mirrored)"}[side]
        title = (
            f"holofold crease pattern ({pattern.meta.get('kind', 'pattern')}), "
            f"{prof.name} profile{face}"
        )
        body.insert(0, f"<desc>{_DESC[side]}</desc>")
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        + head
        + f'width="{w:.6f}mm" height="{h:.6f}mm" viewBox="0 0 {w:.6f} {h:.6f}">\n'
        f"<title>{title}</title>\n" + "\n".join(body) + "\n</svg>\n"
    )


_INKSCAPE_NS = "http://www.inkscape.org/namespaces/inkscape"
_DESC = {
    "both": "Lines by layer: cut (through), score-mountain, score-valley; millimetres.",
    "front": "Pass 1 of 2: cut the registration holes and score the mountains on this face; "
    "then flip the sheet about the vertical axis onto pins through the holes.",
    "back": "Pass 2 of 2 (mirrored): score the valleys, then cut; the registration holes "
    "repeat those of pass 1.",
}


def _simulator_groups(pattern, draw, width, min_opacity, show_facets) -> list[str]:
    """Origami Simulator's groups: ``cut`` (B, C) and ``score`` (the rest), one ``<line>`` per
    edge with its fold angle as opacity and as ``data-foldAngle``."""
    groups: dict[str, list[str]] = {"cut": [], "score": []}
    P = {int(e): seg for role, segs in draw.lines.items()
         for e, seg in zip(draw.edges[role], segs, strict=True)}  # fmt: skip
    on_curves = draw.curve_edges
    for parts_ids in draw.curves.values():
        for parts, ids in parts_ids:
            i = int(ids[0])
            code = str(pattern.assignment[i])
            ang = float(pattern.fold_angle[i])
            opacity = max(abs(ang) / 180.0, min_opacity) if code in ("M", "V") and ang != 0 else 1.0
            groups["cut" if code in _CUT else "score"].append(
                f'<path d="{curve_path(parts)}" stroke="{COLOURS[code]}" '
                f'stroke-opacity="{opacity:.6g}" data-assignment="{code}" '
                f'data-foldAngle="{ang:.12g}" data-edges="{" ".join(map(str, ids.tolist()))}"/>'
            )
    for i in range(pattern.n_edges):
        code = str(pattern.assignment[i])
        if (code == "J" and not show_facets) or i in on_curves:
            continue
        if code == "J":
            a, b = pattern.edges[i]
            seg = _page_segment(pattern, draw, a, b)
        else:
            seg = P[i]
        ang = float(pattern.fold_angle[i])
        opacity = max(abs(ang) / 180.0, min_opacity) if code in ("M", "V") and ang != 0 else 1.0
        (x1, y1), (x2, y2) = seg
        groups["cut" if code in _CUT else "score"].append(
            f'<line x1="{x1:.6f}" y1="{y1:.6f}" x2="{x2:.6f}" y2="{y2:.6f}" '
            f'stroke="{COLOURS[code]}" stroke-opacity="{opacity:.6g}" '
            f'data-assignment="{code}" data-foldAngle="{ang:.12g}" data-edge="{i}"/>'
        )
    stroke = width["mountain"]
    return [
        f'<g id="{gid}" fill="none" stroke-width="{stroke}" stroke-linecap="round">\n  '
        + "\n  ".join(lines)
        + "\n</g>"
        for gid, lines in groups.items()
    ]


def curve_path(parts) -> str:
    """SVG path data of curves (page units): per part ``M`` then ``L`` / ``Q`` / ``C`` (a Bezier
    of degree 1 / 2 / 3) or ``A`` (an elliptical arc; two when it sweeps 1.9 pi or more)."""
    out = []
    for cv in parts:
        p0 = cv.point(0.0)[0]
        d = [f"M {p0[0]:.9f} {p0[1]:.9f}"]
        if cv.kind == "bezier":
            cmd = {2: "L", 3: "Q", 4: "C"}[len(cv.points)]
            d.append(cmd + " " + " ".join(f"{x:.9f} {y:.9f}" for x, y in cv.points[1:]))
        else:
            n = 1 if abs(cv.sweep) < 1.9 * np.pi else 2
            rx, ry = cv.radii
            rot = np.degrees(cv.rotation)
            for k in range(n):
                q = cv.point((k + 1) / n)[0]
                large = int(abs(cv.sweep) / n > np.pi)
                sweep = int(cv.sweep > 0)
                d.append(f"A {rx:.9f} {ry:.9f} {rot:.9f} {large} {sweep} {q[0]:.9f} {q[1]:.9f}")
        out.append(" ".join(d))
    return " ".join(out)


def _page_segment(pattern, draw, a, b) -> np.ndarray:
    """Page coordinates (2, 2) of the flat edge a-b (for lines no role draws: joins)."""
    xy = pattern.flat * 1000.0
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    margin = (draw.width - (hi[0] - lo[0])) / 2
    pts = np.array([[xy[v, 0] - lo[0] + margin, hi[1] - xy[v, 1] + margin + draw.top]
                    for v in (a, b)])  # fmt: skip
    return pts


def _cutter_layers(draw, width) -> list[str]:
    """One Inkscape layer per profile layer: a ``<path>`` per edge (dashes as subpaths) and the
    registration holes."""
    prof = draw.profile
    out = []
    for layer in prof.layers:
        items = []
        for role in ROLES:
            st = prof.strokes[role]
            if st.layer != layer:
                continue
            if role == "registration":
                for c in draw.holes:
                    pts = hole_points(c, draw.hole_radius)[:-1]
                    d = "M " + " L ".join(f"{x:.4f} {y:.4f}" for x, y in pts) + " Z"
                    items.append(
                        f'<path d="{d}" stroke="{st.colour}" stroke-width="{width[role]}"/>'
                    )
                continue
            for parts, ids in draw.curves.get(role, ()):
                items.append(
                    f'<path d="{curve_path(parts)}" stroke="{st.colour}" '
                    f'stroke-width="{width[role]}" data-role="{role}" '
                    f'data-edges="{" ".join(map(str, ids.tolist()))}"/>'
                )
            segs, owner = draw.lines.get(role), draw.edges.get(role)
            if segs is not None and len(segs) and draw.curves:
                keep = ~np.isin(owner, list(draw.curve_edges))
                segs, owner = segs[keep], owner[keep]
            if segs is None or not len(segs):
                continue
            cuts = np.flatnonzero(np.diff(owner)) + 1
            for part, e in zip(np.split(segs, cuts), owner[np.r_[0, cuts]], strict=True):
                d = " ".join(
                    f"M {x1:.4f} {y1:.4f} L {x2:.4f} {y2:.4f}" for (x1, y1), (x2, y2) in part
                )
                items.append(
                    f'<path d="{d}" stroke="{st.colour}" stroke-width="{width[role]}" '
                    f'data-role="{role}" data-edge="{int(e)}"/>'
                )
        if items:
            out.append(
                f'<g id="{layer}" inkscape:groupmode="layer" inkscape:label="{layer}" '
                'fill="none" stroke-linecap="butt">\n  ' + "\n  ".join(items) + "\n</g>"
            )
    return out


def polylines_svg(
    lines, colours, title: str, *, margin_mm: float = 5.0, stroke_mm: float = 0.5
) -> str:
    """SVG text (mm, y up as drawn) of 2-D polylines given in metres.

    ``lines``: sequence of (k, 2) arrays (x, y), m; ``colours``: one stroke colour per line.
    Used for drawings that are not crease patterns (e.g. a strip's plan view).
    """
    pts = [np.asarray(L, float) * np.array([1000.0, -1000.0]) for L in lines]
    allp = np.vstack(pts)
    lo, hi = allp.min(axis=0) - margin_mm, allp.max(axis=0) + margin_mm
    w, h = hi - lo
    body = [
        f'<polyline fill="none" stroke="{c}" stroke-width="{stroke_mm}" points="'
        + " ".join(f"{x - lo[0]:.6f},{y - lo[1]:.6f}" for x, y in P)
        + '"/>'
        for P, c in zip(pts, colours, strict=True)
    ]
    return (
        f'<svg xmlns="{_SVG_NS}" width="{w:.6f}mm" height="{h:.6f}mm" '
        f'viewBox="0 0 {w:.6f} {h:.6f}">\n<title>{title}</title>\n' + "\n".join(body) + "\n</svg>\n"
    )


@dataclass(frozen=True)
class SvgLines:
    """Lines read from an SVG crease pattern.

    ``segments`` (n, 2, 2) end points in metres with y up; ``assignment`` (n,) FOLD codes;
    ``fold_angle`` (n,) degrees; ``group`` (n,) "cut" or "score" ("" outside those groups);
    ``edge`` (n,) the pattern edge id of each line (``data-edge``), -1 where absent.
    """

    segments: np.ndarray
    assignment: np.ndarray
    fold_angle: np.ndarray
    group: np.ndarray
    edge: np.ndarray


def _code_of(el) -> str:
    code = el.get("data-assignment")
    if code:
        return code
    colour = (el.get("stroke") or "").lower()
    for k, v in COLOURS.items():
        if v == colour:
            return k
    return "U"


def load_svg(text: str | bytes) -> SvgLines:
    """Read the ``<line>`` elements of an SVG crease pattern written by :func:`export_svg`
    (a kept curve's ``<path>`` is not read: one warning line says how many).

    Coordinates are converted back from millimetres with y flipped up, relative to the
    drawing's lower-left corner (the margin removed only if the file is one of ours, i.e. all
    lines share the viewBox convention).
    """
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise FormatError(f"SVG: not well-formed XML ({exc})") from None
    if not root.tag.endswith("svg"):
        raise FormatError("SVG: the root element is not <svg>")
    vb = root.get("viewBox")
    try:
        height = float(vb.split()[3]) if vb else float(root.get("height", "0").removesuffix("mm"))
    except (ValueError, IndexError):
        raise FormatError(f"SVG: cannot read the drawing height from viewBox {vb!r}") from None
    segs, codes, angles, groups, ids = [], [], [], [], []

    def walk(el, group):
        for child in el:
            tag = child.tag.rsplit("}", 1)[-1]
            if tag == "g" and child.get("id") == "legend":
                continue
            if tag == "g":
                walk(child, child.get("id", group))
            elif tag == "line":
                try:
                    x1, y1, x2, y2 = (float(child.get(k)) for k in ("x1", "y1", "x2", "y2"))
                except (TypeError, ValueError):
                    raise FormatError("SVG: a <line> lacks numeric x1 y1 x2 y2") from None
                segs.append([[x1, height - y1], [x2, height - y2]])
                code = _code_of(child)
                codes.append(code)
                ang = child.get("data-foldAngle")
                if ang is None:
                    op = float(child.get("stroke-opacity", "1"))
                    ang = {"M": -180.0 * op, "V": 180.0 * op}.get(code, 0.0)
                angles.append(float(ang))
                groups.append(group)
                ids.append(int(child.get("data-edge", "-1")))
            elif tag == "path" and child.get("data-edges") is not None:
                curved.append(child)

    curved: list = []
    walk(root, "")
    if curved:
        warnings.warn(
            f"SVG: {len(curved)} curved crease path(s) (data-edges) not read: load_svg reads "
            "<line>s; read_svg_pattern reads the curves",
            UserWarning,
            stacklevel=2,
        )
    if not segs:
        raise FormatError("SVG: no <line> elements found")
    return SvgLines(
        np.asarray(segs) / 1000.0,
        np.asarray(codes),
        np.asarray(angles),
        np.asarray(groups),
        np.asarray(ids),
    )
