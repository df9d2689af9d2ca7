"""The print bed: a part's extent, whether it fits a bed, and a class of its print time.

A :class:`Bed` is the printable area of a desktop printer (metres inside; people give it in
millimetres, ``Bed.parse("250x210")``); :data:`DEFAULT_BED` is 250 x 210 x 220 mm, the bed of
the common Prusa i3-class printers (MK3S, MK4). :func:`bed_fit` says whether a part lying on
z = 0 fits the bed, turned about z if need be: the turn is searched over the directions of the
footprint's convex hull edges and every half degree (a long thin part may fit only along the
bed's diagonal).

The print time is a class from a slicer-like volume, not a slicer's estimate: a slicer fills a
part's skins and perimeters solid and the rest at 15 %, so the deposited volume is about
``min(V, A * SOLID_SKIN) + INFILL * (V - that)`` (A the area the part stands on, SOLID_SKIN
1.2 mm), deposited at :data:`PRINT_RATE`. Calibrated with PrusaSlicer 2.5's default profile,
0.2 mm layers, on three holofold parts: a 6 x 6 Miura ``printable.stl`` (2 mm, 21 743 mm^3;
the slicer says 2 h 31 min), the offset-panel 4 x 4 Miura that folds to 0.1 (4 242 mm^3;
39 min 45 s) and a 164 x 149 x 5.6 mm piece of the demo's arch (117 768 mm^3; 5 h 17 min): the
rate comes out 1.6-2.1 mm^3/s, so the estimate is good to about 15 % on those parts, enough to
tell minutes from an overnight print.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError

__all__ = [
    "Bed",
    "DEFAULT_BED",
    "BedFit",
    "bed_fit",
    "place_on_bed",
    "deposited_volume",
    "PRINT_RATE",
    "TIME_CLASSES",
    "print_time_text",
]

#: deposition rate of a desktop FDM printer, m^3/s (1.8 mm^3/s; see the module docstring)
PRINT_RATE = 1.8e-9
#: depth printed solid from the bed and the top (skins and perimeters), m
SOLID_SKIN = 1.2e-3
#: infill of the rest of the part
INFILL = 0.15
#: (upper bound in hours, class name) in order
TIME_CLASSES = (
    (1.0, "under 1 h"),
    (4.0, "1-4 h"),
    (12.0, "4-12 h (overnight)"),
    (48.0, "12-48 h"),
    (math.inf, "over 2 days"),
)


def print_time_text(hours: float) -> str:
    """A print time in hours and days: ``"about 510 h (21 days)"``, ``"about 40 min"``,
    ``"about 7.5 h"``; the class alone (``"over 2 days"``) hides how many."""
    if not math.isfinite(hours) or hours < 0:
        return "unknown"
    if hours < 1.0:
        return f"about {max(1, round(60 * hours))} min"
    text = f"about {hours:.2g} h" if hours < 10 else f"about {hours:.0f} h"
    if hours >= 24.0:
        days = hours / 24.0
        text += f" ({days:.2g} days)" if days < 10 else f" ({days:.0f} days)"
    return text


@dataclass(frozen=True)
class Bed:
    """A printer's build volume, m: ``width`` (x) by ``depth`` (y), ``height`` (z)."""

    width: float
    depth: float
    height: float = 0.22

    def __post_init__(self):
        for name in ("width", "depth", "height"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
                raise ParameterError(f"bed {name} must be a length > 0 in metres, got {v!r}")

    @classmethod
    def parse(cls, text: str) -> Bed:
        """A bed from ``"250x210"`` or ``"250x210x220"`` (millimetres; ``x`` or ``*``)."""
        parts = re.split(r"\s*[xX*]\s*", str(text).strip().removesuffix("mm").strip())
        try:
            mm = [float(p) for p in parts]
        except ValueError:
            mm = []
        if len(mm) not in (2, 3) or not all(math.isfinite(v) and v > 0 for v in mm):
            raise ParameterError(
                f"bed {text!r}: give width x depth (x height) in millimetres, e.g. 250x210"
            )
        if max(mm) < 10:
            raise ParameterError(
                f"bed {text!r} is read in millimetres: {max(mm):g} mm is no printer's bed "
                "(metres given? 0.25 m is 250)"
            )
        if max(mm) > 10_000:
            raise ParameterError(
                f"bed {text!r} is read in millimetres: {max(mm):.4g} mm ({max(mm) / 1000:.4g} m) "
                "is no printer's bed (at most 10,000 mm)"
            )
        return cls(*(v / 1000.0 for v in mm))

    def __str__(self) -> str:
        return f"{1000 * self.width:g} x {1000 * self.depth:g} mm"


#: a common desktop printer's bed (Prusa MK3S / MK4: 250 x 210 x 220 mm)
DEFAULT_BED = Bed(0.250, 0.210, 0.220)


@dataclass(frozen=True)
class BedFit:
    """How a part lying on z = 0 sits on a bed.

    Attributes
    ----------
    extent : (3,) float
        Axis-aligned extent of the part as given (x, y, z), m.
    footprint : (2,) float
        Sides of the smallest-area rectangle around its footprint (long, short), m.
    fits : bool
        Whether it fits the bed, turned about z by ``angle``.
    angle : float
        The turn about z (radians) that places it on the bed (the one with the most room);
        nan when it does not fit.
    volume : float
        Volume of the part, m^3.
    print_hours : float
        :func:`deposited_volume` / :data:`PRINT_RATE`, hours (good to about 15 %).
    time_class : str
        One of :data:`TIME_CLASSES`.
    bed : Bed
    """

    extent: tuple[float, float, float]
    footprint: tuple[float, float]
    fits: bool
    angle: float
    volume: float
    print_hours: float
    time_class: str
    bed: Bed

    def summary(self) -> str:
        """One line in millimetres: extent, the bed verdict and the print-time class."""
        x, y, z = (1000 * v for v in self.extent)
        verdict = (
            f"fits the {self.bed} bed"
            + ("" if abs(self.angle) < 1e-9 else f" turned {math.degrees(self.angle):.3g} deg")
            if self.fits
            else f"does not fit the {self.bed} bed"
        )
        return (
            f"{x:.4g} x {y:.4g} x {z:.3g} mm, {verdict}; print time "
            f"{print_time_text(self.print_hours)} ({self.time_class})"
        )


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (k, 2) of 2-D points, counter-clockwise (monotone chain)."""
    pts = np.unique(np.round(points, 12), axis=0)
    if len(pts) < 3:
        return pts

    def half(seq):
        out: list = []
        for p in seq:
            while len(out) >= 2:
                a, b = out[-2], out[-1]
                if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0:
                    break
                out.pop()
            out.append(p)
        return out

    lower = half(pts)
    upper = half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def footprint_turns(points: np.ndarray, bed: Bed) -> tuple[tuple[float, float], float]:
    """The smallest-area bounding rectangle's sides (long, short) of 2-D ``points`` (m), and the
    turn (rad) that fits them on ``bed``: none if they fit as they lie, else the one with the
    most room (nan if none does)."""
    hull = _hull(np.asarray(points, float))
    edges = np.diff(np.vstack([hull, hull[:1]]), axis=0)
    angles = np.concatenate(
        [-np.arctan2(edges[:, 1], edges[:, 0]), np.radians(np.arange(0, 180, 0.5))]
    )
    c, s = np.cos(angles), np.sin(angles)
    x = hull[:, 0][None] * c[:, None] - hull[:, 1][None] * s[:, None]
    y = hull[:, 0][None] * s[:, None] + hull[:, 1][None] * c[:, None]
    w, h = np.ptp(x, axis=1), np.ptp(y, axis=1)
    k = int(np.argmin(w * h))
    rect = (float(max(w[k], h[k])), float(min(w[k], h[k])))
    room = np.minimum(bed.width - w, bed.depth - h)
    if room[len(edges)] >= -1e-12:  # angles[len(edges)] is 0: as it lies, no turn to explain
        return rect, 0.0
    # a half turn fits as well: turns in [-90, 90) degrees; of the roomiest, the smallest turn
    turns = (angles + math.pi / 2) % math.pi - math.pi / 2
    top = room.max()
    if top < -1e-12:
        return rect, math.nan
    best = np.flatnonzero(room >= top - 1e-9 * max(bed.width, bed.depth))
    return rect, float(turns[best[np.argmin(np.abs(turns[best]))]])


def deposited_volume(mesh) -> float:
    """The volume a slicer deposits for ``mesh`` (lying on z = 0), m^3: solid to
    :data:`SOLID_SKIN` over the area it stands on, :data:`INFILL` of the rest."""
    volume = float(abs(mesh.volume))
    down = mesh.face_normals[:, 2] < -0.99
    base = float(mesh.area_faces[down].sum())
    solid = min(volume, base * SOLID_SKIN)
    return solid + INFILL * (volume - solid)


def bed_fit(mesh, bed: Bed = DEFAULT_BED) -> BedFit:
    """Whether ``mesh`` (a ``trimesh.Trimesh`` in metres, lying on z = 0 as printed) fits
    ``bed``, turned about z if need be; its extent, volume and print-time class."""
    v = np.asarray(mesh.vertices, float)
    extent = tuple(float(e) for e in np.ptp(v, axis=0))
    rect, angle = footprint_turns(v[:, :2], bed)
    fits = math.isfinite(angle) and extent[2] <= bed.height + 1e-12
    volume = float(abs(mesh.volume))
    hours = deposited_volume(mesh) / PRINT_RATE / 3600.0
    name = next(label for top, label in TIME_CLASSES if hours < top)
    return BedFit(extent, rect, bool(fits), angle if fits else math.nan, volume, hours, name, bed)


def place_on_bed(mesh, fit: BedFit):
    """A copy of ``mesh`` turned by ``fit.angle`` about z with its lower corner at the origin
    (the bed's corner). Raises :class:`ParameterError` if it does not fit."""
    if not fit.fits:
        raise ParameterError(f"the part does not fit the {fit.bed} bed: {fit.summary()}")
    out = mesh.copy()
    c, s = math.cos(fit.angle), math.sin(fit.angle)
    turn = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    out.apply_transform(turn)
    out.apply_translation(-out.bounds[0])
    return out
