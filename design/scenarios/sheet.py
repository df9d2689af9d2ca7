"""The sheet kind: Miura-ori or TMP sheets of any footprint (the paper's canopy, generalised).

docs/scenarios.md §8. A :class:`SheetSetting` fixes everything a design does not vary: the
footprint, the Miura sector angle (unless it is the feature ``gama``), the extensions at which
the sheet is modelled, the load cases, the material and the supports; the pattern and the cell
counts are features unless the setting fixes them. :func:`sheet_scenario` turns a setting and
the design features into a :class:`~holofold.design.scenarios.base.Scenario`.

Geometry, m and n panels along x and y, footprint ``size_x`` x ``size_y`` (the paper's L):

* Miura-ori (``pattern`` 1): b = size_x/m, a = (size_y - b cot gamma)/n (needs a > 0);
* Tachi-Miura polyhedron (``pattern`` 2, m even, n a multiple of 3): b = size_x/m,
  a = size_y/n (a design whose folded tubes overlap at the smallest extension is invalid).

One stress-free concentrated-hinge model per extension (``row["W"]``, ``row["tcrease"]``,
``row["tpanel"]``; E of panels and creases from the optional features ``panelE``/``creaseE``,
default the setting's E). The nodes at x = min are fixed; the nodes at x = max share each load
case (Newton-Raphson load control from the stress-free state, ``increments`` equal steps).

Columns, SI units:

``{load}stiff{tag}``
    total force / mean displacement of the loaded nodes along the load direction, N/m, at
    the extension ``ext`` with ``tag = round(100 ext)`` (``bendstiff30``: load ``bend`` at 0.3);
``mass``
    density x (panel area x tpanel + fold-line length x W x (tcrease - tpanel)), kg: the flat
    sheet of panel thickness, thinned to the crease thickness over a strip of width W along
    every fold line;
``overlap``, ``clearance``
    volume where the thick panels (tpanel, pulled back W/2 from the creases) intersect, m^3,
    and the smallest gap between panels sharing no vertex, m, folded to the smallest modelled
    extension (the most folded state the sheet is used in): 0 overlap means the part can be
    folded there as designed (:func:`holofold.geometry.printability`);
``thick``
    the thickness technique of those panels, 0 centred, 1 offset, 2 tapered: the setting's
    ``thick``, or with ``thick = "auto"`` (the default) the first whose panels fold from flat
    to that extension without collision (:func:`~holofold.geometry.choose_thickness`;
    offset and tapered panels are checked at four states on the way and report ``overlap``
    over the path and ``clearance`` nan). The files and the printable part use it.

The paper's canopy (:mod:`~holofold.design.scenarios.canopy`) is this kind with a 0.2 m square,
gamma = 70 deg, extensions 0.3, 0.6, 0.9 and the loads ``bend`` (3 N in -z) and ``axial``
(3 N in +x); the single Miura cell (:mod:`~holofold.design.scenarios.single_miura`) is a fixed
2 x 2 Miura sheet of 0.04 m with the feature ``gama`` and the ``axial`` load alone.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache, partial

import numpy as np

from holofold.design.scenarios.base import Column, Scenario, integer, positive, setting_hooks
from holofold.design.scenarios.config import (
    Section,
    load_name,
    read_direction,
    read_dofs,
    read_features,
    read_loads,
    read_material,
    read_solver,
)
from holofold.design.scenarios.pattern_loads import write_row_files
from holofold.design.scenarios.plausible import FORCE, check_lengths, check_plausible
from holofold.design.scenarios.sheet_families import (
    MIURA_SHEET,
    SHEET_FAMILIES,
    TMP_SHEET,
    miura_sides,
    sheet_family,
)
from holofold.geometry import MAX_PANELS, THICK_CHOICES, choose_thickness
from holofold.geometry.errors import DegenerateGeometryError
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.analyses import load_along, secant_stiffness_batch
from holofold.mechanics.assembly import BatchAssembler
from holofold.mechanics.compat import PAPER
from holofold.mechanics.hinges import build_concentrated_batch
from holofold.mechanics.status import Outcome, Status
from holofold.mechanics.structure import support_mask
from holofold.mechanics.threads import single_threaded

__all__ = [
    "MIURA",
    "TMP",
    "PATTERNS",
    "GAMMA_70",
    "SheetLoad",
    "SheetSetting",
    "SHEET_FEATURES",
    "sheet_features",
    "sheet_columns",
    "sheet_nodes",
    "sheet_models",
    "sheet_models_batch",
    "sheet_mass",
    "check_sheet",
    "evaluate_sheet",
    "evaluate_sheet_batch",
    "sheet_batch_key",
    "sheet_shape",
    "write_sheet_files",
    "sheet_view",
    "sheet_part",
    "sheet_scenario",
    "extension_tag",
    "from_config",
]

MIURA, TMP = MIURA_SHEET.code, TMP_SHEET.code


class _PatternCodes(Mapping):
    """Pattern names of scenario files -> the feature's codes, read from
    :data:`SHEET_FAMILIES` on every call (a family registered later is named too)."""

    def _now(self) -> dict[str, int]:
        return {f.name: code for code, f in SHEET_FAMILIES.items()}

    def __getitem__(self, name: str) -> int:
        return self._now()[name]

    def __iter__(self):
        return iter(self._now())

    def __len__(self) -> int:
        return len(self._now())

    def __repr__(self) -> str:
        return repr(self._now())


#: pattern names of scenario files -> the feature's codes (the sheet families, live)
PATTERNS: Mapping[str, int] = _PatternCodes()
GAMMA_70 = 70.0 / 180.0 * math.pi  #: the canopy's Miura sector angle, rad

#: every feature a sheet can have, with the paper's ranges (canopy; ``gama`` from data0).
#: ``pattern``, ``m``, ``n`` are features unless the setting fixes them, ``gama`` only when the
#: setting has no sector angle; ``creaseE``/``panelE`` are optional (default: the setting's E).
SHEET_FEATURES = (
    Column(
        "pattern", "-", "1 = Miura-ori, 2 = TMP", choices=(1.0, 2.0), names=("Miura-ori", "TMP")
    ),
    Column("m", "-", "panels along x (TMP: even)", choices=(24.0, 30.0, 36.0)),
    Column("n", "-", "panels along y (TMP: multiple of 3)", choices=(6.0, 9.0, 12.0)),
    Column("tcrease", "m", "crease thickness", 0.5e-3, 1.0e-3, display="mm"),
    Column("tpanel", "m", "panel thickness", 1e-3, 6e-3, display="mm"),
    Column("W", "m", "crease width", 1e-3, 4e-3, display="mm"),
    Column(
        "gama", "rad", "Miura sector angle gamma", math.radians(50), math.radians(80), display="deg"
    ),
    Column(
        "creaseE",
        "Pa",
        "crease Young's modulus",
        1e9,
        5e9,
        required=False,
        default=2e9,
        display="GPa",
    ),
    Column(
        "panelE",
        "Pa",
        "panel Young's modulus",
        1e9,
        5e9,
        required=False,
        default=2e9,
        display="GPa",
    ),
)
_OPTIONAL_E = ("creaseE", "panelE")


@dataclass(frozen=True)
class SheetLoad:
    """One load case on a sheet: the nodes at x = max share the force equally.

    Attributes
    ----------
    name : str
        Column prefix: the case gives ``{name}stiff{tag}`` per extension.
    direction : (3,) float
        Direction of the force (normalised), e.g. ``(0, 0, -1)``.
    force : float
        Total force after the last increment, N (> 0).
    increments : int
        Equal load increments (>= 1).
    """

    name: str
    direction: tuple[float, float, float]
    force: float = 3.0
    increments: int = 3


@dataclass(frozen=True)
class SheetSetting:
    """The fixed setting of a sheet scenario (everything a design does not vary).

    Attributes
    ----------
    size_x, size_y : float
        Footprint, m: b = size_x/m; a = (size_y - b cot gamma)/n (Miura) or size_y/n (TMP).
    gamma : float or None
        Miura sector angle, rad, in (0, pi/2); None: the feature ``gama``.
    extensions : tuple of float
        Extension ratios in (0, 1], one stress-free model each (distinct ``extension_tag``).
    loads : tuple of SheetLoad
    E, nu : float
        Young's modulus (Pa; default of ``creaseE``/``panelE``) and Poisson's ratio.
    density : float
        kg/m^3, for ``mass``.
    pattern, m, n : int or None
        Fixed pattern (:data:`MIURA` or :data:`TMP`) and panel counts; None: features.
    support_dofs : str
        Fixed directions of the nodes at x = min (any of "xyz").
    tol : float
        Newton-Raphson tolerance on ||dU||, m.
    max_iter : int
        Iteration cap per increment (the reference's: 30, i.e. 29 iterations).
    """

    size_x: float = 0.2
    size_y: float = 0.2
    gamma: float | None = GAMMA_70
    extensions: tuple[float, ...] = (0.3, 0.6, 0.9)
    loads: tuple[SheetLoad, ...] = (
        SheetLoad("bend", (0.0, 0.0, -1.0)),
        SheetLoad("axial", (1.0, 0.0, 0.0)),
    )
    E: float = 2e9
    nu: float = 0.3
    density: float = 1200.0
    pattern: int | None = None
    m: int | None = None
    n: int | None = None
    support_dofs: str = "xyz"
    tol: float = 1e-7
    max_iter: int = 30
    thick: str = "auto"


def extension_tag(ext: float) -> int:
    """Column tag of an extension: round(100 ext) (0.3 -> 30)."""
    return int(round(100 * ext))


def sheet_features(setting: SheetSetting, moduli: bool = True) -> tuple[Column, ...]:
    """The default features of a setting: :data:`SHEET_FEATURES` without what it fixes and,
    with ``moduli``, the optional ``creaseE``/``panelE`` defaulting to its E over the data4
    range scaled to it, [E/2, 5E/2]."""
    fixed = {k for k in ("pattern", "m", "n") if getattr(setting, k) is not None}
    fam = sheet_family(setting.pattern)
    if setting.gamma is not None or (fam is not None and not fam.has_gamma):
        fixed.add("gama")
    if not moduli:
        fixed.update(_OPTIONAL_E)
    E = setting.E
    out = []
    for c in SHEET_FEATURES:
        if c.name in _OPTIONAL_E:
            c = replace(c, low=E / 2, high=2.5 * E, default=E)
        if c.name not in fixed:
            out.append(c)
    return tuple(out)


def _along(direction) -> str:
    """``in -z`` for an axis direction, else ``along (x, y, z)``."""
    nz = [k for k, v in enumerate(direction) if v]
    if len(nz) == 1:
        return f"in {'+' if direction[nz[0]] > 0 else '-'}{'xyz'[nz[0]]}"
    return f"along ({', '.join(f'{v:g}' for v in direction)})"


def sheet_columns(setting: SheetSetting, extras: bool = True) -> tuple[Column, ...]:
    """Performance columns: per load, per extension ``{load}stiff{tag}``; with ``extras``
    ``mass``."""
    cols = [
        Column(
            f"{ld.name}stiff{extension_tag(e)}",
            "N/m",
            f"secant stiffness under {ld.force:g} N {_along(ld.direction)} at Ext = {e:g}",
        )
        for ld in setting.loads
        for e in setting.extensions
    ]
    if extras:
        cols.append(Column("mass", "kg", "mass of the sheet (panels and thinned fold lines)"))
        most = min(setting.extensions)
        cols.append(
            Column(
                "overlap",
                "m^3",
                "volume where the thick panels intersect, folded to "
                f"Ext = {most:g} (the most folded modelled state)",
                display="mm^3",
            )
        )
        cols.append(Column("clearance", "m", "smallest gap between centred panels sharing no "
                           f"vertex, folded to Ext = {most:g} (nan for offset and tapered "
                           "panels: their overlap is checked along the fold path)",
                           display="mm"))  # fmt: skip
        cols.append(Column("thick", "-", "thickness technique of the panels: 0 centred, "
                           "1 offset, 2 tapered (with thick = 'auto' the first that folds "
                           f"from flat to Ext = {most:g} without collision)",
                           choices=(0.0, 1.0, 2.0),
                           names=("centred", "offset", "tapered")))  # fmt: skip
    return tuple(cols)


def _design(setting: SheetSetting, row) -> tuple[int, int, int, float | None]:
    """(pattern, m, n, gamma) of a design: the setting's values, else the row's."""
    pat = setting.pattern if setting.pattern is not None else int(row["pattern"])
    m = setting.m if setting.m is not None else int(row["m"])
    n = setting.n if setting.n is not None else int(row["n"])
    has_gamma = SHEET_FAMILIES[pat].has_gamma
    gamma = setting.gamma if setting.gamma is not None or not has_gamma else float(row["gama"])
    return pat, m, n, gamma


@lru_cache(maxsize=32)
def _topology(pattern: int, m: int, n: int) -> CreasePattern:
    """A sheet with the right faces (coordinates are replaced per design)."""
    fam = SHEET_FAMILIES[pattern]
    return CreasePattern.from_faces(fam.topology_nodes(m, n), fam.faces(m, n))


_miura_sides = miura_sides  # the footprint's Miura panel sides (a, b)


def sheet_nodes(setting: SheetSetting, row, ext: float) -> np.ndarray:
    """Node coordinates of the design's sheet folded to ``ext``, (nv, 3) m."""
    pat, m, n, gamma = _design(setting, row)
    return SHEET_FAMILIES[pat].nodes(setting, m, n, gamma, ext)


def _modulus(row, key: str, default: float) -> float:
    v = row.get(key, default)
    return default if v is None or math.isnan(v) else v


def sheet_models(setting: SheetSetting, row, *, profile=PAPER, extensions=None):
    """Stress-free models with supports, one per extension (default the setting's).

    Returns
    -------
    list of (Structure, tuple of LoadGroup)
        The load groups in the order of ``setting.loads``.
    """
    return sheet_models_batch(setting, [row], profile=profile, extensions=extensions)[0]


def sheet_models_batch(setting: SheetSetting, rows, *, profile=PAPER, extensions=None):
    """:func:`sheet_models` of several designs, the models of one pattern, m and n built
    together (:func:`~holofold.mechanics.hinges.build_concentrated_batch`, bit for bit the
    same)."""
    exts = setting.extensions if extensions is None else extensions
    out: list = [[None] * len(exts) for _ in rows]
    groups: dict = {}
    for i, row in enumerate(rows):
        pat, m, n, _ = _design(setting, row)
        groups.setdefault((pat, m, n), []).append(i)
    for (pat, m, n), idx in groups.items():
        topo = _topology(pat, m, n)
        items = [(i, e) for i in idx for e in range(len(exts))]
        gammas = [_design(setting, rows[i])[3] for i, _ in items]
        X = SHEET_FAMILIES[pat].nodes_batch(  # every sheet's nodes at once (bit for bit)
            setting, m, n, gammas, [exts[e] for _, e in items]
        )
        # the nodes at x = min (fixed) and x = max (loaded) of every sheet, in two calls
        x0 = X[:, :, 0]
        lows = x0 == x0.min(axis=1, keepdims=True)
        highs = x0 == x0.max(axis=1, keepdims=True)
        nn = X.shape[1] + topo.n_faces
        sups = [_support(nn, low.tobytes(), setting.support_dofs) for low in lows]
        col = lambda f, items=items: [f(rows[i]) for i, _ in items]  # noqa: E731
        structures = build_concentrated_batch(
            topo,
            X,
            crease_width=col(lambda r: r["W"]),
            crease_thickness=col(lambda r: r["tcrease"]),
            panel_thickness=col(lambda r: r["tpanel"]),
            E_panel=col(lambda r: _modulus(r, "panelE", setting.E)),
            E_crease=col(lambda r: _modulus(r, "creaseE", setting.E)),
            nu_panel=setting.nu,
            nu_crease=setting.nu,
            profile=profile,
            supports=sups,
        )
        dirs = tuple(tuple(float(v) for v in ld.direction) for ld in setting.loads)
        for (i, e), high, st in zip(items, highs, structures, strict=True):
            out[i][e] = (st, _load_groups(high.tobytes(), dirs))
    return out


# the supports and load groups of a sheet depend on which of its nodes lie at x = min and
# x = max, the same for every design of one pattern and size in practice: built once per set
# (read-only arrays, shared by the structures and groups built from them)
@lru_cache(maxsize=256)
def _support(n_nodes: int, low: bytes, dofs: str) -> np.ndarray:
    """(n_nodes, 3) read-only support mask fixing ``dofs`` of the vertices where the bool
    bytes ``low`` (one per vertex) are set."""
    fixed = np.flatnonzero(np.frombuffer(low, bool))
    mask = support_mask(n_nodes, fixed, dofs)
    mask.setflags(write=False)
    return mask


@lru_cache(maxsize=256)
def _load_groups(high: bytes, directions: tuple[tuple[float, ...], ...]) -> tuple:
    """One :class:`~holofold.mechanics.analyses.LoadGroup` per load direction on the vertices
    where the bool bytes ``high`` are set (read-only node ids)."""
    tip = np.flatnonzero(np.frombuffer(high, bool))
    tip.setflags(write=False)
    return tuple(load_along(tip, d) for d in directions)


def sheet_mass(setting: SheetSetting, row) -> float:
    """density x (panel area x tpanel + fold-line length x W x (tcrease - tpanel)), kg, of the
    flat sheet (ext = 1; rigid folding keeps panel areas and fold lengths)."""
    pat, m, n, _ = _design(setting, row)
    X = sheet_nodes(setting, row, 1.0)
    topo = _topology(pat, m, n)
    area = 0.0
    for f in topo.faces:  # vector area of each planar polygon
        P = X[f]
        area += 0.5 * np.linalg.norm(np.cross(P, np.roll(P, -1, axis=0)).sum(axis=0))
    e = topo.edges[topo.interior]
    fold_length = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1).sum()
    tp, tc, w = float(row["tpanel"]), float(row["tcrease"]), float(row["W"])
    return float(setting.density * (area * tp + fold_length * w * (tc - tp)))


def check_sheet(setting: SheetSetting, row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    errs = positive(row, ("tcrease", "tpanel", "W"))
    for opt in _OPTIONAL_E:
        v = row.get(opt)
        if v is not None and not (isinstance(v, float) and math.isnan(v)):
            errs += positive(row, (opt,))
    d = dict(row)
    for k in ("pattern", "m", "n"):
        if getattr(setting, k) is not None:
            d[k] = getattr(setting, k)
    p = d.get("pattern")
    fam = sheet_family(p)
    if fam is None:
        codes = " or ".join(f"{c} ({f.label})" for c, f in SHEET_FAMILIES.items())
        errs.append(f"pattern = {p!r} must be {codes}")
    ok_m, ok_n = not integer(d, "m", 1), not integer(d, "n", 1)
    errs += integer(d, "m", 1) + integer(d, "n", 1)
    if ok_m and ok_n and d["m"] * d["n"] > MAX_PANELS:
        errs.append(
            f"m = {int(d['m'])} x n = {int(d['n'])} = {int(d['m']) * int(d['n'])} panels is "
            f"over the limit of {MAX_PANELS} (docs/limits.md)"
        )
        ok_m = ok_n = False  # no geometry checks on a sheet too large to build
    if fam is not None:
        g = None
        if fam.has_gamma:
            g = setting.gamma if setting.gamma is not None else row.get("gama")
        errs += fam.check(setting, d, ok_m, ok_n, g)
    return errs


def evaluate_sheet(setting: SheetSetting, columns: Sequence[str], row) -> dict:
    """The ``columns`` of one design (see the module docstring) and a status."""
    return evaluate_sheet_batch(setting, columns, [row])[0]


def sheet_batch_key(setting: SheetSetting, row) -> tuple[int, int, int]:
    """Designs with the same key (pattern, m, n) have models of one size: one batch."""
    pat, m, n, _ = _design(setting, row)
    return pat, m, n


@single_threaded
def evaluate_sheet_batch(setting: SheetSetting, columns: Sequence[str], rows) -> list[dict]:
    """:func:`evaluate_sheet` of several designs of one pattern, m and n: the models of every
    design and extension that share a support mask are solved together, per load
    (:func:`secant_stiffness_batch`); each output is the design's own."""
    models = sheet_models_batch(setting, rows)
    outs: list = [{} for _ in rows]
    # each design's cases in the order its status lists them: by extension, then load
    labels = [f"{ld.name} Ext {ext}" for ext in setting.extensions for ld in setting.loads]
    cases: list = [dict.fromkeys(labels) for _ in rows]
    together: dict = {}  # support mask -> the (design, extension) models that share it
    for i, mod in enumerate(models):
        for e in range(len(setting.extensions)):
            together.setdefault(mod[e][0].supports.tobytes(), []).append((i, e))
    for items in together.values():
        structures = [models[i][e][0] for i, e in items]
        batch = BatchAssembler(structures)  # one pattern and reduction for every load case
        for k, ld in enumerate(setting.loads):
            runs = secant_stiffness_batch(
                structures,
                [models[i][e][1][k] for i, e in items],
                force_per_increment=ld.force / ld.increments,
                increments=ld.increments,
                tol=setting.tol,
                max_iter=setting.max_iter,
                batch=batch,
            )
            for (i, e), r in zip(items, runs, strict=True):
                ext = setting.extensions[e]
                outs[i][f"{ld.name}stiff{extension_tag(ext)}"] = r.stiffness
                cases[i][f"{ld.name} Ext {ext}"] = r.result.status
    result = []
    for row, out, case in zip(rows, outs, cases, strict=True):
        if "mass" in columns:
            out["mass"] = sheet_mass(setting, row)
        if "overlap" in columns:
            got = sheet_thickness(setting, row)
            out["overlap"], out["clearance"], out["thick"] = got.overlap, got.clearance, got.code
        out = {c: out[c] for c in columns}
        out["status"] = Status.gather(case, worst=Outcome.NOT_CONVERGED)
        result.append(out)
    return result


#: clearance reported when every pair of panels shares a vertex, m (as the strip kind's)
_NO_NEIGHBOUR = 1e3


def sheet_fold_path(setting: SheetSetting, row) -> tuple[CreasePattern, list[CreasePattern]]:
    """The design folded to the smallest modelled extension (where its panels come closest)
    and four states on the way from flat, m."""
    most = min(setting.extensions)
    way = [sheet_shape(setting, row, float(e)) for e in np.linspace(1.0, most, 6)[1:-1]]
    return sheet_shape(setting, row, most), way


def sheet_thickness(setting: SheetSetting, row):
    """The design's thick panels (:func:`~holofold.geometry.choose_thickness`):
    the setting's technique, or with ``thick = "auto"`` the first of centred, offset and
    tapered whose panels fold from flat to the smallest modelled extension without collision
    (trimesh, scipy.spatial and manifold3d load on first use)."""

    state, way = sheet_fold_path(setting, row)
    return choose_thickness(state, float(row["tpanel"]), float(row["W"]), path=way,
                            thick=setting.thick, no_neighbour=_NO_NEIGHBOUR)  # fmt: skip


def sheet_shape(setting: SheetSetting, row, ext: float | None = None) -> CreasePattern:
    """The design's stress-free sheet folded to ``ext`` (default the largest of the setting's
    extensions: the least folded modelled state), with its flat layout and M/V assignment, m."""
    ext = max(setting.extensions) if ext is None else ext
    pat, m, n, gamma = _design(setting, row)
    return SHEET_FAMILIES[pat].shape(setting, m, n, gamma, ext)


def sheet_view(setting: SheetSetting, row):
    """The design folding from flat (Ext = 1) through each modelled extension, with the
    supported nodes (x = min) and the loads shared by the nodes at x = max
    (:class:`~holofold.design.report.view.DesignView`)."""
    from holofold.design.report.view import DesignView, Load

    exts = [1.0] + [e for e in sorted(setting.extensions, reverse=True) if e < 1.0]
    frames = np.stack([sheet_nodes(setting, row, e) for e in exts])
    pat, m, n, _ = _design(setting, row)
    topo = _topology(pat, m, n)
    shape = sheet_shape(setting, row)
    last = frames[-1]
    fixed = np.flatnonzero(last[:, 0] == last[:, 0].min())
    tip = np.flatnonzero(last[:, 0] == last[:, 0].max())
    loads = tuple(Load(int(v), ld.direction, f"{ld.name}: {ld.force:g} N shared")
                  for ld in setting.loads for v in tip)  # fmt: skip
    labels = tuple("flat" if e == 1.0 else f"Ext {e:g}" for e in exts)
    return DesignView(
        frames=frames, labels=labels, faces=[list(f) for f in topo.faces], edges=shape.edges,
        kinds="".join(str(a)[0] for a in shape.assignment), supports=fixed, loads=loads,
        facts=(("supports", f"the nodes at x = min, fixed in {setting.support_dofs}"),),
    )  # fmt: skip


def sheet_part(setting: SheetSetting, row):
    """The printable part: the sheet's flat layout, printed with panels of ``tpanel`` joined
    by hinge strips of ``tcrease`` and width ``W``
    (:class:`~holofold.design.loop.buildability.PrintablePart`)."""
    from holofold.design.loop.buildability import PrintablePart

    got = sheet_thickness(setting, row)
    state, way = sheet_fold_path(setting, row)
    return PrintablePart(state, float(row["tpanel"]), float(row["tcrease"]), float(row["W"]),
                         thick=got.technique, path=tuple(way))  # fmt: skip


def write_sheet_files(
    setting: SheetSetting, row, folder, ext: float | None = None, units: str = "mm", cutter=None
):
    """The design's fabrication set (:func:`~holofold.geometry.write_fabrication_set`) for the
    sheet folded as :func:`sheet_shape`: its printable part, FOLD, SVG and DXF for ``cutter``,
    STL/OBJ and the thick solid (meshes in ``units``); if the thick panels overlap too much in
    that state, every file but the solids, with a note saying why.
    """
    got = sheet_thickness(setting, row)
    state, way = sheet_fold_path(setting, row)
    return write_row_files(sheet_shape(setting, row, ext), folder, row, units=units,
                           cutter=cutter, thick=got.technique, fallback=DegenerateGeometryError,
                           what="no thick.stl", path=[*way, state])  # fmt: skip


def sheet_scenario(
    name: str,
    description: str,
    setting: SheetSetting,
    features: tuple[Column, ...] | None = None,
    *,
    extras: bool = True,
    source: str = "",
) -> Scenario:
    """The :class:`Scenario` of a sheet setting (picklable for worker processes); ``features``
    default to :func:`sheet_features`."""
    features = sheet_features(setting) if features is None else features
    perf = sheet_columns(setting, extras)
    codes = ", ".join(f"{c} {f.label}" for c, f in SHEET_FAMILIES.items())
    pattern = {
        None: f"feature pattern ({codes})",
        **{c: f.label for c, f in SHEET_FAMILIES.items()},
    }
    words = {
        "footprint (m)": f"{setting.size_x:g} x {setting.size_y:g}",
        "pattern": pattern[setting.pattern],
        "panels m x n": f"{'feature m' if setting.m is None else setting.m} x "
        f"{'feature n' if setting.n is None else setting.n}",
        "Miura sector angle": "feature gama"
        if setting.gamma is None
        else f"{math.degrees(setting.gamma):g} deg",
        "extensions": ", ".join(f"{e:g}" for e in setting.extensions),
        "E (Pa)": setting.E,
        "nu": setting.nu,
        "density (kg/m^3)": setting.density,
        "supports": f"the nodes at x = min, fixed in {setting.support_dofs}",
    }
    for ld in setting.loads:
        words[f"load {ld.name}"] = (
            f"{ld.force:g} N {_along(ld.direction)} shared by the nodes at x = max, "
            f"{ld.increments} increments"
        )
    return Scenario(
        name=name,
        description=description,
        features=features,
        performance=perf,
        check=partial(check_sheet, setting),
        evaluate=partial(evaluate_sheet, setting, tuple(c.name for c in perf)),
        evaluate_batch=partial(evaluate_sheet_batch, setting, tuple(c.name for c in perf)),
        batch_key=partial(sheet_batch_key, setting),
        categorical=tuple(c.name for c in features if c.choices),
        kind="sheet",
        setting=words,
        source=source,
        **setting_hooks(setting, sheet_shape, write_sheet_files, sheet_view, sheet_part),
    )


# ---------------------------------------------------------------------- scenario files
def _known(sec: Section, allowed: Sequence[str]) -> None:
    """Refuse unknown keys first (a misspelt key is named as such, not as a missing one)."""
    for k in allowed:
        sec.raw(k)
    sec.done(allowed)


def _read_load(sec: Section, names: set) -> SheetLoad:
    _known(sec, ["name", "direction", "force", "increments"])
    name = load_name(sec, names, "'bend' or 'axial'")
    if not sec.has("force"):
        raise sec.error("missing key 'force' (total force, N)")
    load = SheetLoad(
        name=name,
        direction=read_direction(sec),
        force=sec.number("force", low=0.0, low_open=True),
        increments=sec.number("increments", 3, low=1, high=1000, integer=True),
    )
    check_plausible(sec, "force", load.force, *FORCE)
    return load


def _read_extensions(sec: Section) -> tuple[float, ...]:
    raw = sec.raw("extensions", [0.3, 0.6, 0.9])
    ok = isinstance(raw, list) and raw and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in raw
    )  # fmt: skip
    if not ok or not all(0 < v <= 1 for v in raw):
        raise sec.error(
            f"extensions = {raw!r} must be a list of extension ratios in (0, 1], e.g. [0.3, 0.6]"
        )
    exts = tuple(float(v) for v in raw)
    tags = [extension_tag(e) for e in exts]
    for k, t in enumerate(tags):
        if t in tags[:k]:
            other = exts[tags.index(t)]
            raise sec.error(
                f"extensions = {raw!r}: {other:g} and {exts[k]:g} give the same column tag {t} "
                "(round(100 Ext)); allowed: ratios whose round(100 Ext) differ"
            )
    return exts


def _read_sheet(sec: Section) -> dict:
    """The ``[sheet]`` table: footprint, sector angle, extensions, fixed pattern and counts."""
    _known(sec, ["size_x", "size_y", "gamma", "gamma_deg", "extensions", "pattern", "m", "n"])
    if not sec.has("size_x") or not sec.has("size_y"):
        raise sec.error("size_x and size_y (the footprint, m) are required")
    out = {
        "size_x": sec.number("size_x", low=0.0, low_open=True),
        "size_y": sec.number("size_y", low=0.0, low_open=True),
        "extensions": _read_extensions(sec),
    }
    check_lengths(sec, "sheet", {"size_x": out["size_x"], "size_y": out["size_y"]})
    if sec.has("gamma") and sec.has("gamma_deg"):
        raise sec.error("give gamma (rad) or gamma_deg, not both")
    if sec.has("gamma_deg"):
        out["gamma"] = sec.number("gamma_deg", low=0.0, high=90.0, low_open=True) / 180.0 * math.pi
    elif sec.has("gamma"):
        out["gamma"] = sec.number("gamma", low=0.0, high=math.pi / 2, low_open=True)
    else:
        out["gamma"] = None  # fixed at 70 deg unless [features] names gama
    if out["gamma"] is not None and not out["gamma"] < math.pi / 2:
        raise sec.error("the sector angle must be < 90 deg (pi/2 rad)")
    pat = sec.choice("pattern", tuple(PATTERNS))
    out["pattern"] = None if pat is None else PATTERNS[pat]
    for k in ("m", "n"):
        out[k] = sec.number(k, low=1, high=10000, integer=True)
    if out["pattern"] is not None:
        problem = SHEET_FAMILIES[out["pattern"]].check_setting(out)
        if problem:
            raise sec.error(problem)
    return out


def _values(c: Column) -> tuple[float, ...]:
    return c.choices or (c.low, c.high)


def _check_features(doc: Section, sheet: dict, features: tuple[Column, ...]) -> None:
    """Refuse feature levels that no design could use (before anything is simulated)."""
    by = {c.name: c for c in features}
    pats = (sheet["pattern"],) if sheet["pattern"] is not None else _values(by["pattern"])
    if not set(pats) <= set(SHEET_FAMILIES):
        codes = ", ".join(f"{c} ({f.label})" for c, f in SHEET_FAMILIES.items())
        names = " | ".join(f"'{f.name}'" for f in SHEET_FAMILIES.values())
        raise doc.error(
            f"[features] pattern = {pats}: allowed: {codes}, or fix one with "
            f"[sheet] pattern = {names}"
        )
    counts, where = {}, {}
    for k in ("m", "n"):
        counts[k] = (sheet[k],) if sheet[k] is not None else _values(by[k])
        where[k] = f"[sheet] {k}" if sheet[k] is not None else f"[features] {k}"
        if not all(v >= 1 and v == int(v) for v in counts[k]):
            raise doc.error(f"{where[k]} must be integers >= 1, got {counts[k]}")
    largest = int(max(counts["m"])) * int(max(counts["n"]))
    if largest > MAX_PANELS:
        raise doc.error(
            f"{where['m']} = {counts['m']} x {where['n']} = {counts['n']}: the largest sheet has "
            f"{largest} panels; at most {MAX_PANELS} (docs/limits.md)"
        )
    # a crease as wide as the widest panel any design has (a panel spans size_x / m along x,
    # Miura and TMP alike): every row would fail alike
    widest = sheet["size_x"] / min(counts["m"])
    if "W" in by and min(_values(by["W"])) >= widest:
        raise doc.error(
            f"[features] W = {_values(by['W'])} m: every crease is at least "
            f"{min(_values(by['W'])):g} m wide, as wide as the widest panel of any design "
            f"({widest:.4g} m = size_x / m = {sheet['size_x']:g} / {min(counts['m']):g})"
        )
    for code in sorted(SHEET_FAMILIES, reverse=True):  # TMP's parity, then Miura's angle
        if code not in pats:
            continue
        fam = SHEET_FAMILIES[code]
        gammas = ()
        if fam.has_gamma:
            gammas = (sheet["gamma"],) if sheet["gamma"] is not None else _values(by["gama"])
        problem = fam.check_levels(sheet, counts, where, gammas)
        if problem:
            raise doc.error(problem)


def from_config(doc: Section, name: str, description: str) -> Scenario:
    """The sheet scenario of a parsed scenario file (``kind = "sheet"``)."""
    sheet = _read_sheet(doc.sub("sheet", required=True))
    E, nu, density = read_material(doc)
    sup = doc.sub("supports")
    dofs = read_dofs(sup)
    sup.done()
    tol, max_iter = read_solver(doc)
    loads = read_loads(doc, _read_load)
    fsec = doc.sub("features")
    for k in ("pattern", "m", "n"):
        if sheet[k] is not None and fsec.has(k):
            raise fsec.error(f"{k} is fixed in [sheet]; remove it there or here")
    gama_feature = fsec.has("gama")
    fixed = sheet_family(sheet["pattern"])
    no_gamma = fixed is not None and not fixed.has_gamma
    if gama_feature and (sheet["gamma"] is not None or no_gamma):
        why = f"pattern = '{fixed.name}' has no sector angle" if no_gamma else (
            "the sector angle is fixed in [sheet]; remove it there or here")  # fmt: skip
        raise fsec.error(f"gama: {why}")
    if sheet["gamma"] is None and not gama_feature and not no_gamma:
        sheet["gamma"] = GAMMA_70
    setting = SheetSetting(
        size_x=sheet["size_x"],
        size_y=sheet["size_y"],
        gamma=sheet["gamma"],
        extensions=sheet["extensions"],
        loads=tuple(loads),
        E=E,
        nu=nu,
        density=density,
        pattern=sheet["pattern"],
        m=sheet["m"],
        n=sheet["n"],
        support_dofs=dofs,
        tol=tol,
        max_iter=max_iter,
        thick=doc.choice("thick", THICK_CHOICES, "auto"),
    )
    # the optional moduli are features when the file names them (else E holds everywhere)
    moduli = any(fsec.has(k) for k in _OPTIONAL_E)
    features = read_features(fsec, sheet_features(setting, moduli), kind="sheet")
    if moduli and not all(fsec.has(k) for k in _OPTIONAL_E):
        features = tuple(c for c in features if c.name not in _OPTIONAL_E or fsec.has(c.name))
    _check_features(doc, sheet, features)
    return sheet_scenario(name, description, setting, features)
