"""Which thick panels a folded design is made with: centred, offset or tapered.

:func:`choose_thickness` tries the thickening techniques of :mod:`holofold.geometry.thick` in
order and keeps the first whose panels fold clear of each other (:class:`ThicknessChoice`: the
technique, its overlap in m^3 and clearance in m); ``thick`` columns store the technique as a
code (:data:`THICK_CODES`, :func:`thick_name`). Lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass

from holofold.geometry.clearance import printability
from holofold.geometry.thick import path_overlap, thick_panels

__all__ = ["THICK_CHOICES", "THICK_CODES", "ThicknessChoice", "choose_thickness", "thick_name"]

#: the thickness techniques in the order ``thick = "auto"`` tries them, by column code
THICK_CODES = {"centred": 0, "offset": 1, "tapered": 2}
#: what a scenario's ``thick`` key takes: a technique, or "auto" (the first that folds clear)
THICK_CHOICES = (*THICK_CODES, "auto")
#: summed overlap of thick panels that counts as none, m^3 (0.001 mm^3; as the loop's
#: :data:`holofold.design.loop.choice.OVERLAP_TOLERANCE`)
_CLEAR = 1e-12


def thick_name(code: float) -> str:
    """The technique of a ``thick`` column code (0 centred, 1 offset, 2 tapered)."""
    for name, c in THICK_CODES.items():
        if c == int(round(float(code))):
            return name
    raise ValueError(f"thick = {code!r} is no technique code (0 centred, 1 offset, 2 tapered)")


@dataclass(frozen=True)
class ThicknessChoice:
    """How a design's panels are thickened: the technique kept, its overlap and clearance.

    ``overlap`` (m^3): centred panels in the folded state (:func:`holofold.geometry.printability`);
    offset and tapered panels the largest over the fold path
    (:func:`holofold.geometry.thick.path_overlap`, exact intersections). ``clearance`` (m): the
    smallest gap between panels sharing no vertex in the folded state, from the centred panels'
    mid-surface distance less their half thicknesses; a lower bound for tapered panels (inside
    the centred slabs: the same number) and offset ones (inside slabs twice as thick: one
    thickness less). ``tried`` the techniques tried, in order."""

    technique: str
    overlap: float
    clearance: float
    tried: tuple[str, ...] = ()

    @property
    def code(self) -> int:
        return THICK_CODES[self.technique]


def choose_thickness(
    state,
    thickness: float,
    crease_width: float,
    *,
    path=(),
    thick: str = "auto",
    no_neighbour: float = 1e3,
) -> ThicknessChoice:
    """The thick panels of a design folded to ``state`` (a CreasePattern with its flat layout;
    ``path`` other states on the way from flat): with ``thick = "auto"`` centred, offset, then
    tapered panels, the first whose panels do not overlap (by more than 0.001 mm^3; centred
    ones also with no negative clearance: panels sharing no vertex apart), else the
    centred ones (the measure the loop's overlap rule was calibrated on); a technique name:
    that one. ``no_neighbour`` caps the clearance where every pair of panels shares a vertex."""
    if thick not in THICK_CHOICES:
        raise ValueError(f"thick = {thick!r}; known: {', '.join(THICK_CHOICES)}")
    order = tuple(THICK_CODES) if thick == "auto" else (thick,)
    p = printability(state, thickness, crease_width)
    gap = float(min(p.clearance, no_neighbour))
    centred = ThicknessChoice("centred", float(p.overlap), gap, ("centred",))
    tried = []
    for name in order:
        tried.append(name)
        if name == "centred":
            got = centred
        else:
            try:
                panels = thick_panels(state, thickness, crease_width, name, path=path)
                over = path_overlap([*path, state], panels)
            except ValueError:  # panels too small for their bevels: not this technique
                continue
            low = gap - (thickness if name == "offset" else 0.0) if gap < no_neighbour else gap
            got = ThicknessChoice(name, float(over.volume.max()), low)
        clear = got.overlap <= _CLEAR and (name != "centred" or not got.clearance < 0)
        if clear or len(order) == 1:
            return ThicknessChoice(got.technique, got.overlap, got.clearance, tuple(tried))
    return ThicknessChoice("centred", centred.overlap, centred.clearance, tuple(tried))
