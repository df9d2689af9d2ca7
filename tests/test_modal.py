"""Lumped mass and natural frequencies: analytic bar chain, mass totals, published freqFinal."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from holofold.design.scenarios.gripper import build_model, natural_frequency
from holofold.geometry.gripper import two_panel_gripper
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.hinges import build_compliant
from holofold.mechanics.modal import eigenvalues, lumped_mass, natural_frequencies
from holofold.mechanics.structure import Structure


def test_cantilever_bar_chain_first_axial_frequency():
    """Fixed-free rod: omega_1 = (pi / 2) sqrt(E / rho) / l (rad/s)."""
    n, length, E, rho, A = 40, 2.0, 2e9, 1200.0, 1e-4
    x = np.linspace(0, length, n + 1)
    nodes = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    bars = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    sup = np.zeros((n + 1, 3), bool)
    sup[:, 1:] = True  # axial motion only
    sup[0] = True
    s = Structure(nodes=nodes, bars=bars, bar_area=A, bar_E=E, springs=np.zeros((0, 4)),
                  spring_k=[], spring_rest=[], supports=sup)  # fmt: skip
    _, _, K = Assembler(s).evaluate(np.zeros((n + 1, 3)))
    m = np.full(n + 1, rho * A * length / n)
    m[[0, -1]] /= 2
    w = natural_frequencies(K, np.repeat(m, 3), s.free_dofs, n=2)
    exact = np.pi / 2 * np.sqrt(E / rho) / length
    assert w[0] == pytest.approx(exact, rel=0.02)
    assert w[0] == pytest.approx(exact, rel=1e-3)  # lumped chain converges as 1/n^2
    assert w[1] == pytest.approx(3 * exact, rel=0.02)


def test_eigenvalues_match_direct_generalised_solve():
    rng = np.random.default_rng(3)
    B = rng.normal(size=(12, 12))
    K = B @ B.T + 12 * np.eye(12)
    m = rng.uniform(0.5, 2.0, 12)
    ref = sla.eigh(K, np.diag(m), eigvals_only=True)
    np.testing.assert_allclose(eigenvalues(K, m), ref, rtol=1e-12)
    # massless DOFs: eigenvalues of the statically condensed problem
    m0 = m.copy()
    m0[[2, 7]] = 0.0
    i, o = np.setdiff1d(np.arange(12), [2, 7]), np.array([2, 7])
    Kc = K[np.ix_(i, i)] - K[np.ix_(i, o)] @ np.linalg.solve(K[np.ix_(o, o)], K[np.ix_(o, i)])
    ref0 = sla.eigh(Kc, np.diag(m0[i]), eigvals_only=True)
    np.testing.assert_allclose(eigenvalues(K, m0), ref0, rtol=1e-10)
    # free-DOF selection
    free = np.arange(3, 12)
    ref_f = sla.eigh(K[3:, 3:], np.diag(m[3:]), eigvals_only=True)
    np.testing.assert_allclose(eigenvalues(K, m, free), ref_f, rtol=1e-12)
    with pytest.raises(ValueError):
        eigenvalues(K, -m)


def _structure():
    pat = two_panel_gripper(4.1e-3, 3.1e-3, 0.49).pattern
    s = build_compliant(pat, crease_width=150e-6, crease_thickness=1.2e-6, panel_thickness=27e-6,
                        E_panel=2e9, E_crease=2e9, nu_panel=0.3, nu_crease=0.3)  # fmt: skip
    return pat, s


def _tri_mass(s, rho):
    X = s.nodes
    t = s.triangles
    area = 0.5 * np.linalg.norm(np.cross(X[t[:, 1]] - X[t[:, 0]], X[t[:, 2]] - X[t[:, 0]]), axis=1)
    return area * rho * s.tri_thickness


def test_lumped_mass_totals_and_shares():
    pat, s = _structure()
    mt = _tri_mass(s, 1200.0)
    m = lumped_mass(s, 1200.0)
    assert m.sum() == pytest.approx(mt.sum(), rel=1e-13)
    # panel mass of a flat panel: 1200 * t * area of the shrunk panel
    P = len(pat.faces)
    m_skip = lumped_mass(s, 1200.0, skip_first=P)
    assert m_skip.sum() == pytest.approx(mt.sum() - mt[:P].sum(), rel=1e-13)
    assert (s.tri_crease[:P] >= 0).all()  # the skipped ones are crease triangles (quirk)
    # the first crease's p1, p2, c lose (part of) their mass
    c0 = s.creases.nodes[0, 4:]
    assert np.all(m_skip[c0] < m[c0])
    # 4/6 to the panel centre (later SWOMPS versions)
    m46 = lumped_mass(s, 1200.0, centre_share=4 / 6)
    assert m46.sum() == pytest.approx(mt.sum(), rel=1e-13)
    centres = s.panel_centres
    panel_mass = np.bincount(s.tri_panel[s.tri_panel >= 0], weights=mt[s.tri_panel >= 0])
    np.testing.assert_allclose(m46[centres], 4 / 6 * panel_mass, rtol=1e-13)
    np.testing.assert_allclose(m[centres], 1 / 3 * panel_mass, rtol=1e-13)
    with pytest.raises(ValueError):
        lumped_mass(s, 1200.0, skip_first=len(s.triangles) + 1)


# row 1 of each published gripper file (docs/scenarios.md §6)
PUBLISHED = {
    "data2_MiuraBased_sample": 94.82475367,
    "data2_SplittedMiura_sample": 20.64866054,
    "data2_TwoPanel_sample": 45.44220967,
}


@pytest.mark.parametrize("stem", list(PUBLISHED))
def test_published_freq_final(reference_data, stem):
    row = reference_data.load(stem).iloc[0]
    assert row["freqFinal"] == pytest.approx(PUBLISHED[stem], rel=1e-9)
    P = int(row["Pattern"])
    feats = [row[k] for k in ("L1", "L2", "t1", "t2", "tpanel", "rate", "W")]
    pat, s = build_model(P, *feats)
    w = natural_frequency(P, pat, s)
    assert w == pytest.approx(row["freqFinal"], rel=1e-6)


def test_singular_stiffness_falls_back_to_the_direct_form():
    """A free spring-mass chain is a mechanism (K singular): the inverse form cannot be used,
    the direct form gives the rigid-body mode lambda = 0 and the analytic 2 k (1/m1 + 1/m2)/2."""
    k, m1, m2 = 3.0, 2.0, 0.5
    K = np.array([[k, -k], [-k, k]])
    lam = eigenvalues(K, np.array([m1, m2]))
    np.testing.assert_allclose(lam, [0.0, k * (1 / m1 + 1 / m2)], atol=1e-12)
    # a massless middle node is condensed out: two springs k in series (k/2), masses 1 and 1
    K3 = np.array([[2 * k, -k, -k], [-k, k, 0.0], [-k, 0.0, k]])
    lam3 = eigenvalues(K3, np.array([0.0, 1.0, 1.0]))
    np.testing.assert_allclose(lam3, [0.0, k], atol=1e-12)
