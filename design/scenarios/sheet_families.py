"""The patterns a sheet scenario can be made of, behind one protocol: Miura-ori and TMP.

The sheet kind (:mod:`~holofold.design.scenarios.sheet`) asks a :class:`SheetFamily` everything
that depends on the pattern, instead of branching on it: its topology (from the geometry
family's ``faces``), the vertex coordinates of a design folded to an extension over the sheet's
footprint, whether it has a sector angle, its checks (of one design, of a file's fixed setting
and of a file's feature levels) and its folded shape with flat layout. The node sets of every
sheet are the same: the vertices at x = min are held, those at x = max loaded.

Families are found by the ``pattern`` feature's code (1 Miura-ori, 2 TMP, as the published
databases have it) in :data:`SHEET_FAMILIES`; :func:`register_sheet_family` adds one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from holofold.geometry import Registry
from holofold.geometry.families import get_family

__all__ = [
    "SheetFamily",
    "SHEET_FAMILIES",
    "MIURA_SHEET",
    "TMP_SHEET",
    "register_sheet_family",
    "sheet_family",
]


@dataclass(frozen=True)
class SheetFamily:
    """One pattern of sheet scenarios.

    Attributes
    ----------
    code : int
        Value of the ``pattern`` feature.
    name : str
        Name in scenario files (``[sheet] pattern = "miura"``) and of its geometry family.
    label : str
        For reports.
    has_gamma : bool
        Whether a design has a sector angle (the ``gama`` feature).
    nodes : callable(setting, m, n, gamma, ext) -> (nv, 3)
        Vertex coordinates of a design over the setting's footprint, m.
    nodes_batch : callable(setting, m, n, gammas, exts) -> (S, nv, 3)
        The same for S designs of one m, n (bit for bit ``nodes``).
    topology_nodes : callable(m, n) -> (nv, 3)
        Any folded state of the topology (its coordinates are replaced per design).
    check : callable(setting, d, ok_m, ok_n, gamma) -> list of str
        Problems of one design (``d`` its pattern, m, n).
    check_setting : callable(sheet) -> str or None
        Problem of a file's fixed ``[sheet]`` setting for this pattern.
    check_levels : callable(sheet, counts, where, gammas) -> str or None
        Problem of a file's feature levels for this pattern.
    shape : callable(setting, m, n, gamma, ext) -> CreasePattern
        The folded sheet with its flat layout and assignments.
    """

    code: int
    name: str
    label: str
    has_gamma: bool
    nodes: Callable
    nodes_batch: Callable
    topology_nodes: Callable
    check: Callable
    check_setting: Callable
    check_levels: Callable
    shape: Callable

    def faces(self, m: int, n: int):
        """The topology: the geometry family's faces."""
        return get_family(self.name).faces({"m": m, "n": n})


# ------------------------------------------------------------------ Miura-ori
def miura_sides(setting, m: int, n: int, gamma: float) -> tuple[float, float]:
    """Panel sides (a, b) of a Miura sheet over the footprint: b = size_x/m,
    a = (size_y - b cot gamma)/n, m."""
    b = setting.size_x / m
    return (setting.size_y - b / math.tan(gamma)) / n, b


def _miura_nodes(setting, m, n, gamma, ext):
    from holofold.geometry.miura import miura_nodes

    a, b = miura_sides(setting, m, n, gamma)
    return miura_nodes(m, n, a, b, gamma, ext)


def _miura_nodes_batch(setting, m, n, gammas, exts):
    from holofold.geometry.miura import miura_nodes_batch

    sides = [miura_sides(setting, m, n, g) for g in gammas]
    return miura_nodes_batch(m, n, [a for a, _ in sides], [b for _, b in sides], gammas, exts)


def _miura_topology(m, n):
    from holofold.geometry.miura import miura_nodes

    return miura_nodes(m, n, 1.0, 1.0, 1.0, 0.5)


def _miura_check(setting, d, ok_m, ok_n, g):
    if g is None or not math.isfinite(g) or not 0 < g < math.pi / 2:
        return [f"gama = {g!r} rad must lie in (0, pi/2)"]
    if ok_m and ok_n and not miura_sides(setting, int(d["m"]), int(d["n"]), g)[0] > 0:
        return [
            f"m = {d['m']:g} is too small for the Miura sheet with gamma = {g:.6g} rad: "
            f"a = (size_y - b cot gamma)/n must be > 0 (m tan(gamma) > size_x/size_y)"
        ]
    return []


def _miura_levels(sheet, counts, where, gammas):
    if not all(0 < g < math.pi / 2 for g in gammas):
        return f"[features] gama = {gammas} rad must lie in (0, pi/2)"
    m, g = min(counts["m"]), min(gammas)
    if not sheet["size_y"] * m * math.tan(g) > sheet["size_x"]:
        return (
            f"{where['m']} = {m:g} with the sector angle {math.degrees(g):.6g} deg gives Miura "
            f"panels of side a <= 0; allowed: m tan(gamma) > size_x/size_y = "
            f"{sheet['size_x'] / sheet['size_y']:.6g}"
        )
    return None


def _miura_shape(setting, m, n, gamma, ext):
    from holofold.geometry.miura import miura_sheet

    a, b = miura_sides(setting, m, n, gamma)
    return miura_sheet(m, n, a, b, gamma, ext)


MIURA_SHEET = SheetFamily(
    code=1, name="miura", label="Miura-ori", has_gamma=True, nodes=_miura_nodes,
    nodes_batch=_miura_nodes_batch, topology_nodes=_miura_topology, check=_miura_check,
    check_setting=lambda sheet: None, check_levels=_miura_levels, shape=_miura_shape,
)  # fmt: skip


# ------------------------------------------------------------------ Tachi-Miura polyhedron
def _tmp_nodes(setting, m, n, gamma, ext):
    """TMP nodes with b = size_x/m, a = size_y/n: those of
    :func:`holofold.geometry.tmp.tmp_nodes` (with its ``L_y`` for a rectangle)."""
    from holofold.geometry.tmp import tmp_nodes

    sx, sy = setting.size_x, setting.size_y
    return tmp_nodes(m, n, sx, ext, None if sx == sy else sy)


def _tmp_nodes_batch(setting, m, n, gammas, exts):
    return np.stack([_tmp_nodes(setting, m, n, None, e) for e in exts])


def _tmp_topology(m, n):
    from holofold.geometry.tmp import tmp_nodes

    return tmp_nodes(m, n, 1.0, 0.5)


def _tmp_check(setting, d, ok_m, ok_n, gamma):
    errs = []
    if ok_m and d["m"] % 2:
        errs.append(f"m = {d['m']:g} must be even for a TMP sheet")
    if ok_n and d["n"] % 3:
        errs.append(f"n = {d['n']:g} must be a multiple of 3 for a TMP sheet")
    if ok_m and ok_n and not d["n"] % 3:
        ext = min(setting.extensions)
        b, a = setting.size_x / d["m"], setting.size_y / d["n"]
        if 2 * b * math.sqrt(1 - ext**2) > a:
            errs.append(
                f"m = {d['m']:g}, n = {d['n']:g}: the TMP tubes overlap at Ext = {ext:g} "
                f"(2 b sqrt(1 - Ext^2) = {2 * b * math.sqrt(1 - ext**2):.4g} m > a = {a:.4g} m)"
            )
    return errs


def _tmp_setting(sheet):
    if sheet["gamma"] is not None:
        return "gamma/gamma_deg is the Miura sector angle; pattern = 'tmp' has none"
    if sheet["m"] is not None and sheet["m"] % 2:
        return f"m = {sheet['m']} must be even for pattern = 'tmp'"
    if sheet["n"] is not None and sheet["n"] % 3:
        return f"n = {sheet['n']} must be a multiple of 3 for pattern = 'tmp'"
    return None


def _tmp_levels(sheet, counts, where, gammas):
    if any(int(v) % 2 for v in counts["m"]):
        return f"{where['m']} = {counts['m']}: TMP sheets (pattern 2) need even m"
    if any(int(v) % 3 for v in counts["n"]):
        return f"{where['n']} = {counts['n']}: TMP sheets (pattern 2) need multiples of 3"
    return None


def _tmp_shape(setting, m, n, gamma, ext):
    from holofold.geometry.miura import rigid_fold_pattern
    from holofold.geometry.tmp import tmp_faces

    lx, ly = setting.size_x, setting.size_y
    meta = {"kind": "tmp", "m": m, "n": n, "size_x": lx, "size_y": ly, "ext": ext}
    return rigid_fold_pattern(
        _tmp_nodes(setting, m, n, None, ext),
        tmp_faces(m, n),
        _tmp_nodes(setting, m, n, None, 1.0)[:, :2],
        _tmp_nodes(setting, m, n, None, 0.5),
        meta | {"a": ly / n, "b": lx / m},
    )


TMP_SHEET = SheetFamily(
    code=2, name="tmp", label="TMP", has_gamma=False, nodes=_tmp_nodes,
    nodes_batch=_tmp_nodes_batch, topology_nodes=_tmp_topology, check=_tmp_check,
    check_setting=_tmp_setting, check_levels=_tmp_levels, shape=_tmp_shape,
)  # fmt: skip


def _check_sheet(code, family) -> SheetFamily:
    if not isinstance(family, SheetFamily):
        raise TypeError(f"expected a SheetFamily, got {type(family).__name__}")
    if isinstance(code, bool) or not isinstance(code, int) or code != family.code:
        raise ValueError(f"sheet family {family.name!r}: its code must be an integer, got {code!r}")
    return family


#: code of the ``pattern`` feature -> family (a :class:`~holofold.geometry.Registry`)
SHEET_FAMILIES: Registry[SheetFamily] = Registry(
    "sheet family", {f.code: f for f in (MIURA_SHEET, TMP_SHEET)}, check=_check_sheet
)


def sheet_family(code) -> SheetFamily | None:
    """The family of a ``pattern`` code (None if there is none; 1.0 finds 1, 1.5 nothing)."""
    return SHEET_FAMILIES.get(code)


def register_sheet_family(family: SheetFamily, *, replace: bool = False) -> SheetFamily:
    """Add a sheet pattern (its ``name`` must be a geometry family with ``faces``); a built-in
    code cannot be taken, a registered one only with ``replace=True``."""
    return SHEET_FAMILIES.register(family, family.code, replace=replace)
