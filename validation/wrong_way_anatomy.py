"""Why crease patterns turn against their assignment: the anatomy of every wrong-way crease.

Folds Origami Simulator's example files the way ``validation/origami_simulator_examples.py``
does (200 mm, PP, 1 mm panels, 0.2 mm x 1 mm creases, concentrated hinges, contact off, the
intersection check on) and, for every driven crease that stands more than
``WRONG_WAY_DEG`` (10 deg) against its assignment at some stored state, reports:

* its assignment and target (deg), its length relative to the other driven creases at its
  two ends (with one section for every crease, a crease spring's stiffness is proportional to
  its length, so this is its stiffness relative to its neighbours);
* how far it goes against (deg, the largest over the path), the fraction at which it first
  stands more than 10 deg against, and where it stands after the first accepted step (the
  sign against the target: a branch taken at flat, or a later turn);
* its two end vertices: interior or on the border, Kawasaki's alternating sector sum and
  Maekawa's |M - V| over the driven creases of the flat layout, and the closure error of the
  full targets there (the rotation, deg, left by going round the vertex through its sectors
  and fold angles: 0 where the target state is compatible at the vertex);
* the detection checks: whether the edge is a facet or split edge (it never should be),
  whether its target is small (below 2 x 10 deg), whether an angle was unwrapped past
  +-180 deg on it, and the largest change of its angle between two stored states (a jump
  over 90 deg would make the unwrapping ambiguous).

Usage::

    python validation/wrong_way_anatomy.py /work/os-examples/assets [--limit 150] [--only crane]
        [--json out.json] [--option name=value ...]

``--option`` passes FoldSettings fields (``--option leave="staged"``) to compare remedies.
Prints one block per file; ``--json`` writes the records.
"""

from __future__ import annotations

import argparse
import ast
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from holofold.geometry import read_pattern
from holofold.mechanics import fold_pattern, scaled_pattern
from holofold.mechanics.folding import DRIVEN, WRONG_WAY_DEG, crease_classes, vertex_closure

SECTION = dict(panel_thickness=1e-3, crease_thickness=0.2e-3, crease_width=1e-3, E=1.5e9, nu=0.42)
SIZE = 0.2  # m

#: the 15 files of the acceptance run of 2026-12-07 that turn against their assignment
WRONG_WAY_FILES = (
    "Origami/flappingBird.svg",
    "Origami/traditionalCrane.svg",
    "Origami/flat_crane.svg",
    "Origami/langKnlDragon.svg",
    "Origami/langOrchid.svg",
    "Tessellations/langWedgeDoubleFaced.svg",
    "doc/simplePatterns.svg",
    "Tessellations/FTpoly7.svg",
    "Origami/MoosersTrainRigid-Gardner.svg",
    "Squaremaze/cross.svg",
    "Tessellations/langHoneycomb.svg",
    "Tessellations/HexTriFlatFoldableTess.svg",
    "Pleating/BoxPleatPyramid.fold",
    "Polygami/polygami.svg",
    "Squaremaze/origamisimulator.svg",
)


def vertex_table(p) -> dict:
    """Per vertex: interior?, Kawasaki error (deg), Maekawa |M-V|, closure error (deg) of the
    full targets, over the driven creases (M, V with a nonzero target) of the flat layout."""
    cls = crease_classes(p)
    xy = p.flat
    nv = p.n_vertices
    border = np.zeros(nv, bool)
    outer = ~p.interior
    border[p.edges[outer].ravel()] = True
    inc: list[list[int]] = [[] for _ in range(nv)]
    for e, (a, b) in enumerate(p.edges):
        inc[a].append(e)
        inc[b].append(e)
    closure = vertex_closure(p)
    out = {}
    for v in range(nv):
        es = [e for e in inc[v] if cls[e] == DRIVEN and p.fold_angle[e] != 0]
        if not es:
            continue
        other = [int(p.edges[e][1] if p.edges[e][0] == v else p.edges[e][0]) for e in es]
        ang = np.arctan2(xy[other, 1] - xy[v, 1], xy[other, 0] - xy[v, 0])
        order = np.argsort(ang)
        ang = ang[order]
        es = [es[i] for i in order]
        sect = np.diff(np.concatenate([ang, [ang[0] + 2 * math.pi]]))
        even = len(es) % 2 == 0
        kaw = float(np.degrees(abs(sect[0::2].sum() - sect[1::2].sum()))) if even else math.nan
        asg = p.assignment[es]
        mae = int(abs((asg == "M").sum() - (asg == "V").sum()))
        clo = float(closure[v])
        out[v] = dict(
            interior=not border[v], degree=len(es), kawasaki_deg=round(kaw, 3),
            maekawa=mae, closure_deg=round(clo, 2),
        )  # fmt: skip
    return out


def anatomy(path: Path, limit: float, **settings) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = read_pattern(path)
    p = scaled_pattern(p, SIZE / float(np.ptp(p.flat, axis=0).max()))
    t0 = time.process_time()
    r = fold_pattern(p, 1.0, time_limit=limit, **SECTION, **settings)
    cpu = time.process_time() - t0
    cls = crease_classes(r.pattern)
    tgt = r.target
    A = r.fold_angles  # (k, ne) unwrapped
    driven = (cls == DRIVEN) & (tgt != 0)
    against = -np.sign(tgt)[None] * A  # > 0: against the assignment
    bad = driven[None] & (against > WRONG_WAY_DEG)
    ever = np.flatnonzero(bad.any(axis=0))
    L = r.pattern.flat_edge_lengths
    k_edge = np.bincount(
        r.structure.spring_crease[r.structure.spring_crease >= 0],
        weights=r.structure.spring_k[r.structure.spring_crease >= 0],
        minlength=r.pattern.n_edges,
    )
    verts = vertex_table(r.pattern)
    inc: dict[int, list[int]] = {}
    for e in np.flatnonzero(driven):
        for v in r.pattern.edges[e]:
            inc.setdefault(int(v), []).append(int(e))
    first = A[1] if len(A) > 1 else A[0]
    # the crease springs' own dihedral angles in the last state (the hinge, not the panels'
    # mean normals): a second reading of every fold angle
    from holofold.mechanics.springs import dihedral_angle

    cm = r.structure.creases
    th = dihedral_angle(r.structure.nodes + r.U[-1], r.structure.springs)
    hinge = np.zeros(r.pattern.n_edges)
    hinge[cm.ids] = np.degrees(th[cm.springs[:, 0]] - np.pi)
    side1 = np.sign(first) * np.sign(tgt)
    creases = []
    for e in ever:
        nb = sorted({x for v in r.pattern.edges[e] for x in inc.get(int(v), []) if x != e})
        k_rel = float(k_edge[e] / np.median(k_edge[nb])) if nb else math.nan
        jumps = np.abs(np.diff(A[:, e])).max(initial=0.0)
        creases.append(
            dict(
                edge=int(e),
                assignment=str(r.pattern.assignment[e]),
                target_deg=round(float(tgt[e]), 2),
                against_max_deg=round(float(against[:, e].max()), 2),
                against_end_deg=round(float(against[-1, e]), 2),
                hinge_against_end_deg=round(float(-np.sign(tgt[e]) * hinge[e]), 2),
                first_at=round(float(r.fractions[np.flatnonzero(bad[:, e])[0]]), 4),
                step1_deg=round(float(first[e] * np.sign(tgt[e])), 4),
                step1_side=int(side1[e]),
                stiffness_rel=round(k_rel, 3),
                length_mm=round(1e3 * float(L[e]), 2),
                ends=[dict(vertex=int(v), **verts.get(int(v), {})) for v in r.pattern.edges[e]],
                small_target=bool(abs(tgt[e]) < 2 * WRONG_WAY_DEG),
                unwrapped=bool(np.abs(A[:, e]).max() > 180.0),
                max_jump_deg=round(float(jumps), 2),
                facet=bool(r.pattern.assignment[e] in ("F", "J")),
            )
        )
    nd = int(driven.sum())
    vint = [d for d in verts.values() if d["interior"]]
    return dict(
        file=path.relative_to(path.parents[1]).as_posix(),
        driven=nd,
        verdict=r.verdict,
        reached=round(r.reached, 4),
        wrong_end=int(r.wrong_way.size),
        wrong_ever=int(ever.size),
        wrong_at=round(r.wrong_at, 4) if np.isfinite(r.wrong_at) else None,
        step1_against=int(((side1 < 0) & driven).sum()),
        step1_flat=int(((np.abs(first) < 1e-3) & driven).sum()),
        interior_vertices=len(vint),
        kawasaki_bad=sum(1 for d in vint if not d["kawasaki_deg"] <= 0.01),
        maekawa_bad=sum(1 for d in vint if d["maekawa"] != 2),
        closure_bad=sum(1 for d in vint if d["closure_deg"] > 0.5),
        touch_at=round(r.touch_at, 4) if np.isfinite(r.touch_at) else None,
        cpu_s=round(cpu, 1),
        steps=len(r.fractions) - 1,
        note=r.note,
        creases=creases,
    )


def report(rec: dict) -> str:
    lines = [
        f"## {rec['file']}: {rec['verdict']} at {100 * rec['reached']:.1f} %, "
        f"{rec['wrong_end']} wrong at the end, {rec['wrong_ever']} ever, first at "
        f"{rec['wrong_at']}; {rec['driven']} driven; after step 1 {rec['step1_against']} against, "
        f"{rec['step1_flat']} flat; interior vertices {rec['interior_vertices']} "
        f"(Kawasaki off {rec['kawasaki_bad']}, Maekawa off {rec['maekawa_bad']}, "
        f"targets not closing {rec['closure_bad']}); {rec['cpu_s']} CPU s"
    ]
    for c in rec["creases"]:
        ends = "; ".join(
            f"v{d['vertex']} {'int' if d.get('interior') else 'border'} deg{d.get('degree')} "
            f"K{d.get('kawasaki_deg')} M{d.get('maekawa')} C{d.get('closure_deg')}"
            for d in c["ends"]
        )
        lines.append(
            f"  e{c['edge']} {c['assignment']} tgt {c['target_deg']} against max "
            f"{c['against_max_deg']} end {c['against_end_deg']} "
            f"(hinge {c['hinge_against_end_deg']}) "
            f"from {c['first_at']} "
            f"step1 {c['step1_deg']} k/nb {c['stiffness_rel']} L {c['length_mm']} mm "
            f"small {c['small_target']} unwrapped {c['unwrapped']} jump {c['max_jump_deg']} "
            f"| {ends}"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("root", type=Path, help="Origami Simulator's assets folder")
    ap.add_argument("--limit", type=float, default=150.0, help="wall seconds per fold")
    ap.add_argument("--only", action="append", default=[], help="files containing this")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--option", action="append", default=[], help="FoldSettings field=value")
    args = ap.parse_args(argv)
    opts = {}
    for o in args.option:
        k, v = o.split("=", 1)
        try:
            opts[k] = ast.literal_eval(v)
        except (ValueError, SyntaxError):
            opts[k] = v
    files = [f for f in WRONG_WAY_FILES if not args.only or any(s in f for s in args.only)]
    recs = []
    for f in files:
        path = args.root / f
        rec = anatomy(path, args.limit, **opts)
        recs.append(rec)
        print(report(rec), flush=True)
        if args.json:
            args.json.write_text(json.dumps(recs, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
