"""The flat printable part of thick panels (:mod:`~holofold.geometry.thick`): the panels in
the flat layout joined by the hinge strips and vertex patches of
:func:`~holofold.geometry.printable.printable_layout`, one watertight body on the bed, m."""

from __future__ import annotations

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.printable import _one_body, _prisms, printable_layout
from holofold.geometry.thick import ThickPanels, _flat_state, _orientation, panel_solids_of

__all__ = ["thick_printable", "turned_over"]


def _along_normal(a: float, b: float, sgn: float) -> tuple[float, float]:
    lo, hi = sorted((sgn * a, sgn * b))
    return lo, hi


def turned_over(layout: CreasePattern, panels: ThickPanels) -> bool:
    """Whether :func:`thick_printable` turns the part over (180 degrees about x) to print it
    hinge face down: the material lies below the flat layout's reference face."""
    return panels.side * _orientation(layout) < 0


def thick_printable(
    layout: CreasePattern, panels: ThickPanels, crease_thickness: float, *, turn: bool = True
):
    """The flat printable part with these thick panels: the panels of ``panels`` in the flat
    layout joined by the hinge strips and vertex patches of
    :func:`~holofold.geometry.printable.printable_layout`, ``crease_thickness`` thick at the
    reference face (offset: the panels' hinge face, turned onto the bed; centred and tapered:
    the mid-plane). One watertight body lying on z = 0, m. ``turn=False`` keeps it in the
    flat layout's frame (x, y as the layout; :func:`turned_over` says whether it prints
    turned)."""
    import manifold3d as m3d

    if layout.flat is None:
        raise ParameterError("a printable part needs the pattern's flat layout")
    tc = check_range("crease_thickness", crease_thickness, 0.0, panels.thickness, low_open=True)
    flat = _flat_state(layout)
    sgn = _orientation(layout)
    lay = printable_layout(layout, max(panels.crease_width, 1e-12))
    a, b = {1: (0.0, tc), -1: (-tc, 0.0), 0: (-tc / 2, tc / 2)}[panels.side]
    z0, z1 = _along_normal(a, b, sgn)
    parts = panel_solids_of(flat, panels) + _prisms(list(lay.hinges) + list(lay.patches), z0, z1)
    whole = m3d.Manifold.batch_boolean(parts, m3d.OpType.Add)
    if turn and panels.side * sgn < 0:  # the material lies below the reference face: turn over
        whole = whole.rotate((180.0, 0.0, 0.0))
    lo = whole.bounding_box()[2]
    out = _one_body(whole.translate((0.0, 0.0, -lo)), f"printable part ({panels.technique} panels)")
    out.metadata["layout"] = lay
    return out
