"""The three electro-thermal gripper patterns of Zhu & Filipov (2022), flat, in metres.

Each generator takes the arm length ``L1``, arm width ``L2``, the tip-segment fraction ``rate``
and the gap ``range`` between the two arms' roots, and returns a :class:`GripperPattern`: the
flat :class:`~geometry.pattern.CreasePattern` plus the data the paper's scripts attach to it
(active creases, their bimorph signs and heated lengths). Vertex ids, face order and face vertex
order are exactly those of the reference scripts, so that the reference crease enumeration gives
the published crease numbers: ``pattern.edges[c - 1]`` is the scripts' crease ``c``. Ids are
0-based here (reference number - 1).

The scripts give each active (compliant, bimorph-coated) crease the sign of its layers'
thermal-expansion mismatch, but that sign is relative to the orientation of the reference
simulator's rotational springs, which that (2022) simulator did not normalise: a positive sign
folds crease c toward +z exactly when its raw spring orientation is the normalised one. The
physical fold direction is therefore ``fold_sign = alpha_sign * orientation``, where
``orientation`` is -1 when the raw spring ``[N11, c, p1, N21]`` of the compliant mesh (N11: the
earlier panel's copy of the crease end listed first in that panel) has a positive z component of
``(x_j - x_i) x (x_k - x_j)``. Active creases carry assignment ``V`` where they fold toward +z
when heated and ``M`` where they fold toward -z; all fold angles are 0 (flat).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from holofold.geometry.errors import ParameterError, check_range
from holofold.geometry.pattern import CreasePattern

__all__ = [
    "GripperPattern",
    "miura_based_gripper",
    "splitted_miura_gripper",
    "two_panel_gripper",
    "gripper_pattern",
    "DEFAULT_RANGE",
    "GRIPPER_NAMES",
]

#: default gap between the arm roots ("range"), metres, per pattern 1/2/3
DEFAULT_RANGE = {1: 2e-3, 2: 1e-3, 3: 2e-3}
GRIPPER_NAMES = {1: "miura-based", 2: "splitted-miura", 3: "two-panel"}


@dataclass(frozen=True, eq=False)
class GripperPattern:
    """A flat gripper pattern and what the reference scripts attach to it.

    Attributes
    ----------
    pattern : CreasePattern
        The flat pattern (z = 0), numbered as in the reference scripts.
    kind : int
        1 Miura-based, 2 splitted Miura, 3 two-panel.
    L1, L2 : float
        Arm length and arm width, m.
    rate : float
        Tip-segment fraction of ``L1``.
    range : float
        Gap between the two arms' roots, m.
    active : (na,) int
        Edge ids of the compliant (bimorph) creases, increasing.
    alpha_sign : (na,) float
        +1 / -1: the scripts' expansion-mismatch sign (raw spring orientation).
    fold_sign : (na,) float
        +1 / -1: the physical fold direction (+1 toward +z).
    heat_length : (na,) float
        Length of each active crease as the scripts multiply it by the heating rate, m.
    """

    pattern: CreasePattern
    kind: int
    L1: float
    L2: float
    rate: float
    range: float
    active: np.ndarray
    alpha_sign: np.ndarray
    fold_sign: np.ndarray
    heat_length: np.ndarray

    @property
    def name(self) -> str:
        """``miura-based``, ``splitted-miura`` or ``two-panel``."""
        return GRIPPER_NAMES[self.kind]


def _check(L1, L2, rate, range_):
    L1 = check_range("L1", L1, 0.0, None, low_open=True)
    L2 = check_range("L2", L2, 0.0, None, low_open=True)
    rate = check_range("rate", rate, 0.0, 1.0, low_open=True, high_open=True)
    range_ = check_range("range", range_, 0.0, None, low_open=True)
    return L1, L2, rate, range_


def _raw_orientation(pat: CreasePattern, creases: np.ndarray) -> np.ndarray:
    """+1 / -1 per crease: orientation of the reference's raw compliant-crease springs.

    The raw centre spring is ``[N11, c, p1, N21]``. N11 is the earlier panel's copy of the
    crease end ``a`` that comes first in that panel's vertex list (the perimeter bar's smaller
    meshed node id), c lies on the crease's centre line and p1 at its ``a`` end. With ``t``
    the unit vector from ``a`` to the other end ``b`` and ``n`` the in-plane normal pointing
    from the earlier panel across the crease, the z component of ``(c - N11) x (p1 - c)`` has
    the sign of ``-(n x t)_z``; -1 is returned where it is positive (reversed orientation).
    """
    xy = pat.flat
    out = np.ones(len(creases))
    for k, e in enumerate(creases):
        u, v = pat.edges[e]
        first = next(f for f in pat.faces if u in f and v in f)
        pos = {int(w): i for i, w in enumerate(first)}
        a, b = (u, v) if pos[int(u)] < pos[int(v)] else (v, u)
        t = xy[b] - xy[a]
        n = np.array([-t[1], t[0]])  # a normal; orient it away from the earlier panel
        if n @ (xy[first].mean(axis=0) - xy[a]) > 0:
            n = -n
        z = -(n[0] * t[1] - n[1] * t[0])
        out[k] = -1.0 if z > 0 else 1.0
    return out


def _build(kind, coords2d, faces1, active1, signs, heat_length, L1, L2, rate, r):
    coords2d = np.asarray(coords2d, float)
    faces = [np.asarray(f, np.int64) - 1 for f in faces1]
    pat = CreasePattern.from_faces(
        np.column_stack([coords2d, np.zeros(len(coords2d))]), faces, flat=coords2d
    )
    active = np.asarray(active1, np.int64) - 1
    interior = pat.interior
    if not interior[active].all():
        bad = active[~interior[active]]
        raise ParameterError(f"active creases {(bad + 1).tolist()} are not interior edges")
    asg = np.where(interior, "F", "B").astype("<U1")
    signs = np.asarray(signs, float)
    fold = signs * _raw_orientation(pat, active)
    asg[active] = np.where(fold > 0, "V", "M")
    flat = CreasePattern(
        pat.coords,
        pat.faces,
        pat.edges,
        asg,
        np.zeros(len(pat.edges)),
        flat=coords2d,
        meta={"kind": f"{GRIPPER_NAMES[kind]} gripper"},
    )
    return GripperPattern(
        pattern=flat,
        kind=kind,
        L1=L1,
        L2=L2,
        rate=rate,
        range=r,
        active=active,
        alpha_sign=signs,
        fold_sign=fold,
        heat_length=np.asarray(heat_length, float),
    )


def miura_based_gripper(L1: float, L2: float, rate: float, range_: float = 2e-3) -> GripperPattern:
    """Pattern 1, the Miura-based gripper (12 vertices, 10 panels, 21 edges, 13 active creases).

    Arms along +-x. Requires ``(1 - rate) L1 > L2 / 2`` (the arm's root fold line must lie
    outside the base diamond).
    """
    L1, L2, rate, r = _check(L1, L2, rate, range_)
    if (1 - rate) * L1 - L2 / 2 <= 0:
        raise ParameterError(
            f"Miura-based gripper needs (1 - rate) L1 > L2/2; got rate = {rate!r}, "
            f"L1 = {L1!r}, L2 = {L2!r} (allowed: rate < 1 - L2/(2 L1) = {1 - L2 / (2 * L1):.6g})"
        )
    X1 = r / 2 + (1 - rate) * L1
    h = L2 / 2
    xy = [
        (-r / 2, 0), (r / 2, 0), (0, -h), (0, h),
        (X1, -h), (X1 - h, 0), (X1, h), (r / 2 + L1, 0),
        (-X1, -h), (-(X1 - h), 0), (-X1, h), (-(r / 2 + L1), 0),
    ]  # fmt: skip
    faces = [
        [1, 3, 2], [1, 2, 4], [2, 3, 5, 6], [2, 6, 7, 4], [5, 8, 6], [6, 8, 7],
        [1, 10, 9, 3], [10, 1, 4, 11], [12, 9, 10], [12, 10, 11],
    ]  # fmt: skip
    active = [1, 2, 3, 4, 5, 6, 8, 9, 12, 14, 15, 17, 19]
    minus = {4, 6, 12, 17}
    signs = [-1.0 if c in minus else 1.0 for c in active]
    diag = 0.5 * math.hypot(r, L2)
    arm_root = (1 - rate) * L1 - L2 / 2
    tip = rate * L1 + L2 / 2
    sq = math.sqrt(2) * L2 / 2
    lengths = {1: r, 2: diag, 3: diag, 4: diag, 5: diag, 6: arm_root, 14: arm_root,
               8: sq, 9: sq, 15: sq, 17: sq, 12: tip, 19: tip}  # fmt: skip
    return _build(1, xy, faces, active, signs, [lengths[c] for c in active], L1, L2, rate, r)


def splitted_miura_gripper(
    L1: float, L2: float, rate: float, range_: float = 1e-3
) -> GripperPattern:
    """Pattern 2, the splitted-Miura gripper (24 vertices, 15 panels, 22 active creases).

    Arms along +-y. Requires ``(1 - rate) L1 > L2 / 2``.
    """
    L1, L2, rate, r = _check(L1, L2, rate, range_)
    if (1 - rate) * L1 - L2 / 2 <= 0:
        raise ParameterError(
            f"splitted-Miura gripper needs (1 - rate) L1 > L2/2; got rate = {rate!r}, "
            f"L1 = {L1!r}, L2 = {L2!r}"
        )
    q, h = L2 / 4, L2 / 2
    Y1 = r / 2 + (1 - rate) * L1
    Y2 = r / 2 + L1
    up = [
        (-h, Y1 - q), (-q, Y1), (q, Y1), (h, Y1 - q),
        (-h, Y2 - q), (-q, Y2), (q, Y2), (h, Y2 - q),
    ]  # fmt: skip
    xy = [
        (-q, -r / 2), (q, -r / 2), (q, r / 2), (-q, r / 2),
        (-h, -r / 2 - q), (h, -r / 2 - q), (h, r / 2 + q), (-h, r / 2 + q),
        *up,
        *[(x, -y) for x, y in up],
    ]  # fmt: skip
    faces = [
        [1, 2, 3, 4], [5, 1, 4, 8], [2, 6, 7, 3], [3, 7, 12, 11], [4, 3, 11, 10], [8, 4, 10, 9],
        [9, 10, 14, 13], [10, 11, 15, 14], [11, 12, 16, 15], [5, 17, 18, 1], [18, 19, 2, 1],
        [19, 20, 6, 2], [21, 22, 18, 17], [22, 23, 19, 18], [23, 24, 20, 19],
    ]  # fmt: skip
    active = [1, 2, 3, 4, 6, 7, 8, 10, 11, 13, 14, 15, 17, 19, 21, 26, 27, 28, 29, 30, 34, 36]
    signs = [-1.0 if c in (27, 29) else 1.0 for c in active]
    s2 = math.sqrt(2) * L2 / 4
    lengths = {1: r, 3: r, 2: h, 4: h, 15: h, 28: h}
    lengths.update({c: s2 for c in (6, 7, 8, 10, 13, 17, 26, 30)})
    lengths.update({c: (1 - rate) * L1 for c in (11, 14, 27, 29)})
    lengths.update({c: rate * L1 for c in (19, 21, 34, 36)})
    return _build(2, xy, faces, active, signs, [lengths[c] for c in active], L1, L2, rate, r)


def two_panel_gripper(L1: float, L2: float, rate: float, range_: float = 2e-3) -> GripperPattern:
    """Pattern 3, the two-panel gripper (12 vertices, 5 panels, 4 active creases).

    Arms along +-y, each of a root panel and a tip panel.
    """
    L1, L2, rate, r = _check(L1, L2, rate, range_)
    a = r / 2 + (1 - rate) * L1
    b = r / 2 + L1
    xy = [
        (0, -r / 2), (L2, -r / 2), (0, r / 2), (L2, r / 2),
        (0, a), (L2, a), (0, b), (L2, b),
        (0, -a), (L2, -a), (0, -b), (L2, -b),
    ]  # fmt: skip
    faces = [[1, 2, 4, 3], [3, 4, 6, 5], [5, 6, 8, 7], [9, 10, 2, 1], [11, 12, 10, 9]]
    active = [2, 4, 7, 12]
    return _build(3, xy, faces, active, [1.0] * 4, [L2] * 4, L1, L2, rate, r)


_GENERATORS = {1: miura_based_gripper, 2: splitted_miura_gripper, 3: two_panel_gripper}


def gripper_pattern(
    pattern: int, L1: float, L2: float, rate: float, range_: float | None = None
) -> GripperPattern:
    """Pattern ``pattern`` (1, 2 or 3) with its default ``range`` unless one is given."""
    try:
        p = int(pattern)
    except (TypeError, ValueError):
        raise ParameterError(f"gripper pattern must be 1, 2 or 3, got {pattern!r}") from None
    if p not in _GENERATORS or p != pattern:
        raise ParameterError(f"gripper pattern must be 1, 2 or 3, got {pattern!r}")
    r = DEFAULT_RANGE[p] if range_ is None else range_
    return _GENERATORS[p](L1, L2, rate, r)
