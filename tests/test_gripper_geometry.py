"""The three gripper patterns: crease numbering and meshed node ids of the reference scripts."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.geometry.errors import ParameterError
from holofold.geometry.gripper import (
    DEFAULT_RANGE,
    GRIPPER_NAMES,
    GripperPattern,
    gripper_pattern,
    miura_based_gripper,
    splitted_miura_gripper,
    two_panel_gripper,
)
from holofold.mechanics.hinges import build_compliant

L1, L2, RATE, W = 5.2e-3, 2.9e-3, 0.37, 180e-6

# interior creases as (reference number, vertex a, vertex b), 1-based, as the scripts number them
CREASES = {
    1: [(1, 1, 2), (2, 1, 3), (3, 2, 3), (4, 1, 4), (5, 2, 4), (6, 2, 6), (8, 5, 6), (9, 6, 7),
        (12, 6, 8), (14, 1, 10), (15, 9, 10), (17, 10, 11), (19, 10, 12)],
    2: [(1, 1, 4), (2, 1, 2), (3, 2, 3), (4, 3, 4), (6, 1, 5), (7, 4, 8), (8, 2, 6), (10, 3, 7),
        (11, 3, 11), (13, 11, 12), (14, 4, 10), (15, 10, 11), (17, 9, 10), (19, 10, 14),
        (21, 11, 15), (26, 17, 18), (27, 1, 18), (28, 18, 19), (29, 2, 19), (30, 19, 20),
        (34, 18, 22), (36, 19, 23)],
    3: [(2, 1, 2), (4, 3, 4), (7, 5, 6), (12, 9, 10)],
}  # fmt: skip
N_EDGES = {1: 21, 2: 38, 3: 16}
MINUS = {1: {4, 6, 12, 17}, 2: {27, 29}, 3: set()}


def _mesh(p):
    pat = gripper_pattern(p, L1, L2, RATE)
    s = build_compliant(
        pat.pattern,
        crease_width=W,
        crease_thickness=1e-6,
        panel_thickness=20e-6,
        E_panel=2e9,
        E_crease=2e9,
        nu_panel=0.3,
        nu_crease=0.3,
    )
    return pat, s


@pytest.mark.parametrize("p", [1, 2, 3])
def test_reference_crease_numbers(p):
    pat = gripper_pattern(p, L1, L2, RATE)
    assert pat.pattern.n_edges == N_EDGES[p]
    edges, interior = pat.pattern.edges, pat.pattern.interior
    got = [(i + 1, a + 1, b + 1) for i, (a, b) in enumerate(edges) if interior[i]]
    assert got == CREASES[p]
    active = pat.active + 1
    assert active.tolist() == [c for c, _, _ in CREASES[p]]
    minus = {int(c) for c, s in zip(active, pat.alpha_sign, strict=True) if s < 0}
    assert minus == MINUS[p]
    assert np.all(pat.pattern.coords[:, 2] == 0)


def test_heat_lengths_as_coded():
    r = 2e-3
    pat = miura_based_gripper(L1, L2, RATE)
    h = dict(zip((pat.active + 1).tolist(), pat.heat_length, strict=True))
    assert h[1] == pytest.approx(r)
    assert h[3] == pytest.approx(0.5 * np.hypot(r, L2))
    assert h[6] == h[14] == pytest.approx((1 - RATE) * L1 - L2 / 2)
    assert h[12] == pytest.approx(RATE * L1 + L2 / 2)
    # the coded lengths are the true crease lengths for patterns 2 and 3
    for p in (2, 3):
        pat = gripper_pattern(p, L1, L2, RATE)
        true = pat.pattern.edge_lengths[pat.active]
        np.testing.assert_allclose(pat.heat_length, true, rtol=1e-12)


@pytest.mark.parametrize("p,nn,nb", [(1, 83, 198), (2, 141, 340), (3, 37, 80)])
def test_mesh_sizes(p, nn, nb):
    _, s = _mesh(p)
    assert (s.n_nodes, len(s.bars)) == (nn, nb)


# (meshed id, pattern vertex id), 1-based, as the scripts use them
NODE_IDS = {
    1: [(1, 1), (4, 1), (3, 2), (5, 2), (2, 3), (8, 3), (24, 3), (6, 4), (14, 4), (27, 4),
        (16, 8), (19, 8), (29, 12), (32, 12)],
    2: [(1, 1), (2, 2), (3, 3), (4, 4), (15, 12), (24, 9), (38, 17), (46, 20), (31, 15),
        (32, 14), (53, 22), (54, 23)],
    3: [(1, 1), (2, 2), (3, 4), (4, 3), (11, 8), (12, 7), (17, 11), (18, 12)],
}  # fmt: skip


@pytest.mark.parametrize("p", [1, 2, 3])
def test_meshed_node_ids(p):
    pat, s = _mesh(p)
    nv = s.node_vertex
    for mid, v in NODE_IDS[p]:
        assert nv[mid - 1] == v - 1, (mid, v)
    if p == 1:
        assert s.panel_centres[:2].tolist() == [73, 74]  # ids 74, 75
        cid = s.creases.ids.tolist()
        # 59 / 71: first crease node (p1) of c12 / c19, at the tip end of the axial crease
        for c, node, tip in ((12, 59, 8), (19, 71, 12)):
            p1, p2 = s.creases.nodes[cid.index(c - 1), 4:6]
            assert p1 == node - 1
            d1, d2 = np.linalg.norm(s.nodes[[p1, p2]] - pat.pattern.coords[tip - 1], axis=1)
            assert d1 < 4 * W < d2


@pytest.mark.parametrize("p", [1, 2, 3])
def test_fold_sign_matches_raw_mesh_orientation(p):
    """fold_sign = alpha_sign * (orientation of the raw spring [N11, c, p1, N21])."""
    pat, s = _mesh(p)
    X = s.nodes
    n11, _, n21, _, p1, _, c = s.creases.nodes.T
    z = np.cross(X[c] - X[n11], X[p1] - X[c])[:, 2]
    order = np.searchsorted(pat.active, s.creases.ids)
    expect = pat.alpha_sign[order] * np.where(z > 0, -1.0, 1.0)
    np.testing.assert_array_equal(pat.fold_sign[order], expect)
    asg = pat.pattern.assignment[pat.active]
    np.testing.assert_array_equal(asg == "V", pat.fold_sign > 0)


def test_two_panel_is_mirror_symmetric_in_folding():
    pat = two_panel_gripper(L1, L2, RATE)
    assert np.all(pat.fold_sign > 0)


def test_bad_parameters():
    with pytest.raises(ParameterError, match="rate"):
        two_panel_gripper(L1, L2, 1.2)
    with pytest.raises(ParameterError, match="L2/2"):
        splitted_miura_gripper(3e-3, 4e-3, 0.6)
    with pytest.raises(ParameterError, match="L1"):
        miura_based_gripper(-1.0, L2, RATE)
    with pytest.raises(ParameterError, match="pattern"):
        gripper_pattern(4, L1, L2, RATE)


@pytest.mark.parametrize("p", [1, 2, 3])
def test_gripper_pattern_fields(p):
    """Explicit fields instead of meta keys."""
    grip = gripper_pattern(p, L1, L2, RATE)
    assert isinstance(grip, GripperPattern) and grip.kind == p and grip.name == GRIPPER_NAMES[p]
    assert (grip.L1, grip.L2, grip.rate, grip.range) == (L1, L2, RATE, DEFAULT_RANGE[p])
    na = len(grip.active)
    assert grip.alpha_sign.shape == grip.fold_sign.shape == grip.heat_length.shape == (na,)
    assert np.all(np.diff(grip.active) > 0) and np.all(grip.heat_length > 0)
    assert grip.pattern.meta == {"kind": f"{GRIPPER_NAMES[p]} gripper"}
    assert grip.pattern.interior[grip.active].all()
    assert gripper_pattern(p, L1, L2, RATE, 1.5e-3).range == 1.5e-3
