"""Physical sanity of a sheet before a model is built from it, checked in one place.

Every command that builds a model from a crease pattern (``simulate``, ``pattern``, ``fit``, the
scenario kinds) calls :func:`check_sheet` first, so a pattern scaled to millimetres with a
millimetre crease width is refused rather than simulated with a negative mass. Lengths in
metres.
"""

from __future__ import annotations

import warnings

import numpy as np

from holofold.geometry.errors import ParameterError

__all__ = ["SHEET_EXTENT", "PLAUSIBLE_EXTENT", "SheetWarning", "check_sheet", "sheet_mass"]

#: a sheet outside this span, m, is refused (no origami part is under 1 mm or over 1 km)
SHEET_EXTENT = (1e-3, 1e3)
#: a sheet outside this span, m, is warned about with the length it was read as
PLAUSIBLE_EXTENT = (1e-2, 1e2)


class SheetWarning(UserWarning):
    """A sheet whose size is possible but unlikely (a unit mistake, most often)."""


def _areas_perimeters(xy, faces):
    a, p = [], []
    for f in faces:
        q = xy[np.asarray(f)]
        r = np.roll(q, -1, axis=0)
        a.append(0.5 * abs(float(np.sum(q[:, 0] * r[:, 1] - r[:, 0] * q[:, 1]))))
        p.append(float(np.linalg.norm(r - q, axis=1).sum()))
    return np.array(a), np.array(p)


def sheet_mass(pattern, panel_thickness, crease_thickness, crease_width, density) -> float:
    """density x (panel area x tpanel + crease length x W x (tcrease - tpanel)), kg."""
    xy = pattern.flat if pattern.flat is not None else pattern.coords[:, :2]
    area = _areas_perimeters(xy, pattern.faces)[0].sum()
    e = pattern.edges[np.asarray(pattern.interior, bool)]
    length = float(np.linalg.norm(xy[e[:, 1]] - xy[e[:, 0]], axis=1).sum())
    return float(
        density
        * (area * panel_thickness + length * crease_width * (crease_thickness - panel_thickness))
    )


def check_sheet(
    pattern,
    *,
    panel_thickness: float | None = None,
    crease_thickness: float | None = None,
    crease_width: float | None = None,
    density: float | None = None,
    what: str = "pattern",
    unit: str | None = None,
) -> None:
    """Refuse (:class:`ParameterError`, one line) a sheet that cannot be physical.

    Its extent must lie in :data:`SHEET_EXTENT` (warned outside :data:`PLAUSIBLE_EXTENT`, with
    the length it was read as, naming ``unit`` when given); thicknesses finite and > 0, the
    panel thickness under every panel's width (2 x area / perimeter); the crease width fits
    every panel (the hinge-gap pull-back of ``geometry.solid``, which ``holofold pattern``
    applies); the mass, with ``density``, > 0.
    """
    from holofold.geometry.solid import shrunk_panels

    xy = pattern.flat if pattern.flat is not None else pattern.coords[:, :2]
    span = float(np.ptp(np.asarray(xy, float), axis=0).max())
    lo, hi = SHEET_EXTENT
    read = f" (read in {unit})" if unit else ""
    if not lo <= span <= hi:
        raise ParameterError(
            f"the {what} is {span:.4g} m across{read}, outside {lo:g}-{hi:g} m: "
            "check its unit or scale"
        )
    plo, phi = PLAUSIBLE_EXTENT
    if not plo <= span <= phi:
        warnings.warn(
            f"the {what} is {1e3 * span:.4g} mm across{read}, unlikely for an origami part "
            f"({plo:g}-{phi:g} m): check its unit or scale",
            SheetWarning,
            stacklevel=2,
        )
    for name, t in (("panel thickness", panel_thickness), ("crease thickness", crease_thickness)):
        if t is not None and not (np.isfinite(t) and t > 0):
            raise ParameterError(f"{name} must be finite and > 0 m, got {t!r}")
    area, perim = _areas_perimeters(xy, pattern.faces)
    if panel_thickness is not None and len(area):
        width = 2.0 * area / np.maximum(perim, 1e-300)
        k = int(np.argmin(width))
        if panel_thickness >= width[k]:
            raise ParameterError(
                f"panel thickness {1e3 * panel_thickness:.4g} mm is not under panel {k}'s width "
                f"({1e3 * width[k]:.4g} mm) in a {1e3 * span:.4g} mm {what}"
            )
    if crease_width is not None:
        if not (np.isfinite(crease_width) and crease_width >= 0):
            raise ParameterError(f"crease width must be finite and >= 0 m, got {crease_width!r}")
        try:
            shrunk_panels(pattern, crease_width)
        except ParameterError as exc:
            raise ParameterError(
                f"{exc} in a {1e3 * span:.4g} mm {what}; give a narrower crease width or a "
                "larger scale"
            ) from None
    if None not in (density, panel_thickness, crease_thickness, crease_width):
        m = sheet_mass(pattern, panel_thickness, crease_thickness, crease_width, density)
        if not m > 0:
            raise ParameterError(
                f"the {what} would weigh {1e3 * m:.4g} g: its creases ({1e3 * crease_width:.4g}"
                f" mm wide) take more than its panels"
            )
