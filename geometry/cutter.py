"""Cutter profiles: how a flat crease pattern is drawn for a machine that cuts and scores it.

A :class:`CutterProfile` gives every role of a line (boundary, cut, mountain score, valley score,
other creases) a colour, a stroke width and a layer, and says how creases are drawn: whole, or
as dashes (perforations) that stop short of every vertex. :data:`PROFILES`:

* ``origami-simulator`` (the default): Origami Simulator's import convention (mountain red,
  valley blue, boundary black, cut green, fold angle as opacity), 0.2 mm strokes, creases whole
  from vertex to vertex (the simulator builds its faces from them), a legend above the pattern.
* ``laser``: the laser drivers' convention: red hairlines (0.01 mm) cut through, so boundary
  and cut lines are red; mountain scores blue and valley scores green, also hairlines (vector
  operations at the power set per colour, e.g. in LightBurn); creases dashed 3 mm on, 1.5 mm
  off, 1.5 mm clear of each vertex (a solid score weakens the sheet and tears at vertices). No
  text anywhere (a driver would cut or engrave it).
* ``cricut``: Cricut Design Space and Silhouette Studio: black cut lines, red mountain and blue
  valley scores on their own layers (set them to Score, or Perforate, in the program), 0.25 mm
  strokes, creases whole but 1 mm clear of each vertex. No text.

:func:`cutter_drawing` lays a pattern out on a page in millimetres (y down, as SVG; the DXF
writer flips it back) as a :class:`CutterDrawing`: segments per role, already dashed. With
``side="front"`` / ``"back"`` it is one face of a two-pass job: score the mountains on the front
(a score opens on the outside of its fold), flip the sheet about the page's vertical axis, score
the valleys and cut on the back. The back is drawn mirrored, and both faces carry the same three
registration holes (cut through on the first pass; pins through them hold the sheet in
register, and the odd one at the bottom tells a wrong flip).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.registry import Registry

__all__ = [
    "Stroke",
    "CutterProfile",
    "PROFILES",
    "DEFAULT_PROFILE",
    "ROLES",
    "CutterDrawing",
    "cutter_drawing",
    "dashes",
    "get_profile",
    "register_profile",
    "CutterOptions",
]

#: the finest dash, gap or vertex gap drawn, mm (no laser or blade resolves less)
MIN_CUT_MM = 0.01

#: the roles of a line; each FOLD assignment has one (:data:`ROLE_OF`)
ROLES = ("boundary", "cut", "mountain", "valley", "flat", "unassigned", "registration")
#: FOLD assignment -> role (J, triangulation lines, are not drawn)
ROLE_OF = {"B": "boundary", "C": "cut", "M": "mountain", "V": "valley", "F": "flat",
           "U": "unassigned"}  # fmt: skip


@dataclass(frozen=True)
class Stroke:
    """A line's ``colour`` (``#rrggbb``), ``width`` (mm) and ``layer`` (group / DXF layer)."""

    colour: str
    width: float
    layer: str


@dataclass(frozen=True)
class CutterProfile:
    """How lines are drawn for one kind of machine (see the module docstring).

    ``strokes`` maps every role of :data:`ROLES` to its :class:`Stroke`; ``dash``, ``gap`` and
    ``vertex_gap`` (mm) are the crease defaults (``dash = 0``: whole lines); ``legend`` and
    ``opacity`` (fold angle as stroke opacity) are Origami Simulator's; ``suits`` names the
    machines and programs.
    """

    name: str
    strokes: Mapping[str, Stroke]
    dash: float = 0.0
    gap: float = 0.0
    vertex_gap: float = 0.0
    legend: bool = False
    opacity: bool = False
    suits: str = ""
    layers: tuple[str, ...] = field(default=())

    def __post_init__(self):
        missing = [r for r in ROLES if r not in self.strokes]
        if missing:
            raise ValueError(f"profile {self.name!r} lacks strokes for {missing}")
        order = []
        for r in ROLES:
            if self.strokes[r].layer not in order:
                order.append(self.strokes[r].layer)
        object.__setattr__(self, "layers", tuple(order))


def _check_profile(name, profile) -> CutterProfile:
    if not isinstance(profile, CutterProfile):
        raise TypeError(f"expected a CutterProfile, got {type(profile).__name__}")
    if profile.name != name:
        raise ValueError(f"cutter profile {profile.name!r} registered as {name!r}")
    return profile


_BUILTIN_PROFILES = {
    "origami-simulator": CutterProfile(
        "origami-simulator",
        {
            "boundary": Stroke("#000000", 0.2, "cut"),
            "cut": Stroke("#00ff00", 0.2, "cut"),
            "mountain": Stroke("#ff0000", 0.2, "score"),
            "valley": Stroke("#0000ff", 0.2, "score"),
            "flat": Stroke("#ffff00", 0.2, "score"),
            "unassigned": Stroke("#ff00ff", 0.2, "score"),
            "registration": Stroke("#000000", 0.2, "registration"),
        },
        legend=True,
        opacity=True,
        suits="Origami Simulator, Rabbit Ear; pen plotters",
    ),
    "laser": CutterProfile(
        "laser",
        {
            "boundary": Stroke("#ff0000", 0.01, "cut"),
            "cut": Stroke("#ff0000", 0.01, "cut"),
            "mountain": Stroke("#0000ff", 0.01, "score-mountain"),
            "valley": Stroke("#00ff00", 0.01, "score-valley"),
            "flat": Stroke("#ff00ff", 0.01, "score-other"),
            "unassigned": Stroke("#ff00ff", 0.01, "score-other"),
            "registration": Stroke("#ff0000", 0.01, "registration"),
        },
        dash=3.0,
        gap=1.5,
        vertex_gap=1.5,
        suits="laser cutters through LightBurn, RDWorks, Epilog / Trotec drivers, Glowforge, "
        "xTool; Inkscape and Illustrator for editing",
    ),
    "cricut": CutterProfile(
        "cricut",
        {
            "boundary": Stroke("#000000", 0.25, "cut"),
            "cut": Stroke("#000000", 0.25, "cut"),
            "mountain": Stroke("#ff0000", 0.25, "score-mountain"),
            "valley": Stroke("#0000ff", 0.25, "score-valley"),
            "flat": Stroke("#ff00ff", 0.25, "score-other"),
            "unassigned": Stroke("#ff00ff", 0.25, "score-other"),
            "registration": Stroke("#000000", 0.25, "registration"),
        },
        vertex_gap=1.0,
        suits="Cricut Design Space (Maker, Explore), Silhouette Studio (Cameo), Brother "
        "ScanNCut; other drag-knife plotters",
    ),
}
#: name -> profile (a :class:`~holofold.geometry.registry.Registry`; plug-ins from the
#: entry-point group ``holofold.cutter_profiles``)
PROFILES: Registry[CutterProfile] = Registry(
    "cutter profile",
    _BUILTIN_PROFILES,
    group="holofold.cutter_profiles",
    check=_check_profile,
    error=ParameterError,
)
DEFAULT_PROFILE = "origami-simulator"


def get_profile(name: str | CutterProfile) -> CutterProfile:
    """The profile of that name (one of :data:`PROFILES`), or the profile given."""
    if isinstance(name, CutterProfile):
        return name
    return PROFILES[name]


def register_profile(profile: CutterProfile, *, replace: bool = False) -> CutterProfile:
    """Add a cutter profile under its name (a built-in name never, a registered one only with
    ``replace=True``); ``--profile`` and scenario files name it from then on."""
    return PROFILES.register(profile, replace=replace)


def dashes(p0: np.ndarray, p1: np.ndarray, dash: float, gap: float, end_gap: tuple) -> np.ndarray:
    """Dashes (k, 2, 2) along the segment p0-p1 (mm): ``end_gap`` (at p0, at p1) left clear,
    then dashes of about ``dash`` separated by ``gap``, stretched so that the first and the last
    dash end exactly at the clear ends (``dash = 0``: one line between them). Empty when the
    line is shorter than its clear ends."""
    d = p1 - p0
    L = float(np.hypot(*d))
    if L <= 0:
        return np.zeros((0, 2, 2))
    u = d / L
    a, b = end_gap[0], L - end_gap[1]
    span = b - a
    if span <= 1e-9:
        return np.zeros((0, 2, 2))
    if dash <= 0:
        return np.array([[p0 + a * u, p0 + b * u]])
    n = max(1, round((span + gap) / (dash + gap)))
    on = (span - (n - 1) * gap) / n
    if on <= 0:  # too short for its gaps: one dash over the whole span
        return np.array([[p0 + a * u, p0 + b * u]])
    start = a + np.arange(n) * (on + gap)
    return np.stack([p0 + start[:, None] * u, p0 + (start + on)[:, None] * u], axis=1)


@dataclass(frozen=True, eq=False)
class CutterDrawing:
    """A pattern laid out on a page for a profile, in millimetres, y down (SVG's convention).

    Attributes
    ----------
    profile : CutterProfile
    width, height : float
        Page size, mm.
    lines : mapping role -> (k, 2, 2) float
        Segments of each role (dashed as the profile says), page mm.
    edges : mapping role -> (k,) int
        The pattern edge of each segment.
    angles : mapping role -> (k,) float
        Fold angle of each segment's edge, degrees.
    holes : (h, 2) float
        Centres of the registration holes, page mm (empty on a one-face drawing).
    hole_radius : float
        mm.
    side : str
        "both", "front" or "back" (mirrored).
    top : float
        Room above the pattern left for a legend, mm.
    curves : mapping role -> tuple of (tuple of Curve, (k,) int)
        The pattern's kept curves of each role on the page (mm, y down): per curve the parts
        drawn (the whole curve, its dashes, or the stretches between vertex gaps), each a
        :class:`~holofold.geometry.curved.Curve`, and the pattern edges (its straight pieces)
        it stands for; ``lines`` still holds those edges' chords, which a writer drawing
        curves leaves out (:attr:`curve_edges`).
    """

    profile: CutterProfile
    width: float
    height: float
    lines: Mapping[str, np.ndarray]
    edges: Mapping[str, np.ndarray]
    angles: Mapping[str, np.ndarray]
    holes: np.ndarray
    hole_radius: float
    side: str
    top: float = 0.0
    curves: Mapping[str, tuple] = field(default_factory=dict)

    @property
    def curve_edges(self) -> set[int]:
        """The pattern edges drawn as parts of curves (their chords are not drawn)."""
        return {int(e) for parts in self.curves.values() for _, ids in parts for e in ids}


#: the roles scored on each face of a two-pass job (a score opens on the outside of its fold)
FACE_ROLES = {
    "both": ("boundary", "cut", "mountain", "valley", "flat", "unassigned"),
    "front": ("mountain", "flat", "unassigned"),
    "back": ("valley", "boundary", "cut"),
}


def cutter_drawing(
    pattern: CreasePattern,
    profile: str | CutterProfile = DEFAULT_PROFILE,
    *,
    dash: float | None = None,
    gap: float | None = None,
    vertex_gap: float | None = None,
    side: str = "both",
    margin: float = 5.0,
    top: float = 0.0,
    curves: bool = True,
) -> CutterDrawing:
    """The pattern's flat layout on a page for ``profile`` (mm; see :class:`CutterDrawing`).

    ``dash``, ``gap`` and ``vertex_gap`` (mm) override the profile's; ``side`` is "both" (one
    file), "front" or "back" (a two-pass job, with registration holes; the back mirrored);
    ``margin`` (mm) surrounds the pattern (at least 8 mm on a two-pass job, for the holes);
    ``top`` (mm) is extra room above it; ``curves``: lay out the pattern's kept curves as
    curves (``CutterDrawing.curves``; False: their chords only).
    """
    prof = get_profile(profile)
    if pattern.flat is None:
        raise ValueError(
            "this pattern has no flat layout to draw as a crease pattern; export FOLD instead"
        )
    if side not in FACE_ROLES:
        raise ParameterError(f"side must be one of {', '.join(FACE_ROLES)}, got {side!r}")
    dash = prof.dash if dash is None else check_range("dash", dash, 0.0, 1000.0)
    gap = prof.gap if gap is None else check_range("gap", gap, 0.0, 1000.0)
    vgap = (
        prof.vertex_gap if vertex_gap is None else check_range("vertex_gap", vertex_gap, 0.0, 100.0)
    )
    if prof.name == "origami-simulator" and (dash > 0 or vgap > 0):
        raise ParameterError(
            "the origami-simulator profile draws creases whole, vertex to vertex (Origami "
            "Simulator builds its faces from them); dashes and vertex gaps are for the laser "
            "and cricut profiles"
        )
    for what, v in (("dash", dash), ("gap", gap), ("vertex_gap", vgap)):
        if 0 < v < MIN_CUT_MM:
            raise ParameterError(
                f"{what} {v:.3g} mm is under {MIN_CUT_MM:g} mm, finer than any cutter draws; "
                "give 0 (none) or at least that"
            )
    if dash > 0 and gap <= 0:
        raise ParameterError("dashed creases need a gap > 0 between the dashes (mm)")
    two = side != "both"
    margin = max(check_range("margin", margin, 0.0, 1000.0), 8.0 if two else 0.0)
    xy = pattern.flat * 1000.0
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    w, h = hi - lo + 2 * margin
    h += top
    px = xy[:, 0] - lo[0] + margin
    py = hi[1] - xy[:, 1] + margin + top  # y down: the drawing is not mirrored
    if side == "back":
        px = w - px
    P = np.column_stack([px, py])
    lines, edges, angles = {}, {}, {}
    wanted = FACE_ROLES[side]
    for code, role in ROLE_OF.items():
        if role not in wanted:
            continue
        ids = np.flatnonzero(pattern.assignment == code)
        segs, owner = [], []
        creased = role not in ("boundary", "cut")
        for e in ids:
            a, b = pattern.edges[e]
            if creased:
                d = dashes(P[a], P[b], dash, gap, (vgap, vgap))
            else:
                d = np.array([[P[a], P[b]]])
            segs.append(d)
            owner.append(np.full(len(d), e))
        lines[role] = np.concatenate(segs) if segs else np.zeros((0, 2, 2))
        edges[role] = np.concatenate(owner) if owner else np.zeros(0, int)
        angles[role] = pattern.fold_angle[edges[role]].astype(float)
    holes = np.zeros((0, 2))
    if two:
        r = margin / 4
        holes = np.array([[margin / 2, margin / 2], [w - margin / 2, margin / 2],
                          [w / 2, h - margin / 2]])  # fmt: skip
    else:
        r = 0.0
    page_curves = {}
    if curves and pattern.curves:
        if side == "back":
            shift = (lo[0] - margin + w, hi[1] + margin + top)
        else:
            shift = (-lo[0] + margin, hi[1] + margin + top)
        page_curves = _page_curves(pattern, wanted, shift, side == "back", dash, gap, vgap)
    return CutterDrawing(
        prof, float(w), float(h), lines, edges, angles, holes, r, side, top, page_curves
    )


def _covered(curve, xy, E, t, p) -> list[tuple[float, float, list[float]]]:
    """The parameter intervals of ``curve`` its pieces ``E`` (vertex pairs; ``xy`` page mm)
    cover, merged: (t0, t1, the parameters of the piece ends inside)."""
    from scipy.optimize import minimize_scalar

    def param(q):
        k = int(np.argmin(np.linalg.norm(p - q, axis=1)))
        if k in (0, len(t) - 1):
            return float(t[k])
        lo_, hi_ = t[max(k - 1, 0)], t[min(k + 1, len(t) - 1)]
        r = minimize_scalar(
            lambda u: float(np.sum((curve.point(u)[0] - q) ** 2)),
            bounds=(lo_, hi_), method="bounded", options={"xatol": 1e-13},
        )  # fmt: skip
        return float(r.x)

    tv = {int(v): param(xy[v]) for v in np.unique(E)}
    spans = sorted((min(tv[a], tv[b]), max(tv[a], tv[b])) for a, b in E.tolist())
    out: list[list] = []
    for a, b in spans:
        if out and a <= out[-1][1] + 1e-9:
            out[-1][1] = max(out[-1][1], b)
            out[-1][2].append(a)
        else:
            out.append([a, b, []])
    return [(a, b, sorted(set(inner))) for a, b, inner in out]


def _page_curves(pattern, wanted, shift, mirror, dash, gap, vgap) -> dict[str, tuple]:
    """role -> ((Curve on the page, edge ids), ...): every kept curve over the stretches its
    pieces cover; creases dashed and kept ``vgap`` clear of the vertices where other lines meet
    them (not of a joint where the next curve of the same line goes on), as :func:`dashes` does
    for a straight crease (lengths along the curve)."""
    xy = pattern.flat * 1000.0
    xy = np.column_stack([xy[:, 0] * (-1.0 if mirror else 1.0), -xy[:, 1]]) + np.asarray(shift)
    ec = pattern.edge_curve
    drawn = pattern.assignment != "J"
    deg = np.bincount(pattern.edges[drawn].ravel(), minlength=pattern.n_vertices)
    out: dict[str, list] = {}
    for c, curve in enumerate(pattern.curves):
        ids = np.flatnonzero(ec == c)
        if not ids.size:
            continue
        code = str(pattern.assignment[ids[0]])
        role = ROLE_OF.get(code)
        if role not in wanted or (pattern.assignment[ids] != code).any():
            continue
        page = curve.mapped(1000.0, shift, flip_y=True, flip_x=mirror)
        E = pattern.edges[ids]
        t, s_of = page.lengths()
        p = page.point(t)
        creased = role not in ("boundary", "cut")
        parts = []
        for t0, t1, inner in _covered(page, xy, E, t, p):
            if not creased or (dash <= 0 and vgap <= 0):
                parts.append(page.sub(t0, t1) if (t0, t1) != (0.0, 1.0) else page)
                continue
            # stretches between vertices where another line meets the curve
            cut = [u for u in inner if _vertex_degree_at(page, u, xy, deg, E) > 2]
            bounds = [t0, *cut, t1]
            # no gap where the curve runs on into the next piece of its line (degree 2)
            g0 = vgap if _vertex_degree_at(page, t0, xy, deg, E) > 2 else 0.0
            g1 = vgap if _vertex_degree_at(page, t1, xy, deg, E) > 2 else 0.0
            for a, b in zip(bounds[:-1], bounds[1:], strict=True):
                sa, sb = np.interp([a, b], t, s_of)
                ends = (g0 if a == t0 else vgap, g1 if b == t1 else vgap)
                d = dashes(np.array([sa, 0.0]), np.array([sb, 0.0]), dash, gap, ends)
                for u0, u1 in np.interp(d[:, :, 0], s_of, t):
                    parts.append(page.sub(float(u0), float(u1)))
        out.setdefault(role, []).append(parts and (tuple(parts), ids))
    return {r: tuple(x for x in v if x) for r, v in out.items()}


def _vertex_degree_at(page, u, xy, deg, E) -> int:
    """The number of drawn lines at the piece vertex nearest the curve's point at ``u``."""
    vs = np.unique(E)
    q = page.point(u)[0]
    return int(deg[vs[int(np.argmin(np.linalg.norm(xy[vs] - q, axis=1)))]])


def hole_points(centre: np.ndarray, radius: float, n: int = 24) -> np.ndarray:
    """A closed polygon (n + 1, 2) approximating a hole, mm."""
    t = np.linspace(0.0, 2 * math.pi, n + 1)
    return centre + radius * np.column_stack([np.cos(t), np.sin(t)])


@dataclass(frozen=True)
class CutterOptions:
    """How a fabrication set draws its flat pattern: a profile name (:data:`PROFILES`), the
    crease drawing (mm; None: the profile's) and whether to add the two faces of a two-pass job
    (``two_sided``). Checked once, here."""

    profile: str = DEFAULT_PROFILE
    dash: float | None = None
    gap: float | None = None
    vertex_gap: float | None = None
    two_sided: bool = False

    def __post_init__(self):
        get_profile(self.profile)
        for name in ("dash", "gap", "vertex_gap"):
            v = getattr(self, name)
            if v is not None:
                check_range(name, v, 0.0, 1000.0)
        if self.two_sided and self.profile == "origami-simulator":
            raise ParameterError(
                "two faces (front and back) are for a cutter: use the laser or cricut profile"
            )
        # the profile's own checks (dashes and vertex gaps) before any work
        if self.profile == "origami-simulator" and (
            (self.dash or 0) > 0 or (self.vertex_gap or 0) > 0
        ):
            raise ParameterError(
                "the origami-simulator profile draws creases whole, vertex to vertex; dashes "
                "and vertex gaps are for the laser and cricut profiles"
            )

    def drawing(self) -> dict:
        """The keywords of :func:`~holofold.geometry.svg.export_svg` and
        :func:`~holofold.geometry.dxf.export_dxf`."""
        return {"profile": self.profile, "dash": self.dash, "gap": self.gap,
                "vertex_gap": self.vertex_gap}  # fmt: skip
