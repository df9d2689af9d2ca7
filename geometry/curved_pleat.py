"""The curved pleat: concentric circular creases on an annulus sector, meshed along its rulings.

A sector of angle ``sector`` (from the +x axis, counter-clockwise) of the annulus between the
inner rim (radius ``inner_radius``) and the outer rim (``inner_radius + (creases + 1) *
pleat_width``) carries ``creases`` concentric circular creases, one every ``pleat_width``,
alternating valley (the innermost) and mountain, all at the fold angle ``fold_angle``; both
rims and the two straight ends are borders. With one crease it is the creased annulus sector.

The fold of concentric circles is rotationally symmetric, so every pleat folds into a band of a
cone whose rulings are radial. The mesh follows them exactly: ``pieces + 1`` radial lines cut
every arc into ``pieces`` equal angles (the crease is the inscribed polygon, the same angles at
every radius), ``across`` rings of quads fill each pleat, and each quad is split by one
diagonal into two triangles (the diagonal's direction alternating like a chequer board). Edge
assignments (FOLD):

* ``M``/``V`` the crease arcs, ``B`` rims and ends;
* ``J`` every mesh edge inside a pleat: the radial lines along the rulings (where the panels
  bend), the quad diagonals and the rings. The bar-and-hinge model gives them the plate's
  bending stiffness (:func:`holofold.mechanics.build_concentrated`: ``D L`` over half the
  distance between the two opposite corners, ``D = E t^3 / (12 (1 - nu^2))``), as it does the
  ruling mesh of a drawn curved crease, so the hinges add up to the plate's bending energy as
  the mesh refines, whatever the crease width.
Lengths in metres, angles in radians (fold angles in degrees in the pattern, FOLD's sign).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError
from holofold.geometry.pattern import MAX_PANELS, CreasePattern

__all__ = [
    "CurvedPleat",
    "curved_pleat",
    "DEFAULTS",
    "PIECE_ANGLE",
]

#: the default arc piece, rad: the coarsest mesh within 2 % of the converged shape (0.48 % of
#: the sheet's size at 8 pieces over 90 deg, docs/curved-creases.md "Convergence")
PIECE_ANGLE = math.radians(11.25)

#: default values of every parameter (SI; ``pieces`` None: one per :data:`PIECE_ANGLE` of the
#: sector, at least 2; ``across`` 1, the coarsest within 2 %)
DEFAULTS = {
    "inner_radius": 0.1,
    "pleat_width": 0.02,
    "creases": 3,
    "sector": math.radians(90.0),
    "fold_angle": math.radians(60.0),
    "pieces": None,
    "across": 1,
}


@dataclass(frozen=True)
class CurvedPleat:
    """A curved pleat's geometry (see the module docstring).

    Attributes
    ----------
    inner_radius, pleat_width : float
        m.
    creases : int
    sector, fold_angle : float
        rad (the fold angle's magnitude; valley first, then alternating).
    pieces, across : int
        Radial lines minus one (pieces per arc) and quads across each pleat.
    """

    inner_radius: float
    pleat_width: float
    creases: int
    sector: float
    fold_angle: float
    pieces: int
    across: int

    @property
    def outer_radius(self) -> float:
        """m."""
        return self.inner_radius + (self.creases + 1) * self.pleat_width

    @property
    def radii(self) -> np.ndarray:
        """(nr,) radii of the rings of vertices, m (inner rim first)."""
        n = (self.creases + 1) * self.across
        return self.inner_radius + self.pleat_width * np.arange(n + 1) / self.across

    @property
    def angles(self) -> np.ndarray:
        """(pieces + 1,) polar angles of the radial lines, rad: the sector turns
        counter-clockwise from the +x axis (its first end on y = 0, vertex set ``side:-y``;
        at 90 deg its other end on x = 0, ``side:-x``)."""
        return self.sector * np.arange(self.pieces + 1) / self.pieces

    def crease_rings(self) -> np.ndarray:
        """(creases,) ring index of every crease (innermost first)."""
        return self.across * np.arange(1, self.creases + 1)

    def vertex(self, ring, line) -> np.ndarray:
        """Vertex id of ring ``ring`` (0 the inner rim) and radial line ``line``."""
        return np.asarray(ring) * (self.pieces + 1) + np.asarray(line)

    def area(self) -> float:
        """Area of the exact annulus sector, m^2."""
        return 0.5 * self.sector * (self.outer_radius**2 - self.inner_radius**2)

    def polygon_area(self) -> float:
        """Area of the mesh (arcs replaced by their chords), m^2: ``area() * sin(d)/d`` with
        ``d`` the angle of one piece."""
        d = self.sector / self.pieces
        return self.area() * math.sin(d) / d

    def pattern(self) -> CreasePattern:
        """The flat crease pattern (z = 0), fold angles at ``fold_angle``."""
        r, th = self.radii, self.angles
        nr, nl = len(r), len(th)
        xy = np.column_stack(
            [np.outer(r, np.cos(th)).ravel(), np.outer(r, np.sin(th)).ravel()]
        )  # fmt: skip
        # exact: every vertex of ring j at distance r[j] (to rounding) from the centre
        faces = []
        for j in range(nr - 1):
            for k in range(nl - 1):
                a, b = self.vertex(j, k), self.vertex(j + 1, k)
                c, d = self.vertex(j + 1, k + 1), self.vertex(j, k + 1)
                if (j + k) % 2 == 0:  # diagonal a-c
                    faces += [(a, b, c), (a, c, d)]
                else:  # diagonal b-d
                    faces += [(a, b, d), (b, c, d)]
        base = CreasePattern.from_faces(
            np.column_stack([xy, np.zeros(len(xy))]), faces, flat=xy
        )  # fmt: skip
        e = base.edges
        ring, line = np.divmod(e, nl)
        circ = ring[:, 0] == ring[:, 1]
        asg = np.full(len(e), "J", dtype="<U1")
        ang = np.zeros(len(e))
        asg[~base.interior] = "B"
        deg = math.degrees(self.fold_angle)
        for i, cr in enumerate(self.crease_rings()):
            on = circ & (ring[:, 0] == cr)
            asg[on] = "V" if i % 2 == 0 else "M"
            ang[on] = deg if i % 2 == 0 else -deg
        meta = {"family": "curved-pleat", "pieces": self.pieces, "across": self.across}
        return CreasePattern(
            base.coords, base.faces, e, asg, ang, flat=xy, meta=meta
        )  # fmt: skip


def curved_pleat(
    inner_radius: float = DEFAULTS["inner_radius"],
    pleat_width: float = DEFAULTS["pleat_width"],
    creases: int = DEFAULTS["creases"],
    sector: float = DEFAULTS["sector"],
    fold_angle: float = DEFAULTS["fold_angle"],
    pieces: int | None = None,
    across: int = DEFAULTS["across"],
) -> CreasePattern:
    """The flat curved pleat (module docstring); lengths m, angles rad; ``pieces`` None: one
    per :data:`PIECE_ANGLE` of the sector."""
    return _checked(
        inner_radius, pleat_width, creases, sector, fold_angle, pieces, across, str
    ).pattern()


def _checked(r1, w, n, sector, fold, pieces, across, label) -> CurvedPleat:
    if pieces is None and isinstance(sector, int | float) and 0 < sector < 2 * math.pi:
        pieces = max(2, math.ceil(sector / PIECE_ANGLE - 1e-9))
    for name, v in (("inner_radius", r1), ("pleat_width", w)):
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            raise ParameterError(f"{label(name)} = {v!r} must be a length > 0 (m)")
    if not 0 < sector < 2 * math.pi:
        raise ParameterError(
            f"{label('sector')} = {math.degrees(sector):g} deg must lie in (0, 360)"
        )
    if not 0 <= fold <= math.radians(179.0):
        raise ParameterError(
            f"{label('fold_angle')} = {math.degrees(fold):g} deg must lie in [0, 179]"
        )
    for name, v, low in (("creases", n, 1), ("pieces", pieces, 2), ("across", across, 1)):
        if isinstance(v, bool) or int(v) != v or v < low:
            raise ParameterError(f"{label(name)} = {v!r} must be an integer >= {low}")
    quads = int(pieces) * (int(n) + 1) * int(across)
    if 2 * quads > MAX_PANELS:
        raise ParameterError(
            f"{label('pieces')} {pieces} x ({label('creases')} {n} + 1) x {label('across')} "
            f"{across} quads = {2 * quads} panels; at most {MAX_PANELS}"
        )
    return CurvedPleat(float(r1), float(w), int(n), float(sector), float(fold), int(pieces),
                       int(across))  # fmt: skip


def geometry_of(values: dict, label=str) -> CurvedPleat:
    """The :class:`CurvedPleat` of a family's SI values (None: the default)."""
    v = {k: (DEFAULTS[k] if values.get(k) is None else values[k]) for k in DEFAULTS}
    return _checked(v["inner_radius"], v["pleat_width"], v["creases"], v["sector"],
                    v["fold_angle"], v["pieces"], v["across"], label)  # fmt: skip


def build_family(values: dict, label) -> CreasePattern:
    """The family's ``build`` (geometry/families.py)."""
    return geometry_of(values, label).pattern()


def describe(values: dict) -> str:
    """A design's short label."""
    g = geometry_of(values)
    return (
        f"curved pleat, {g.creases} crease(s) of {1e3 * g.pleat_width:g} mm from "
        f"r {1e3 * g.inner_radius:g} mm over {math.degrees(g.sector):g} deg at "
        f"{math.degrees(g.fold_angle):g} deg"
    )
