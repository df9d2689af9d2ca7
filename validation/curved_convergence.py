"""Convergence of folded curved creases under mesh refinement (issue 36 item 3).

Two reference cases of the ``curved-pleat`` family (:mod:`holofold.geometry.curved_pleat`):

* ``sector``: the creased annulus sector, one circular crease (r 100-160 mm, crease at 130 mm,
  90 deg sector, valley at 60 deg);
* ``pleat``: a curved pleat of 3 creases (r 100-180 mm, every 20 mm, 90 deg, 60 deg).

Each is folded by :func:`holofold.mechanics.fold_pattern` (concentrated hinges, E 2 GPa,
nu 0.3, panels 0.2 mm, creases 0.5 mm thick and 1 mm wide; the mesh edges inside a pleat
bend with the plate's stiffness, :func:`holofold.mechanics.build_concentrated`; intersections
not checked) to 100 % at refinement levels ``pieces:across`` (pieces per arc, quads across each
pleat). The levels are nested, so the vertices of the coarsest level are the same material
points in every level. Measured per level:

* ``shape``: the largest distance of those points from the finest level's, after the best
  rigid alignment (Kabsch; the default support, the panel nearest the centre, differs between
  meshes), in % of the sheet's size (the flat layout's larger side);
* ``energy``: the elastic energy at the full fold (J), and its ratio to the plate energy of
  the rotationally symmetric fold (:func:`cone_energy`);
* ``opening``: the opening stiffness of the folded sector (N/m, :func:`opening_stiffness`: a
  force pair at its two straight ends, linear from the folded state);
* the analytic check along every crease (Fuchs & Tabachnikov, "More on paperfolding", Amer.
  Math. Monthly 106, 1999; Duncan & Duncan, "Folded developables", Proc. R. Soc. A 383,
  1982): in a fold of a curved crease, the crease's curvature in the flat sheet
  ``kappa_g = 1 / rho`` equals its 3-D curvature ``kappa`` times ``cos(alpha)``, ``alpha`` the
  angle between the crease's osculating plane and the tangent plane of the surface on either
  side. ``kappa`` and the binormal ``b`` from the circle through three crease vertices
  ``sector / 16`` apart, the tangent plane of a side spanned by the crease's tangent and the
  radial ruling from the vertex to the next ring, ``cos(alpha) = |b . n|`` (the mean of the two
  sides). Reported: the largest relative error ``|kappa cos(alpha) - 1/rho| rho`` over the
  middle half of every crease (:func:`curvature_error`).

* the energy shares (:func:`energy_shares`): which elements carry the folded state's energy
  and the opening mode's (bars, panel springs, crease hinges, and the ``J`` joins inside the
  pleats split into radial, ring and diagonal ones, :func:`edge_classes`).

The observed order between levels ``a`` and ``b`` is ``log2(e_a / e_b) / log2(h_a / h_b)``
(``h`` the arc piece). Run::

    python validation/curved_convergence.py [--levels 8:1,16:1,32:2,64:4] [--case sector]
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass

import numpy as np

from holofold.geometry.curved_pleat import CurvedPleat
from holofold.mechanics import SpringRole, fold_pattern

#: the two reference cases: name -> CurvedPleat arguments (without pieces, across)
CASES = {
    "sector": dict(inner_radius=0.1, pleat_width=0.03, creases=1, sector=math.radians(90.0),
                   fold_angle=math.radians(60.0)),
    "pleat": dict(inner_radius=0.1, pleat_width=0.02, creases=3, sector=math.radians(90.0),
                  fold_angle=math.radians(60.0)),
}  # fmt: skip
#: the section and material of every fold
SECTION = dict(panel_thickness=0.2e-3, crease_thickness=0.5e-3, E=2e9, nu=0.3)
CREASE_WIDTH = 1e-3
LEVELS = ((8, 1), (16, 1), (32, 2), (64, 4))


@dataclass(frozen=True)
class Level:
    """One folded level: its geometry, folded coordinates (nv, 3), energy (J), seconds, the
    fraction reached, the verdict, the largest relative error of the curvature relation and
    the opening stiffness (N/m)."""

    geometry: CurvedPleat
    coords: np.ndarray
    energy: float
    seconds: float
    reached: float
    verdict: str
    curvature_error: float
    opening: float
    shares: tuple[dict, dict]


def fold_level(case: str, pieces: int, across: int, time_limit: float | None = None) -> Level:
    """Fold ``case`` at one level (module docstring)."""
    g = CurvedPleat(**CASES[case], pieces=pieces, across=across)
    p = g.pattern()
    t0 = time.perf_counter()
    res = fold_pattern(
        p, 1.0, crease_width=CREASE_WIDTH, **SECTION,
        check_intersections=False, time_limit=time_limit,
    )  # fmt: skip
    dt = time.perf_counter() - t0
    x = res.coords[-1]
    return Level(g, x, float(res.energy.total), dt, res.reached, res.verdict,
                 curvature_error(g, x), opening_stiffness(g, res),
                 energy_shares(g, res))  # fmt: skip


def opening_stiffness(g: CurvedPleat, res) -> float:
    """The folded sector's opening stiffness, N/m: a force pair (1 N each way, shared equally
    by the vertices of each straight end) along the line between the two ends' centroids,
    over the change of their distance, from the tangent at the folded state (linear; the
    fold's supports, the panel nearest the centre, take no load from a balanced pair)."""
    from holofold.mechanics.assembly import Assembler

    st = res.structure
    u = _opening_mode(g, res, Assembler(st)).reshape(-1, 3)
    rings = np.arange(len(g.radii))
    a, b = st.vertex_nodes(g.vertex(rings, 0)), st.vertex_nodes(g.vertex(rings, g.pieces))
    x = res.coords[-1]
    d = x[g.vertex(rings, g.pieces)].mean(axis=0) - x[g.vertex(rings, 0)].mean(axis=0)
    d /= np.linalg.norm(d)
    return float(1.0 / ((u[b].mean(axis=0) - u[a].mean(axis=0)) @ d))


def edge_classes(g: CurvedPleat, p) -> np.ndarray:
    """(ne,) class of every edge of ``g``'s pattern ``p``: ``crease``, ``border``, and the
    ``J`` joins inside a pleat split into ``radial`` (along the rulings), ``ring`` and
    ``diagonal``."""
    ring, line = np.divmod(p.edges, g.pieces + 1)
    asg = np.asarray(p.assignment)
    out = np.where(ring[:, 0] == ring[:, 1], "ring", "diagonal").astype(object)
    out[line[:, 0] == line[:, 1]] = "radial"
    out[(asg == "M") | (asg == "V")] = "crease"
    out[asg == "B"] = "border"
    return out


def energy_shares(g: CurvedPleat, res) -> tuple[dict, dict]:
    """Where the energy is: the fractions of the folded state's elastic energy, and of the
    opening mode's (:func:`opening_stiffness`: the quadratic energy of the displacement under
    the force pair, by central differences of every element's energy), carried by the bars,
    the panel springs and the hinges of each :func:`edge_classes` class."""
    from holofold.mechanics.assembly import Assembler

    st = res.structure
    asm = Assembler(st)
    U = res.U[-1]
    role, sc = np.asarray(st.spring_role), np.asarray(st.spring_crease)
    lab = np.full(len(role), "panel", dtype=object)
    hinge = role == SpringRole.HINGE
    lab[hinge] = edge_classes(g, g.pattern())[sc[hinge]]
    u = _opening_mode(g, res, asm).reshape(U.shape)
    eps = 1e-6 / np.abs(u).max()
    b0, s0 = asm.element_response(U, res.rest, tangent=False)
    bp, sp = asm.element_response(U + eps * u, res.rest, tangent=False)
    bm, sm = asm.element_response(U - eps * u, res.rest, tangent=False)
    qb = bp.energy + bm.energy - 2 * b0.energy
    qs = sp.energy + sm.energy - 2 * s0.energy
    shares = []
    for eb, es in ((b0.energy, s0.energy), (qb, qs)):
        tot = eb.sum() + es.sum()
        d = {"bars": float(eb.sum() / tot)}
        d.update({c: float(es[lab == c].sum() / tot) for c in sorted(set(lab))})
        shares.append(d)
    return shares[0], shares[1]


def _opening_mode(g: CurvedPleat, res, asm) -> np.ndarray:
    """(3 n_nodes,) displacement under the opening force pair (:func:`opening_stiffness`),
    over the force (m/N)."""
    st = res.structure
    _, _, solve = asm.evaluate_factorized(res.U[-1], res.rest)
    rings = np.arange(len(g.radii))
    a, b = st.vertex_nodes(g.vertex(rings, 0)), st.vertex_nodes(g.vertex(rings, g.pieces))
    x = res.coords[-1]
    d = x[g.vertex(rings, g.pieces)].mean(axis=0) - x[g.vertex(rings, 0)].mean(axis=0)
    d /= np.linalg.norm(d)
    f = np.zeros((st.n_nodes, 3))
    f[a] -= d / len(a)
    f[b] += d / len(b)
    free = asm.free_dofs
    u = np.zeros(3 * st.n_nodes)
    u[free] = solve(f.ravel()[free])
    return u


def cone_energy(g: CurvedPleat) -> float:
    """Plate bending energy (J) of the rotationally symmetric fold of ``g`` at its full fold
    angle: every crease folds by ``2 alpha`` (its osculating plane bisecting the fold), every
    pleat is a cone band with the radial rulings and the curvature ``tan(alpha) / r`` across
    them, so ``D / 2 tan^2(alpha) sector ln(r_out / r_in)`` with ``D = E t^3 / (12 (1 -
    nu^2))`` of the panels (the creases at their rest angle store nothing). An equilibrium of
    the plate by symmetry (the free ends may let a lower one exist): the reference the model's
    energy should approach."""
    t, E, nu = SECTION["panel_thickness"], SECTION["E"], SECTION["nu"]
    D = E * t**3 / (12.0 * (1.0 - nu**2))
    c = math.tan(0.5 * g.fold_angle)
    return 0.5 * D * c**2 * g.sector * math.log(g.outer_radius / g.inner_radius)


def curvature_error(g: CurvedPleat, x: np.ndarray, span: int = 16) -> float:
    """Largest ``|kappa cos(alpha) rho - 1|`` over the crease vertices of the middle half of
    every crease (module docstring); ``x`` (nv, 3) folded vertex coordinates.

    The three points are ``sector / span`` apart (a fixed material stencil: one arc piece at
    ``pieces = span``, more at finer levels, so that the chequered diagonals' zig-zag of a
    few pieces does not enter), and ``cos(alpha)`` is the mean of the two sides' (the
    osculating plane bisects the fold: both are the same in the continuum).
    """
    s = max(1, g.pieces // span)
    k = np.arange(max(s, g.pieces // 4), min(g.pieces - s, 3 * g.pieces // 4) + 1)
    worst = 0.0
    for ring in g.crease_rings():
        rho = g.radii[ring]
        p, a, b = x[g.vertex(ring, k)], x[g.vertex(ring, k - s)], x[g.vertex(ring, k + s)]
        u, v = a - p, b - p
        cr = np.cross(u, v)
        area2 = np.linalg.norm(cr, axis=1)
        kappa = 2.0 * area2 / (
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1) * np.linalg.norm(b - a, axis=1)
        )  # fmt: skip
        binormal = cr / area2[:, None]
        tangent = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
        cos_a = np.zeros(len(k))
        for side in (ring - 1, ring + 1):
            n = np.cross(tangent, x[g.vertex(side, k)] - p)
            n /= np.linalg.norm(n, axis=1)[:, None]
            cos_a += 0.5 * np.abs(np.einsum("ij,ij->i", binormal, n))
        worst = max(worst, float(np.abs(kappa * cos_a * rho - 1.0).max()))
    return worst


def material_points(g: CurvedPleat, coarse: CurvedPleat) -> np.ndarray:
    """Vertex ids in ``g`` of the vertices of the coarser nested level ``coarse``."""
    fp, fa = g.pieces // coarse.pieces, g.across // coarse.across
    if fp * coarse.pieces != g.pieces or fa * coarse.across != g.across:
        raise ValueError("levels are not nested")
    nr = len(coarse.radii)
    j, k = np.meshgrid(np.arange(nr) * fa, np.arange(coarse.pieces + 1) * fp, indexing="ij")
    return g.vertex(j, k).ravel()


def aligned_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) distances of the points ``a`` from ``b`` after the best rigid motion of ``a``."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    h = (a - ca).T @ (b - cb)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return np.linalg.norm((a - ca) @ r.T + cb - b, axis=1)


def study(case: str, levels=LEVELS, time_limit: float | None = None, say=print) -> list[dict]:
    """Fold ``case`` at every level; one row per level (shape error against the finest, %)."""
    done = [fold_level(case, p, a, time_limit) for p, a in levels]
    for lv in done:
        say(f"  {case} {lv.geometry.pieces}:{lv.geometry.across} {lv.seconds:.1f} s {lv.verdict}")
    coarse, fine = done[0].geometry, done[-1]
    size = float(np.ptp(coarse.pattern().flat, axis=0).max())  # the sheet's size, m
    ref = fine.coords[material_points(fine.geometry, coarse)]
    rows = []
    for lv in done:
        pts = lv.coords[material_points(lv.geometry, coarse)]
        d = aligned_distance(pts, ref)
        rows.append(
            dict(case=case, pieces=lv.geometry.pieces, across=lv.geometry.across,
                 panels=2 * lv.geometry.pieces * (lv.geometry.creases + 1) * lv.geometry.across,
                 shape_pct=100.0 * float(d.max()) / size, energy=lv.energy,
                 energy_pct=100.0 * abs(lv.energy / fine.energy - 1.0),
                 energy_cone=lv.energy / cone_energy(lv.geometry), opening=lv.opening,
                 opening_pct=100.0 * abs(lv.opening / fine.opening - 1.0),
                 curvature=lv.curvature_error, reached=lv.reached, verdict=lv.verdict,
                 seconds=lv.seconds, shares=lv.shares)
        )  # fmt: skip
    return rows


def orders(rows: list[dict], key: str) -> list[float]:
    """Observed order of ``key`` between consecutive levels but the last (NaN where a
    difference is 0)."""
    out = []
    for a, b in zip(rows[:-2], rows[1:-1], strict=True):
        ea, eb = a[key], b[key]
        h = math.log2(b["pieces"] / a["pieces"])
        out.append(math.log2(ea / eb) / h if ea > 0 and eb > 0 else float("nan"))
    return out


def richardson(rows: list[dict], key: str) -> tuple[float, float]:
    """``(order, limit)`` of ``key`` from the last three levels (each halving the piece):
    the observed order ``p = log2((v1 - v2) / (v2 - v3))`` and ``v3 - (v2 - v3) / (2^p - 1)``
    (NaN where the differences do not shrink monotonically)."""
    v1, v2, v3 = (r[key] for r in rows[-3:])
    q = (v1 - v2) / (v2 - v3) if v2 != v3 else float("nan")
    if not q > 1.0:
        return float("nan"), float("nan")
    return math.log2(q), v3 - (v2 - v3) / (q - 1.0)


def table(rows: list[dict]) -> str:
    """A markdown table of :func:`study` rows."""
    lines = [
        "| case | pieces:across | panels | shape (% of size) | energy (mJ) | energy (%) "
        "| energy / cone "
        "| opening (N/m) | opening (%) | curvature relation (rel.) | reached | verdict "
        "| fold (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['pieces']}:{r['across']} | {r['panels']} | "
            f"{r['shape_pct']:.3g} | {1e3 * r['energy']:.4g} | {r['energy_pct']:.3g} | "
            f"{r['energy_cone']:.3f} | "
            f"{r['opening']:.4g} | {r['opening_pct']:.3g} | "
            f"{r['curvature']:.2e} | {100 * r['reached']:.0f} % | {r['verdict']} | "
            f"{r['seconds']:.1f} |"
        )
    return "\n".join(lines)


def shares_table(rows: list[dict]) -> str:
    """A markdown table of the energy shares (%, :func:`energy_shares`) of :func:`study` rows,
    the folded state's then the opening mode's, per level."""
    keys = sorted({k for r in rows for sh in r["shares"] for k in sh})
    lines = [
        "| case | pieces:across | state | " + " | ".join(keys) + " |",
        "|---|---|---|" + "---|" * len(keys),
    ]
    for r in rows:
        for name, sh in zip(("folded", "opening"), r["shares"], strict=True):
            cells = " | ".join(f"{100 * sh.get(k, 0.0):.1f}" for k in keys)
            lines.append(f"| {r['case']} | {r['pieces']}:{r['across']} | {name} | {cells} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", default=",".join(f"{p}:{a}" for p, a in LEVELS))
    ap.add_argument("--case", action="append", choices=sorted(CASES))
    ap.add_argument("--time-limit", type=float, default=None)
    args = ap.parse_args(argv)
    levels = [tuple(int(v) for v in s.split(":")) for s in args.levels.split(",")]
    for case in args.case or list(CASES):
        rows = study(case, levels, args.time_limit)
        print(table(rows))
        print(f"observed order, shape: {[round(v, 2) for v in orders(rows, 'shape_pct')]}; "
              f"energy: {[round(v, 2) for v in orders(rows, 'energy_pct')]}; "
              f"opening: {[round(v, 2) for v in orders(rows, 'opening_pct')]}")  # fmt: skip
        for key in ("energy", "opening"):
            p, lim = richardson(rows, key)
            print(f"Richardson from the last three levels, {key}: order {p:.2f}, limit {lim:.4g}")
        print(shares_table(rows))
        print()


if __name__ == "__main__":
    main()
