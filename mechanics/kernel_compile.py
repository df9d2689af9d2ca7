"""Compiling the compiled kernel path ahead: small models through every assembly and solver
path, so that numba compiles (or loads) every specialisation holofold calls before a real run
needs it (tests/test_kernel_paths.py checks that a warm cache serves the scenarios without
compiling).

:func:`compile_kernels` is what the background compile of ``HOLOFOLD_KERNELS=auto`` runs
(:mod:`holofold.mechanics.kernels`), and what ``python -m holofold.mechanics.kernel_compile``
does (``status``: the kernel path in use and the cache folder; ``compile``: compile now). This
module sits above the kernel selector: it imports the models and solvers it exercises, none of
them imports it.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from holofold.geometry.errors import EnvironmentFault
from holofold.mechanics.kernels import (
    ENV,
    _failed_marker,
    _ready_marker,
    _require_numba,
    active,
    cache_folder,
    requested,
)

__all__ = ["run_warmup", "compile_kernels"]


def _sheet(m: int, n: int, *, compliant: bool = False):
    from holofold.geometry.miura import miura_sheet
    from holofold.mechanics.hinges import build_compliant, build_concentrated

    pat = miura_sheet(m, n, a=0.02, b=0.02, gamma=1.0, ext=0.6)
    kw = dict(crease_width=2e-3, crease_thickness=5e-4, panel_thickness=2e-3)
    if compliant:
        s = build_compliant(pat, **kw, E_panel=2e9, E_crease=2e9, nu_panel=0.3, nu_crease=0.3)
    else:
        s = build_concentrated(pat, **kw)
    sup = np.zeros((s.n_nodes, 3), bool)
    sup[:3] = True
    return s.with_supports(sup)


def _exercise(structures) -> None:
    from holofold.mechanics.assembly import Assembler, BatchAssembler

    s = structures[0]
    rng = np.random.default_rng(0)
    U = 1e-4 * rng.normal(size=(s.n_nodes, 3))
    asm = Assembler(s)
    asm.evaluate(U)
    asm.evaluate_reduced(U, dense=True)
    asm.evaluate_reduced(U, dense=False)
    asm.internal_force(U)
    asm.element_response(U)
    _, f, solve = asm.evaluate_factorized(U)
    solve(-f[asm.free_dofs])
    Uf = np.ascontiguousarray(U.ravel())
    F = np.zeros(s.n_dof)
    step = asm.dense_stepper(Uf, F, r=np.empty(asm.free_dofs.size))
    if step is not None:
        step()
    step = asm.dense_stepper(Uf, F)
    if step is not None:
        step()
    batch = BatchAssembler(structures)
    US = np.ascontiguousarray(np.tile(U.ravel(), (len(structures), 1)))
    batch.factorized(US.reshape(len(structures), -1, 3), np.ones(len(structures), bool))
    batch.newton_step(US, np.zeros_like(US), np.ones(len(structures), bool))
    from holofold.mechanics.solvers import solve_newton, solve_newton_batch, solve_selffold

    load = np.zeros((s.n_nodes, 3))
    load[-1, 2] = -1e-3
    solve_newton_batch(structures, [load] * len(structures), increments=2, tol=1e-9)
    # one structure's load increments in one kernel call (the gripper's prying load)
    solve_newton(s, load, increments=2, tol=1e-9)
    # self-folding by rest angles (fold_pattern, the surface fold check, the thermal stages):
    # every increment in one kernel call on the dense path (missing here, the first fold of a
    # process compiled it: 17 s CPU, 2026-12-07)
    solve_selffold(s, s.spring_rest - 0.05, increments=2, tol=1e-9)


def _thermal() -> None:
    from holofold.geometry.gripper import two_panel_gripper
    from holofold.mechanics.hinges import build_compliant
    from holofold.mechanics.thermal import heat_input_matrix, steady_temperature, thermal_model

    pat = two_panel_gripper(4.1e-3, 3.1e-3, 0.49).pattern
    s = build_compliant(
        pat, crease_width=150e-6, crease_thickness=1.2e-6, panel_thickness=27e-6,
        E_panel=2e9, E_crease=2e9, nu_panel=0.3, nu_crease=0.3, diagonal_rate=100.0,
    )  # fmt: skip
    model = thermal_model(s, panel_conductivity=0.3, crease_conductivity=0.3, air_thickness=4.6e-3)
    q = heat_input_matrix(s.creases.nodes, s.n_nodes) @ np.full(len(s.creases.ids), 0.01)
    steady_temperature(model, s.nodes, q)


def _supernodal() -> None:
    """holofold's own sparse Cholesky (the "cholesky" path without cvxopt) and LDL^T, on a 2-D
    grid Laplacian: every function of its analysis, factorisations and solves."""
    import scipy.sparse as sp

    from holofold.mechanics.supernodal import SupernodalCholesky

    n = 12
    T = sp.diags([-np.ones(n - 1), 4.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    S = sp.diags([-np.ones(n - 1)] * 2, [-1, 1])
    K = (sp.kron(sp.identity(n), T) + sp.kron(S, sp.identity(n))).tocsr()
    K.sort_indices()
    chol = SupernodalCholesky(K.indptr, K.indices)
    factor = chol.factor(K.data)
    factor.solve(np.ones(n * n))
    factor.solve(np.ones((n * n, 2)))
    # indefinite (diagonal +-5, dominant): the LDL^T factor and its solve
    rows = np.repeat(np.arange(n * n), np.diff(K.indptr))
    signed = np.where(rows == K.indices, np.where(rows % 2, 5.0, -5.0), K.data)
    chol.factor_ldl(signed).solve(np.ones(n * n))


def run_warmup() -> None:
    """Evaluate, factorise and step small dense (2 x 2 Miura), banded (6 x 6) and compliant
    models, one design and batches, the gripper's small thermal model and holofold's own
    sparse Cholesky."""
    for m, n in ((2, 2), (6, 6)):
        _exercise([_sheet(m, n), _sheet(m, n)])
    _exercise([_sheet(2, 2, compliant=True)] * 2)
    _thermal()
    _supernodal()


def compile_kernels(*, marker: bool = False) -> float:
    """Compile (or load) every specialisation of the compiled kernels that holofold calls, by
    running small models through each assembly and solver path; returns the seconds it took.
    With ``marker``, records in the cache folder that they are ready (or why they failed)."""
    t0 = time.perf_counter()
    _require_numba()
    try:
        os.environ[ENV] = "compiled"
        run_warmup()
    except BaseException as exc:
        if marker:
            _failed_marker().write_text(f"{type(exc).__name__}: {exc}\n")
            (cache_folder() / "compiling").unlink(missing_ok=True)
        if isinstance(exc, Exception) and not isinstance(exc, EnvironmentFault):
            raise EnvironmentFault(
                f"the compiled kernels failed to compile ({type(exc).__name__}: {exc}); "
                f"set {ENV}=numpy to run on the numpy kernels"
            ) from exc
        raise
    if marker:
        tmp = cache_folder() / f".ready-{os.getpid()}"
        tmp.write_text(f"{time.perf_counter() - t0:.1f} s\n")
        tmp.replace(_ready_marker())
        (cache_folder() / "compiling").unlink(missing_ok=True)
    return time.perf_counter() - t0


def _main(argv: list[str]) -> int:
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m holofold.mechanics.kernel_compile",
        description="Show or compile holofold's kernel paths.",
    )
    parser.add_argument("action", choices=["status", "compile"], nargs="?", default="status")
    parser.add_argument("--marker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.action == "compile":
        seconds = compile_kernels(marker=args.marker)
        print(f"compiled kernels ready in {cache_folder()} ({seconds:.1f} s)")  # noqa: T201
        return 0
    print(f"{ENV}={requested()}; active path: {active().name}; cache: {cache_folder()}")  # noqa: T201
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
