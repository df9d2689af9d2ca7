"""The analytic Miura-like strip over a planar curve: its construction steps and named nodes.

Construction (metres; curve in the x-z plane, strip width along y):

1. Sample 2m + 1 points P_k = c(t_k), k = 0..2m: ``sampling="paper"`` uses t_k = k/(2m)
   (the published construction), ``"arclength"`` equal arc-length steps.
2. Every middle point P_{2i-1} (i = 1..m) moves by the offset l_o along the left normal
   (-c_z, c_x) of the unit chord c of P_{2i} - P_{2i-2}. The zigzag P_0..P_2m is the
   centre fold line.
3. Side line S: at interior vertices, S_k = P_k + (W_s / sin phi) v with v = (u1 + u2)/2 the
   (non-normalised) mean of the unit segment directions and phi the angle between v and u2 (a
   tangential shift of length W_s cot phi). At the ends, S_0 = P_0 + W_s unit(dz, -dx) of the
   first segment and S_2m = P_2m + W_s unit(-dz, dx) of the last one (asymmetric, as published).
4. 3-D nodes (0-based): centre line 0..2m at (P_x, 0, P_z); side A 2m+1..4m+1 at
   (S_x, -l_e, S_z); side B 4m+2..6m+2 at (S_x, +l_e, S_z). Panels, for segment j = 0..2m-1:
   [j, 2m+1+j, 2m+2+j, j+1] (side A) then [j, 4m+2+j, 4m+3+j, j+1] (side B).

What holds and what does not (checked in tests/test_strip.py):

* At every interior centre-line vertex the four sector angles sum to 2 pi, and on each side
  the two angles are supplementary (they sum to pi).
* The quads are **not planar**: :func:`quad_warp` is, per panel, the distance between the
  two diagonals (shortest distance of the lines P_j-S_{j+1} and S_j-P_{j+1}) divided by the
  mean diagonal length (0 for a planar quad). Over the 3000 published designs the largest
  warp of a design ranges 0.07 %-3.5 % (median 0.86 %; docs/strip-fit.md §4.2). The
  construction is kept as published; the mechanics
  model fans each panel from its centre node, so the as-built shape is its stress-free state.
* The two panels of a segment have opposite vertex orientation (as in the reference), so
  the 3-D strip pattern has no flat layout.
* Flat layout for fabrication (:func:`sector_angle_development`, used by
  ``StripFit.flat_pattern``): the *sector-angle development*. Because the angles on each side of
  the centre line are supplementary, the centre line develops to a straight line (segment
  lengths kept) and each transverse crease P_k-S_k is drawn with its 3-D length at its 3-D angle
  to the centre line. Centre-line lengths, transverse-crease lengths and the sector angles at
  centre-line vertices are exact; the side-line edges are not (the warped quads cannot be
  flattened isometrically): ``StripFit.flat_length_error`` is their largest relative length
  error. An exactly isometric development exists only for each side separately (as a triangle
  strip), which is not provided.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from holofold.fitting.curves import PlanarCurve
from holofold.geometry.errors import DegenerateGeometryError, ParameterError, check_range

__all__ = [
    "StripGeometry",
    "strip_geometry",
    "strip_samples",
    "chord_normals",
    "zigzag_centre_line",
    "side_line",
    "strip_nodes",
    "strip_faces",
    "quad_warp",
    "sector_angle_development",
    "SAMPLINGS",
    "MAX_M",
    "check_m",
    "check_sampling",
]

SAMPLINGS = ("paper", "arclength")
#: the largest m that ``holofold fit`` fits and the strip scenarios simulate (a strip of 4m
#: panels; fitting m = 2000 takes 4 s); the Python functions take any m
MAX_M = 2000
_MIN_SIN_PHI = 1e-6  # below this the tangential shift W_s/sin(phi) is considered unbounded


@dataclass(frozen=True, eq=False)
class StripGeometry:
    """The strip of one curve and design, with its node numbering named.

    Attributes
    ----------
    m : int
        Number of Miura units (2m centre-line segments).
    t : (2m+1,) float
        Curve parameters of the samples.
    samples : (2m+1, 2) float
        On-curve samples c(t_k) before the offset, m.
    centre_line : (2m+1, 2) float
        The zigzag centre fold line P (x, z), m.
    side_line : (2m+1, 2) float
        The side line S (x, z) shared by both sides, m.
    nodes : (6m+3, 3) float
        3-D nodes: centre line, side A (y = -l_e), side B (y = +l_e), m.
    faces : (4m, 4) int
        Panels in the published order.

    Named node sets (ids into ``nodes``): :attr:`centre`, :attr:`side_a`, :attr:`side_b`
    (the three lines), :attr:`ends` (their six end nodes, the paper's supports) and
    :attr:`apex` (the middle centre-line vertex, the paper's loaded node).
    """

    m: int
    t: np.ndarray
    samples: np.ndarray
    centre_line: np.ndarray
    side_line: np.ndarray
    nodes: np.ndarray
    faces: np.ndarray

    @property
    def centre(self) -> np.ndarray:
        """(2m+1,) ids of the centre-line nodes, in curve order."""
        return np.arange(2 * self.m + 1)

    @property
    def side_a(self) -> np.ndarray:
        """(2m+1,) ids of the side-A nodes (y = -l_e)."""
        return self.centre + 2 * self.m + 1

    @property
    def side_b(self) -> np.ndarray:
        """(2m+1,) ids of the side-B nodes (y = +l_e)."""
        return self.centre + 4 * self.m + 2

    @property
    def ends(self) -> np.ndarray:
        """(6,) ids of the first and last node of the centre line, side A and side B."""
        return np.array([line[k] for line in (self.centre, self.side_a, self.side_b)
                         for k in (0, -1)])  # fmt: skip

    @property
    def apex(self) -> int:
        """Id of the middle centre-line vertex (node m; on the curve for even m)."""
        return self.m


# ---------------------------------------------------------------------- validation
def check_m(m) -> int:
    """``m`` as an int if it is an integer >= 2 (the number of Miura units)."""
    try:
        mf = float(m)
    except (TypeError, ValueError):
        raise ParameterError(f"m must be an integer >= 2, got {m!r}") from None
    if not math.isfinite(mf) or mf != round(mf) or mf < 2:
        raise ParameterError(f"m must be an integer >= 2 (number of Miura units), got {m!r}")
    return int(mf)


def check_sampling(sampling: str | None, curve: PlanarCurve) -> str:
    """``sampling``, or the curve's default when None, if it is one of :data:`SAMPLINGS`."""
    s = curve.default_sampling if sampling is None else sampling
    if s not in SAMPLINGS:
        raise ParameterError(f"sampling must be one of {SAMPLINGS}, got {sampling!r}")
    return s


# ---------------------------------------------------------------------- construction steps
def strip_samples(curve: PlanarCurve, m: int, sampling: str = "paper"):
    """Parameters t (2m+1,) and points (2m+1, 2) of the on-curve samples (step 1)."""
    n = 2 * check_m(m)
    if sampling == "paper":
        t = np.arange(n + 1) / n
        return t, curve(t)
    if sampling == "arclength":
        return curve.resample(n + 1, "arclength")
    raise ParameterError(f"sampling must be one of {SAMPLINGS}, got {sampling!r}")


def chord_normals(P: np.ndarray) -> np.ndarray:
    """Unit left normals (-c_z, c_x) of the chords P_{2i} - P_{2i-2}, (m, 2)."""
    c = P[2::2] - P[:-2:2]
    n = np.linalg.norm(c, axis=1)
    bad = np.flatnonzero(n <= 0)
    if bad.size:
        raise DegenerateGeometryError(
            f"chord of unit {int(bad[0]) + 1} has zero length (samples {2 * bad[0]} and "
            f"{2 * bad[0] + 2} coincide)"
        )
    c = c / n[:, None]
    return np.column_stack([-c[:, 1], c[:, 0]])


def zigzag_centre_line(samples: np.ndarray, offset: float) -> np.ndarray:
    """Centre line (2m+1, 2): odd samples moved by ``offset`` along the chord's left normal."""
    P = np.array(samples, dtype=float)
    P[1::2] += offset * chord_normals(P)
    return P


def side_line(P: np.ndarray, strip_width: float) -> np.ndarray:
    """Side line S (2m+1, 2) of the centre line P (step 3, including the end shifts).

    Raises :class:`DegenerateGeometryError` where the centre line does not turn (phi ~ 0, the
    shift W_s/sin(phi) is unbounded) or folds back on itself.
    """
    d = np.diff(P, axis=0)
    L = np.linalg.norm(d, axis=1)
    if (L <= 0).any():
        k = int(np.flatnonzero(L <= 0)[0])
        raise DegenerateGeometryError(f"centre-line segment {k} has zero length")
    u = d / L[:, None]
    u1, u2 = u[:-1], u[1:]
    v = 0.5 * (u1 + u2)
    cross = np.abs(u1[:, 0] * u2[:, 1] - u1[:, 1] * u2[:, 0])  # |u1 x u2| = 2 |v| sin(phi)
    vn = np.linalg.norm(v, axis=1)
    sin_phi = np.where(vn > 0, 0.5 * cross / np.where(vn > 0, vn, 1.0), 0.0)
    bad = np.flatnonzero((sin_phi < _MIN_SIN_PHI) | (vn < _MIN_SIN_PHI))
    if bad.size:
        k = int(bad[0]) + 1
        phi = math.degrees(math.atan2(sin_phi[k - 1], vn[k - 1]))
        raise DegenerateGeometryError(
            f"the centre line does not turn at vertex {k} (half turning angle phi = {phi:.3g} "
            f"deg) or reverses there; W_s/sin(phi) is unbounded. Use a larger offset, another "
            f"m, or a curve without straight parts"
        )
    S = np.empty_like(P)
    S[1:-1] = P[1:-1] + (strip_width / sin_phi)[:, None] * v
    h, tl = u[0], u[-1]
    S[0] = P[0] + strip_width * np.array([h[1], -h[0]])
    S[-1] = P[-1] + strip_width * np.array([-tl[1], tl[0]])
    return S


def strip_nodes(P: np.ndarray, S: np.ndarray, extrude: float) -> np.ndarray:
    """3-D nodes (6m+3, 3): centre line, side A (y = -l_e), side B (y = +l_e)."""
    n1 = len(P)
    X = np.zeros((3 * n1, 3))
    X[:n1, 0], X[:n1, 2] = P[:, 0], P[:, 1]
    for blk, y in ((1, -extrude), (2, extrude)):
        X[blk * n1 : (blk + 1) * n1] = np.column_stack([S[:, 0], np.full(n1, y), S[:, 1]])
    return X


def strip_faces(m: int) -> np.ndarray:
    """Panels (4m, 4), 0-based, in the published order (two panels per segment)."""
    m = check_m(m)
    j = np.arange(2 * m)
    a = np.stack([j, 2 * m + 1 + j, 2 * m + 2 + j, j + 1], axis=1)
    b = np.stack([j, 4 * m + 2 + j, 4 * m + 3 + j, j + 1], axis=1)
    return np.stack([a, b], axis=1).reshape(-1, 4)


def quad_warp(X: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Relative warp (nf,) of quads: distance between the diagonals / mean diagonal length."""
    a, b, c, d = (X[faces[:, i]] for i in range(4))
    d1, d2 = c - a, d - b
    n = np.cross(d1, d2)
    nn = np.linalg.norm(n, axis=1)
    gap = np.abs(np.einsum("ij,ij->i", b - a, n)) / np.where(nn > 0, nn, 1.0)
    mean_diag = 0.5 * (np.linalg.norm(d1, axis=1) + np.linalg.norm(d2, axis=1))
    return gap / mean_diag


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))


def sector_angle_development(X: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat layout (6m+3, 2) keeping centre/transverse lengths and centre-vertex angles.

    Returns the layout and the angle defect (2m-1,) pi - (sum of the two side-A sector angles)
    at interior centre vertices (0 up to rounding for the published construction).
    """
    n1 = 2 * m + 1
    C, A, B = X[:n1], X[n1 : 2 * n1], X[2 * n1 :]
    seg = np.linalg.norm(np.diff(C, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    fwd = np.empty_like(C)
    fwd[:-1] = C[1:] - C[:-1]
    back = np.empty_like(C)
    back[1:] = C[:-1] - C[1:]
    ta = A - C
    beta = np.empty(n1)
    beta[:-1] = _angle(fwd[:-1], ta[:-1])  # angle from the forward centre segment
    beta[-1] = np.pi - _angle(back[-1:], ta[-1:])[0]
    defect = np.pi - (_angle(fwd[1:-1], ta[1:-1]) + _angle(back[1:-1], ta[1:-1]))
    lt = np.linalg.norm(ta, axis=1)
    flat = np.zeros((3 * n1, 2))
    flat[:n1, 0] = s
    flat[n1 : 2 * n1] = np.column_stack([s + lt * np.cos(beta), -lt * np.sin(beta)])
    lb = np.linalg.norm(B - C, axis=1)
    betab = np.empty(n1)
    tb = B - C
    betab[:-1] = _angle(fwd[:-1], tb[:-1])
    betab[-1] = np.pi - _angle(back[-1:], tb[-1:])[0]
    flat[2 * n1 :] = np.column_stack([s + lb * np.cos(betab), lb * np.sin(betab)])
    return flat, defect


def strip_geometry(
    curve: PlanarCurve,
    m: int,
    offset: float,
    strip_width: float,
    extrude: float,
    sampling: str = "paper",
) -> StripGeometry:
    """Construct the strip (steps 1-4 of the module docstring) for one design.

    Parameters
    ----------
    curve : PlanarCurve
        Target curve in the x-z plane, m.
    m : int
        Number of Miura units, >= 2.
    offset, strip_width, extrude : float
        l_o, W_s and l_e, m (each > 0).
    sampling : {"paper", "arclength"}

    Raises
    ------
    ParameterError, DegenerateGeometryError
        Invalid values, or a centre line that does not turn (the side line is unbounded).
    """
    m = check_m(m)
    offset = check_range("offset", offset, 0.0, None, low_open=True)
    strip_width = check_range("strip_width", strip_width, 0.0, None, low_open=True)
    extrude = check_range("extrude", extrude, 0.0, None, low_open=True)
    t, samples = strip_samples(curve, m, sampling)
    P = zigzag_centre_line(samples, offset)
    S = side_line(P, strip_width)
    return StripGeometry(m, t, samples, P, S, strip_nodes(P, S, extrude), strip_faces(m))
