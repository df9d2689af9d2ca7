"""Global assembly: agreement with a naive dense scatter, derivatives, rigid-body modes."""

import numpy as np
import pytest
import scipy.sparse as sp

from holofold.mechanics.assembly import Assembler, assembly_pattern
from holofold.mechanics.bars import bar_forces
from holofold.mechanics.springs import dihedral_angle, spring_forces
from holofold.mechanics.structure import Structure


def grid_structure(nx=4, ny=3, *, amp=0.15, seed=0, k=0.5, supports=None):
    """A triangulated nx x ny sheet with random heights; bars on all edges, springs on every
    interior edge, stress free (rest angles measured)."""
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float))
    nodes = np.c_[xs.ravel(), ys.ravel(), amp * rng.normal(size=xs.size)]
    tris = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = j * nx + i
            tris += [[a, a + 1, a + nx + 1], [a, a + nx + 1, a + nx]]
    opp = {}
    for p, q, r in tris:
        for u, v, o in ((p, q, r), (q, r, p), (r, p, q)):
            opp.setdefault((min(u, v), max(u, v)), []).append(o)
    bars = np.array(sorted(opp))
    springs = np.array([[o[0], e[0], e[1], o[1]] for e, o in sorted(opp.items()) if len(o) == 2])
    return Structure(
        nodes=nodes,
        bars=bars,
        bar_area=rng.uniform(0.5, 1.5, len(bars)) * 1e-3,
        bar_E=1e5,
        springs=springs,
        spring_k=k * rng.uniform(0.5, 1.5, len(springs)),
        spring_rest=dihedral_angle(nodes, springs),
        supports=supports,
    )


def _dense_reference(s, U):
    """Element loops with np.add.at (slow, obviously right)."""
    n = s.n_dof
    K = np.zeros((n, n))
    f = np.zeros(n)
    rb = bar_forces(s.nodes, U, s.bars, s.bar_length, s.bar_E * s.bar_area)
    rs = spring_forces(s.nodes + U, s.springs, s.spring_k, s.spring_rest)
    for dofs, res in ((s.bar_dofs, rb), (s.spring_dofs, rs)):
        np.add.at(f, dofs, res.force)
        np.add.at(K, (dofs[:, :, None], dofs[:, None, :]), res.tangent)
    return rb.energy.sum() + rs.energy.sum(), f, K


def test_matches_dense_scatter_and_reduction():
    sup = np.zeros((12, 3), bool)
    sup[[0, 3]] = True
    sup[8, 2] = True
    s = grid_structure(supports=sup)
    U = 0.05 * np.random.default_rng(5).normal(size=(12, 3))
    asm = Assembler(s)
    e, f, K = asm.evaluate(U)
    e_ref, f_ref, K_ref = _dense_reference(s, U)
    assert e == pytest.approx(e_ref, rel=1e-13)
    np.testing.assert_allclose(f, f_ref, atol=1e-12 * np.abs(f_ref).max())
    assert sp.isspmatrix_csr(K) or isinstance(K, sp.csr_array)
    np.testing.assert_allclose(K.toarray(), K_ref, atol=1e-12 * np.abs(K_ref).max())
    free = np.flatnonzero(~sup.ravel())
    np.testing.assert_array_equal(asm.free_dofs, free)
    for dense in (True, False):
        _, f2, Kf = asm.evaluate_reduced(U, dense=dense)
        Kf = Kf if dense else Kf.toarray()
        np.testing.assert_allclose(Kf, K_ref[np.ix_(free, free)], atol=1e-12 * np.abs(K_ref).max())
        np.testing.assert_array_equal(f2, f)
    # other rest angles
    rest = s.spring_rest + 0.1
    e3, f3, _ = asm.evaluate(U, rest)
    e_ref3, f_ref3, _ = _dense_reference(s.with_rest_angles(rest), U)
    assert e3 == pytest.approx(e_ref3, rel=1e-13)


def test_global_force_and_tangent_are_derivatives():
    s = grid_structure(seed=2)
    asm = Assembler(s)
    rng = np.random.default_rng(6)
    U = 0.05 * rng.normal(size=(s.n_nodes, 3))
    e, f, K = asm.evaluate(U)
    K = K.toarray()
    assert np.abs(K - K.T).max() <= 1e-14 * np.abs(K).max()
    h = 1e-6
    u = U.ravel()
    f_fd = np.zeros(s.n_dof)
    K_fd = np.zeros((s.n_dof, s.n_dof))
    for a in range(s.n_dof):
        up, um = u.copy(), u.copy()
        up[a] += h
        um[a] -= h
        ep, fp = asm.internal_force(up)
        em, fm = asm.internal_force(um)
        f_fd[a] = (ep - em) / (2 * h)
        K_fd[:, a] = (fp - fm) / (2 * h)
    assert np.linalg.norm(f_fd - f) / np.linalg.norm(f) <= 1e-6
    assert np.linalg.norm(K_fd - K) / np.linalg.norm(K) <= 1e-6


def _rigid_modes(K, rel=1e-9):
    w = np.linalg.eigvalsh(K)
    return int(np.sum(np.abs(w) < rel * np.abs(w).max())), w


def test_free_models_have_six_rigid_body_modes():
    # folded two-triangle hinge: 4 nodes, 5 bars, 1 spring -> 12 - 6 = 6 zero modes
    x = np.array([[0.4, -1.0, 0.1], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.6, 0.8, 0.5]])
    bars = [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    springs = np.array([[0, 1, 2, 3]])
    s = Structure(
        nodes=x,
        bars=bars,
        bar_area=1e-3,
        bar_E=1e5,
        springs=springs,
        spring_k=[1.0],
        spring_rest=dihedral_angle(x, springs),
    )
    n0, w = _rigid_modes(Assembler(s).evaluate(np.zeros((4, 3))).stiffness.toarray())
    assert n0 == 6
    assert w[6] > 1e-6 * w.max()
    # folded, randomly perturbed triangulated 5 x 4 sheet (stress free)
    s = grid_structure(5, 4, amp=0.3, seed=4, k=5.0)
    n0, w = _rigid_modes(Assembler(s).evaluate(np.zeros((20, 3))).stiffness.toarray())
    assert n0 == 6
    # without spring stiffness the bar framework alone has folding mechanisms
    s0 = s.replace(spring_k=np.zeros(len(s.springs)))
    n00, _ = _rigid_modes(Assembler(s0).evaluate(np.zeros((20, 3))).stiffness.toarray())
    assert n00 > 6
    # and at a rigidly rotated configuration the six modes persist
    c, si = np.cos(0.9), np.sin(0.9)
    Q = np.array([[c, 0, si], [0, 1, 0], [-si, 0, c]])
    U = s.nodes @ Q.T + 0.5 - s.nodes
    energy, f, K = Assembler(s).evaluate(U)
    assert energy < 1e-20 and np.abs(f).max() < 1e-9
    assert _rigid_modes(K.toarray())[0] == 6


def test_pattern_is_shared_and_checked():
    a = grid_structure(seed=1)
    b = grid_structure(seed=2)  # same connectivity, other geometry and properties
    assert assembly_pattern(a) is assembly_pattern(b)
    c = grid_structure(5, 3)
    assert assembly_pattern(c) is not assembly_pattern(a)
    with pytest.raises(ValueError, match="connectivity"):
        Assembler(c, pattern=assembly_pattern(a))
    # a different support mask reuses the pattern with another reduction
    sup = np.zeros((12, 3), bool)
    sup[0] = True
    a2 = a.with_supports(sup)
    assert Assembler(a2).pattern is Assembler(a).pattern
    assert Assembler(a2).free_dofs.size == a.n_dof - 3


@pytest.mark.parametrize("dense_max", [10_000, 0])
def test_factorized_solves_match_dense_solution(dense_max):
    """Dense LAPACK, banded Cholesky and SuperLU (indefinite fallback) give one answer."""
    sup = np.zeros((40, 3), bool)
    sup[:8] = True
    s = grid_structure(8, 5, seed=7, supports=sup)
    asm = Assembler(s, dense_max=dense_max)
    rng = np.random.default_rng(8)
    U = 0.02 * rng.normal(size=(40, 3)) * ~sup
    _, f, K = asm.evaluate(U)
    free = asm.free_dofs
    Kff = K.toarray()[np.ix_(free, free)]
    rhs = rng.normal(size=(free.size, 2))
    e2, f2, solve = asm.evaluate_factorized(U)
    np.testing.assert_array_equal(f2, f)
    x = solve(rhs)
    np.testing.assert_allclose(Kff @ x, rhs, atol=1e-9 * np.abs(rhs).max())
    # an indefinite tangent (large negative rest-angle misfit) still solves (LU fallback)
    rest = s.spring_rest + 3.0
    _, _, K2 = asm.evaluate(U, rest)
    K2ff = K2.toarray()[np.ix_(free, free)]
    assert np.linalg.eigvalsh(K2ff).min() < 0
    x2 = asm.evaluate_factorized(U, rest)[2](rhs[:, 0])
    np.testing.assert_allclose(K2ff @ x2, rhs[:, 0], atol=1e-8 * np.abs(rhs).max())
