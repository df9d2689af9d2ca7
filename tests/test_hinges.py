"""Builders of the bar-and-hinge models: numbering, counts, formulas, stress-free state."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from holofold.geometry.errors import ParameterError
from holofold.geometry.miura import miura_sheet_paper
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.compat import PAPER, PHYSICAL
from holofold.mechanics.hinges import (
    build_compliant,
    build_concentrated,
    build_concentrated_batch,
    crease_rest_targets,
    orient_springs,
)
from holofold.mechanics.solvers import solve_newton
from holofold.mechanics.springs import dihedral_angle
from holofold.mechanics.structure import SpringRole, Structure, support_mask

MAT = dict(E_panel=2e9, E_crease=2e9, nu_panel=0.3, nu_crease=0.3)


def four_vertex(z_centre: float = 0.0) -> CreasePattern:
    """The 3 x 3-vertex, 4-panel pattern whose creases number like SWOMPS' 4-vertex example.

    Faces (1-based) [2,5,4,1], [5,2,3,6], [7,4,5,8], [6,9,8,5]: interior creases 2, 3, 5, 10
    in discovery order, central vertex 5 at local positions 2, 1, 3, 4 of the four panels.
    """
    X = np.array(
        [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0], [0, 2, 0], [1, 2, 0],
         [2, 2, 0]],
        float,
    )  # fmt: skip
    X[4, 2] = z_centre
    faces = [np.array(f) - 1 for f in ([2, 5, 4, 1], [5, 2, 3, 6], [7, 4, 5, 8], [6, 9, 8, 5])]
    return CreasePattern.from_faces(X, faces)


def miura_cell(ext=0.6, gamma=1.1):
    return miura_sheet_paper(2, 2, 0.04, gamma, ext)


# ----------------------------------------------------------------------------- compliant
def test_compliant_four_vertex_counts_and_numbering():
    p = four_vertex()
    assert (np.flatnonzero(p.interior) + 1).tolist() == [2, 3, 5, 10]
    s = build_compliant(p, crease_width=0.1, crease_thickness=1e-3, panel_thickness=1e-2, **MAT)
    assert s.n_nodes == 32
    assert len(s.bars) == 16 + 40 + 16 == 72
    assert len(s.springs) == 48
    assert np.bincount(s.spring_role, minlength=5).tolist() == [0, 16, 8, 8, 16]
    cn = s.creases.nodes + 1  # 1-based like the reference
    assert cn[:, 4:].tolist() == [[17, 18, 19], [20, 21, 22], [23, 24, 25], [26, 27, 28]]
    assert (s.panel_centres + 1).tolist() == [29, 30, 31, 32]
    # the four copies of the central vertex are the example's supports 2, 5, 11, 16
    assert (np.flatnonzero(s.node_vertex == 4) + 1).tolist() == [2, 5, 11, 16]
    assert (s.creases.ids + 1).tolist() == [2, 3, 5, 10]
    # crease_springs columns sit on the right bars
    spr = s.springs[s.creases.springs]
    hinge = np.sort(spr[:, :, 1:3], axis=2)
    n11, n12, n21, n22, p1, p2, c = s.creases.nodes.T
    assert np.array_equal(hinge[:, 0], np.sort(np.stack([n11, n12], 1), 1))
    assert np.array_equal(hinge[:, 1], np.sort(np.stack([n21, n22], 1), 1))
    assert np.array_equal(hinge[:, 2], np.sort(np.stack([n11, c], 1), 1))
    assert np.array_equal(hinge[:, 4], np.sort(np.stack([p1, c], 1), 1))
    assert np.array_equal(hinge[:, 7], np.sort(np.stack([n22, c], 1), 1))
    # triangles: 6 per crease first, then 16 fan triangles
    assert len(s.triangles) == 24 + 16
    assert (s.tri_crease[:24] >= 0).all() and (s.tri_panel[24:] >= 0).all()


def test_compliant_shrinks_panels_by_half_width():
    s = build_compliant(
        four_vertex(), crease_width=0.1, crease_thickness=1e-3, panel_thickness=1e-2, **MAT
    )
    # panel 1 = [2,5,4,1]: the central corner moves to (0.95, 0.95), the others by 0.05 once
    assert np.allclose(s.nodes[:4, :2], [[0.95, 0], [0.95, 0.95], [0, 0.95], [0, 0]])
    # crease strip: N11..N22 at distance W/2 from the crease line x = 1 (crease 2 = (2,5))
    n11, n12, n21, n22 = s.creases.nodes[0, :4]
    assert np.allclose(sorted(s.nodes[[n11, n12, n21, n22], 0]), [0.95, 0.95, 1.05, 1.05])


def test_compliant_corner_offset_profiles():
    """A 60-degree corner between two creases: exact offset = approximate / sin(beta)."""
    X = np.array([[0, 0, 0], [1, 0, 0], [0.5, math.sqrt(3) / 2, 0], [1.5, math.sqrt(3) / 2, 0],
                  [-0.5, math.sqrt(3) / 2, 0]])  # fmt: skip
    faces = [[0, 1, 2], [1, 3, 2], [0, 2, 4]]
    p = CreasePattern.from_faces(X, faces)
    kw = dict(crease_width=0.02, crease_thickness=1e-4, panel_thickness=1e-3, **MAT)
    a = build_compliant(p, profile=PAPER, **kw)
    e = build_compliant(p, profile=PHYSICAL, **kw)
    # corner 2 of panel 0 (vertex 2) lies between creases (1,2) and (0,2)
    d_app = np.linalg.norm(a.nodes[2] - X[2])
    d_ex = np.linalg.norm(e.nodes[2] - X[2])
    assert d_ex == pytest.approx(d_app / math.sin(math.radians(60)), rel=1e-12)
    # exact: distance W/2 to both crease lines
    for u, v in ((1, 2), (0, 2)):
        t = (X[v] - X[u]) / np.linalg.norm(X[v] - X[u])
        r = e.nodes[2] - X[u]
        assert np.linalg.norm(r - (r @ t) * t) == pytest.approx(0.01, rel=1e-12)


def test_compliant_areas_and_stiffness_formulas():
    W, tc, tp = 0.1, 1e-3, 1e-2
    s = build_compliant(four_vertex(), crease_width=W, crease_thickness=tc, panel_thickness=tp,
                        diagonal_rate=4.0, **MAT)  # fmt: skip
    Ec, nu = 2e9, 0.3
    cs = s.creases.springs[0]
    ell = 0.95
    k1 = Ec * tc**3 / (4 * W)
    L = np.linalg.norm(s.nodes[s.springs[:, 2]] - s.nodes[s.springs[:, 1]], axis=1)
    assert s.spring_k[cs[0]] == pytest.approx(k1 * ell)
    assert s.spring_k[cs[4]] == pytest.approx(k1 * L[cs[4]])
    assert s.spring_k[cs[2]] == pytest.approx(4 * k1 * L[cs[2]])
    # three spring lines in series: E t^3 l / (12 W)
    lines = [s.spring_k[cs[0]], s.spring_k[cs[1]], s.spring_k[cs[4]] + s.spring_k[cs[5]]]
    assert 1 / sum(1 / k for k in lines) == pytest.approx(Ec * tc**3 * ell / (12 * W))
    A1 = ell * tc / (2 * (1 - nu**2))
    A2 = (ell**2 + W**2) ** 1.5 * tc / (4 * (1 + nu) * ell * W)
    crease_bars = s.bar_type[16:26]
    assert np.allclose(s.bar_area[16:26][crease_bars == 2], A1)
    assert np.allclose(s.bar_area[16:26][crease_bars != 2], A2)
    # panel bars: sum A_b L_b = 2 t A / (1 - nu) per panel (Filipov et al. 2017)
    panel0 = np.r_[0:4, 56:60]
    area = 0.95 * 0.95
    assert (s.bar_area[panel0] * s.bar_length[panel0]).sum() == pytest.approx(
        2 * tp * area / (1 - nu)
    )
    assert np.allclose(s.bar_E, 2e9)


def test_compliant_single_fold_stiffness():
    """Two panels, one compliant crease: fold stiffness ~ E t^3 l / (12 W) (bar-and-hinge §4.4)."""
    a, W, tc, tp = 0.01, 1e-3, 1e-4, 2e-3
    X = np.array([[0, 0, 0], [a, 0, 0], [a, a, 0], [0, a, 0], [2 * a, 0, 0], [2 * a, a, 0]])
    p = CreasePattern.from_faces(X, [[0, 1, 2, 3], [1, 4, 5, 2]])
    s = build_compliant(p, crease_width=W, crease_thickness=tc, panel_thickness=tp,
                        diagonal_rate=1000.0, panel_width=W, **MAT)  # fmt: skip
    sup = np.zeros((s.n_nodes, 3), bool)
    sup[:4] = True  # panel 1 corners
    s = s.with_supports(sup)
    far = [i for i in range(4, 8) if np.isclose(s.nodes[i, 0], 2 * a)]
    near = [i for i in range(4, 8) if not np.isclose(s.nodes[i, 0], 2 * a)]
    F = 1e-6
    load = np.zeros((s.n_nodes, 3))
    load[far, 2] = F / 2
    r = solve_newton(s, load, increments=1, tol=1e-14)
    assert r.ok
    U = r.U
    xc = a  # crease centre line
    arm = 2 * a - xc
    # rotation of panel 2 from its two edges (it is much stiffer than the crease)
    rot = (U[far, 2].mean() - U[near, 2].mean()) / (
        s.nodes[far, 0].mean() - s.nodes[near, 0].mean()
    )
    k_fold = F * arm / rot
    ell = a
    expected = 2e9 * tc**3 * ell / (12 * W)
    assert k_fold == pytest.approx(expected, rel=0.01)


# ----------------------------------------------------------------------------- concentrated
def test_concentrated_miura_cell_counts():
    p = miura_cell()
    s = build_concentrated(p, crease_width=2e-3, crease_thickness=7e-4, panel_thickness=3e-3)
    assert s.n_nodes == 13 and len(s.bars) == 28
    assert np.array_equal(s.bars[:12], p.edges)  # bar i == crease i
    assert len(s.springs) == 4 + 16
    assert (s.spring_role[:4] == SpringRole.HINGE).all()
    assert np.array_equal(s.spring_crease[:4], np.flatnonzero(p.interior))
    assert len(s.triangles) == 16
    assert np.allclose(s.nodes[9:], [s.nodes[f].mean(0) for f in p.faces])


def test_concentrated_formulas_and_area_quirk():
    p = four_vertex()
    X = p.coords.copy()  # make the panels unequal: stretch the top row
    X[6:, 1] = 3.0
    p = CreasePattern.from_faces(X, list(p.faces))
    W, tc, tp, E = 2e-3, 1e-3, 5e-3, 2e9
    s = build_concentrated(p, crease_width=W, crease_thickness=tc, panel_thickness=tp)
    q = build_concentrated(p, crease_width=W, crease_thickness=tc, panel_thickness=tp,
                           profile=PHYSICAL)  # fmt: skip
    areas = np.array([1, 1, 2, 2.0])
    spokes = np.array([4 * math.sqrt(0.5), 4 * math.sqrt(0.5), 4 * math.sqrt(1.25),
                       4 * math.sqrt(1.25)])  # fmt: skip
    perim = np.array([4, 4, 6, 6.0])
    Ap = 2 * tp * areas / (0.7 * (perim + spokes))
    edges = p.edges
    # PAPER: every edge bar gets 2 A_p of the last panel using it; PHYSICAL: the sum
    users = [[f for f, face in enumerate(p.faces) if set(e) <= set(face.tolist())] for e in edges]
    assert np.allclose(s.bar_area[:12], [2 * Ap[max(u)] for u in users])
    assert np.allclose(q.bar_area[:12], [Ap[u].sum() for u in users])
    assert np.allclose(s.bar_area[12:], np.repeat(Ap, 4))
    L = p.edge_lengths
    cid = np.flatnonzero(p.interior)
    assert np.allclose(s.spring_k[:4], E * tc**3 * L[cid] / (12 * W))
    # panel springs: w = crease width (paper) or the panel's mean spoke length (physical)
    ls = s.bar_length[12:]
    assert np.allclose(s.spring_k[4:], E * tp**3 * ls / (12 * W))
    assert np.allclose(q.spring_k[4:], E * tp**3 * ls / (12 * np.repeat(spokes / 4, 4)))


@pytest.mark.parametrize("builder", ["concentrated", "compliant"])
def test_flat_pattern_rest_angles_are_pi(builder):
    p = four_vertex()
    kw = dict(crease_width=0.05, crease_thickness=1e-3, panel_thickness=1e-2)
    s = (
        build_concentrated(p, **kw)
        if builder == "concentrated"
        else build_compliant(p, **kw, **MAT)
    )
    assert np.allclose(s.spring_rest, np.pi, atol=1e-14)


@pytest.mark.parametrize("builder", ["concentrated", "compliant"])
def test_as_built_state_is_stress_free(builder):
    p = miura_cell(0.5)
    kw = dict(crease_width=1e-3, crease_thickness=7e-4, panel_thickness=3e-3)
    s = (
        build_concentrated(p, **kw)
        if builder == "concentrated"
        else build_compliant(p, **kw, **MAT)
    )
    assert np.allclose(s.spring_rest, dihedral_angle(s.nodes, s.springs), atol=0)
    energy, f, _ = Assembler(s).evaluate(np.zeros((s.n_nodes, 3)))
    # zero to round-off: the kernels' angles may differ from dihedral_angle's in the last bit
    # (libm's atan2 against numpy's SIMD arctan2), ~1e-16 rad per spring; the scales are the
    # energy and the force of a 1 rad rotation of the stiffest spring
    k, L = s.spring_k.max(), s.bar_length.min()
    assert 0.0 <= energy <= 1e-24 * k
    assert np.abs(f).max() <= 1e-12 * k / L
    assert not np.allclose(s.spring_rest[s.spring_role != SpringRole.PANEL], np.pi)


def test_polarity_valley_towards_plus_z():
    """Lifting the centre vertex of the flat 4-vertex pattern folds creases; theta > pi for
    wings rotating towards +z (the m vector of every spring points to +z)."""
    s = build_concentrated(four_vertex(), crease_width=1e-3, crease_thickness=1e-3,
                           panel_thickness=1e-3)  # fmt: skip
    x = s.nodes
    sp = s.springs
    m = np.cross(x[sp[:, 0]] - x[sp[:, 1]], x[sp[:, 2]] - x[sp[:, 1]])
    assert (m[:, 2] >= 0).all()
    # rotate panel 2 (right-bottom) about crease (2,5) -- x = 1 -- towards +z
    y = x.copy()
    right = x[:, 0] > 1 + 1e-9
    y[right, 2] += 0.1 * (x[right, 0] - 1)
    th = dihedral_angle(y, sp[:1])
    assert th[0] > np.pi


def test_orient_springs_fallback():
    x = np.array([[1, 0, 0.5], [0, 0, 0], [0, 0, 1.0], [0, 1, 0.5]])
    spr = np.array([[0, 1, 2, 3]])
    assert np.array_equal(orient_springs(x, spr, z_only=True), spr)  # z component is 0
    v = np.cross(x[1] - x[0], x[2] - x[1])
    out = orient_springs(x, spr, z_only=False)
    assert v[1] > 0 and out.tolist() == [[3, 1, 2, 0]]


def test_crease_rest_targets():
    p = miura_cell(0.7)
    s = build_compliant(p, crease_width=1e-3, crease_thickness=5e-4, panel_thickness=2e-3,
                        split_factor=0.5, **MAT)  # fmt: skip
    theta = np.full(p.n_edges, 2.0)
    t = crease_rest_targets(s, theta)
    cs = s.creases.springs
    assert np.allclose(t[cs[:, :2]], np.pi + 0.25 * (2.0 - np.pi))
    assert np.allclose(t[cs[:, 4:6]], np.pi + 0.5 * (2.0 - np.pi))
    rest = np.setdiff1d(np.arange(len(t)), cs[:, [0, 1, 4, 5]].ravel())
    assert np.allclose(t[rest], np.pi)  # paper: everything else reset to flat
    t2 = crease_rest_targets(s, theta, profile=PHYSICAL)
    assert np.allclose(t2[rest], s.spring_rest[rest])
    c = build_concentrated(p, crease_width=1e-3, crease_thickness=5e-4, panel_thickness=2e-3)
    tc = crease_rest_targets(c, theta)
    assert np.allclose(tc[:4], 2.0) and np.allclose(tc[4:], np.pi)


def test_bad_parameters_raise():
    p = miura_cell()
    with pytest.raises(ParameterError, match="crease_width"):
        build_concentrated(p, crease_width=-1e-3, crease_thickness=1e-3, panel_thickness=1e-3)
    with pytest.raises(ParameterError, match="panel_thickness"):
        build_concentrated(p, crease_width=1e-3, crease_thickness=1e-3, panel_thickness=[1, 2])
    with pytest.raises(ParameterError, match="nu_panel"):
        build_concentrated(p, crease_width=1e-3, crease_thickness=1e-3, panel_thickness=1e-3,
                           nu_panel=0.5)  # fmt: skip
    with pytest.raises(ParameterError, match="coords"):
        build_concentrated(p, crease_width=1e-3, crease_thickness=1e-3, panel_thickness=1e-3,
                           coords=np.zeros((3, 3)))  # fmt: skip
    # per-edge values: only interior creases are checked
    w = np.where(p.interior, 1e-3, 0.0)
    s = build_concentrated(p, crease_width=w, crease_thickness=1e-3, panel_thickness=1e-3)
    assert np.isfinite(s.spring_k).all()


def test_compliant_gripper_numbering_matches_the_reference_scripts():
    """Node ids the gripper scripts use (docs/scenarios.md §4.2), 1-based."""
    gripper = pytest.importorskip("holofold.geometry.gripper")
    kw = dict(crease_width=2e-4, crease_thickness=1e-6, panel_thickness=1e-5, **MAT)
    s = build_compliant(gripper.miura_based_gripper(5e-3, 4e-3, 0.4).pattern, **kw)
    assert (s.n_nodes, len(s.bars)) == (83, 198)
    assert (s.creases.ids + 1).tolist() == [1, 2, 3, 4, 5, 6, 8, 9, 12, 14, 15, 17, 19]
    nv = s.node_vertex

    def copies(v):  # 1-based ids of the copies of 1-based old vertex v
        return (np.flatnonzero(nv == v - 1) + 1).tolist()

    assert copies(1)[:2] == [1, 4] and copies(2)[:2] == [3, 5]
    assert copies(3) == [2, 8, 24] and copies(4) == [6, 14, 27]
    assert copies(8) == [16, 19] and copies(12) == [29, 32]
    assert (s.panel_centres[:2] + 1).tolist() == [74, 75]
    cid = s.creases.ids.tolist()
    assert s.creases.nodes[[cid.index(11), cid.index(18)], 4].tolist() == [58, 70]
    s2 = build_compliant(gripper.splitted_miura_gripper(5e-3, 4e-3, 0.4).pattern, **kw)
    assert (s2.n_nodes, len(s2.bars), len(s2.creases.ids)) == (141, 340, 22)
    assert (s2.panel_centres[0] + 1) == 127
    s3 = build_compliant(gripper.two_panel_gripper(5e-3, 4e-3, 0.4).pattern, **kw)
    assert (s3.n_nodes, len(s3.bars)) == (37, 80)
    assert (s3.creases.ids + 1).tolist() == [2, 4, 7, 12]


def test_supports_and_vertex_nodes_by_name():
    """Structure.fixed fixes named nodes' DOFs; vertex_nodes finds every copy of a vertex."""
    p = four_vertex()
    c = build_concentrated(p, crease_width=1e-3, crease_thickness=1e-3, panel_thickness=1e-3)
    f = c.fixed([0, 2], "xz")
    assert f.supports.sum() == 4 and f.supports[0].tolist() == [True, False, True]
    g = c.fixed([([0], "xyz"), ([3], "y")])
    assert g.supports.sum() == 4 and g.supports[3].tolist() == [False, True, False]
    assert c.vertex_nodes([4]).tolist() == [4]  # concentrated: vertex v is node v
    s = build_compliant(p, crease_width=0.1, crease_thickness=1e-3, panel_thickness=1e-2, **MAT)
    copies = s.vertex_nodes(4)
    assert len(copies) == 4 and np.all(s.node_vertex[copies] == 4)
    np.testing.assert_allclose(s.nodes[copies].mean(axis=0), p.coords[4], atol=1e-12)
    with pytest.raises(ValueError, match="dofs"):
        c.fixed([0], "w")
    with pytest.raises(ValueError, match="outside"):
        c.fixed([99])


def test_vertex_copies_per_panel():
    p = four_vertex()
    s = build_compliant(p, crease_width=0.1, crease_thickness=1e-3, panel_thickness=1e-2, **MAT)
    per_panel = [s.vertex_nodes(4, panel=f) for f in range(p.n_faces)]
    assert all(len(n) == 1 for n in per_panel)
    np.testing.assert_array_equal(np.sort(np.concatenate(per_panel)), s.vertex_nodes(4))


def test_with_supports_changes_only_the_supports():
    s = build_concentrated(four_vertex(), crease_width=1e-3, crease_thickness=1e-3,
                           panel_thickness=1e-3)  # fmt: skip
    assert s.free_dofs.size == s.n_dof
    f = s.fixed([0, 1])
    assert f.free_dofs.size == s.n_dof - 6 and s.free_dofs.size == s.n_dof  # not shared
    assert f.nodes is s.nodes and f.creases is s.creases and f.profile is s.profile
    np.testing.assert_array_equal(f.bar_dofs, s.bar_dofs)
    with pytest.raises(ValueError, match="supports must have shape"):
        s.with_supports(np.zeros((2, 3), bool))


def _same_structure(a, b) -> bool:
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            if x.shape != y.shape or not np.array_equal(x, y, equal_nan=True):
                return False
        elif dataclasses.is_dataclass(x):
            if not _same_structure(x, y):
                return False
        elif x != y:
            return False
    return True


@pytest.mark.parametrize("profile", [PAPER, PHYSICAL])
def test_batch_build_is_each_designs_own(profile):
    """build_concentrated_batch: every structure bit for bit build_concentrated's."""
    pat = miura_sheet_paper(3, 2, 0.04, 1.1, 0.7)
    rng = np.random.default_rng(3)
    S = 5
    X = pat.coords[None] + 1e-3 * rng.standard_normal((S, pat.n_vertices, 3))
    X[1, :, 0] *= -1.0  # mirrored: the polarity rule orients its springs the other way
    W, tc, tp = rng.uniform(1e-3, 4e-3, S), rng.uniform(5e-4, 1e-3, S), rng.uniform(1e-3, 6e-3, S)
    E = rng.uniform(1e9, 3e9, S)
    sups = [support_mask(pat.n_vertices + pat.n_faces, [0, i + 1]) for i in range(S)]
    batch = build_concentrated_batch(
        pat, X, crease_width=W, crease_thickness=tc, panel_thickness=tp, E_panel=E,
        E_crease=2e9, profile=profile, supports=sups,
    )  # fmt: skip
    for i in range(S):
        one = build_concentrated(
            pat, coords=X[i], crease_width=W[i], crease_thickness=tc[i], panel_thickness=tp[i],
            E_panel=E[i], E_crease=2e9, profile=profile, supports=sups[i],
        )  # fmt: skip
        assert _same_structure(one, batch[i])
    with pytest.raises(ParameterError, match="crease_width"):
        build_concentrated_batch(
            pat, X, crease_width=np.r_[W[:-1], -1.0], crease_thickness=tc, panel_thickness=tp
        )
    # the builders skip Structure's checks (trusted_structure): the same arrays, dtypes and all
    for s in batch:
        fields = {f.name: getattr(s, f.name) for f in dataclasses.fields(s)}
        checked = Structure(**fields)
        assert _same_structure(checked, s)
        for f in dataclasses.fields(s):
            x = getattr(s, f.name)
            if isinstance(x, np.ndarray):
                assert x.dtype == getattr(checked, f.name).dtype, f.name
    assert any((b.springs != batch[0].springs).any() for b in batch)  # polarity per design


def test_batch_build_keeps_structures_checks():
    """What Structure refused (coincident nodes, coordinates whose panel centres overflow) the
    batch builder refuses with the same message, for the first design that has it."""
    pat = miura_sheet_paper(2, 2, 0.04, 1.1, 0.7)
    X = np.repeat(pat.coords[None], 3, axis=0)
    X[2, 1] = X[2, 0]  # design 2: a zero-length bar
    X[1] = 1.5e308  # design 1: finite corners, infinite centres
    kw = dict(crease_width=2e-3, crease_thickness=5e-4, panel_thickness=3e-3)
    with pytest.raises(ValueError, match="non-finite coordinates"), np.errstate(all="ignore"):
        build_concentrated_batch(pat, X, **kw)
    with pytest.raises(ValueError, match="bar 0 has zero rest length"):
        build_concentrated_batch(pat, X[[0, 2]], **kw)
    with pytest.raises(ValueError, match="zero rest length"):
        build_concentrated(pat, coords=X[2], **kw)
