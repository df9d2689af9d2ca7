"""The fabrication files of a fitted strip (what ``holofold fit`` writes).

``strip.fold`` (FOLD 1.2: the flat sector-angle development as crease pattern plus the 3-D
strip as a folded-form frame, published node numbering; side-B panel loops are reversed so
that every panel is counter-clockwise in the layout), ``strip.svg`` (that development as an
Origami-Simulator-coloured crease pattern in mm; the x-z plan view of centre and side lines
where no development exists), ``strip.stl`` and ``strip.obj`` (the 3-D strip surface),
``strip_solid.stl`` (the folded panel prisms with hinge gaps, loose bodies) when a panel
thickness and crease width are given, ``printable.stl`` (the flat part to print: panels joined by
hinge strips, :func:`~holofold.geometry.printable.printable_solid`) and
``printable_folded.stl`` (that part folded, hinges bent; left out with a warning where it cannot
be built) when a crease thickness is given too, and ``candidates.csv`` (the candidates of an
automatic fit) when given. Meshes are in ``units`` (default mm, what slicers and CAD read), FOLD
in m, SVG in mm.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from holofold.fitting.strip_fit import StripFit
from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.export import export
from holofold.geometry.mesh import MESH_UNITS
from holofold.geometry.outputs import atomic_write, write_text
from holofold.geometry.printable import folded_printable, printable_solid
from holofold.geometry.solid import thick_solid
from holofold.geometry.svg import polylines_svg
from holofold.geometry.units import length_factor

__all__ = ["export_strip_files"]


def export_strip_files(
    fit: StripFit,
    folder: str | os.PathLike,
    *,
    panel_thickness: float | None = None,
    crease_width: float | None = None,
    crease_thickness: float | None = None,
    candidates: pd.DataFrame | None = None,
    units: str = MESH_UNITS,
) -> list[Path]:
    """Write the strip's files into ``folder`` (created if needed); returns their paths.

    ``panel_thickness`` and ``crease_width`` (m, both or neither) add the thick solid;
    ``crease_thickness`` (m, with both) the printable part, which needs the flat layout. They
    are built, and can be refused, before the first file is written. Meshes in ``units``.
    """
    length_factor(units)
    thick = (panel_thickness, crease_width)
    solid = part = bent = None
    if crease_thickness is not None and any(v is None for v in thick):
        raise ParameterError(
            "a printable part needs a panel thickness and a crease width besides the crease "
            "thickness"
        )
    if any(v is not None for v in thick):
        if any(v is None for v in thick):
            raise ParameterError("a thick solid needs both a panel thickness and a crease width")
        t = check_range("panel_thickness", panel_thickness, 0.0, None, low_open=True)
        w = check_range("crease_width", crease_width, 0.0, None, low_open=True)
        solid = thick_solid(fit.pattern, t, w)
    flat = fit.flat_pattern  # layout + 3-D state, side B loops counter-clockwise
    if crease_thickness is not None:
        tc = check_range("crease_thickness", crease_thickness, 0.0, None, low_open=True)
        if flat is None:
            raise ParameterError(
                "this strip has no flat layout (its development overlaps): no printable part"
            )
        part = printable_solid(flat, t, tc, w)
        bent = folded_printable(fit.pattern, t, tc, w)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    fold_kw = {} if solid is None else {"panel_thickness": t, "crease_width": w}
    if part is not None:
        fold_kw["crease_thickness"] = tc
    written = [export(flat if flat is not None else fit.pattern, out / "strip.fold", **fold_kw)]
    if flat is not None:
        written.append(export(flat, out / "strip.svg"))
    else:
        title = "plan view (x-z) of the strip: centre line and side line (no flat layout)"
        svg = polylines_svg([fit.centre_line, fit.side_line], ["#000000", "#7f7f7f"], title)
        written.append(write_text(out / "strip.svg", svg))
    written.append(export(fit.pattern, out / "strip.stl", units=units))
    written.append(export(fit.pattern, out / "strip.obj", units=units))
    if solid is not None:
        written.append(export(solid, out / "strip_solid.stl", units=units))
    if part is not None:
        written.append(export(part, out / "printable.stl", units=units))
    if bent is not None:
        written.append(export(bent, out / "printable_folded.stl", units=units))
    if candidates is not None:
        path = out / "candidates.csv"
        written.append(atomic_write(path, lambda tmp: candidates.to_csv(tmp, index=False)))
    return written
