"""Fitting errors of a strip's centre line against its target curve.

Two measures:

* :func:`paper_error` / :func:`index_matched_error`: the published error of Zhu & Filipov
  (docs/strip-fit.md §5.1). Each of the 2m centre-line segments is cut into ``seg = 10``
  sub-intervals; the end point of sub-interval j of segment i is compared with the curve point
  of the same parameter, and e is the mean distance. It is index-matched (not a closest-point
  distance) and, for the paper's half circle, depends only on (m, offset).
* :func:`closest_point_error`: the distance from points of the centre-line polyline to the
  closest point of the curve (length-weighted mean and maximum), and optionally from the
  curve to the centre line (a one-sided Hausdorff distance each way). Meaningful for any
  curve and any sampling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.fitting.curve_files import load_curve
from holofold.fitting.curves import PlanarCurve
from holofold.fitting.strip import chord_normals
from holofold.geometry.errors import ParameterError

__all__ = [
    "ClosestPointError",
    "paper_error",
    "index_matched_error",
    "closest_point_error",
    "polyline_distance",
]

SEG = 10  # sub-intervals per centre-line segment in the published error


def index_matched_error(
    curve: PlanarCurve, centre_line: np.ndarray, t: np.ndarray, seg: int = SEG
) -> float:
    """The 5.5 error for a centre line whose vertex k was sampled at parameter ``t[k]``.

    Target parameters are ``t[i-1] + j/seg (t[i] - t[i-1])`` (j = 1..seg), i.e. q/(20m) for
    the paper's equal spacing. Returns the mean distance, metres.
    """
    P = np.asarray(centre_line, float)
    t = np.asarray(t, float)
    j = np.arange(1, seg + 1) / seg
    F = (P[:-1, None, :] * (1 - j)[None, :, None] + P[1:, None, :] * j[None, :, None]).reshape(
        -1, 2
    )
    tq = (t[:-1, None] + j[None, :] * np.diff(t)[:, None]).ravel()
    return float(np.linalg.norm(F - curve(tq), axis=1).mean())


def paper_error(curve, m, offset, seg: int = SEG):
    """Published fitting error e(m, l_o) of docs/strip-fit.md §5.1 (paper sampling).

    Parameters
    ----------
    curve : PlanarCurve or spec accepted by :func:`holofold.fitting.curve_files.load_curve`
        The target (the paper: ``half-circle:radius=2``).
    m : int or array_like of int
        Number of Miura units (>= 1 here; the strip itself needs >= 2).
    offset : float or array_like
        Offset l_o of the odd (middle) vertices along the chord's left normal, metres.
        ``m`` and ``offset`` broadcast against each other.

    Returns
    -------
    float or ndarray
        e in metres, the shape of the broadcast inputs. Vectorised: one evaluation of the
        curve per distinct m.
    """
    curve = load_curve(curve)
    m_arr, off_arr = np.broadcast_arrays(np.asarray(m), np.asarray(offset, dtype=float))
    if not np.isfinite(off_arr).all():
        raise ParameterError("offset must be finite")
    mf = np.asarray(m_arr, dtype=float)
    if not (np.isfinite(mf).all() and np.all(mf == np.round(mf)) and np.all(mf >= 1)):
        raise ParameterError(f"m must be integers >= 1, got {np.unique(mf)[:5].tolist()}")
    out = np.empty(m_arr.shape, dtype=float)
    flat_m = np.asarray(mf, dtype=np.int64).ravel()
    flat_off = off_arr.ravel()
    flat_out = out.reshape(-1)
    j = np.arange(1, seg + 1) / seg
    for mm in np.unique(flat_m):
        sel = np.flatnonzero(flat_m == mm)
        n = 2 * int(mm)
        P = curve(np.arange(n + 1) / n)
        N = np.zeros_like(P)
        N[1::2] = chord_normals(P)
        # centre line for every offset: P + l_o N, sub-sampled per segment (n_off, n*seg, 2)
        F0 = (P[:-1, None] * (1 - j)[None, :, None] + P[1:, None] * j[None, :, None]).reshape(-1, 2)
        G = (N[:-1, None] * (1 - j)[None, :, None] + N[1:, None] * j[None, :, None]).reshape(-1, 2)
        T = curve(np.arange(1, n * seg + 1) / (n * seg))
        D = (F0 - T)[None] + flat_off[sel, None, None] * G[None]
        flat_out[sel] = np.sqrt((D**2).sum(axis=2)).mean(axis=1)
    return float(out) if out.ndim == 0 else out


def polyline_distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance (n,) from ``points`` (n, 2) to the polyline (k, 2) (all segments, exact)."""
    q = np.asarray(points, float).reshape(-1, 2)
    a = np.asarray(polyline, float)[:-1]
    ab = np.diff(np.asarray(polyline, float), axis=0)
    den = np.einsum("kj,kj->k", ab, ab)
    lam = np.einsum("nkj,kj->nk", q[:, None, :] - a[None], ab) / np.where(den > 0, den, 1.0)
    foot = a[None] + lam.clip(0, 1)[..., None] * ab[None]
    return np.sqrt(((foot - q[:, None, :]) ** 2).sum(axis=2)).min(axis=1)


@dataclass(frozen=True)
class ClosestPointError:
    """Closest-point errors, metres.

    ``mean``/``max``: from the centre line (sampled ``seg`` points per segment, mean weighted by
    length) to the curve; ``curve_mean``/``curve_max``: from the curve (sampled equally in arc
    length) to the centre-line polyline (NaN unless requested).
    """

    mean: float
    max: float
    curve_mean: float = float("nan")
    curve_max: float = float("nan")


def closest_point_error(
    curve: PlanarCurve,
    centre_line: np.ndarray,
    *,
    seg: int = SEG,
    both: bool = True,
    n_curve: int = 1025,
) -> ClosestPointError:
    """Closest-point error of a centre-line polyline (k, 2) against ``curve``."""
    P = np.asarray(centre_line, float)
    j = np.arange(seg + 1) / seg
    Q = P[:-1, None] * (1 - j)[None, :, None] + P[1:, None] * j[None, :, None]  # (k-1, seg+1, 2)
    d = curve.distance(Q.reshape(-1, 2)).reshape(len(P) - 1, seg + 1)
    w = np.full(seg + 1, 1.0 / seg)
    w[[0, -1]] *= 0.5
    L = np.linalg.norm(np.diff(P, axis=0), axis=1)
    mean = float((d @ w * L).sum() / L.sum())
    mx = float(d.max())
    cmean = cmax = float("nan")
    if both:
        _, C = curve.resample(n_curve, "arclength")
        dc = polyline_distance(C, P)
        wc = np.full(n_curve, 1.0)
        wc[[0, -1]] = 0.5
        cmean = float((dc * wc).sum() / wc.sum())
        cmax = float(dc.max())
    return ClosestPointError(mean, mx, cmean, cmax)
