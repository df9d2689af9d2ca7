"""Kernel benchmark: assembly time per evaluation and one Newton solve, growing model size,
on each kernel path (numpy, the reference; compiled, numba).

Run from the repository root::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_kernels.py [--repeat 7]

Models: concentrated-hinge Miura sheets (``geometry.miura.miura_sheet`` +
``mechanics.hinges.build_concentrated``) when those modules are importable, and synthetic
triangulated sheets (bars on every edge, a spring on every interior edge) otherwise / as well.
Each row reports medians over ``--repeat`` runs (wall clock and process CPU time): one
``Assembler.evaluate_factorized`` (energy, internal force, tangent, factorisation), one linear
solve with it, and one ``solve_newton`` of 3 load increments (tol 1e-8 relative to the model
size), with the linear-solver path taken (dense LAPACK, banded Cholesky or SuperLU).
"""

from __future__ import annotations

import argparse
import os

import numpy as np
from _timing import median_times

from holofold.mechanics import kernels
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.linear import BANDED_MAX_WORK, DENSE_MAX_DOF, solver_path
from holofold.mechanics.solvers import solve_newton
from holofold.mechanics.springs import dihedral_angle
from holofold.mechanics.structure import Structure


def synthetic_sheet(nx: int, ny: int, *, seed: int = 0) -> Structure:
    """Triangulated nx x ny node grid (unit spacing, wavy heights), stress free, clamped on
    the first row of nodes."""
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float))
    z = 0.2 * np.sin(xs) + 0.01 * rng.normal(size=xs.shape)
    nodes = np.c_[xs.ravel(), ys.ravel(), z.ravel()] * 0.01
    tris = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = j * nx + i
            tris += [[a, a + 1, a + nx + 1], [a, a + nx + 1, a + nx]]
    opp: dict[tuple[int, int], list[int]] = {}
    for p, q, r in tris:
        for u, v, o in ((p, q, r), (q, r, p), (r, p, q)):
            opp.setdefault((min(u, v), max(u, v)), []).append(o)
    bars = np.array(sorted(opp))
    springs = np.array([[o[0], e[0], e[1], o[1]] for e, o in sorted(opp.items()) if len(o) == 2])
    sup = np.zeros((nx * ny, 3), bool)
    sup[:nx] = True
    return Structure(
        nodes=nodes,
        bars=bars,
        bar_area=1e-6,
        bar_E=2e9,
        springs=springs,
        spring_k=1e-3,
        spring_rest=dihedral_angle(nodes, springs),
        supports=sup,
    )


def miura_model(m: int, n: int) -> Structure | None:
    try:
        from holofold.geometry.miura import miura_sheet
        from holofold.mechanics.hinges import build_concentrated
    except ImportError:
        return None
    p = miura_sheet(m, n, 0.01, 0.01, np.deg2rad(60.0), 0.6)
    s = build_concentrated(p, crease_width=3e-3, crease_thickness=5e-4, panel_thickness=2e-3)
    sup = np.zeros((s.n_nodes, 3), bool)
    x = s.nodes[:, 0]
    sup[np.isclose(x, x.min())] = True
    return s.with_supports(sup)


def _path(asm: Assembler) -> str:
    return solver_path(asm.reduction, asm.dense_max)


def bench(name: str, s: Structure, repeat: int) -> str:
    """One table row on the active kernel path."""
    asm = Assembler(s)
    rng = np.random.default_rng(1)
    U = 1e-4 * rng.normal(size=(s.n_nodes, 3)) * ~s.supports
    nf = asm.free_dofs.size
    t_eval = median_times(lambda: asm.evaluate_factorized(U), repeat)
    t_asm = median_times(lambda: asm.evaluate(U), repeat)
    rhs = np.ones(nf)
    solve = asm.evaluate_factorized(U)[2]
    t_sol = median_times(lambda: solve(rhs), repeat)
    load = np.zeros((s.n_nodes, 3))
    free_nodes = np.flatnonzero(~s.supports.any(axis=1))
    load[free_nodes[-3:], 2] = -1e-3
    res = solve_newton(s, load, increments=3, tol=1e-10, assembler=asm)
    t_nr = median_times(
        lambda: solve_newton(s, load, increments=3, tol=1e-10, assembler=asm), repeat
    )
    bw = asm.reduction.band.bandwidth if nf > asm.dense_max else 0
    return (
        f"| {kernels.active().name:<8} | {name:<14} | {s.n_nodes:5d} | {len(s.bars):5d} "
        f"| {len(s.springs):5d} | {nf:5d} "
        f"| {bw:4d} | {_path(asm):<7} | {t_asm[0] * 1e3:6.2f} / {t_asm[1] * 1e3:6.2f} "
        f"| {t_eval[0] * 1e3:6.2f} / {t_eval[1] * 1e3:6.2f} | {t_sol[0] * 1e3:6.3f} "
        f"| {int(res.iterations.sum()):3d} | {t_nr[0] * 1e3:7.1f} / {t_nr[1] * 1e3:7.1f} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7, help="runs per timing (median)")
    args = ap.parse_args()
    print(
        f"dense below {DENSE_MAX_DOF} free DOFs; banded Cholesky up to n*(bw+1)^2 = "
        f"{BANDED_MAX_WORK:.0e}; medians of {args.repeat} runs (ms)"
    )
    print("times: wall / process CPU, ms (assemble = energy + force + tangent scatter;")
    print("asm+fact = assemble + reduced factorisation; solve = one back-substitution;")
    print("NR = solve_newton, 3 increments, tol 1e-10 m, total iterations 'it')")
    print(
        "| path     | model          | nodes |  bars | sprgs |  free |   bw | solver  "
        "|     assemble    |     asm+fact    |  solve | it |   Newton (3 inc)  |"
    )
    print("|" + "|".join("-" * w for w in (10, 16, 7, 7, 7, 7, 6, 9, 17, 17, 8, 4, 19)) + "|")
    models = []
    for m, n in ((2, 2), (4, 4), (8, 4), (12, 6), (24, 8), (36, 12)):
        s = miura_model(m, n)
        if s is not None:
            models.append((f"miura {m}x{n}", s))
    for nx, ny in ((4, 4), (10, 6), (20, 10), (40, 16), (60, 20)):
        models.append((f"sheet {nx}x{ny}", synthetic_sheet(nx, ny)))
    for name, s in models:
        for path in kernels.KERNEL_PATHS:
            os.environ[kernels.ENV] = path
            print(bench(name, s, args.repeat), flush=True)


if __name__ == "__main__":
    main()
