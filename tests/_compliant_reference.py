"""The compliant-crease builder before issue 37, kept as the reference of the vectorised one.

A verbatim copy of ``build_compliant``'s per-corner and per-crease loops (commit de38fbf),
for tests/test_hinges_vectorised.py only.
"""

import numpy as np

from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.compat import PAPER, Profile
from holofold.mechanics.hinges import (
    _edge_faces,
    _edge_ids,
    _flat_faces,
    _panel_width,
    _per_item,
    _scalar,
    orient_springs,
)
from holofold.mechanics.springs import dihedral_angle
from holofold.mechanics.structure import (
    COMPLIANT,
    BarType,
    CreaseModel,
    SpringRole,
    Structure,
)


def _topology(pattern: CreasePattern) -> dict:
    """Index arrays of a pattern's faces and edges (cached per pattern object).

    ``side[q]`` is the edge joining corner q to the next corner of its face.
    """
    if True:
        sizes, verts, start, face, nxt, prv = _flat_faces(pattern)
        side = _edge_ids(pattern, verts, verts[nxt])
        first, last, count = _edge_faces(pattern, side, face)
        topo = dict(
            sizes=sizes,
            verts=verts,
            face=face,
            nxt=nxt,
            prv=prv,
            side=side,
            first=first,
            last=last,
            interior=count == 2,
        )
    return topo


def _unit(v):
    return v / np.linalg.norm(v)


def reference_build_compliant(
    pattern: CreasePattern,
    *,
    crease_width,
    crease_thickness,
    panel_thickness,
    E_panel: float,
    E_crease: float,
    nu_panel: float,
    nu_crease: float,
    panel_width=None,
    diagonal_rate: float = 4.0,
    split_factor: float = 0.5,
    profile: Profile = PAPER,
) -> Structure:
    """build_compliant as it was before issue 37 (per-corner, per-crease loops)."""
    E_panel = _scalar(E_panel, "E_panel", 0.0, None, low_open=True)
    E_crease = _scalar(E_crease, "E_crease", 0.0, None, low_open=True)
    nu_panel = _scalar(nu_panel, "nu_panel", -1.0, 0.5, low_open=True, high_open=True)
    nu_crease = _scalar(nu_crease, "nu_crease", -1.0, 0.5, low_open=True, high_open=True)
    diagonal_rate = _scalar(diagonal_rate, "diagonal_rate", 0.0, None, low_open=True)
    split_factor = _scalar(split_factor, "split_factor", 0.0, 1.0)
    ne, nf = pattern.n_edges, pattern.n_faces
    t = _topology(pattern)
    sizes, verts, face, nxt, prv = t["sizes"], t["verts"], t["face"], t["nxt"], t["prv"]
    side_edge = t["side"][prv]  # side j joins C(j-1)-C(j)
    interior = t["interior"]
    W = _per_item(crease_width, ne, "crease_width", interior)
    tc = _per_item(crease_thickness, ne, "crease_thickness", interior)
    tp = _per_item(panel_thickness, nf, "panel_thickness")
    X = pattern.coords

    # A. shrunk panel copies (one node per corner, numbered like the corners)
    nc0 = len(verts)
    corner = X[verts].copy()
    for q in range(nc0):
        e_prev = side_edge[q]  # C(j-1)-C(j)
        e_next = side_edge[nxt[q]]  # C(j)-C(j+1)
        cp, cn = interior[e_prev], interior[e_next]
        if not (cp or cn):
            continue
        p = X[verts[q]]
        v1 = _unit(X[verts[nxt[q]]] - p)  # towards the next vertex
        v2 = _unit(X[verts[prv[q]]] - p)  # towards the previous vertex
        sin_b = np.linalg.norm(np.cross(v1, v2))
        if sin_b <= 1e-12:
            continue  # collinear sides: not moved
        if cp and cn:
            W1, W2 = W[e_next], W[e_prev]
            off = 0.5 * W1 * v2 + 0.5 * W2 * v1
            if not profile.approximate_corner_offset:
                off = off / sin_b
        elif cp:  # crease on the previous side: slide along the next side
            off = W[e_prev] / (2.0 * sin_b) * v1
        else:
            off = W[e_next] / (2.0 * sin_b) * v2
        corner[q] = p + off
    # perimeter bars: bar q joins corner nodes prv[q] and q
    perim = np.sort(np.column_stack([prv, np.arange(nc0)]), axis=1)

    # B. crease regions
    cid = np.flatnonzero(interior)
    nci = len(cid)
    side_of = {}
    for q in range(nc0):
        side_of.setdefault(int(side_edge[q]), []).append(q)
    new_nodes = []
    crease_nodes = np.zeros((nci, 7), np.intp)
    cbars, cbar_type, cbar_slot_spring = [], [], []
    ctris = []
    crease_edge_bars = np.zeros((nci, 2), np.intp)
    for r, e in enumerate(cid):
        b1, b2 = side_of[int(e)]  # earlier panel first (corners are in panel order)
        n11, n12 = perim[b1]
        n21, n22 = perim[b2]
        if np.linalg.norm(corner[n11] - corner[n21]) > np.linalg.norm(corner[n11] - corner[n22]):
            n21, n22 = n22, n21
        p1 = 0.5 * (corner[n11] + corner[n21])
        p2 = 0.5 * (corner[n12] + corner[n22])
        c = 0.25 * (corner[n11] + corner[n12] + corner[n21] + corner[n22])
        base = nc0 + 3 * r
        ip1, ip2, ic = base, base + 1, base + 2
        new_nodes += [p1, p2, c]
        crease_nodes[r] = [n11, n12, n21, n22, ip1, ip2, ic]
        crease_edge_bars[r] = [b1, b2]
        rows = [
            (2, (n11, ip1), None),
            (3, (n11, ic), (n12, ic, n11, ip1)),
            (3, (n12, ic), (ip2, ic, n12, n11)),
            (2, (n12, ip2), None),
            (4, (ip1, ic), (n11, ic, ip1, n21)),
            (4, (ip2, ic), (n12, ip2, ic, n22)),
            (2, (n21, ip1), None),
            (3, (n21, ic), (ip1, ic, n21, n22)),
            (3, (n22, ic), (ip2, n22, ic, n21)),
            (2, (n22, ip2), None),
        ]
        for t, bar, spr in rows:
            cbars.append(sorted(bar))
            cbar_type.append(t)
            cbar_slot_spring.append(spr)
        ctris += [
            (ic, ip1, n11),
            (n21, ip1, ic),
            (n21, ic, n22),
            (n22, ip2, ic),
            (n12, ic, ip2),
            (n12, ic, n11),
        ]
    n_cnodes = nc0 + 3 * nci

    # C. panel fans (centres of the shrunk panels)
    centres = np.zeros((nf, 3))
    np.add.at(centres, face, corner)
    centres /= sizes[:, None]
    cnode = n_cnodes + face
    nodes = np.vstack([corner, np.array(new_nodes).reshape(-1, 3), centres])
    spokes = np.column_stack([np.arange(nc0), cnode])
    bars = np.vstack([perim, np.array(cbars, np.intp).reshape(-1, 2), spokes])
    L = np.linalg.norm(nodes[bars[:, 1]] - nodes[bars[:, 0]], axis=1)
    nb = len(bars)
    b_crease0 = nc0
    b_spoke0 = nc0 + 10 * nci
    bar_type = np.concatenate(
        [
            np.full(nc0, BarType.PANEL_EDGE, np.int8),
            np.array(cbar_type, np.int8),
            np.full(nc0, BarType.PANEL_SPOKE, np.int8),
        ]
    )

    # springs by slot (bar id)
    slot_spr = np.full((nb, 4), -1, np.intp)
    for r in range(nci):
        n11, n12, n21, n22, ip1, ip2, ic = crease_nodes[r]
        b1, b2 = crease_edge_bars[r]
        slot_spr[b1] = (ic, n11, n12, cnode[b1])
        slot_spr[b2] = (ic, n22, n21, cnode[b2])
        for t in range(10):
            s = cbar_slot_spring[10 * r + t]
            if s is not None:
                slot_spr[b_crease0 + 10 * r + t] = s
    slot_spr[b_spoke0:] = np.column_stack([prv, np.arange(nc0), cnode, nxt])
    slots = np.flatnonzero(slot_spr[:, 0] >= 0)
    slot_to_spring = np.full(nb, -1, np.intp)
    slot_to_spring[slots] = np.arange(len(slots))
    crease_springs = np.zeros((nci, 8), np.intp)
    crease_springs[:, 0] = slot_to_spring[crease_edge_bars[:, 0]]
    crease_springs[:, 1] = slot_to_spring[crease_edge_bars[:, 1]]
    for col, t in zip(range(2, 8), (1, 2, 4, 5, 7, 8), strict=True):
        crease_springs[:, col] = slot_to_spring[b_crease0 + 10 * np.arange(nci) + t]
    orient = np.ones(len(slots), bool)
    if profile.raw_crease_polarity:  # the reference's raw crease springs (compat)
        orient[crease_springs.ravel()] = False
    springs = orient_springs(nodes, slot_spr[slots], z_only=profile.polarity_z_only, where=orient)

    # stiffness and areas
    ell = L[crease_edge_bars[:, 0]] if nci else np.zeros(0)
    Wc, tcc = W[cid], tc[cid]
    k1 = E_crease * tcc**3 / (4.0 * Wc)
    spring_k = np.zeros(len(slots))
    role = np.full(len(slots), SpringRole.PANEL, np.int8)
    crease_of = np.full(len(slots), -1, np.intp)
    spring_k[crease_springs[:, :2]] = (k1[:, None] * L[crease_edge_bars]).reshape(nci, 2)
    role[crease_springs[:, :2]] = SpringRole.CREASE_EDGE
    cb = b_crease0 + 10 * np.arange(nci)
    for col, t, rl in (
        (2, 1, SpringRole.CREASE_DIAGONAL),
        (3, 2, SpringRole.CREASE_DIAGONAL),
        (4, 4, SpringRole.CREASE_CENTRE),
        (5, 5, SpringRole.CREASE_CENTRE),
        (6, 7, SpringRole.CREASE_DIAGONAL),
        (7, 8, SpringRole.CREASE_DIAGONAL),
    ):
        rate = diagonal_rate if rl == SpringRole.CREASE_DIAGONAL else 1.0
        spring_k[crease_springs[:, col]] = rate * k1 * L[cb + t]
        role[crease_springs[:, col]] = rl
    crease_of[crease_springs.ravel()] = np.repeat(cid, 8)
    spk_slots = slots >= b_spoke0
    spoke_len = L[b_spoke0:]
    w = _panel_width(profile, panel_width, W, interior, nf, spoke_len, face)
    spring_k[spk_slots] = E_panel * tp[face] ** 3 * spoke_len / (12.0 * w)

    tri_area = 0.5 * np.linalg.norm(
        np.cross(corner - centres[face], corner[nxt] - centres[face]), axis=1
    )
    area = np.bincount(face, weights=tri_area, minlength=nf)
    per = np.bincount(face, weights=L[:nc0] + spoke_len, minlength=nf)
    A_p = 2.0 * tp * area / ((1.0 - nu_panel) * per)
    bar_area = np.zeros(nb)
    bar_area[:nc0] = A_p[face]
    bar_area[b_spoke0:] = A_p[face]
    A1 = ell * tcc / (2.0 * (1.0 - nu_crease**2))
    A2 = (ell**2 + Wc**2) ** 1.5 * tcc / (4.0 * (1.0 + nu_crease) * ell * Wc)
    for t in range(10):
        bar_area[cb + t] = A1 if cbar_type[t] == 2 else A2
    bar_E = np.where(np.isin(bar_type, (1, 5)), E_panel, E_crease)

    triangles = np.vstack(
        [np.array(ctris, np.intp).reshape(-1, 3), np.column_stack([cnode, np.arange(nc0), nxt])]
    )
    nct = 6 * nci
    node_vertex = np.concatenate([verts, np.full(3 * nci, -1), np.full(nf, -2)])
    return Structure(
        nodes=nodes,
        bars=bars,
        bar_area=bar_area,
        bar_E=bar_E,
        bar_length=L,
        bar_type=bar_type,
        springs=springs,
        spring_k=spring_k,
        spring_rest=dihedral_angle(nodes, springs),
        spring_role=role,
        spring_crease=crease_of,
        triangles=triangles,
        tri_thickness=np.concatenate([np.repeat(tcc, 6), tp[face]]),
        tri_crease=np.concatenate([np.repeat(cid, 6), np.full(nc0, -1)]),
        tri_panel=np.concatenate([np.full(nct, -1), face]),
        creases=CreaseModel(
            kind=COMPLIANT,
            ids=cid,
            springs=crease_springs,
            nodes=crease_nodes,
            split_factor=split_factor,
        ),
        panel_centres=n_cnodes + np.arange(nf),
        node_vertex=node_vertex,
        profile=profile,
    )
