"""The two kernel paths (numpy, the reference; compiled, numba) agree with each other and with
the element kernels to round-off: forces, tangents and energies to 1e-12 relative to their
scale. No test here asserts bit equality across the paths: their rounding differs with the CPU
(numpy's SIMD arctan2 against libm's atan2) and the summation order."""

import inspect

import numpy as np
import pytest
import scipy.sparse as sp
from _kernel_paths import NO_COMPILED, path  # noqa: F401  (the kernel-path fixture: numpy, compiled)

from holofold.mechanics import kernels
from holofold.mechanics.assembly import Assembler, BatchAssembler, sum_into
from holofold.mechanics.bars import bar_kernel
from holofold.mechanics.linear import SingularSystemError, dense_solver
from holofold.mechanics.sparsity import sum_lists
from holofold.mechanics.springs import dihedral_angle, spring_kernel
from holofold.mechanics.structure import Structure

RTOL = 1e-12  # of the array's scale (its largest magnitude)


def close(a, b, rtol=RTOL):
    """``a`` equals ``b`` to ``rtol`` of ``b``'s scale (max |b|)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    scale = np.abs(b).max() if b.size else 0.0
    err = np.abs(a - b).max() if b.size else 0.0
    assert err <= rtol * scale, f"max error {err:.3e} > {rtol:g} x scale {scale:.3e}"


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
def test_spring_elements_are_the_spring_kernel(path, negative_k, tangent, element_major):  # noqa: F811
    # 70 springs: the compiled loop's vectorised body and its remainder; strided outputs
    # (element-major arrays) take its scalar path
    X, U, sT, k, th0, *_ = _random_model(1, negative_k=negative_k)
    ref, theta = spring_kernel((X + U).T[:, sT], k, th0, tangent=tangent)
    ns = sT.shape[1]
    e, f, K, t = np.empty(ns), np.empty((3, 4, ns)), np.empty((3, 3, 10, ns)), np.empty(ns)
    if element_major:
        f = np.empty((ns, 4, 3)).transpose(2, 1, 0)
        K = np.empty((ns, 10, 3, 3)).transpose(2, 3, 1, 0)
    path.module.spring_elements(X, U, sT, k, th0, bool((k >= 0).all()), tangent, (e, f, K, t))
    close(e, ref.energy)
    close(f, ref.force)
    close(t, theta)
    if tangent:
        close(K, ref.tangent)


def test_generated_spring_loop_is_current():
    """mechanics/_spring_loop.py is what its generator writes (regenerate with
    ``python -m holofold.mechanics._spring_codegen``)."""
    from holofold.mechanics import _spring_codegen

    assert _spring_codegen.TARGET.read_text() == _spring_codegen.source()


def test_bar_elements_are_the_bar_kernel(path):  # noqa: F811
    X, U, _, _, _, bars, L0, EA = _random_model(2)
    b0, b1 = bars[:, 0].copy(), bars[:, 1].copy()
    D0 = np.ascontiguousarray((X[b1] - X[b0]).T)
    ref = bar_kernel(D0, (U[b1] - U[b0]).T, L0, EA)
    nb = len(bars)
    e, f, K = np.empty(nb), np.empty((3, 2, nb)), np.empty((3, 3, 2, 2, nb))
    path.module.bar_elements(X, U, b0, b1, D0, L0, EA, True, (e, f, K))
    close(e, ref.energy)
    close(f, ref.force)
    close(K, ref.tangent)


@pytest.mark.parametrize("n_families", [1, 2, 3])
def test_scatter_sums_each_target(path, n_families):  # noqa: F811
    # random targets with many repeats and dropped entries (-1, n), values over 16 decades,
    # written to out[dest[target]] (out is 3n long, zeros elsewhere)
    rng = np.random.default_rng(n_families)
    n = 50
    pos = [rng.integers(-1, n + 1, size) for size in (700, 400, 300)[:n_families]]
    vals = [rng.standard_normal(p.size) * 10.0 ** rng.integers(-8, 8, p.size) for p in pos]
    dest = rng.permutation(3 * n)[:n]
    lists = sum_lists(pos, n, dest)
    expect, mag = np.zeros(3 * n), np.zeros(3 * n)
    for p, v in zip(pos, vals, strict=True):
        keep = (p >= 0) & (p < n)
        np.add.at(expect, dest[p[keep]], v[keep])
        np.add.at(mag, dest[p[keep]], np.abs(v[keep]))
    while len(vals) < 3:
        vals.append(np.zeros(0))
    out = np.zeros(3 * n)
    path.module.scatter(
        lists.bar_src, lists.bar_tgt, vals[0], lists.spring_src, lists.spring_tgt, vals[1],
        lists.mirror_src, lists.mirror_tgt, vals[2], out,
    )  # fmt: skip
    # each target's sum to round-off of the magnitudes summed into it
    assert np.all(np.abs(out - expect) <= 1e-14 * mag) and np.abs(out).max() > 0
    assert np.all(out[mag == 0] == 0)


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


def _reference_assembly(s, U):
    """Element kernels + np.bincount, written out: the assembly's definition."""
    from holofold.mechanics.sparsity import AssemblyPattern

    pat = AssemblyPattern(s.n_dof, s.bar_dofs, s.spring_dofs)
    XT, UT = s.nodes.T, U.T
    b0, b1 = s.bars[:, 0], s.bars[:, 1]
    rb = bar_kernel(XT[:, b1] - XT[:, b0], UT[:, b1] - UT[:, b0], s.bar_length,
                    s.bar_E * s.bar_area)  # fmt: skip
    rs, _ = spring_kernel((XT + UT)[:, s.springs.T], s.spring_k, s.spring_rest)
    n = s.n_dof
    f = np.bincount(pat.bar_force_dofs, weights=rb.force.ravel(), minlength=n)
    f += np.bincount(pat.spring_force_dofs, weights=rs.force.ravel(), minlength=n)
    data = np.bincount(pat.bar_slot, weights=rb.tangent.ravel(), minlength=pat.nnz)
    w = rs.tangent.ravel()
    data += np.bincount(pat.spring_slot, weights=w, minlength=pat.nnz)
    data += np.bincount(pat.spring_slot_mirror, weights=w, minlength=pat.nnz + 1)[:-1]
    K = sp.csr_matrix((data, pat.indices, pat.indptr), shape=(n, n)).toarray()
    return float(rb.energy.sum() + rs.energy.sum()), f, K, rb, rs


@pytest.mark.parametrize("seed", [3, 4])
def test_assembly_in_every_storage(path, seed):  # noqa: F811
    s, U = _structure(seed)
    asm = Assembler(s)
    energy, f, K, rb, rs = _reference_assembly(s, U)
    e2, f2, K2 = asm.evaluate(U)
    assert e2 == pytest.approx(energy, rel=RTOL)
    close(f2, f)
    close(K2.toarray(), K)
    free = asm.free_dofs
    Kff = K[np.ix_(free, free)]
    close(asm.evaluate_reduced(U, dense=True).stiffness, Kff)
    close(asm.evaluate_reduced(U, dense=False).stiffness.toarray(), Kff)
    # the band (column-major upper, on the reverse Cuthill-McKee order)
    red = asm.reduction
    band = red.band
    a = asm._kernels(U, None, True, asm._buffers())
    ab = sum_into(red.tangent_sums("banded"), a.bar_tangent, a.spring_tangent,
                  np.zeros(band.size)).reshape(red.n_free, band.bandwidth + 1).T  # fmt: skip
    P = Kff[np.ix_(band.perm, band.perm)]
    for d in range(band.bandwidth + 1):  # row bw - d of ab holds the d-th superdiagonal
        close(ab[band.bandwidth - d, d:], np.diagonal(P, d), rtol=RTOL * np.abs(Kff).max()
              / max(np.abs(np.diagonal(P, d)).max(), 1e-300))  # fmt: skip


def test_paths_agree_on_a_model(monkeypatch):
    if NO_COMPILED:
        pytest.skip(f"compiled path: {NO_COMPILED}")
    s, U = _structure(6)
    out = {}
    for name in kernels.KERNEL_PATHS:
        monkeypatch.setenv(kernels.ENV, name)
        asm = Assembler(s)
        rb, rs = asm.element_response(U)
        out[name] = (asm.evaluate(U), rb, rs)
    (en, fn, Kn), rbn, rsn = out["numpy"]
    (ec, fc, Kc), rbc, rsc = out["compiled"]
    assert ec == pytest.approx(en, rel=RTOL)
    close(fc, fn)
    close(Kc.toarray(), Kn.toarray())
    for a, b in zip((*rbc, *rsc), (*rbn, *rsn), strict=True):
        close(a, b)


def test_element_response_gives_new_arrays(path):  # noqa: F811
    s, U = _structure(5)
    asm = Assembler(s)
    rb, rs = asm.element_response(U)
    _, _, _, rb0, rs0 = _reference_assembly(s, U)
    for a, b in zip((*rb, *rs), (*rb0, *rs0), strict=True):
        close(a, b)
    rb2, _ = asm.element_response(U)
    assert rb2.tangent is not rb.tangent


def test_dense_solver_solves():
    rng = np.random.default_rng(7)
    for n in (3, 30, 99, 150):
        K = rng.normal(size=(n, n)) + n * np.eye(n)
        K[0, 1] += 1e-3  # not symmetric
        solve = dense_solver(K)
        for rhs in (rng.normal(size=n), rng.normal(size=(n, 2)), rng.normal(size=n)):
            x = solve(rhs)
            close(K @ x, rhs, rtol=1e-12 * np.linalg.cond(K))
    with pytest.raises(SingularSystemError, match="singular stiffness matrix"):
        dense_solver(np.zeros((4, 4)))(np.ones(4))


@pytest.mark.parametrize("seed", [0, 1])
def test_dense_newton_update_is_the_factorized_step(path, seed):  # noqa: F811
    # the one kernel call solve_selffold makes per iteration on the dense path
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
        close(r, rb, rtol=1e-10)
        close(dUa, dUb, rtol=1e-9)
        close(Ua, Ub, rtol=1e-9)
    # not the dense path: nothing done, the caller takes evaluate_factorized
    assert Assembler(s, dense_max=2).dense_newton_update(Ua, F, rest, r) is None


def test_dense_newton_update_raises_on_a_singular_tangent(path):  # noqa: F811
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


@pytest.mark.parametrize("dense_max", [2, 10_000])  # banded and dense batch steps
def test_batch_newton_step_is_each_designs_own_step(path, dense_max):  # noqa: F811
    rng = np.random.default_rng(11)
    structures, Us = [], []
    for seed in (3, 3, 4):
        s, U = _structure(seed)
        structures.append(s)
        Us.append(1e-3 * U.ravel())
    # same sizes: the random models of seeds 3 and 4 differ in connectivity (two groups)
    batch = BatchAssembler(structures, dense_max=dense_max)
    U = np.ascontiguousarray(np.stack(Us))
    F = 1e-3 * rng.normal(size=U.shape)
    expect = []
    for s, u, fi in zip(structures, U.copy(), F, strict=True):
        asm = Assembler(s, dense_max=dense_max)
        _, f, solve = asm.evaluate_factorized(u)
        try:
            d = solve((fi - f)[asm.free_dofs])
        except SingularSystemError:
            d = None
        expect.append(d)
    dU, errors = batch.newton_step(U, F, np.ones(3, bool))
    for j, d in enumerate(expect):
        if d is None:
            assert j in errors
        else:
            close(dU[j], d, rtol=1e-9)


def test_a_broken_lapack_is_one_environment_line(monkeypatch):
    import builtins

    real = builtins.__import__

    def broken(name, *args, **kwargs):
        if name == "scipy.linalg.lapack":
            raise ImportError("libopenblas.so.0: cannot open shared object file")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", broken)
    with pytest.raises(
        kernels.EnvironmentFault, match="scipy's LAPACK cannot be loaded.*reinstall"
    ):
        kernels.check_environment()


def test_an_unknown_kernel_path_is_one_environment_line(monkeypatch):
    monkeypatch.setenv(kernels.ENV, "fortran")
    with pytest.raises(kernels.EnvironmentFault, match="use auto, numpy or compiled"):
        kernels.active()


def _parameters(fn) -> list[str]:
    return list(inspect.signature(getattr(fn, "py_func", fn)).parameters)


@pytest.mark.skipif(NO_COMPILED is not None, reason=f"no compiled path: {NO_COMPILED}")
def test_both_paths_take_the_same_few_arguments():
    """Issue 35: every kernel the two paths share has the same parameters in both, and no
    kernel (theirs, the thermal and the supernodal Cholesky's) takes more than
    MAX_KERNEL_ARGS: the rest travel in the named tuples of mechanics/kernel_args.py."""
    from holofold.mechanics import _compiled, _numpy_kernels, supernodal
    from holofold.mechanics.kernel_args import MAX_KERNEL_ARGS

    shared = set(_numpy_kernels.__all__) - {"lapack_addresses"}
    assert {"assemble_batch", "newton_increments", "small_newton_step"} <= shared
    for name in sorted(shared):
        assert _parameters(getattr(_compiled, name)) == _parameters(
            getattr(_numpy_kernels, name)
        ), name
    over = {}
    for mod in (_compiled, _numpy_kernels, supernodal):
        for name, fn in vars(mod).items():
            kernel = hasattr(fn, "py_func") or (
                inspect.isfunction(fn) and fn.__module__ == mod.__name__
            )
            if kernel and len(_parameters(fn)) > MAX_KERNEL_ARGS:
                over[f"{mod.__name__}.{name}"] = len(_parameters(fn))
    assert over == {}
