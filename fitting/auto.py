"""Choosing a strip automatically: the smallest m and an offset meeting an error tolerance.

:func:`fit_auto` walks m upwards over ``m_range``; for each m it evaluates every offset
(centre line, side line and closest-point error, without building the crease pattern), and
stops at the first m where some offset meets the tolerance and gives a valid, non-overlapping
strip whose quads warp no more than ``max_warp`` (default :data:`PUBLISHED_MAX_WARP`, the
largest warp of the 3000 published arch designs: 3.47 %, docs/strip-fit.md §4.2) and, with
``panel_thickness`` and ``crease_width``, whose folded thick panels do not overlap
(:func:`~holofold.geometry.clearance.printability`) when ``require_no_overlap``. Among the
offsets that qualify it prefers the **largest** (deepest corrugation: the most turning at the
centre-line vertices, so the smallest side-line shifts W_s cot(phi); the paper's stiffest arches
also have large offsets), unless ``prefer="smallest-error"``. Deep corrugations warp the quads
most, so the warp limit is what keeps the largest offset from running away.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pandas as pd

from holofold.fitting.curve_files import load_curve
from holofold.fitting.error import closest_point_error, index_matched_error
from holofold.fitting.strip import (
    check_m,
    check_sampling,
    quad_warp,
    side_line,
    strip_faces,
    strip_nodes,
    strip_samples,
    zigzag_centre_line,
)
from holofold.fitting.strip_fit import StripFit, fit_strip
from holofold.geometry.clearance import printability
from holofold.geometry.errors import (
    DegenerateGeometryError,
    ParameterError,
    check_range,
    record_or_keywords,
)
from holofold.geometry.thick import TECHNIQUES, path_overlap, thick_panels

__all__ = [
    "AutoFit",
    "FitNotFoundError",
    "ThickCheck",
    "fit_auto",
    "DEFAULT_M_RANGE",
    "PUBLISHED_MAX_WARP",
]

#: largest relative quad warp of the 3000 published arch designs (0.0347, rounded up)
PUBLISHED_MAX_WARP = 0.035

log = logging.getLogger(__name__)

_SLACK = 1e-9  # relative slack on the tolerance (an error equal to it up to rounding meets it)

#: default m values tried: even m (the curve's mid-parameter is then a vertex), 2..60
DEFAULT_M_RANGE = tuple(range(2, 61, 2))


class FitNotFoundError(ParameterError):
    """No (m, offset) in the given ranges meets the tolerance; ``candidates`` holds the table."""

    def __init__(self, message: str, candidates: pd.DataFrame):
        super().__init__(message)
        self.candidates = candidates


@dataclass(frozen=True)
class ThickCheck:
    """The folded thick panels :func:`fit_auto` builds for every candidate strip: panel
    thickness t and crease width W (m; both, or neither: no thick panels), the technique
    (:data:`~holofold.geometry.thick.TECHNIQUES`) and whether a candidate whose panels overlap
    is refused. Checked by :func:`fit_auto`, with its messages."""

    panel_thickness: float | None = None
    crease_width: float | None = None
    require_no_overlap: bool = False
    thick: str = "centred"


class AutoFit(NamedTuple):
    """Result of :func:`fit_auto`: the chosen strip and the table of candidates tried."""

    strip: StripFit
    candidates: pd.DataFrame


def fit_auto(
    curve,
    tolerance: float,
    *,
    m_range: Iterable[int] = DEFAULT_M_RANGE,
    offsets: Iterable[float] | None = None,
    strip_width: float | None = None,
    extrude: float | None = None,
    sampling: str | None = None,
    metric: str = "max",
    prefer: str = "largest-offset",
    max_warp: float | None = PUBLISHED_MAX_WARP,
    thick_check: ThickCheck | None = None,
    **thick_options,
) -> AutoFit:
    """Smallest m (and an offset) whose strip's closest-point error meets ``tolerance``.

    Parameters
    ----------
    curve : PlanarCurve or anything :func:`holofold.fitting.curve_files.load_curve` accepts
    tolerance : float
        Allowed closest-point error, metres (> 0); met if error <= tolerance (1 + 1e-9).
    m_range : iterable of int
        m values to try (each >= 2), tried in increasing order.
    offsets : iterable of float, optional
        Offsets l_o to try, metres (> 0). Default: ``tolerance * [0.1, 0.2, ..., 2.0]``.
    strip_width : float, optional
        W_s, metres. Default: offset / 8 for each candidate (the paper's median ratio).
    extrude : float, optional
        l_e, metres. Default: curve length / 40 (the paper's median for its half circle).
    sampling : {"paper", "arclength"}, optional
        Default: the curve's default.
    metric : {"max", "mean"}
        Which closest-point error (centre line -> curve) must be <= tolerance.
    prefer : {"largest-offset", "smallest-error"}
        Which qualifying offset to take at the smallest m.
    max_warp : float or None
        Largest allowed relative quad warp (diagonal distance / mean diagonal; None: any).
    thick_check : ThickCheck, optional
        The folded thick panels of every candidate built: with ``panel_thickness`` and
        ``crease_width`` (t and W, m) their ``overlap`` (m^3) and ``clearance`` (m) are
        reported; ``require_no_overlap`` refuses candidates whose panels overlap (needs both);
        ``thick`` is the technique (:data:`~holofold.geometry.thick.TECHNIQUES`): the
        ``overlap`` is that of these panels (:func:`~holofold.geometry.thick.path_overlap` in
        the folded state); ``clearance`` stays that of centred slabs.
    **thick_options
        The record's fields by name instead (``panel_thickness=6e-3, crease_width=1e-3``).

    Returns
    -------
    AutoFit
        ``strip`` (:class:`StripFit`) and ``candidates`` (DataFrame with columns m, offset,
        strip_width, extrude, closest_mean, closest_max, index_error, warp_max, valid, meets,
        chosen, reason, and overlap, clearance with a thickness), one row per candidate tried.

    Raises
    ------
    FitNotFoundError
        When no candidate qualifies (the message names the best error reached).
    """
    tc = record_or_keywords(ThickCheck, thick_check, thick_options, "fit_auto", "thick_check")
    panel_thickness, crease_width = tc.panel_thickness, tc.crease_width
    require_no_overlap, thick = tc.require_no_overlap, tc.thick
    curve = load_curve(curve)
    tol = check_range("tolerance", tolerance, 0.0, None, low_open=True)
    if metric not in ("max", "mean"):
        raise ParameterError(f"metric must be 'max' or 'mean', got {metric!r}")
    if prefer not in ("largest-offset", "smallest-error"):
        raise ParameterError(f"prefer must be 'largest-offset' or 'smallest-error', got {prefer!r}")
    ms = sorted({check_m(m) for m in m_range})
    if not ms:
        raise ParameterError("m_range is empty")
    if offsets is None:
        offs = tol * np.linspace(0.1, 2.0, 20)
    else:
        offs = np.array([check_range("offset", o, 0.0, None, low_open=True) for o in offsets])
        if offs.size == 0:
            raise ParameterError("offsets is empty")
    offs = np.unique(offs)
    if strip_width is not None:
        strip_width = check_range("strip_width", strip_width, 0.0, None, low_open=True)
    le = (
        curve.length / 40.0
        if extrude is None
        else check_range("extrude", extrude, 0.0, None, low_open=True)
    )
    sampling = check_sampling(sampling, curve)
    col = "closest_max" if metric == "max" else "closest_mean"
    if max_warp is not None:
        max_warp = check_range("max_warp", max_warp, 0.0, None, low_open=True)
    pair = (panel_thickness, crease_width)
    if any(v is not None for v in pair):
        if any(v is None for v in pair):
            raise ParameterError("overlap needs both a panel thickness and a crease width")
        panel_thickness = check_range("panel_thickness", panel_thickness, 0.0, None, low_open=True)
        crease_width = check_range("crease_width", crease_width, 0.0, None)
    if thick not in TECHNIQUES:
        raise ParameterError(
            f"unknown thickness technique {thick!r}; known: {', '.join(TECHNIQUES)}"
        )
    if require_no_overlap and panel_thickness is None:
        raise ParameterError("require_no_overlap needs a panel thickness and a crease width")

    rows: list[dict] = []
    for m in ms:
        t, samples = strip_samples(curve, m, sampling)
        faces = strip_faces(m)
        start = len(rows)
        for off in offs:
            ws = off / 8.0 if strip_width is None else strip_width
            row = {"m": m, "offset": float(off), "strip_width": ws, "extrude": le}
            P = zigzag_centre_line(samples, off)
            err = closest_point_error(curve, P, both=False)
            row.update(
                closest_mean=err.mean,
                closest_max=err.max,
                index_error=index_matched_error(curve, P, t),
                warp_max=float("nan"),
                valid=True,
                meets=(err.max if metric == "max" else err.mean) <= tol * (1 + _SLACK),
                chosen=False,
                reason="",
            )
            try:
                S = side_line(P, ws)
            except DegenerateGeometryError as exc:
                row.update(valid=False, meets=False, reason=str(exc))
            else:
                row["warp_max"] = float(quad_warp(strip_nodes(P, S, le), faces).max())
                if max_warp is not None and row["warp_max"] > max_warp:
                    row.update(
                        meets=False,
                        reason=f"quads warp {100 * row['warp_max']:.3g} % > max_warp "
                        f"{100 * max_warp:.3g} %",
                    )
            rows.append(row)
        # candidates of this m that meet the tolerance, best first
        ok = [r for r in rows[start:] if r["meets"]]
        if prefer == "largest-offset":
            ok.sort(key=lambda r: -r["offset"])
        else:
            ok.sort(key=lambda r: r[col])
        for r in ok:
            try:
                fit = fit_strip(curve, m, r["offset"], r["strip_width"], le, sampling=sampling)
            except DegenerateGeometryError as exc:
                r.update(valid=False, meets=False, reason=str(exc))
                continue
            if panel_thickness is not None:
                pr = printability(fit.pattern, panel_thickness, crease_width)
                overlap = pr.overlap
                if thick != "centred":
                    geo = fit.flat_pattern if fit.flat_pattern is not None else fit.pattern
                    panels = thick_panels(geo, panel_thickness, crease_width, thick)
                    overlap = float(path_overlap([geo], panels).volume[0])
                r.update(overlap=overlap, clearance=pr.clearance)
                if require_no_overlap and overlap > 0:
                    r.update(meets=False, reason=f"thick panels overlap ({overlap:.3g} m^3)")
                    continue
            r["chosen"] = True
            log.info("fit_auto: m=%d offset=%.4g %s=%.4g warp=%.3g", m, r["offset"], col, r[col],
                     r["warp_max"])  # fmt: skip
            return AutoFit(fit, pd.DataFrame(rows))
    table = pd.DataFrame(rows)
    good = table[table["valid"]]
    if len(good):
        best = good.loc[good[col].idxmin()]
        msg = (
            f"no strip with m in {ms[0]}..{ms[-1]} and offset in {offs.min():.4g}.."
            f"{offs.max():.4g} m meets {col} <= {tol:.4g} m; the best valid candidate reaches "
            f"{best[col]:.4g} m (m={int(best['m'])}, offset={best['offset']:.4g}): "
            "allow larger m, smaller offsets or a larger tolerance"
        )
    else:
        msg = f"no valid strip in the ranges tried ({table['reason'].iloc[0]})"
    close = table[table["valid"] & (table[col] <= tol * (1 + _SLACK))]
    if len(close):  # the tolerance was met, a limit was not
        why = close["reason"].iloc[int(np.argmin(close["warp_max"].to_numpy()))]
        msg = (
            f"no strip with m in {ms[0]}..{ms[-1]} meets {col} <= {tol:.4g} m within the limits: "
            f"the least warped one that meets the tolerance is refused because {why}; allow a "
            "larger max_warp, other m or offsets, or thinner panels"
        )
    raise FitNotFoundError(msg, table)
