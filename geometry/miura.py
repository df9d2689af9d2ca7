"""Miura-ori crease patterns folded rigidly to an extension ratio.

The geometry is the reference simulator's Miura sheet (docs/scenarios.md §2.1): an m x n grid
of parallelogram panels with sides ``a`` (along y) and ``b`` and sector angle ``gamma``, folded
so that the projected x-step ``b sin(theta)`` is ``ext`` times the flat one::

    theta = asin(ext sin(gamma)),  beta = acos(cos(gamma) / cos(theta))
    node (i, j), i = 0..m (x), j = 0..n (y), id = i (n + 1) + j
    x = i b sin(theta)
    y = j a cos(beta) + (b cos(theta) if i is odd else 0)
    z = a sin(beta) if j is odd else 0
    panel (i, j), id = i n + j: [id(i, j), id(i+1, j), id(i+1, j+1), id(i, j+1)]

(0-based; the spec's 1-based "i even" is "i odd" here.) ``ext = 1`` is the flat sheet, which is
also the pattern's ``flat`` layout, where every panel is counter-clockwise.

All angles are in radians (the CLI converts degrees); lengths in metres.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import CreasePattern, measure_fold_angles, reference_edges

__all__ = [
    "miura_cell",
    "miura_sheet",
    "miura_sheet_paper",
    "miura_nodes",
    "miura_nodes_batch",
    "miura_faces",
]

#: extension ratio at which the M/V assignment of a (possibly flat) pattern is read off
_EXT_REFERENCE = 0.5
#: fold angles below this (degrees) count as flat
_FLAT_TOL_DEG = 1e-9


def check_count(name: str, value, low: int = 1) -> int:
    """Return ``int(value)`` or raise :class:`ParameterError` unless it is an integer >= low."""
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be an integer >= {low}, got {value!r}")
    if isinstance(value, numbers.Integral):
        v = int(value)
    else:
        try:
            f = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"{name} must be an integer >= {low}, got {value!r}") from None
        if not math.isfinite(f) or not f.is_integer():
            raise ParameterError(f"{name} must be an integer >= {low}, got {value!r}")
        v = int(f)
    if v < low:
        raise ParameterError(f"{name} = {value!r} is outside the allowed range: integer >= {low}")
    return v


def _check_gamma(gamma) -> float:
    try:
        return check_range("gamma", gamma, 0.0, math.pi / 2, low_open=True, high_open=True)
    except ParameterError as err:
        raise ParameterError(f"{err} (gamma is the sector angle in radians)") from None


def _check_ext(ext) -> float:
    return check_range("ext", ext, 0.0, 1.0, low_open=True)


def rigid_fold_pattern(
    coords: np.ndarray,
    faces: list[np.ndarray],
    flat: np.ndarray,
    reference_coords: np.ndarray,
    meta: dict,
) -> CreasePattern:
    """Pattern in state ``coords`` with M/V read from a folded ``reference_coords`` state.

    The fold angles are measured from ``coords``; their sign is the sign measured in
    ``reference_coords`` (a state of the same rigid mechanism with ext < 1), so a flat or nearly
    flat state keeps its mountain/valley assignment. Border edges are ``B``; interior creases
    that do not fold in the reference state are ``F``.
    """
    edges, n_faces = reference_edges(faces)
    interior = n_faces == 2
    ref = measure_fold_angles(reference_coords, faces, edges)
    sign = np.where(interior & (np.abs(ref) > _FLAT_TOL_DEG), np.sign(ref), 0.0)
    now = np.abs(measure_fold_angles(coords, faces, edges))
    now = np.where(now <= _FLAT_TOL_DEG, 0.0, now)
    fold_angle = sign * now + 0.0  # + 0.0 turns -0.0 into 0.0
    assignment = np.where(~interior, "B", np.where(sign > 0, "V", np.where(sign < 0, "M", "F")))
    return CreasePattern.from_faces(
        coords, faces, flat=flat, assignment=assignment, fold_angle=fold_angle, meta=meta
    )


def miura_nodes(m: int, n: int, a: float, b: float, gamma: float, ext: float) -> np.ndarray:
    """Node coordinates of the folded Miura sheet, (m+1)(n+1) x 3, metres (no validation)."""
    return miura_nodes_batch(m, n, [a], [b], [gamma], [ext])[0]


def miura_nodes_batch(m: int, n: int, a, b, gamma, ext) -> np.ndarray:
    """:func:`miura_nodes` of S sheets of one m x n: ``a``, ``b``, ``gamma``, ``ext`` (S,)
    each; (S, (m+1)(n+1), 3) metres, each sheet's bit for bit :func:`miura_nodes` (no
    validation)."""
    cx, cy, sh, cz = [], [], [], []
    for a_, b_, g_, e_ in zip(a, b, gamma, ext, strict=True):
        a_, b_, g_, e_ = float(a_), float(b_), float(g_), float(e_)
        theta = math.asin(e_ * math.sin(g_))
        # clip: at ext = 1 rounding can push the ratio a hair above 1
        beta = math.acos(min(1.0, max(-1.0, math.cos(g_) / math.cos(theta))))
        cx.append(b_ * math.sin(theta))
        cy.append(a_ * math.cos(beta))
        sh.append(b_ * math.cos(theta))
        cz.append(a_ * math.sin(beta))
    col = lambda v: np.array(v, float)[:, None]  # noqa: E731
    cx, cy, sh, cz = map(col, (cx, cy, sh, cz))
    i, j = np.meshgrid(np.arange(m + 1), np.arange(n + 1), indexing="ij")
    i, j = i.ravel(), j.ravel()  # id = i (n + 1) + j
    x = i * cx
    y = j * cy + np.where(i % 2 == 1, sh, 0.0)
    z = np.where(j % 2 == 1, cz, 0.0)
    return np.stack([x, y, z], axis=-1)


def miura_faces(m: int, n: int) -> list[np.ndarray]:
    """Panels of the m x n sheet in reference order (i outer, j inner), 0-based quads."""
    i, j = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    i, j = i.ravel(), j.ravel()
    k = n + 1
    quads = np.column_stack([i * k + j, (i + 1) * k + j, (i + 1) * k + j + 1, i * k + j + 1])
    return list(quads)


def miura_sheet(
    m: int,
    n: int,
    a: float | None = None,
    b: float | None = None,
    gamma: float | None = None,
    ext: float | None = None,
    *,
    size: float | None = None,
) -> CreasePattern:
    """Rigidly folded m x n Miura-ori sheet (docs/scenarios.md §2.1).

    Parameters
    ----------
    m, n : int
        Panels along x (zig-zag direction) and along y; both >= 1.
    a, b : float
        Panel sides, metres (> 0): ``a`` along y, ``b`` the zig-zag side. Give both, or neither
        together with ``size``.
    gamma : float
        Sector angle, radians, in (0, pi/2).
    ext : float
        Extension ratio in (0, 1]: projected x-length over the flat x-length; 1 is flat.
    size : float, optional
        Sheet size L (metres): use the paper's parametrisation b = L/m,
        a = (L - b cot(gamma))/n instead of ``a`` and ``b``.

    Returns
    -------
    CreasePattern
        ``coords`` (nv, 3) folded state, ``flat`` (nv, 2) the ext = 1 layout, M/V assignment from
        the folded mechanism even when ``ext = 1``; ``meta`` holds kind="miura", m, n, a, b,
        gamma, ext, theta, beta (and size when given).
    """
    m = check_count("m", m)
    n = check_count("n", n)
    if gamma is None:
        raise ParameterError("gamma (sector angle, radians in (0, pi/2)) is required")
    if ext is None:
        raise ParameterError("ext (extension ratio in (0, 1]) is required")
    gamma = _check_gamma(gamma)
    ext = _check_ext(ext)
    meta_extra = {}
    if size is not None:
        if a is not None or b is not None:
            raise ParameterError("give either size or (a, b), not both")
        L = check_range("size", size, 0.0, None, low_open=True)
        b = L / m
        a = (L - b / math.tan(gamma)) / n
        if not a > 0.0:
            raise ParameterError(
                f"a = (L - b cot(gamma))/n = {a:.6g} <= 0 for m = {m}, gamma = {gamma!r} rad: "
                "the paper's parametrisation needs m tan(gamma) > 1"
            )
        meta_extra["size"] = L
    else:
        if a is None or b is None:
            raise ParameterError("give both panel sides a and b (metres), or size")
        a = check_range("a", a, 0.0, None, low_open=True)
        b = check_range("b", b, 0.0, None, low_open=True)
    coords = miura_nodes(m, n, a, b, gamma, ext)
    flat = miura_nodes(m, n, a, b, gamma, 1.0)[:, :2]
    ref = miura_nodes(m, n, a, b, gamma, _EXT_REFERENCE)
    theta = math.asin(ext * math.sin(gamma))
    beta = math.acos(min(1.0, max(-1.0, math.cos(gamma) / math.cos(theta))))
    meta = {
        "kind": "miura",
        "m": m,
        "n": n,
        "a": a,
        "b": b,
        "gamma": gamma,
        "ext": ext,
        "theta": theta,
        "beta": beta,
        **meta_extra,
    }
    return rigid_fold_pattern(coords, miura_faces(m, n), flat, ref, meta)


def miura_cell(a: float, b: float, gamma: float, ext: float) -> CreasePattern:
    """Single Miura-ori unit cell: the 2 x 2 sheet (9 nodes, 4 panels, 4 interior creases).

    Same conventions as :func:`miura_sheet` (radians, metres).
    """
    return miura_sheet(2, 2, a, b, gamma, ext)


def miura_sheet_paper(m: int, n: int, L: float, gamma: float, ext: float) -> CreasePattern:
    """Miura sheet in the paper's parametrisation: b = L/m, a = (L - b cot(gamma))/n.

    The ``cot`` is the reference generator's (the published data depend on it). Requires
    m tan(gamma) > 1 so that a > 0. Radians, metres.
    """
    L = check_range("L", L, 0.0, None, low_open=True)
    return miura_sheet(m, n, gamma=gamma, ext=ext, size=L)
