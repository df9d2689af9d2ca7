"""A Miura-like strip fitted to a curve: the construction with its errors and flat layout.

:func:`fit_strip` builds the strip of :mod:`holofold.fitting.strip` for one design, validates it
as a crease pattern (a self-overlapping strip is refused) and measures it: the index-matched
(paper) and closest-point errors of :mod:`holofold.fitting.error`, the panels' warp and the
sector-angle flat development for fabrication (docs/strip-fit.md).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from holofold.fitting.curve_files import load_curve
from holofold.fitting.curves import PlanarCurve
from holofold.fitting.error import ClosestPointError, closest_point_error, index_matched_error
from holofold.fitting.strip import (
    StripGeometry,
    check_sampling,
    quad_warp,
    sector_angle_development,
    strip_geometry,
)
from holofold.geometry.errors import DegenerateGeometryError, InvalidPatternError
from holofold.geometry.pattern import CreasePattern

__all__ = ["StripFit", "fit_strip"]

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False, repr=False)
class StripFit:
    """A Miura-like strip fitted to a curve.

    Attributes
    ----------
    geometry : StripGeometry
        The construction: samples, centre and side lines, nodes, faces and the named node
        sets (``ends``, ``apex``, ``centre``, ``side_a``, ``side_b``).
    pattern : CreasePattern
        3-D strip, 6m+3 nodes, 4m quads in the published numbering (``flat`` is None).
    curve : PlanarCurve
        The target.
    offset, strip_width, extrude : float
        l_o, W_s, l_e, m.
    sampling : {"paper", "arclength"}
    warp : (4m,) float
        Relative out-of-plane warp of each panel (diagonal distance / mean diagonal).
    index_error : float
        Index-matched error for this sampling (= the published error for ``paper``), m.
    closest : ClosestPointError
        Closest-point errors (centre line -> curve, curve -> centre line), m.
    flat : (6m+3, 2) float
        Sector-angle development (docs/strip-fit.md).
    flat_length_error : float
        Largest relative edge-length difference between ``flat`` and the 3-D strip.
    max_angle_defect : float
        Largest |pi - sum of the two side-A sector angles| at interior centre vertices, rad.

    ``flat_pattern`` (computed on first use): the same strip with ``flat`` as layout and every
    face counter-clockwise in it (side B loops reversed), for fabrication export; None if that
    layout is not a valid pattern (overlapping panels).
    """

    geometry: StripGeometry
    pattern: CreasePattern
    curve: PlanarCurve
    offset: float
    strip_width: float
    extrude: float
    sampling: str
    warp: np.ndarray
    index_error: float
    closest: ClosestPointError
    flat: np.ndarray
    flat_length_error: float
    max_angle_defect: float

    @cached_property
    def flat_pattern(self) -> CreasePattern | None:
        """The strip with :attr:`flat` as layout, faces counter-clockwise in it (or None)."""
        ff = [f.copy() for f in self.pattern.faces]
        ff[1::2] = [f[::-1].copy() for f in ff[1::2]]  # side B loops reversed
        try:
            return CreasePattern.from_faces(
                self.pattern.coords,
                ff,
                flat=self.flat,
                meta={**self.pattern.meta, "flat_layout": "sector-angle development"},
            )
        except ValueError as exc:  # an overlapping development is not a valid layout
            log.info("no flat layout for this strip: %s", exc)
            return None

    @property
    def m(self) -> int:
        return self.geometry.m

    @property
    def t(self) -> np.ndarray:
        """(2m+1,) curve parameters of the samples."""
        return self.geometry.t

    @property
    def samples(self) -> np.ndarray:
        """(2m+1, 2) on-curve samples before the offset, m."""
        return self.geometry.samples

    @property
    def centre_line(self) -> np.ndarray:
        """(2m+1, 2) the zigzag centre fold line (x, z), m."""
        return self.geometry.centre_line

    @property
    def side_line(self) -> np.ndarray:
        """(2m+1, 2) the side line (x, z), m."""
        return self.geometry.side_line

    @property
    def parameters(self) -> dict:
        """The design: m, offset, strip_width, extrude (m), sampling and the curve's name."""
        return {
            "curve": self.curve.name,
            "m": self.m,
            "offset": self.offset,
            "strip_width": self.strip_width,
            "extrude": self.extrude,
            "sampling": self.sampling,
        }

    def __repr__(self) -> str:
        return (
            f"StripFit(curve={self.curve.name!r}, m={self.m}, offset={self.offset:.6g}, "
            f"strip_width={self.strip_width:.6g}, extrude={self.extrude:.6g}, "
            f"sampling={self.sampling!r}, index_error={self.index_error:.6g}, "
            f"closest_max={self.closest.max:.6g})"
        )

    @property
    def errors(self) -> dict[str, float]:
        """All error measures as a flat dict (metres; warp relative)."""
        return {
            "index_error": self.index_error,
            "closest_mean": self.closest.mean,
            "closest_max": self.closest.max,
            "curve_to_strip_mean": self.closest.curve_mean,
            "curve_to_strip_max": self.closest.curve_max,
            "warp_max": float(self.warp.max()),
            "warp_mean": float(self.warp.mean()),
            "flat_length_error": self.flat_length_error,
        }


def fit_strip(
    curve,
    m: int,
    offset: float,
    strip_width: float,
    extrude: float,
    *,
    sampling: str | None = None,
    closest_both: bool = True,
) -> StripFit:
    """Fit the Miura-like strip (docs/strip-fit.md) to ``curve``.

    Parameters
    ----------
    curve : PlanarCurve or anything :func:`~holofold.fitting.curve_files.load_curve` accepts
        Target curve in the x-z plane, metres.
    m : int
        Number of Miura units, >= 2 (2m centre-line segments). The paper uses even m so that
        the apex sample t = 1/2 is an unshifted vertex (node m); odd m is allowed.
    offset : float
        l_o > 0, offset of the middle vertices along the chord's left normal, metres.
    strip_width : float
        W_s > 0, the side-line shift parameter, metres.
    extrude : float
        l_e > 0, half-width of the strip in y, metres.
    sampling : {"paper", "arclength"} or None
        None: the curve's default (``paper`` for the built-in half circle, else ``arclength``).

    Returns
    -------
    StripFit
    """
    curve = load_curve(curve)
    sampling = check_sampling(sampling, curve)
    g = strip_geometry(curve, m, offset, strip_width, extrude, sampling)
    meta = {
        "m": g.m,
        "offset": float(offset),
        "strip_width": float(strip_width),
        "extrude": float(extrude),
        "sampling": sampling,
        "curve": curve.name,
        "curve_params": dict(curve.params),
        "generator": "holofold.fitting.fit_strip",
    }
    P, S, X = g.centre_line, g.side_line, g.nodes
    try:
        pattern = CreasePattern.from_faces(X, list(g.faces), flat=None, meta=meta)
    except InvalidPatternError as exc:
        shift = np.linalg.norm(S - P, axis=1)
        raise DegenerateGeometryError(
            f"the fitted strip is self-overlapping ({exc}); the side-line shift W_s cot(phi) "
            f"reaches {shift.max():.4g} m at vertex {int(np.argmax(shift))} against centre "
            f"segments of {np.linalg.norm(np.diff(P, axis=0), axis=1).min():.4g} m: use a "
            f"smaller strip_width, a larger offset or another m"
        ) from None
    flat, defect = sector_angle_development(X, g.m)
    e = pattern.edges
    l3 = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1)
    lf = np.linalg.norm(flat[e[:, 1]] - flat[e[:, 0]], axis=1)
    return StripFit(
        geometry=g,
        pattern=pattern,
        curve=curve,
        offset=float(offset),
        strip_width=float(strip_width),
        extrude=float(extrude),
        sampling=sampling,
        warp=quad_warp(X, g.faces),
        index_error=index_matched_error(curve, P, g.t),
        closest=closest_point_error(curve, P, both=closest_both),
        flat=flat,
        flat_length_error=float(np.max(np.abs(lf - l3) / l3)),
        max_angle_defect=float(np.abs(defect).max()) if defect.size else 0.0,
    )
