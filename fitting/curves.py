"""Planar target curves in the x-z plane.

A :class:`PlanarCurve` is a map ``t -> (x, z)`` on ``t in [0, 1]`` (metres), vectorised over
``t``. It is built from

* a Python callable (:meth:`PlanarCurve.from_function`),
* an ``(N, 2)`` array of points, interpolated by a scipy spline through the points with a
  chord-length parameter (:meth:`PlanarCurve.from_points`),
* the ``d`` attribute of an SVG path (:meth:`PlanarCurve.from_svg_path`, parsed with
  ``svgelements``; the SVG y axis points down, so z = -y),
* files, in the units they are drawn in: CSV points and SVG drawings
  (:mod:`holofold.fitting.curve_files`),
* a built-in by name (:func:`builtin_curve`, :func:`parse_curve_spec`):
  ``half-circle:radius=2`` (the paper's target, x = R - R cos(pi t), z = R sin(pi t)),
  ``arc:radius=..,angle=..`` (angle in degrees), ``parabola:span=..,height=..``,
  ``sine:span=..,amplitude=..,periods=..``, ``catenary:span=..,height=..``.

Geometry helpers work on a dense polyline of the curve (equal arc-length spacing): arc
length, resampling by equal parameter or equal arc length, and the closest-point distance of
query points (KD-tree candidates, projection onto polyline segments, then a few Newton steps
on the curve itself).

Bad curves raise :class:`CurveError` (a ``ValueError``): fewer than two distinct points,
non-finite values, zero length, unreadable or malformed files. A self-intersecting curve only
gets a :class:`UserWarning`.
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from holofold.geometry.errors import DegenerateGeometryError, FormatError, ParameterError

__all__ = [
    "CurveError",
    "PlanarCurve",
    "BUILTIN_CURVES",
    "builtin_curve",
    "parse_curve_spec",
    "svg_path_curve",
]

log = logging.getLogger(__name__)

_N_DENSE = 4097  # vertices of the dense polyline used for lengths and distances


class CurveError(DegenerateGeometryError):
    """A curve that cannot be used (too few points, non-finite, zero length, bad file)."""


class CurveFormatError(CurveError, FormatError):
    """A curve file or specification that cannot be read."""


def _as_t(t) -> np.ndarray:
    return np.atleast_1d(np.asarray(t, dtype=float))


def _call_vectorised(func: Callable, t: np.ndarray) -> np.ndarray:
    """Evaluate a user callable on ``t`` (n,), returning (n, 2); loops if not vectorised."""
    try:
        out = np.asarray(func(t), dtype=float)
        if out.shape == (len(t), 2):
            return out
        if out.shape == (2, len(t)):
            return out.T.copy()
    except Exception:  # noqa: BLE001 - fall back to a scalar loop below
        out = None
    try:
        vals = [np.asarray(func(float(s)), dtype=float).reshape(-1) for s in t]
    except Exception as exc:
        raise CurveError(f"the curve function failed at t in [0, 1]: {exc}") from exc
    if any(v.shape != (2,) for v in vals):
        raise CurveError("the curve function must return (x, z) pairs")
    return np.stack(vals)


@dataclass(frozen=True, eq=False, repr=False)
class PlanarCurve:
    """A planar curve ``t -> (x, z)``, ``t in [0, 1]``, metres.

    Attributes
    ----------
    func : callable
        Vectorised map from ``t`` (n,) to points (n, 2).
    name : str
        Short label (for reports and file metadata).
    kind : str
        ``"builtin"``, ``"function"``, ``"points"`` or ``"svg"``.
    params : dict
        Parameters of a built-in (or the source file).
    default_sampling : str
        ``"paper"`` for the paper's half circle, else ``"arclength"``.
    """

    func: Callable[[np.ndarray], np.ndarray]
    name: str = "curve"
    kind: str = "function"
    params: dict[str, Any] = field(default_factory=dict)
    default_sampling: str = "arclength"

    def __post_init__(self):
        if self.default_sampling not in ("paper", "arclength"):
            raise ParameterError(
                f"default_sampling must be 'paper' or 'arclength', got {self.default_sampling!r}"
            )
        self._check()

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_function(cls, func: Callable, name: str = "function") -> PlanarCurve:
        """Curve from a callable ``t -> (x, z)`` on [0, 1] (vectorised or scalar)."""
        if not callable(func):
            raise CurveError(f"expected a callable t -> (x, z), got {type(func).__name__}")
        return cls(lambda t: _call_vectorised(func, _as_t(t)), name=name, kind="function")

    @classmethod
    def from_points(
        cls, points, name: str = "points", *, degree: int | None = None, source: str = ""
    ) -> PlanarCurve:
        """Curve through an (N, 2) array of (x, z) points.

        Consecutive duplicates are dropped; the points are interpolated by a scipy B-spline
        (cubic for N >= 4, else of degree N - 1, or ``degree``) over the normalised
        cumulative chord length, so ``t`` is close to the arc-length fraction.
        """
        from scipy.interpolate import make_interp_spline

        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise CurveError(f"points must have shape (N, 2), got {pts.shape}")
        bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
        if bad.size:
            raise CurveError(f"non-finite point(s) at row(s) {bad[:10].tolist()}")
        if len(pts) >= 2:
            step = np.linalg.norm(np.diff(pts, axis=0), axis=1)
            scale = max(float(np.ptp(pts, axis=0).max()), 1e-300)
            keep = np.concatenate([[True], step > 1e-12 * scale])
            pts = pts[keep]
        if len(pts) < 2:
            raise CurveError(f"a curve needs at least two distinct points, got {len(pts)}")
        chord = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        u = np.concatenate([[0.0], np.cumsum(chord)])
        u /= u[-1]
        k = min(3, len(pts) - 1) if degree is None else int(degree)
        if not 1 <= k <= len(pts) - 1:
            raise ParameterError(f"spline degree {degree!r} outside [1, {len(pts) - 1}]")
        spline = make_interp_spline(u, pts, k=k)

        def f(t):
            return spline(np.clip(_as_t(t), 0.0, 1.0))

        params = {"n_points": len(pts), "degree": k}
        if source:
            params["source"] = source
        return cls(f, name=name, kind="points", params=params)

    @classmethod
    def from_svg_path(cls, d: str, name: str = "svg", *, source: str = "") -> PlanarCurve:
        """Curve from the ``d`` attribute of an SVG path (y down in SVG -> z = -y).

        The path is parsed with ``svgelements`` and sampled densely (every segment, points in
        proportion to its length), then interpolated linearly in arc length; the origin is moved
        to the path's first point. One unit of ``d`` is 1 m (scale with :meth:`scaled`); a file
        with its units and transforms is read by
        :func:`~holofold.fitting.curve_files.read_svg_curve`.
        """
        try:
            from svgelements import Path as SvgPath

            path = SvgPath(d)
        except Exception as exc:
            raise CurveFormatError(f"cannot parse SVG path data {d[:60]!r}: {exc}") from exc
        curve = svg_path_curve(path, name, source or "svg path", 1.0)
        return cls(curve.func, name=name, kind="svg", params={"d": d[:200], **curve.params})

    def __getstate__(self) -> dict:
        """Pickled without the dense polyline and its KD-tree (recomputed on first use, ~1 ms)."""
        state = dict(self.__dict__)
        state.pop("_dense", None)
        state.pop("_tree", None)
        return state

    def __repr__(self) -> str:
        return f"PlanarCurve(name={self.name!r}, kind={self.kind!r}, params={self.params!r})"

    def scaled(self, factor: float) -> PlanarCurve:
        """The curve scaled about the origin by ``factor`` > 0 (e.g. SVG units -> metres)."""
        from holofold.geometry.errors import check_range

        k = check_range("scale", factor, 0.0, None, low_open=True)
        if k == 1.0:
            return self
        func = self.func
        return PlanarCurve(
            lambda t: k * func(t),
            name=self.name,
            kind=self.kind,
            params={**self.params, "scale": k},
            default_sampling=self.default_sampling,
        )

    # ------------------------------------------------------------------ evaluation
    def __call__(self, t) -> np.ndarray:
        """Points (n, 2) at parameters ``t`` (n,) in [0, 1]."""
        return np.asarray(self.func(_as_t(t)), dtype=float).reshape(-1, 2)

    def _check(self) -> None:
        t = np.linspace(0.0, 1.0, 1025)
        try:
            p = self(t)
        except CurveError:
            raise
        except Exception as exc:
            raise CurveError(f"curve {self.name!r} cannot be evaluated on [0, 1]: {exc}") from exc
        if p.shape != (len(t), 2):
            raise CurveError(f"curve {self.name!r} must return (n, 2) points, got {p.shape}")
        bad = np.flatnonzero(~np.isfinite(p).all(axis=1))
        if bad.size:
            raise CurveError(f"curve {self.name!r} is non-finite at t = {t[bad[0]]:.6g}")
        length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
        if not length > 0:
            raise CurveError(f"curve {self.name!r} has zero length")
        scale = float(np.ptp(p, axis=0).max())
        if scale <= 1e-12 * max(1.0, float(np.abs(p).max())):
            raise CurveError(f"curve {self.name!r} has fewer than two distinct points")
        if self.self_intersects():
            warnings.warn(
                f"curve {self.name!r} intersects itself; a strip fitted to it will overlap",
                UserWarning,
                stacklevel=3,
            )

    @cached_property
    def _dense(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, points, cumulative length) of a dense, nearly equal arc-length polyline."""
        t0 = np.linspace(0.0, 1.0, 4 * (_N_DENSE - 1) + 1)
        p0 = self(t0)
        s0 = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p0, axis=0), axis=1))])
        target = np.linspace(0.0, s0[-1], _N_DENSE)
        t = np.interp(target, s0, t0)
        t[0], t[-1] = 0.0, 1.0
        p = self(t)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        return t, p, s

    def self_intersects(self, n: int = 513) -> bool:
        """Whether the curve crosses itself (proper crossings of a polyline of ``n`` points).

        Touching without crossing is not reported.
        """
        p = self(np.linspace(0.0, 1.0, n))
        a, b = p[:-1], p[1:]
        i, j = np.triu_indices(len(a), 2)
        closed = np.linalg.norm(p[0] - p[-1]) <= 1e-12 * max(float(np.ptp(p, axis=0).max()), 1e-300)
        if closed:
            keep = ~((i == 0) & (j == len(a) - 1))
            i, j = i[keep], j[keep]

        def orient(u, v, w):
            return (v[:, 0] - u[:, 0]) * (w[:, 1] - u[:, 1]) - (v[:, 1] - u[:, 1]) * (
                w[:, 0] - u[:, 0]
            )

        hit = np.zeros(len(i), bool)
        for lo in range(0, len(i), 200_000):  # bounded memory
            ii, jj = i[lo : lo + 200_000], j[lo : lo + 200_000]
            d1, d2 = orient(a[jj], b[jj], a[ii]), orient(a[jj], b[jj], b[ii])
            d3, d4 = orient(a[ii], b[ii], a[jj]), orient(a[ii], b[ii], b[jj])
            hit[lo : lo + 200_000] = (d1 * d2 < 0) & (d3 * d4 < 0)
        return bool(hit.any())

    # ------------------------------------------------------------------ lengths
    @property
    def length(self) -> float:
        """Arc length, metres (dense polyline, relative error ~1e-8 for smooth curves)."""
        return float(self._dense[2][-1])

    def arc_length(self, t) -> np.ndarray:
        """Arc length from t = 0 to each ``t`` (n,), metres."""
        td, _, s = self._dense
        return np.interp(np.clip(_as_t(t), 0.0, 1.0), td, s)

    def parameter_at_length(self, s) -> np.ndarray:
        """Inverse of :meth:`arc_length`: parameters (n,) at arc lengths ``s`` (metres)."""
        td, _, sd = self._dense
        return np.interp(np.clip(_as_t(s), 0.0, sd[-1]), sd, td)

    def resample(self, n: int, by: str = "arclength") -> tuple[np.ndarray, np.ndarray]:
        """``n`` points from t = 0 to 1 spaced by equal ``"parameter"`` or ``"arclength"``.

        Returns
        -------
        t : (n,) parameters
        points : (n, 2)
        """
        n = int(n)
        if n < 2:
            raise ParameterError(f"resample needs n >= 2 points, got {n}")
        if by == "parameter":
            t = np.arange(n) / (n - 1)
        elif by == "arclength":
            t = self.parameter_at_length(np.linspace(0.0, self.length, n))
            t[0], t[-1] = 0.0, 1.0
        else:
            raise ParameterError(f"by must be 'parameter' or 'arclength', got {by!r}")
        return t, self(t)

    # ------------------------------------------------------------------ distances
    def closest_point(self, points) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest points on the curve to query ``points`` (n, 2).

        Returns
        -------
        distance : (n,) metres
        t : (n,) parameters of the closest points
        foot : (n, 2) the closest points
        """
        from scipy.spatial import cKDTree

        q = np.asarray(points, dtype=float).reshape(-1, 2)
        if not np.isfinite(q).all():
            raise CurveError("query points must be finite")
        td, pd, _ = self._dense
        tree = self._tree if "_tree" in self.__dict__ else None
        if tree is None:
            tree = cKDTree(pd)
            object.__setattr__(self, "_tree", tree)
        k = min(8, len(pd))
        _, idx = tree.query(q, k=k)
        idx = np.atleast_2d(idx).reshape(len(q), k)
        # candidate segments: (v-1, v) and (v, v+1) for each candidate vertex v
        seg = np.concatenate([idx - 1, idx], axis=1).clip(0, len(pd) - 2)
        a, b = pd[seg], pd[seg + 1]  # (n, 2k, 2)
        ab = b - a
        den = np.einsum("nkj,nkj->nk", ab, ab)
        lam = np.einsum("nkj,nkj->nk", q[:, None, :] - a, ab) / np.where(den > 0, den, 1.0)
        lam = lam.clip(0.0, 1.0)
        foot = a + lam[..., None] * ab
        d2 = np.einsum("nkj,nkj->nk", foot - q[:, None, :], foot - q[:, None, :])
        best = np.argmin(d2, axis=1)
        rows = np.arange(len(q))
        sb = seg[rows, best]
        t = td[sb] + lam[rows, best] * (td[sb + 1] - td[sb])
        t, foot, dist = self._refine(q, t)
        return dist, t, foot

    def _refine(self, q: np.ndarray, t: np.ndarray, steps: int = 4):
        """Newton steps on |c(t) - q|^2 (finite-difference derivatives); keeps improvements."""
        h = 1e-5
        c = self(t)
        d = np.linalg.norm(c - q, axis=1)
        for _ in range(steps):
            tp, tm = np.clip(t + h, 0, 1), np.clip(t - h, 0, 1)
            cp, cm = self(tp), self(tm)
            dt = (tp - tm)[:, None]
            d1 = (cp - cm) / np.where(dt > 0, dt, 1.0)
            d2 = (cp - 2 * c + cm) / h**2
            r = c - q
            g = np.einsum("ij,ij->i", r, d1)
            hess = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", r, d2)
            step = np.where(hess > 0, -g / np.where(hess > 0, hess, 1.0), 0.0)
            tn = np.clip(t + step, 0.0, 1.0)
            cn = self(tn)
            dn = np.linalg.norm(cn - q, axis=1)
            better = dn < d
            t = np.where(better, tn, t)
            c = np.where(better[:, None], cn, c)
            d = np.where(better, dn, d)
        return t, c, d

    def distance(self, points) -> np.ndarray:
        """Closest-point distance (n,) of ``points`` (n, 2) to the curve, metres."""
        return self.closest_point(points)[0]

    def polyline(self, n: int = 257) -> np.ndarray:
        """``n`` points equally spaced in arc length, (n, 2) (for plots)."""
        return self.resample(n, "arclength")[1]


# ---------------------------------------------------------------------- built-ins
def _positive(name: str, value: float) -> float:
    from holofold.geometry.errors import check_range

    return check_range(name, value, 0.0, None, low_open=True)


def _half_circle(radius: float = 2.0) -> PlanarCurve:
    R = _positive("radius", radius)

    def f(t):
        t = _as_t(t)
        return np.column_stack([R - R * np.cos(np.pi * t), R * np.sin(np.pi * t)])

    return PlanarCurve(
        f, name="half-circle", kind="builtin", params={"radius": R}, default_sampling="paper"
    )


def _arc(radius: float = 2.0, angle: float = 120.0) -> PlanarCurve:
    from holofold.geometry.errors import check_range

    R = _positive("radius", radius)
    a_deg = check_range("angle", angle, 0.0, 360.0, low_open=True, high_open=True)
    a = math.radians(a_deg)

    def f(t):
        th = a / 2 - a * _as_t(t)
        return np.column_stack(
            [R * math.sin(a / 2) - R * np.sin(th), R * np.cos(th) - R * math.cos(a / 2)]
        )

    return PlanarCurve(f, name="arc", kind="builtin", params={"radius": R, "angle": a_deg})


def _parabola(span: float = 4.0, height: float = 2.0) -> PlanarCurve:
    L = _positive("span", span)
    H = _positive("height", height)

    def f(t):
        t = _as_t(t)
        return np.column_stack([L * t, 4.0 * H * t * (1.0 - t)])

    return PlanarCurve(f, name="parabola", kind="builtin", params={"span": L, "height": H})


def _sine(span: float = 4.0, amplitude: float = 0.5, periods: float = 1.0) -> PlanarCurve:
    L = _positive("span", span)
    A = _positive("amplitude", amplitude)
    n = _positive("periods", periods)

    def f(t):
        t = _as_t(t)
        return np.column_stack([L * t, A * np.sin(2.0 * np.pi * n * t)])

    return PlanarCurve(
        f, name="sine", kind="builtin", params={"span": L, "amplitude": A, "periods": n}
    )


def _catenary(span: float = 4.0, height: float = 2.0) -> PlanarCurve:
    """Inverted catenary z = H - a (cosh((x - L/2)/a) - 1) through (0, 0), (L/2, H), (L, 0)."""
    from scipy.optimize import brentq

    L = _positive("span", span)
    H = _positive("height", height)

    def sag(a):  # a (cosh(L / 2a) - 1) - H, decreasing in a; evaluated in a stable form
        x = L / (2 * a)
        return a * (2.0 * math.sinh(x / 2) ** 2) - H if x < 700 else math.inf

    lo = L / 1400.0
    hi = max(L, L * L / H)
    while sag(hi) > 0:
        hi *= 4.0
    while not sag(lo) > 0:
        lo /= 2.0
    a = brentq(sag, lo, hi, xtol=1e-15 * L, rtol=4 * np.finfo(float).eps, maxiter=500)

    def f(t):
        x = L * _as_t(t)
        return np.column_stack([x, H - a * (np.cosh((x - L / 2) / a) - 1.0)])

    return PlanarCurve(f, name="catenary", kind="builtin", params={"span": L, "height": H, "a": a})


#: built-in curves: name -> (constructor, parameter names)
BUILTIN_CURVES: dict[str, tuple[Callable[..., PlanarCurve], tuple[str, ...]]] = {
    "half-circle": (_half_circle, ("radius",)),
    "arc": (_arc, ("radius", "angle")),
    "parabola": (_parabola, ("span", "height")),
    "sine": (_sine, ("span", "amplitude", "periods")),
    "catenary": (_catenary, ("span", "height")),
}


def builtin_curve(name: str, **params: float) -> PlanarCurve:
    """A built-in curve by name (see :data:`BUILTIN_CURVES`), metres / degrees."""
    key = name.strip().lower().replace("_", "-")
    if key == "halfcircle" or key == "semicircle":
        key = "half-circle"
    if key not in BUILTIN_CURVES:
        raise CurveFormatError(
            f"unknown curve {name!r}; built-ins: {', '.join(sorted(BUILTIN_CURVES))}"
        )
    ctor, names = BUILTIN_CURVES[key]
    unknown = sorted(set(params) - set(names))
    if unknown:
        raise CurveFormatError(
            f"curve {key!r} has no parameter {unknown[0]!r}; allowed: {', '.join(names)}"
        )
    return ctor(**params)


def parse_curve_spec(spec: str) -> PlanarCurve:
    """Parse ``"name:key=value,key=value"`` (e.g. ``"half-circle:radius=2"``)."""
    if not isinstance(spec, str) or not spec.strip():
        raise CurveFormatError(f"empty curve specification {spec!r}")
    name, _, rest = spec.strip().partition(":")
    params: dict[str, float] = {}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, val = item.partition("=")
        if not eq or not key.strip():
            raise CurveFormatError(f"curve parameter {item!r} in {spec!r} is not key=value")
        try:
            v = float(val)
        except ValueError:
            raise CurveFormatError(
                f"curve parameter {key.strip()}={val!r} in {spec!r} is not a number"
            ) from None
        params[key.strip().lower()] = v
    return builtin_curve(name, **params)


def svg_path_curve(path, name: str, source: str, scale: float) -> PlanarCurve:
    """The curve of an svgelements ``Path`` (one subpath), sampled densely (every segment,
    points in proportion to its length) and interpolated linearly in arc length; ``scale`` m
    per coordinate unit, y down in SVG -> z = -y, the origin at the path's first point."""
    from svgelements import Close, Move

    segs = [s for s in path if not isinstance(s, Move)]
    moves = sum(isinstance(s, Move) for s in path)
    if moves > 1:
        raise CurveFormatError(
            f"SVG path {name!r} has {moves} subpaths (M commands); a curve is one line: put "
            "the one to fit in a <path id=...> of its own and read it with file.svg#id"
        )
    if isinstance(segs[-1:] and segs[-1], Close) and segs[-1].length() == 0:
        segs = segs[:-1]
    if not segs:
        raise CurveFormatError(f"SVG path {name!r} has no segments")
    lengths = np.array([float(s.length()) for s in segs])
    if not np.isfinite(lengths).all() or lengths.sum() <= 0:
        raise CurveError(f"SVG path {name!r} has zero or non-finite length")
    n_seg = np.maximum(2, np.ceil(2048 * lengths / lengths.sum()).astype(int))
    pts = []
    for seg, n, ln in zip(segs, n_seg, lengths, strict=True):
        if ln <= 0:
            continue
        ts = np.linspace(0.0, 1.0, n + 1)[(1 if pts else 0) :]
        pts.append(np.asarray(seg.npoint(ts), float).reshape(-1, 2))
    xy = np.concatenate(pts) * scale
    xz = np.column_stack([xy[:, 0], -xy[:, 1]])
    xz -= xz[0]
    return PlanarCurve.from_points(xz, name=name, degree=1, source=source)
