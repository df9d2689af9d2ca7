"""The compiled kernels and scatters equal the numpy kernels and np.bincount bit for bit."""

import numpy as np
import pytest
import scipy.sparse as sp

from holofold.mechanics import _compiled
from holofold.mechanics.assembly import Assembler, _sum, _sum_lists
from holofold.mechanics.bars import bar_kernel
from holofold.mechanics.springs import dihedral_angle, spring_kernel
from holofold.mechanics.structure import Structure


def _random_model(seed, nn=40, ns=70, nb=110, negative_k=False):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(nn, 3))
    X[:12, 2] = 0.0  # a flat region: zeros in m, exact flat angles
    U = 0.05 * rng.normal(size=(nn, 3))
    U[:12] = 0.0
    sT = np.array([rng.choice(nn, 4, replace=False) for _ in range(ns)]).T.astype(np.intp)
    k = rng.uniform(0.1, 2.0, ns)
    if negative_k:
        k[rng.random(ns) < 0.2] *= -1.0
    th0 = rng.uniform(0.0, 2 * np.pi, ns)
    bars = np.array([rng.choice(nn, 2, replace=False) for _ in range(nb)]).astype(np.intp)
    L0 = np.linalg.norm(X[bars[:, 1]] - X[bars[:, 0]], axis=1) * rng.uniform(0.9, 1.1, nb)
    EA = rng.uniform(1.0, 5.0, nb)
    return X, U, np.ascontiguousarray(sT), k, th0, bars, L0, EA


@pytest.mark.parametrize("element_major", [False, True])
@pytest.mark.parametrize("negative_k", [False, True])
@pytest.mark.parametrize("tangent", [True, False])
def test_spring_kernel_is_the_numpy_one_bit_for_bit(negative_k, tangent, element_major):
    # 70 springs: the vectorised loop's remainder runs too; strided outputs (element-major
    # arrays) take the scalar path
    X, U, sT, k, th0, *_ = _random_model(1, negative_k=negative_k)
    ref, theta = spring_kernel((X + U).T[:, sT], k, th0, tangent=tangent)
    ns = sT.shape[1]
    e, f, K, t = np.empty(ns), np.empty((3, 4, ns)), np.empty((3, 3, 10, ns)), np.empty(ns)
    if element_major:
        f = np.empty((ns, 4, 3)).transpose(2, 1, 0)
        K = np.empty((ns, 10, 3, 3)).transpose(2, 3, 1, 0)
    _compiled.spring_elements(X, U, sT, k, th0, bool((k >= 0).all()), tangent, e, f, K, t)
    assert np.array_equal(e, ref.energy) and np.array_equal(f, ref.force)
    assert np.array_equal(t, theta)
    if tangent:
        assert np.array_equal(K, ref.tangent)


def test_generated_spring_loop_is_current():
    """mechanics/_spring_loop.py is what its generator writes (regenerate with
    ``python -m holofold.mechanics._spring_codegen``)."""
    from holofold.mechanics import _spring_codegen

    assert _spring_codegen.TARGET.read_text() == _spring_codegen.source()


def test_bar_kernel_is_the_numpy_one_bit_for_bit():
    X, U, _, _, _, bars, L0, EA = _random_model(2)
    b0, b1 = bars[:, 0].copy(), bars[:, 1].copy()
    D0 = np.ascontiguousarray((X[b1] - X[b0]).T)
    ref = bar_kernel(D0, (U[b1] - U[b0]).T, L0, EA)
    nb = len(bars)
    e, f, K = np.empty(nb), np.empty((3, 2, nb)), np.empty((3, 3, 2, 2, nb))
    _compiled.bar_elements(X, U, b0, b1, D0, L0, EA, True, e, f, K)
    assert np.array_equal(e, ref.energy) and np.array_equal(f, ref.force)
    assert np.array_equal(K, ref.tangent)


def _structure(seed, n_supported=5):
    X, U, sT, k, _, bars, _, EA = _random_model(seed)
    springs = sT.T
    sup = np.zeros((len(X), 3), bool)
    sup[:n_supported] = True
    s = Structure(
        nodes=X, bars=bars, bar_area=1.0, bar_E=EA, springs=springs, spring_k=k,
        spring_rest=dihedral_angle(X, springs) + 0.1, supports=sup,
    )  # fmt: skip
    return s, U


def _numpy_assembly(asm, U):
    """The assembly as it was before the compiled kernels: numpy kernels + np.bincount."""
    pat = asm.pattern
    XT, UT = asm.X.T, U.T
    b0, b1 = asm.bars[:, 0], asm.bars[:, 1]
    rb = bar_kernel(XT[:, b1] - XT[:, b0], UT[:, b1] - UT[:, b0], asm.L0, asm.EA)
    rs, _ = spring_kernel((XT + UT)[:, asm.springs.T], asm.k, asm.theta0)
    n = asm.n_dof
    f = np.bincount(pat.bar_force_dofs, weights=rb.force.ravel(), minlength=n)
    f += np.bincount(pat.spring_force_dofs, weights=rs.force.ravel(), minlength=n)
    data = np.bincount(pat.bar_slot, weights=rb.tangent.ravel(), minlength=pat.nnz)
    w = rs.tangent.ravel()
    data += np.bincount(pat.spring_slot, weights=w, minlength=pat.nnz)
    data += np.bincount(pat.spring_slot_mirror, weights=w, minlength=pat.nnz + 1)[:-1]
    energy = float(rb.energy.sum() + rs.energy.sum())
    return energy, f, data, rb, rs


@pytest.mark.parametrize("n_families", [1, 2, 3])
def test_scatter_is_bincount_per_family_then_added(n_families):
    # random targets with many repeats and dropped entries (-1, n): each family's sum in
    # flat order from 0.0, then (A + B) + C, written to out[dest] for the targets hit
    rng = np.random.default_rng(n_families)
    n = 50
    pos = [rng.integers(-1, n + 1, size) for size in (700, 400, 300)[:n_families]]
    vals = [rng.standard_normal(p.size) * 10.0 ** rng.integers(-8, 8, p.size) for p in pos]
    dest = rng.permutation(3 * n)[:n]
    lists = _sum_lists(pos, n, dest)
    ref = np.zeros(n)
    for p, v in zip(pos, vals, strict=True):
        keep = (p >= 0) & (p < n)
        ref = ref + np.bincount(p[keep], weights=v[keep], minlength=n)
    while len(vals) < 3:
        vals.append(np.zeros(0))
    out = np.zeros(3 * n)
    acc = np.empty(3 * lists[6].size)
    _compiled.scatter(*lists[:2], vals[0], *lists[2:4], vals[1], *lists[4:6], vals[2],
                      lists[6], acc, out)  # fmt: skip
    expect = np.zeros(3 * n)
    hit = np.zeros(n, bool)
    for p in pos:
        hit[p[(p >= 0) & (p < n)]] = True
    expect[dest[hit]] = ref[hit]
    assert np.array_equal(out, expect) and not np.array_equal(out, 0 * out)


@pytest.mark.parametrize("seed", [3, 4])
def test_assembly_is_the_bincount_one_bit_for_bit(seed):
    s, U = _structure(seed)
    asm = Assembler(s)
    energy, f, data, rb, rs = _numpy_assembly(asm, U)
    e2, f2, K = asm.evaluate(U)
    assert e2 == energy and np.array_equal(f2, f) and np.array_equal(K.data, data)
    red = asm.reduction
    nf = red.n_free
    dense = np.zeros(nf * nf)
    dense[red.dense] = data[red.keep]
    _, _, Kd = asm.evaluate_reduced(U, dense=True)
    assert np.array_equal(Kd.ravel(), dense)
    _, _, Ks = asm.evaluate_reduced(U, dense=False)
    assert np.array_equal(Ks.toarray(), sp.csr_matrix(
        (data[red.keep], red.indices, red.indptr), shape=(nf, nf)).toarray())  # fmt: skip
    # the band: bincount over the band positions, as the numpy path filled it
    bar_ab, spring_ab, size = red.banded_slots
    ab = np.bincount(bar_ab, weights=rb.tangent.ravel(), minlength=size + 1)
    ab += np.bincount(spring_ab, weights=rs.tangent.ravel(), minlength=size + 1)
    buffers = asm._kernels(U, None, True, asm._buffers())
    got = _sum(red.band_sums, buffers[2], buffers[5], np.zeros(size))
    assert np.array_equal(got, ab[:size])


def test_element_response_keeps_the_kernel_layouts():
    s, U = _structure(5)
    asm = Assembler(s)
    rb, rs = asm.element_response(U)
    _, _, _, rb0, rs0 = _numpy_assembly(asm, U)
    for a, b in zip((*rb, *rs), (*rb0, *rs0), strict=True):
        assert np.array_equal(a, b)
    rb2, _ = asm.element_response(U)
    assert rb2.tangent is not rb.tangent  # new arrays on every call


def test_dense_solver_is_numpy_solve_bit_for_bit():
    # one right-hand side: LAPACK's dgetrf/dgetrs from scipy instead of np.linalg.solve
    from holofold.mechanics.assembly import SingularSystemError, _dense_solver

    rng = np.random.default_rng(7)
    for n in (3, 30, 99, 150):
        K = rng.normal(size=(n, n)) + n * np.eye(n)
        K[0, 1] += 1e-3  # not symmetric, as an assembled tangent need not be to the bit
        solve = _dense_solver(K)
        for rhs in (rng.normal(size=n), rng.normal(size=(n, 2)), rng.normal(size=n)):
            assert np.array_equal(solve(rhs), np.linalg.solve(K, rhs))
    with pytest.raises(SingularSystemError, match="singular stiffness matrix"):
        _dense_solver(np.zeros((4, 4)))(np.ones(4))


@pytest.mark.parametrize("seed", [0, 1])
def test_dense_newton_update_is_the_factorized_step_bit_for_bit(seed):
    # the one compiled call solve_selffold makes per iteration on the dense path
    s, U = _structure(seed)
    asm, ref = Assembler(s), Assembler(s)
    free = asm.free_dofs
    rng = np.random.default_rng(seed)
    F = rng.normal(size=s.n_dof) * 1e-3
    rest = np.ascontiguousarray(s.spring_rest + 0.05 * rng.normal(size=len(s.springs)))
    Ua, Ub = 1e-3 * U.ravel(), 1e-3 * U.ravel()
    r = np.empty(free.size)
    for _ in range(3):
        dUa = asm.dense_newton_update(Ua, F, rest, r)
        _, f, solve = ref.evaluate_factorized(Ub, rest)
        rb = (F - f)[free]
        dUb = solve(rb)
        Ub[free] += dUb
        assert np.array_equal(r, rb) and np.array_equal(Ua, Ub) and np.array_equal(dUa, dUb)
    # the structure's own rest angles by default, no residual asked for
    _, f, solve = ref.evaluate_factorized(Ub)
    dUb = solve((F - f)[free])
    Ub[free] += dUb
    assert np.array_equal(asm.dense_newton_update(Ua, F), dUb) and np.array_equal(Ua, Ub)
    # not the dense path: nothing done, the caller takes evaluate_factorized
    assert Assembler(s, dense_max=2).dense_newton_update(Ua, F, rest, r) is None
    assert np.array_equal(Ua, Ub)


def test_dense_newton_update_raises_on_a_singular_tangent():
    from holofold.mechanics.assembly import SingularSystemError

    s, _ = _structure(3)
    s0 = Structure(
        nodes=s.nodes, bars=s.bars, bar_area=1.0, bar_E=0.0, springs=s.springs, spring_k=0.0,
        spring_rest=s.spring_rest, supports=s.supports,
    )  # fmt: skip
    U = np.zeros(s.n_dof)
    asm = Assembler(s0)
    with pytest.raises(SingularSystemError, match="singular stiffness matrix"):
        asm.dense_newton_update(U, np.ones(s.n_dof), s.spring_rest, np.empty(asm.free_dofs.size))
    assert not U.any()
