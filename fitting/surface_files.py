"""The files of a surface fit (what ``holofold fit --surface`` writes).

The fabrication set of :func:`~holofold.geometry.fabrication.write_fabrication_set` for the
fitted pattern: ``pattern.fold`` (FOLD 1.2, metres: the flat crease pattern with M/V
assignments and fold angles, the fitted folded state as a frame), ``pattern.svg`` and
``pattern.dxf`` (the flat pattern for a cutter, mm), ``folded.stl`` / ``folded.obj`` (the folded
shell), ``thick.stl`` with a panel thickness, ``printable.stl`` and ``printable_folded.stl`` with
a crease thickness too; then ``target.stl`` (the target surface over its chart) and
``errors.json`` (the fit's inputs, distances and constraint residuals, and the simulated fold's
outcome when given). Meshes are in ``units`` (default: the target file's unit, else mm).
"""

from __future__ import annotations

import os
from pathlib import Path

from holofold.fitting.surface_fit import SurfaceFit
from holofold.geometry.export import export
from holofold.geometry.fabrication import PATTERN_NAMES, FabricationSet, write_fabrication_set
from holofold.geometry.mesh import MESH_UNITS
from holofold.geometry.outputs import write_json
from holofold.geometry.units import length_factor

__all__ = ["export_surface_files"]


def export_surface_files(
    fit: SurfaceFit,
    folder: str | os.PathLike,
    *,
    panel_thickness: float | None = None,
    crease_width: float = 0.0,
    crease_thickness: float | None = None,
    units: str | None = None,
    thick: str = "centred",
    cutter=None,
    fold_check: dict | None = None,
) -> FabricationSet:
    """Write the fit's files into ``folder`` (created if needed); returns the set written.

    ``panel_thickness``, ``crease_width`` and ``crease_thickness`` (m) add the thick panels and
    the printable part, with the thickness accommodation ``thick`` ("centred", "offset" or
    "tapered"); ``cutter`` (:class:`~holofold.geometry.cutter.CutterOptions`) draws the SVG and
    DXF. ``fold_check`` (a :class:`~holofold.mechanics.FoldCheck` summary) goes
    into ``errors.json``. Every solid is built, and can be refused, before the first file.
    """
    if units is None:
        units = fit.target.units if fit.target.kind == "mesh" else MESH_UNITS
    length_factor(units)
    files = write_fabrication_set(
        fit.pattern, folder, names=PATTERN_NAMES, panel_thickness=panel_thickness,
        crease_width=crease_width, crease_thickness=crease_thickness, units=units, thick=thick,
        cutter=cutter,
    )  # fmt: skip
    out = Path(folder)
    files = files.plus("target", export(fit.target.mesh, out / "target.stl", units=units),
                       f"STL of the target surface ({units})")  # fmt: skip
    summary = {**fit.summary, "mesh_units": units, "lengths": "m unless the key names a unit"}
    if fold_check is not None:
        summary.update(fold_check)
    summary["files"] = files.record(out)
    files = files.plus("errors", write_json(out / "errors.json", summary),
                       "the fit's inputs, distances and constraint residuals (JSON)")  # fmt: skip
    return files
