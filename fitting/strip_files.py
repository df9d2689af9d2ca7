"""The fabrication set of a fitted strip (what ``holofold fit`` writes): the set of
:func:`~holofold.geometry.fabrication.write_fabrication_set` with the strip's names.

``strip.fold`` (FOLD 1.2: the flat sector-angle development as crease pattern plus the 3-D
strip as a folded-form frame, published node numbering; side-B panel loops are reversed so
that every panel is counter-clockwise in the layout), ``strip.svg`` and ``strip.dxf`` (that
development for a cutter profile, mm; an SVG plan view of centre and side lines and no DXF where
no development exists), ``strip.stl`` and ``strip.obj`` (the 3-D strip surface),
``strip_solid.stl`` (the folded panel prisms with hinge gaps, loose bodies) when a panel
thickness and crease width are given, ``printable.stl`` and ``printable_folded.stl`` when a
crease thickness is given too, and ``candidates.csv`` (the candidates of an automatic fit) when
given. Meshes are in ``units`` (default mm, what slicers and CAD read), FOLD in m, SVG and DXF
in mm.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from holofold.fitting.strip_fit import StripFit
from holofold.geometry.cutter import CutterOptions
from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.fabrication import STRIP_NAMES, FabricationSet, write_fabrication_set
from holofold.geometry.mesh import MESH_UNITS
from holofold.geometry.outputs import atomic_write
from holofold.geometry.svg import polylines_svg
from holofold.geometry.units import length_factor

__all__ = ["export_strip_files", "write_strip_set"]

_CANDIDATES = "CSV of the automatic fit's candidates: m, offset and their errors"


def write_strip_set(
    fit: StripFit,
    folder: str | os.PathLike,
    *,
    panel_thickness: float | None = None,
    crease_width: float | None = None,
    crease_thickness: float | None = None,
    candidates: pd.DataFrame | None = None,
    units: str = MESH_UNITS,
    cutter: CutterOptions | None = None,
    thick: str = "centred",
) -> FabricationSet:
    """Write the strip's fabrication set into ``folder`` (created if needed).

    ``panel_thickness`` and ``crease_width`` (m, both or neither) add the thick solid;
    ``crease_thickness`` (m, with both) the printable part, which needs the flat layout. They
    are built, and can be refused, before the first file is written. Meshes in ``units``;
    ``cutter`` draws the SVG and DXF; ``thick`` is the thickness accommodation of the solids
    (:data:`~holofold.geometry.thick.TECHNIQUES`; checked in the folded state: a fitted strip
    has no fold path of its own).
    """
    length_factor(units)
    pair = (panel_thickness, crease_width)
    if crease_thickness is not None and any(v is None for v in pair):
        raise ParameterError(
            "a printable part needs a panel thickness and a crease width besides the crease "
            "thickness"
        )
    if any(v is not None for v in pair):
        if any(v is None for v in pair):
            raise ParameterError("a thick solid needs both a panel thickness and a crease width")
        check_range("crease_width", crease_width, 0.0, None, low_open=True)
    flat = fit.flat_pattern  # layout + 3-D state, side B loops counter-clockwise
    plan = None
    if flat is None:
        title = "plan view (x-z) of the strip: centre line and side line (no flat layout)"
        plan = polylines_svg([fit.centre_line, fit.side_line], ["#000000", "#7f7f7f"], title)
    out = write_fabrication_set(
        fit.pattern, folder, flat=flat, names=STRIP_NAMES, panel_thickness=panel_thickness,
        crease_width=crease_width or 0.0, crease_thickness=crease_thickness, units=units,
        cutter=cutter, plan_view=plan, thick=thick,
    )  # fmt: skip
    if candidates is not None:
        path = Path(folder) / "candidates.csv"
        atomic_write(path, lambda tmp: candidates.to_csv(tmp, index=False))
        out = out.plus("candidates", path, _CANDIDATES)
    return out


def export_strip_files(fit: StripFit, folder: str | os.PathLike, **kw) -> list[Path]:
    """:func:`write_strip_set`; returns the paths written."""
    return write_strip_set(fit, folder, **kw).paths
