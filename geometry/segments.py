"""A printable part larger than the bed, cut at panel boundaries into pieces that join.

:func:`segment_part` assigns the panels of a flat pattern to pieces that each fit a
:class:`~holofold.geometry.bed.Bed`: along the layout's long axis (a strip), and in bands
across it where one column of panels is wider than the bed (a wide strip, a sheet); it never
cuts through a panel's middle. At a crease between two pieces the hinge strip stays whole on
the earlier piece, which also takes a rim of the later piece's panel (``rim`` beyond the hinge)
ending in dovetail teeth; the later piece has the matching sockets. Every joint is cut
through the full panel thickness with vertical walls, so both pieces print flat without
supports; pushed together (teeth down into the sockets) and glued, they give the unsegmented
part back, less a gap of ``clearance`` around each joint (the fit of a glued joint on a
desktop printer, 0.2 mm by default). The rim and the teeth are scaled down where a panel is
too small for them.

The pieces are cut from the part of :func:`~holofold.geometry.printable.printable_solid` by
prisms over 2-D regions of the flat layout (manifold3d cross-sections, computed in mm), so the
hinges and vertex patches are those of the whole part. Each piece is placed on the bed (turned
about z, lower corner at the origin) for its own STL; :func:`assembly_sheet` draws the layout
with the pieces numbered in the order to join them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from holofold.geometry.bed import (
    DEFAULT_BED,
    Bed,
    BedFit,
    bed_fit,
    footprint_turns,
    place_on_bed,
    print_time_text,
)
from holofold.geometry.errors import DegenerateGeometryError, InvalidPatternError, check_range
from holofold.geometry.pattern import CreasePattern

__all__ = [
    "Segment",
    "Segmentation",
    "segment_part",
    "assembly_sheet",
    "write_segments",
    "clear_segments",
]

_MM = 1000.0


@dataclass(frozen=True, eq=False)
class Segment:
    """One piece to print.

    Attributes
    ----------
    index : int
        Its number, 1-based: the order on the assembly sheet.
    panels : (k,) int
        Ids of the pattern's faces it carries (a rim of a neighbour's panel besides).
    outline : tuple of (n, 2) float
        Its region in the flat layout, m (counter-clockwise outer contours, clockwise holes).
    mesh : trimesh.Trimesh
        The piece placed on the bed, m.
    fit : BedFit
        How it sits on the bed.
    """

    index: int
    panels: np.ndarray
    outline: tuple[np.ndarray, ...]
    mesh: object
    fit: BedFit


@dataclass(frozen=True, eq=False)
class Segmentation:
    """A part cut into pieces that fit a bed.

    Attributes
    ----------
    bed : Bed
    whole : BedFit
        The unsegmented part on the bed.
    segments : tuple of Segment
        One piece when the whole part fits; empty when it cannot be cut to fit (``problem``).
    joints : (k, 3) int
        Joined pieces (earlier, later, 1-based) and the crease edge id of each joint.
    problem : str
        Why no segmentation fits the bed ("" when it does), with what to do.
    crumbs : float
        Volume of the slivers left out, m^3: separate fragments under 10 mm across that the
        joints' cuts leave at a panel's corner (see :func:`segment_part`).
    """

    bed: Bed
    whole: BedFit
    segments: tuple[Segment, ...]
    joints: np.ndarray
    problem: str = ""
    crumbs: float = 0.0

    @property
    def fits(self) -> bool:
        """Every piece fits the bed."""
        return bool(self.segments) and all(s.fit.fits for s in self.segments)

    def summary(self) -> str:
        """One line: how many pieces, or why none."""
        if self.problem:
            return self.problem
        if len(self.segments) == 1:
            return f"one piece: {self.whole.summary()}"
        hours = sum(s.fit.print_hours for s in self.segments)
        crumbs = (
            f"; {self.crumbs * 1e9:.3g} mm^3 of slivers at joint corners left out"
            if self.crumbs > 0
            else ""
        )
        return (
            f"{len(self.segments)} pieces joined along {len(self.joints)} creases and cuts, "
            f"each fits the {self.bed} bed; {print_time_text(hours)} of printing in all{crumbs}"
        )


# ----------------------------------------------------------------------------- pieces
def _edge_faces(pattern: CreasePattern) -> np.ndarray:
    """(ne, 2) the faces on both sides of every edge (-1 on a border)."""
    nv = np.int64(pattern.n_vertices)
    keys = pattern.edges[:, 0] * nv + pattern.edges[:, 1]
    order = np.argsort(keys)
    out = np.full((pattern.n_edges, 2), -1)
    for f, loop in enumerate(pattern.faces):
        a, b = loop, np.roll(loop, -1)
        e = order[np.searchsorted(keys[order], np.minimum(a, b) * nv + np.maximum(a, b))]
        col = (out[e, 0] >= 0).astype(int)
        out[e, col] = f
    return out


def _clusters(values: np.ndarray, tol: float) -> list[np.ndarray]:
    """Indices of ``values`` grouped in increasing order, a new group after a gap > tol."""
    order = np.argsort(values, kind="stable")
    cut = np.flatnonzero(np.diff(values[order]) > tol) + 1
    return np.split(order, cut)


# ----------------------------------------------------------------------------- cells
@dataclass(frozen=True, eq=False)
class _Cell:
    """A panel, or a slice of a panel larger than the bed: its face and polygon (mm)."""

    face: int
    poly: np.ndarray


def _clip(poly: np.ndarray, axis: np.ndarray, s: float, keep_below: bool) -> np.ndarray:
    """The part of a convex polygon (k, 2) where ``x . axis <= s`` (or ``>= s``)."""
    h = poly @ axis - s
    if not keep_below:
        h = -h
    out = []
    for k in range(len(poly)):
        p, q, hp, hq = poly[k], poly[(k + 1) % len(poly)], h[k], h[(k + 1) % len(poly)]
        if hp <= 0:
            out.append(p)
        if (hp < 0 < hq) or (hq < 0 < hp):
            out.append(p + (q - p) * (hp / (hp - hq)))
    return np.array(out)


def _split(face: int, poly: np.ndarray, fits) -> tuple[list[_Cell], list[tuple]]:
    """The panel as cells that each fit (sliced across its long side), and the chords
    (cell, next cell, p0, p1) between consecutive slices."""
    if fits(poly):
        return [_Cell(face, poly)], []
    centred = poly - poly.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    lo, hi = float((poly @ axis).min()), float((poly @ axis).max())
    for k in range(2, 65):
        cuts = lo + (hi - lo) * np.arange(1, k) / k
        cells, rest = [], poly
        for s in cuts:
            cells.append(_clip(rest, axis, s, True))
            rest = _clip(rest, axis, s, False)
        cells.append(rest)
        if all(fits(c) for c in cells):
            chords = []
            for j, s in enumerate(cuts):
                on = cells[j][np.abs(cells[j] @ axis - s) < 1e-9 * (hi - lo)]
                chords.append((j, j + 1, on[0], on[-1]))
            return [_Cell(face, c) for c in cells], chords
    return [], []


class _Planner:
    """Greedy assignment of cells to pieces that fit the bed (with room for a joint)."""

    def __init__(self, cells: list[_Cell], bed: Bed, margin: float):
        self.cells = cells
        self.bed = bed
        self.margin = margin
        pts = np.vstack([c.poly for c in cells])
        _, _, vt = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)
        self.proj = np.array([c.poly.mean(axis=0) for c in cells]) @ vt.T  # (n, 2)
        size = np.array([np.ptp(c.poly @ vt.T, axis=0) for c in cells])
        self.tol = 0.25 * np.median(size, axis=0)

    def fits(self, members) -> bool:
        pts = np.vstack([self.cells[k].poly for k in members])
        m = self.margin
        grown = np.vstack([pts + [dx, dy] for dx in (-m, m) for dy in (-m, m)])
        return math.isfinite(footprint_turns(grown / _MM, self.bed)[1])

    def _along(self, members: np.ndarray) -> list[np.ndarray] | None:
        cols = [members[c] for c in _clusters(self.proj[members, 0], self.tol[0])]
        pieces, cur = [], np.zeros(0, int)
        for col in cols:
            if not self.fits(col):
                return None
            trial = np.concatenate([cur, col])
            if len(cur) and not self.fits(trial):
                pieces.append(cur)
                trial = col
            cur = trial
        pieces.append(cur)
        return pieces

    def plan(self) -> list[np.ndarray] | None:
        rows = [np.asarray(r) for r in _clusters(self.proj[:, 1], self.tol[1])]
        got = self._plan(rows)
        if got is None and len(rows) < len(self.cells):
            # rows whose cells shift little by little (a generalised Miura-ori's zig-zag)
            # chain into one band: bands of fixed height, each cell by its centre, instead
            y = self.proj[:, 1]
            band = np.floor((y - y.min()) / max(2 * self.tol[1], 1e-300)).astype(int)
            rows = [np.flatnonzero(band == b) for b in np.unique(band)]
            got = self._plan(rows)
        return got

    def _plan(self, rows: list[np.ndarray]) -> list[np.ndarray] | None:
        bands, cur = [], np.zeros(0, int)
        for row in rows:
            trial = np.concatenate([cur, row])
            if self._along(trial) is None:
                if not len(cur) or self._along(row) is None:
                    return None
                bands.append(cur)
                trial = row
            cur = trial
        bands.append(cur)
        pieces = [p for band in bands for p in self._along(band)]
        # assembly order: along the long axis, then across
        key = [(round(float(self.proj[p, 0].min()) / max(self.tol[0], 1e-300)),
                float(self.proj[p, 1].mean())) for p in pieces]  # fmt: skip
        return [np.sort(pieces[k]) for k in sorted(range(len(pieces)), key=lambda k: key[k])]


def _on_line(poly: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> tuple[float, float] | None:
    """The interval (mm along p0 -> p1) of a cell's boundary on the crease line p0-p1."""
    d = p1 - p0
    L = float(np.hypot(*d))
    v = d / L
    off = np.abs((poly - p0) @ np.array([-v[1], v[0]]))
    t = (poly[off < 1e-7 * max(L, 1.0)] - p0) @ v
    if len(t) < 2:
        return None
    return max(0.0, float(t.min())), min(L, float(t.max()))


# ----------------------------------------------------------------------------- joints
def _band(p0, p1, into, depth_far, teeth, s, extend):
    """The region (mm) a joint along p0-p1 gives the earlier piece, grown by ``s``.

    In the joint's frame (v along it, u into the later cell): everything from far behind the
    line to ``depth_far``, dovetail teeth (neck, head, depth, count) beyond it, running past
    each end by ``extend`` (a crease end: the panel's corner goes along); the caller clips it
    to the later cell.
    """
    import manifold3d as m3d

    d = p1 - p0
    L = float(np.hypot(*d))
    v = d / L
    u = np.array([-v[1], v[0]])
    if u @ into < 0:
        u = -u
    neck, head, deep, count = teeth
    back = 10 * (depth_far + deep) + L
    e0, e1 = extend
    pts = [(-e0, -back), (L + e1, -back), (L + e1, depth_far)]
    centres = (np.arange(count) + 0.5) * L / count
    for c in centres[::-1]:
        pts += [(c + neck / 2, depth_far), (c + head / 2, depth_far + deep),
                (c - head / 2, depth_far + deep), (c - neck / 2, depth_far)]  # fmt: skip
    pts.append((-e0, depth_far))
    P = np.array(pts, float)
    xy = p0 + P[:, :1] * v + P[:, 1:] * u
    if _area(xy) < 0:
        xy = xy[::-1]
    cs = m3d.CrossSection([xy])
    return cs.offset(s, m3d.JoinType.Miter, 4.0) if s else cs


def _teeth(L: float, room: float, far: float) -> tuple:
    """Teeth (neck, head, depth, count) for a joint of length L (mm) whose later cell is
    ``room`` deep beyond the line, the joint's straight part ``far`` deep; smaller where the
    cell is small."""
    neck, head, deep = 4.0, 6.0, 3.0
    k = min(1.0, max(0.5 * room - far, 0.0) / deep, 0.3 * L / head)
    return neck * k, head * k, deep * k, max(1, int(L // 30.0))


#: a separate fragment of a piece under this size across (mm) is a sliver the region
#: arithmetic leaves at a joint's corner: it is left out (and its volume counted), where a
#: larger separate body becomes a piece of its own
_CRUMB = 10.0


def _piece_bodies(part, region) -> tuple[list, float]:
    """The part inside ``region``'s prism as its separate bodies, largest first, and the
    volume (mm^3) of the slivers left out (bodies under ``_CRUMB`` mm across, when a larger
    one remains). A planned piece whose panels the joints next to it leave joined only through
    a neighbour's hinge comes out as more than one body: each is printed as a piece of its
    own."""
    import manifold3d as m3d

    prism = m3d.Manifold.extrude(region, 1e6).translate((0.0, 0.0, -5e5))
    bodies = sorted((part ^ prism).decompose(), key=lambda b: -b.volume())
    big = [b for b in bodies if max(np.ptp(np.reshape(b.bounding_box(), (2, 3)), axis=0)) >= _CRUMB]
    keep = big or bodies[:1]
    return keep, float(sum(b.volume() for b in bodies) - sum(b.volume() for b in keep))


def _boxes_meet(box, poly: np.ndarray) -> bool:
    """A body's bounding box (min x, y, z, max x, y, z; mm) and a polygon's (k, 2) overlap in
    the layout's plane."""
    return bool((poly.min(axis=0) <= np.asarray(box[3:5])).all()
                and (poly.max(axis=0) >= np.asarray(box[:2])).all())  # fmt: skip


def _xy_distance(box, point) -> float:
    """Distance (mm) in the layout's plane from a point to a body's bounding box
    (min x, min y, min z, max x, max y, max z)."""
    lo, hi = np.asarray(box[:2]), np.asarray(box[3:5])
    return float(np.hypot(*np.maximum(np.maximum(lo - point, point - hi), 0.0)))


def _joints(pattern, cells, chords, piece_of, W, rim_mm):
    """Every joint: (earlier piece, later piece, later cell, p0, p1, far, extend, edge id)."""
    flat = pattern.flat * _MM
    by_face: dict[int, list[int]] = {}
    for k, c in enumerate(cells):
        by_face.setdefault(c.face, []).append(k)
    out = []
    for a, b, p0, p1 in chords:  # inside a panel: no hinge, teeth straight from the cut
        if piece_of[a] != piece_of[b]:
            lo, hi = sorted((a, b), key=lambda k: piece_of[k])
            out.append((piece_of[lo], piece_of[hi], hi, p0, p1, 0.0, (0.0, 0.0), -1))
    ef = _edge_faces(pattern)
    for e in np.flatnonzero(ef[:, 1] >= 0):
        q0, q1 = flat[pattern.edges[e, 0]], flat[pattern.edges[e, 1]]
        L = float(np.hypot(*(q1 - q0)))
        v = (q1 - q0) / L
        for cf in by_face[ef[e, 0]]:
            for cg in by_face[ef[e, 1]]:
                if piece_of[cf] == piece_of[cg]:
                    continue
                i1, i2 = _on_line(cells[cf].poly, q0, q1), _on_line(cells[cg].poly, q0, q1)
                if i1 is None or i2 is None:
                    continue
                t0, t1 = max(i1[0], i2[0]), min(i1[1], i2[1])
                if t1 - t0 <= 1e-6 * L:
                    continue
                lo, hi = sorted((cf, cg), key=lambda k: piece_of[k])
                big = 10.0 * L
                ext = (big if t0 <= 1e-9 * L else 0.0, big if t1 >= L * (1 - 1e-9) else 0.0)
                far = float(W[e]) / 2 * _MM + rim_mm
                out.append((piece_of[lo], piece_of[hi], hi, q0 + t0 * v, q0 + t1 * v, far,
                            ext, int(e)))  # fmt: skip
    return out


def segment_part(
    pattern: CreasePattern,
    panel_thickness: float,
    crease_thickness: float,
    crease_width,
    bed: Bed = DEFAULT_BED,
    *,
    clearance: float = 0.2e-3,
    rim: float = 3e-3,
    panels=None,
) -> Segmentation:
    """The printable part of ``pattern`` cut into pieces that fit ``bed`` (see the module).

    Parameters
    ----------
    pattern : CreasePattern
        With a flat layout (the printable part's).
    panel_thickness, crease_thickness, crease_width : float
        t_p, t_c and W of :func:`~holofold.geometry.printable.printable_solid`, m.
    bed : Bed
    clearance : float
        Gap around each joint, m (>= 0).
    rim : float
        How far a joint at a crease runs into the later piece's panel beyond the hinge, m.
    panels : ThickPanels, optional
        Offset or tapered panels (:func:`~holofold.geometry.thick.thick_panels`): the part is
        :func:`~holofold.geometry.thick_part.thick_printable`'s, each piece printed the way up it
        prints (hinge face on the bed); default the centred part of ``printable_solid``.
    """
    import manifold3d as m3d
    import trimesh

    from holofold.geometry.printable import printable_solid

    if pattern.flat is None:
        raise InvalidPatternError("segmenting a printable part needs the pattern's flat layout")
    c = check_range("clearance", clearance, 0.0, 5e-3) * _MM
    rim_mm = check_range("rim", rim, 0.0, None, low_open=True) * _MM
    W = np.broadcast_to(np.asarray(crease_width, float), (pattern.n_edges,))
    flip = False
    if panels is None or panels.technique == "centred":
        part_m = printable_solid(pattern, panel_thickness, crease_thickness, crease_width)
    else:
        from holofold.geometry.thick_part import thick_printable, turned_over

        part_m = thick_printable(pattern, panels, crease_thickness, turn=False)
        flip = turned_over(pattern, panels)
    whole = bed_fit(part_m, bed)
    none = np.zeros((0, 3), int)
    if whole.fits:
        lying = part_m.copy()
        if flip:
            lying.apply_transform(np.diag([1.0, -1.0, -1.0, 1.0]))
            lying.apply_translation((0.0, 0.0, -lying.bounds[0][2]))
        seg = Segment(1, np.arange(pattern.n_faces), (), place_on_bed(lying, whole), whole)
        return Segmentation(bed, whole, (seg,), none)
    flat = pattern.flat * _MM
    margin = float(W.max()) / 2 * _MM + rim_mm + 3.0 + c

    def cell_fits(poly):
        grown = np.vstack([poly + [dx, dy] for dx in (-margin, margin) for dy in (-margin, margin)])
        return math.isfinite(footprint_turns(grown / _MM, bed)[1])

    cells, chords = [], []
    for f, loop in enumerate(pattern.faces):
        got, ch = _split(f, flat[loop], cell_fits)
        if not got:
            return Segmentation(
                bed, whole, (), none, f"panel {f} cannot be sliced to fit the {bed} bed"
            )
        n0 = len(cells)
        cells += got
        chords += [(n0 + a, n0 + b, p0, p1) for a, b, p0, p1 in ch]
    plan = _Planner(cells, bed, margin).plan()
    if plan is None:
        return Segmentation(
            bed, whole, (), none,
            f"no cut at its panel boundaries gives pieces that fit the {bed} bed "
            f"with room for their joints ({margin:.3g} mm each side)",
        )  # fmt: skip
    piece_of = np.empty(len(cells), int)
    for k, members in enumerate(plan):
        piece_of[members] = k
    regions = [m3d.CrossSection([cells[k].poly for k in members]) for members in plan]
    joints = []
    for a, b, later, p0, p1, far, ext, e in _joints(pattern, cells, chords, piece_of, W, rim_mm):
        cell = m3d.CrossSection([cells[later].poly])
        gc = cells[later].poly.mean(axis=0)
        v = (p1 - p0) / np.hypot(*(p1 - p0))
        u = np.array([-v[1], v[0]])
        room = float(np.abs((cells[later].poly - p0) @ u).max())
        teeth = _teeth(float(np.hypot(*(p1 - p0))), room, far)
        # grown by 1 um so that it overlaps the earlier piece (rounding leaves no slit)
        target = (cell ^ regions[b]).offset(1e-3, m3d.JoinType.Miter, 4.0)
        give = _band(p0, p1, gc - p0, far, teeth, -c / 2, ext) ^ target
        take = _band(p0, p1, gc - p0, far, teeth, c / 2, ext) ^ cell
        regions[a] = regions[a] + give
        regions[b] = regions[b] - take
        joints.append((a, b, e, (p0 + p1) / 2))
    part = m3d.Manifold(
        m3d.Mesh64(
            vert_properties=np.ascontiguousarray(np.asarray(part_m.vertices) * _MM),
            tri_verts=np.asarray(part_m.faces, np.uint64),
        )
    )
    segments, body_of, crumbs = [], [], 0.0  # body_of[k]: (segment, xy box) of planned piece k
    for k, (members, region) in enumerate(zip(plan, regions, strict=True)):
        bodies, lost = _piece_bodies(part, region)
        crumbs += lost
        if not bodies:
            raise DegenerateGeometryError(f"piece {k + 1} is empty")
        body_of.append([])
        for body in bodies:
            index = len(segments) + 1
            box = body.bounding_box()
            body_of[k].append((index, box))
            solid = body.to_mesh64()
            mesh = trimesh.Trimesh(
                vertices=np.asarray(solid.vert_properties)[:, :3] / _MM,
                faces=np.asarray(solid.tri_verts, np.int64),
                process=False,
            )
            # as its STL (mm) reads back: vertices merged
            closed = trimesh.Trimesh(np.asarray(mesh.vertices) * _MM, mesh.faces)
            if not closed.is_watertight or closed.body_count != 1:
                raise DegenerateGeometryError(
                    f"piece {index} is not one closed body once its vertices are merged (parts "
                    "of it touch along an edge)"
                )
            if flip:  # hinge face down, as the whole part prints
                mesh.apply_transform(np.diag([1.0, -1.0, -1.0, 1.0]))
            mesh.apply_translation((0.0, 0.0, -mesh.bounds[0][2]))
            fit = bed_fit(mesh, bed)
            placed = place_on_bed(mesh, fit) if fit.fits else mesh
            polys = [np.asarray(q) for q in region.to_polygons()]
            if len(bodies) > 1:  # the region's polygons that overlap this body's box
                polys = [q for q in polys if _boxes_meet(box, q)] or polys
            outline = tuple(q / _MM for q in polys)
            near = [m for m in members if _boxes_meet(box, cells[m].poly)]
            faces = np.unique([cells[m].face for m in (members if len(bodies) == 1 else near)])
            segments.append(Segment(index, faces, outline, placed, fit))

    def which(k, point):  # the segment of planned piece k nearest a joint's middle
        return min(body_of[k], key=lambda ib: _xy_distance(ib[1], point))[0]

    joints = [(which(a, mid), which(b, mid), e) for a, b, e, mid in joints]
    out = Segmentation(bed, whole, tuple(segments), np.array(joints, int).reshape(-1, 3),
                       crumbs=crumbs / _MM**3)  # fmt: skip
    if not out.fits:
        bad = next(s for s in segments if not s.fit.fits)
        return Segmentation(
            bed, whole, out.segments, out.joints,
            f"piece {bad.index} ({bad.fit.summary()}) does not fit with its joints; use a "
            "larger bed or scale the design down", crumbs / _MM**3,
        )  # fmt: skip
    return out


# ----------------------------------------------------------------------------- the sheet
_FILLS = ("#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69", "#fccde5")


def assembly_sheet(seg: Segmentation, *, width_mm: float = 277.0) -> str:
    """An SVG page (``width_mm`` wide, A4 landscape by default) of the flat layout with the
    pieces filled, numbered in the order to join them, and the joints listed below."""
    if not seg.segments:
        raise ValueError(f"nothing to draw: {seg.problem}")
    polys = [[np.asarray(p) for p in s.outline] for s in seg.segments]
    if not polys[0]:
        raise ValueError("the part is one piece: no assembly sheet needed")
    pts = np.vstack([p for ps in polys for p in ps])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = hi - lo
    rows = 1
    # a long strip is drawn in rows of consecutive pieces, so the page stays readable
    aspect = span[0] / max(span[1], 1e-300)
    if aspect > 6:
        rows = max(1, min(len(seg.segments), int(math.sqrt(aspect / 2))))
    per = math.ceil(len(seg.segments) / rows)
    groups = [seg.segments[k : k + per] for k in range(0, len(seg.segments), per)]
    # every row at one scale
    row_spans = []
    for grp in groups:
        gp = np.vstack([p for s in grp for p in s.outline])
        row_spans.append((gp.min(axis=0), gp.max(axis=0)))
    wmax = max(h[0] - l[0] for l, h in row_spans)
    scale = (width_mm - 20) / wmax
    body, y0 = [], 20.0
    font = 4.0
    for grp, (l, h) in zip(groups, row_spans, strict=True):
        rh = (h[1] - l[1]) * scale
        for s in grp:
            fill = _FILLS[(s.index - 1) % len(_FILLS)]
            d = " ".join(
                "M " + " L ".join(f"{10 + (x - l[0]) * scale:.3f} {y0 + (h[1] - y) * scale:.3f}"
                                  for x, y in p) + " Z"
                for p in s.outline
            )  # fmt: skip
            body.append(
                f'<path d="{d}" fill="{fill}" fill-rule="evenodd" stroke="#000000" '
                'stroke-width="0.2"/>'
            )
            cx, cy = _centroid(max(s.outline, key=lambda p: abs(_area(p))))
            body.append(
                f'<text x="{10 + (cx - l[0]) * scale:.3f}" y="{y0 + (h[1] - cy) * scale:.3f}" '
                f'font-size="{font:g}" text-anchor="middle" dominant-baseline="middle">'
                f"{s.index}</text>"
            )
        y0 += rh + 10
    pairs = [f"{a}-{b}" for a, b in sorted({(int(a), int(b)) for a, b, _ in seg.joints})]
    notes = [
        f"{len(seg.segments)} pieces for a {seg.bed} bed: print each segment_NN.stl flat,",
        "then join them in this order (push the teeth into the sockets, glue):",
    ]
    per_line = max(1, int((width_mm - 20) / (0.55 * font * 7)))
    notes += [", ".join(pairs[k : k + per_line]) for k in range(0, len(pairs), per_line)]
    for k, line in enumerate(notes):
        body.append(f'<text x="10" y="{y0 + 4 + 6 * k:.3f}" font-size="{font:g}">{line}</text>')
    height = y0 + 6 * len(notes) + 10
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width_mm:g}mm" height="{height:.3f}mm" '
        f'viewBox="0 0 {width_mm:g} {height:.3f}" font-family="sans-serif">\n'
        "<title>holofold assembly sheet</title>\n"
        f'<rect width="{width_mm:g}" height="{height:.3f}" fill="#ffffff"/>\n'
        + "\n".join(body)
        + "\n</svg>\n"
    )


def _centroid(p: np.ndarray) -> np.ndarray:
    """Area centroid of a polygon (k, 2)."""
    x, y = p[:, 0], p[:, 1]
    cr = x * np.roll(y, -1) - np.roll(x, -1) * y
    a = cr.sum() / 2
    if abs(a) < 1e-300:
        return p.mean(axis=0)
    return np.array([((x + np.roll(x, -1)) * cr).sum(), ((y + np.roll(y, -1)) * cr).sum()]) / (
        6 * a
    )


def _area(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float((x * np.roll(y, -1) - np.roll(x, -1) * y).sum())


def clear_segments(folder) -> None:
    """Remove the pieces (``segment_NN.stl``) and ``assembly.svg`` an earlier run wrote into
    ``folder``, and the folder if that leaves it empty (a rerun must not leave pieces of
    another design beside the new ones)."""
    from pathlib import Path

    out = Path(folder)
    if not out.is_dir() or out.is_symlink():
        return
    for p in [*out.glob("segment_*.stl"), out / "assembly.svg"]:
        if p.is_file() and not p.is_symlink():
            p.unlink()
    if not any(out.iterdir()):
        out.rmdir()


def write_segments(seg: Segmentation, folder, units: str = "mm") -> list:
    """Write ``segment_NN.stl`` (each piece placed on the bed, in ``units``) and, for more
    than one piece, ``assembly.svg`` into ``folder`` (created if needed; the pieces an earlier
    run left there are removed first); returns the paths."""
    from pathlib import Path

    from holofold.geometry.export import export
    from holofold.geometry.outputs import write_text

    if not seg.segments:
        raise ValueError(seg.problem or "no pieces to write")
    clear_segments(folder)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    written = [export(s.mesh, out / f"segment_{s.index:02d}.stl", units=units)
               for s in seg.segments]  # fmt: skip
    if len(seg.segments) > 1:
        written.append(write_text(out / "assembly.svg", assembly_sheet(seg)))
    return written
