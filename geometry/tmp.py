"""Tachi-Miura polyhedron (TMP) sheets folded rigidly to an extension ratio.

The geometry is the reference simulator's TMP sheet (docs/scenarios.md §3.1) for an L x L sheet
with m strips along x (m even) and n panels along y (n a multiple of 3); a = L/n, b = L/m::

    delta = b sqrt(1 - ext^2),  theta = atan(2 delta / a)
    z_s = a sin(2 theta),  y_s = a cos(2 theta),  p = a + 2 y_s

Nodes lie in columns at constant x: A_0, B_0, A_1, B_1, ..., A_{m/2} (0-based here), A_i at
x = 2 i b ext with n + 1 nodes, B_i at x = (2 i + 1) b ext with n nodes. Block i (of 2n + 1 ids,
starting at i (2n + 1)) holds A_i then B_i; the last A column follows. Within a column, group
g = 0..n/3-1 (y0 = g p) holds rows r = 3g, 3g+1, 3g+2::

    A: (y0, z_s + delta), (y0 + y_s, delta), (y0 + a + y_s, delta)
    A closing row n: (p n/3, z_s + delta)
    B: (y0 + a/2, z_s), (y0 + a/2 + y_s, 0), (y0 + a/2 + 2 y_s, z_s)

At ext = 1 (delta = theta = 0) this is the flat sheet: A columns at y = 0, a, ..., L and B columns
offset by a/2, which is also the pattern's ``flat`` layout (every panel counter-clockwise there).
Panels: per block, the left strip (A_i-B_i) then the right strip (B_i-A_{i+1}), quads and
triangles in the reference order (:func:`tmp_faces`).

When 2 b sqrt(1 - ext^2) > a the fold angle 2 theta passes 90 degrees (y_s < 0) and the folded
sheet overlaps itself; like the reference generator this module still returns that geometry
(it logs a warning). The published sheets (m >= 24, n <= 12) never reach it.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.miura import check_count, rigid_fold_pattern
from holofold.geometry.pattern import CreasePattern

__all__ = ["tmp_sheet", "tmp_nodes", "tmp_faces", "tmp_node_count"]

logger = logging.getLogger(__name__)

_EXT_REFERENCE = 0.5


def tmp_node_count(m: int, n: int) -> int:
    """Number of nodes, (m/2)(2n + 1) + n + 1."""
    return (m // 2) * (2 * n + 1) + n + 1


def _column_ids(m: int, n: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """0-based ids of the A columns (m/2 + 1 of them, n + 1 rows) and B columns (m/2, n rows)."""
    blk = 2 * n + 1
    A = [i * blk + np.arange(n + 1) for i in range(m // 2 + 1)]
    B = [i * blk + n + 1 + np.arange(n) for i in range(m // 2)]
    return A, B


def tmp_nodes(m: int, n: int, L: float, ext: float, L_y: float | None = None) -> np.ndarray:
    """Node coordinates of the folded TMP sheet, (tmp_node_count(m, n), 3), metres.

    ``L`` is the sheet's size along x and, unless ``L_y`` is given, along y (the paper's
    square). No validation (see :func:`tmp_sheet`).
    """
    a, b = (L if L_y is None else L_y) / n, L / m
    delta = b * math.sqrt(1.0 - ext**2)
    theta = math.atan(2.0 * delta / a)
    zs, ys = a * math.sin(2.0 * theta), a * math.cos(2.0 * theta)
    p = a + 2.0 * ys
    y0 = p * np.arange(n // 3)
    ones = np.ones(n // 3)
    # A column: rows 3g, 3g+1, 3g+2 then the closing row n (p n/3, summed as the reference does)
    ya = np.append(np.column_stack([y0, ys + y0, (a + ys) + y0]).ravel(), p + p * (n // 3 - 1))
    za = np.append(
        np.column_stack([(zs + delta) * ones, delta * ones, delta * ones]).ravel(), zs + delta
    )
    yb = np.column_stack([a / 2 + y0, (a / 2 + ys) + y0, (a / 2 + 2 * ys) + y0]).ravel()
    zb = np.column_stack([zs * ones, 0.0 * ones, zs * ones]).ravel()
    coords = np.zeros((tmp_node_count(m, n), 3))
    A, B = _column_ids(m, n)
    for i, ids in enumerate(A):
        coords[ids] = np.column_stack([np.full(n + 1, b * ext * (2 * i)), ya, za])
    for i, ids in enumerate(B):
        coords[ids] = np.column_stack([np.full(n, b * ext * (2 * i) + b * ext), yb, zb])
    return coords


def tmp_faces(m: int, n: int) -> list[np.ndarray]:
    """Panels in the reference order: 2(4K + 3) per block with K = n/3 - 1, 0-based ids."""
    A_cols, B_cols = _column_ids(m, n)
    K = n // 3 - 1
    faces: list[list[int]] = []
    for i in range(m // 2):
        A, B, A2 = A_cols[i], B_cols[i], A_cols[i + 1]
        # the spec's 1-based A(r) is A[r - 1] here; s = 3(j - 1) for j = 1..K
        for s in range(0, 3 * K, 3):
            faces += [
                [A[s], B[s], B[s + 1], A[s + 1]],
                [A[s + 1], B[s + 1], A[s + 2]],
                [A[s + 2], B[s + 1], B[s + 2], A[s + 3]],
                [A[s + 3], B[s + 2], B[s + 3]],
            ]
        faces += [
            [A[n - 3], B[n - 3], B[n - 2], A[n - 2]],
            [A[n - 2], B[n - 2], A[n - 1]],
            [A[n - 1], B[n - 2], B[n - 1], A[n]],
        ]
        for s in range(0, 3 * K, 3):
            faces += [
                [B[s], A2[s], A2[s + 1], B[s + 1]],
                [B[s + 1], A2[s + 1], A2[s + 2]],
                [B[s + 1], A2[s + 2], A2[s + 3], B[s + 2]],
                [B[s + 2], A2[s + 3], B[s + 3]],
            ]
        faces += [
            [B[n - 3], A2[n - 3], A2[n - 2], B[n - 2]],
            [B[n - 2], A2[n - 2], A2[n - 1]],
            [B[n - 2], A2[n - 1], A2[n], B[n - 1]],
        ]
    return [np.array(f, dtype=np.int64) for f in faces]


def tmp_sheet(m: int, n: int, L: float, ext: float) -> CreasePattern:
    """Rigidly folded Tachi-Miura polyhedron sheet (docs/scenarios.md §3.1).

    Parameters
    ----------
    m : int
        Strips along x; even, >= 2.
    n : int
        Panels along y; a positive multiple of 3.
    L : float
        Flat sheet size (L x L), metres, > 0.
    ext : float
        Extension ratio in (0, 1]: the x-extent is L ext; 1 is flat.

    Returns
    -------
    CreasePattern
        ``coords`` (nv, 3) folded state, ``flat`` (nv, 2) the ext = 1 layout, M/V assignment from
        the folded mechanism even when ``ext = 1``; ``meta`` holds kind="tmp", m, n, L, a, b, ext,
        delta, theta.
    """
    m = check_count("m", m, 2)
    n = check_count("n", n, 3)
    if m % 2:
        raise ParameterError(f"m = {m} must be even for a TMP sheet (allowed: 2, 4, 6, ...)")
    if n % 3:
        raise ParameterError(
            f"n = {n} must be a multiple of 3 for a TMP sheet (allowed: 3, 6, 9, ...)"
        )
    L = check_range("L", L, 0.0, None, low_open=True)
    ext = check_range("ext", ext, 0.0, 1.0, low_open=True)
    a, b = L / n, L / m
    delta = b * math.sqrt(1.0 - ext * ext)
    meta = {
        "kind": "tmp",
        "m": m,
        "n": n,
        "L": L,
        "a": a,
        "b": b,
        "ext": ext,
        "delta": delta,
        "theta": math.atan(2.0 * delta / a),
    }
    if 2.0 * delta > a:
        logger.warning(
            "TMP sheet m=%d, n=%d at ext=%g: 2 b sqrt(1 - ext^2) > a, the folded tubes overlap "
            "(y_s < 0); the geometry follows the reference formulas regardless",
            m,
            n,
            ext,
        )
    coords = tmp_nodes(m, n, L, ext)
    flat = tmp_nodes(m, n, L, 1.0)[:, :2]
    ref = tmp_nodes(m, n, L, _EXT_REFERENCE)
    return rigid_fold_pattern(coords, tmp_faces(m, n), flat, ref, meta)
