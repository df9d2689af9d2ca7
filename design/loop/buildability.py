"""Can the chosen design be made on the designer's printer: extent, bed fit, pieces, print time.

The geometry is :mod:`holofold.geometry.bed` (a part's extent, the turn that fits it on a
:class:`~holofold.geometry.Bed`, a print-time class from its volume) and
:mod:`holofold.geometry.segments` (a part larger than the bed cut at panel boundaries into
pieces that each fit, joined by dovetail teeth, with an assembly sheet). This module wires them
to a design: a kind that prints a part says what it is (:class:`PrintablePart`, the scenario's
``part``), :func:`part_fit` fits it on the bed and, when it does not fit whole, writes its pieces;
the :class:`PartFit` record is what the report's first screen states.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from holofold.geometry import DEFAULT_BED, Bed

__all__ = [
    "Bed",
    "DEFAULT_BED",
    "PrintablePart",
    "PartFit",
    "parse_bed",
    "part_fit",
    "FILM",
]

#: a part thinner than this is a film to cut, not a part to print (half a 0.2 mm layer), m
FILM = 0.1e-3


def _mm(v: float) -> str:
    """A length (m) in mm as the report writes it: whole mm from 100 mm, else 3 digits."""
    from holofold.design.scenarios import format_value

    mm = 1e3 * v
    return f"{mm:.0f}" if mm >= 100 else format_value(mm, digits=3)


def parse_bed(text: str | Bed | tuple) -> Bed:
    """``"250x210"`` (mm, as ``--bed`` takes it) or a :class:`Bed` or (x, y) in m."""
    if isinstance(text, Bed):
        return text
    if isinstance(text, tuple):
        return Bed(*map(float, text))
    try:
        return Bed.parse(str(text))
    except ValueError as exc:
        raise ValueError(f"--bed {text!r}: {exc}") from None


@dataclass(frozen=True)
class PrintablePart:
    """The part a design prints: its crease pattern with the flat layout, and the panel
    thickness, hinge (crease) thickness and hinge width it is printed with, m; ``thick`` the
    thickness technique of its panels (:data:`holofold.geometry.TECHNIQUES`) and ``path`` the
    fold states their bevels are cut for."""

    pattern: object
    panel_thickness: float
    crease_thickness: float
    crease_width: float
    thick: str = "centred"
    path: tuple = ()

    def panels(self):
        """The :class:`~holofold.geometry.ThickPanels` of ``thick`` (None: centred), bevelled
        for the fold ``path`` (states of the pattern; a Miura sheet's own path by default)."""
        if self.thick == "centred":
            return None
        from holofold.geometry.thick import miura_path, thick_panels

        path = self.path
        if not path and self.pattern.meta.get("kind") == "miura":
            path = tuple(miura_path(self.pattern, 10))
        return thick_panels(self.pattern, self.panel_thickness, self.crease_width, self.thick,
                            path=path)  # fmt: skip


@dataclass(frozen=True)
class PartFit:
    """The part to print on a bed, as the report states it.

    Attributes
    ----------
    file : str
        The part's file, relative to the design folder.
    extent : (float, float, float)
        Its size along x, y (lying on the bed) and z, m.
    volume : float
        m^3.
    bed : (float, float)
        The bed's width and depth, m.
    turn : float or None
        The turn about z (degrees) at which the whole part fits; None: it does not.
    hours : float
        Print time estimated from the volume (a class, not a slicer's estimate), h.
    time_class : str
        The print-time class (:data:`holofold.geometry.bed.TIME_CLASSES`).
    pieces : int
        Pieces it is printed in: 1 when it fits, the segments written when it does not, 0 when
        it cannot be cut to fit (``problem`` says why).
    segments : str
        The folder of the pieces' STL files and ``assembly.svg`` ("" if none), relative.
    problem : str
        Why it cannot be printed on this bed ("" when it can).
    """

    file: str
    extent: tuple[float, float, float]
    volume: float
    bed: tuple[float, float]
    turn: float | None
    hours: float
    time_class: str
    pieces: int
    segments: str = ""
    problem: str = ""

    def __post_init__(self):
        if len(self.extent) != 3 or not all(math.isfinite(v) and v >= 0 for v in self.extent):
            raise ValueError(f"a part's extent must be three lengths >= 0, got {self.extent!r}")
        if self.pieces < 0 or (self.turn is not None and self.pieces != 1):
            raise ValueError(f"a part that fits whole is one piece, got {self.pieces}")

    @property
    def fits(self) -> bool:
        return self.turn is not None

    @property
    def bed_text(self) -> str:
        return f"{1e3 * self.bed[0]:g} x {1e3 * self.bed[1]:g} mm"

    @property
    def film(self) -> bool:
        """Thinner than :data:`FILM`: cut from a sheet, not printed."""
        return self.extent[2] < FILM

    def extent_text(self) -> str:
        """``1132 x 126 x 3.53 mm``: whole millimetres from 100 mm, else three significant
        digits (no exponent)."""
        return " x ".join(_mm(v) for v in self.extent) + " mm"

    @property
    def advice(self) -> str:
        """What to do, in a sentence or two."""
        if self.film:
            return (
                f"It is a film {1e3 * self.extent[2]:.3g} mm thick, thinner than one layer of "
                "a desktop printer: cut it from a sheet of that thickness (laser or blade, "
                "the pattern's SVG or DXF), do not print it."
            )
        if self.fits:
            how = "as it lies" if abs(self.turn) < 1e-9 else f"turned by {self.turn:.0f} degrees"
            return f"It fits the {self.bed_text} bed {how}."
        a, b = max(self.extent[:2]), min(self.extent[:2])
        need = f"{_mm(a)} x {_mm(b)} mm"
        scale = "Do not scale the file down: that thins the hinges with it."
        if self.pieces:
            return (
                f"It does not fit the {self.bed_text} bed whole: it is cut at panel "
                f"boundaries into {self.pieces} pieces that each fit ({self.segments}), "
                "joined by dovetail teeth and glued in the order assembly.svg shows; or "
                f"print it whole on a bed of at least {need}. {scale}"
            )
        return (
            f"It does not fit the {self.bed_text} bed ({self.problem or 'no cut fits'}): "
            f"print it on a bed of at least {need}, or change the design's size "
            f"(its length and width features). {scale}"
        )

    def line(self) -> str:
        """One line for the command line: file, extent, bed fit, pieces, print time."""
        from holofold.geometry.bed import print_time_text

        if self.film:
            return f"{self.file}: {self.extent_text()}, a film: cut it, do not print it"
        if self.fits:
            verdict = f"fits the {self.bed_text} bed whole (1 piece)"
        elif self.pieces:
            verdict = (
                f"does not fit the {self.bed_text} bed whole: cut into {self.pieces} pieces "
                f"that each fit ({self.segments}/, assembly.svg)"
            )
        else:
            verdict = f"does not fit the {self.bed_text} bed and is not cut ({self.problem})"
        return (
            f"{self.file}: {self.extent_text()}, {verdict}; print time "
            f"{print_time_text(self.hours)}"
        )

    def to_json(self) -> dict:
        return {
            "file": self.file,
            "extent_m": list(self.extent),
            "extent": self.extent_text(),
            "volume_m3": self.volume,
            "bed_m": list(self.bed),
            "bed": self.bed_text,
            "fits": self.fits,
            "turn_deg": self.turn,
            "print_hours": self.hours,
            "print_time": "not printed: a film" if self.film else self._time_text(),
            "print_class": "not printed: a film" if self.film else self.time_class,
            "pieces": self.pieces,
            "segments": self.segments,
            "problem": self.problem,
            "advice": self.advice,
        }

    def _time_text(self) -> str:
        from holofold.geometry.bed import print_time_text

        return print_time_text(self.hours)

    @classmethod
    def from_json(cls, d) -> PartFit:
        if not isinstance(d, dict):
            raise ValueError("fabrication must be an object")
        try:
            return cls(
                str(d["file"]),
                tuple(float(v) for v in d["extent_m"]),
                float(d["volume_m3"]),
                tuple(float(v) for v in d["bed_m"]),
                None if d.get("turn_deg") is None else float(d["turn_deg"]),
                float(d["print_hours"]),
                str(d["print_class"]),
                int(d["pieces"]),
                str(d.get("segments") or ""),
                str(d.get("problem") or ""),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"fabrication: {exc}") from None


def part_fit(
    path: str | Path,
    bed: Bed = DEFAULT_BED,
    *,
    units: str = "mm",
    root: str | Path | None = None,
    part: PrintablePart | None = None,
) -> PartFit:
    """The :class:`PartFit` of the STL at ``path`` (in ``units``) on ``bed``; paths relative to
    ``root``. When it does not fit whole and ``part`` says how it was made, it is cut into
    pieces (:func:`holofold.geometry.segment_part`) written beside it in ``segments/``
    (``segment_NN.stl`` placed on the bed, ``assembly.svg``)."""
    import trimesh

    from holofold.geometry import bed_fit, clear_segments, segment_part, write_segments
    from holofold.geometry.units import length_factor

    clear_segments(Path(path).parent / "segments")  # pieces of an earlier run: not this part's

    mesh = trimesh.load_mesh(str(path), force="mesh")
    mesh.apply_scale(length_factor(units))  # metres
    fit = bed_fit(mesh, bed)
    rel = os.path.relpath(path, root) if root is not None else str(path)
    turn = math.degrees(fit.angle) if fit.fits else None
    pieces, folder, problem = (1, "", "") if fit.fits else (0, "", "")
    if not fit.fits and part is not None:
        from holofold.geometry.errors import DegenerateGeometryError

        try:
            seg = segment_part(part.pattern, part.panel_thickness, part.crease_thickness,
                               part.crease_width, bed, panels=part.panels())  # fmt: skip
        except DegenerateGeometryError as exc:  # a cut the geometry could not make
            seg = None
            problem = f"cutting it into bed-sized pieces failed: {exc}"
        if seg is not None and seg.segments and seg.fits:
            where = Path(path).parent / "segments"
            write_segments(seg, where, units=units)
            pieces = len(seg.segments)
            folder = os.path.relpath(where, root) if root is not None else str(where)
        elif seg is not None:
            problem = seg.problem
    elif not fit.fits:
        problem = "this kind of part has no flat layout to cut into pieces"
    return PartFit(rel.replace(os.sep, "/"), tuple(float(v) for v in fit.extent),
                   float(fit.volume), (bed.width, bed.depth), turn, float(fit.print_hours),
                   fit.time_class, pieces, folder.replace(os.sep, "/"), problem)  # fmt: skip
