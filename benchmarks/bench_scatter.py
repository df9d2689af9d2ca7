"""Tangent sums by scatter (the assembler's) against a gather target by target (the code
before it): where ``_compiled.scatter`` comes from (issue 14).

Every Newton step sums the kernels' element entries into the tangent's targets (the band, the
dense block or the CSR data). Bit for bit the same sums either way: each target's entries of a
family added in the kernels' flat order, then the families added. A gather visits the targets
one by one and reads each one's entries from wherever they lie; the scatter reads the entries
in the order they lie in memory and adds each into its target's sum. For concentrated-hinge
models of growing size this times, in one process and interleaved round by round (so that a
machine whose speed drifts meets all alike), the bar and spring kernels of one step alone, and
with the tangent and force sums by each method, and checks that both give the same bits.

    python benchmarks/bench_scatter.py [--rounds 60] [--sizes single arch8 sheet24x8 ...]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit
from threadpoolctl import threadpool_limits

import holofold.mechanics.assembly as assembly
from holofold.design.scenarios import arch, canopy, single_miura
from holofold.design.scenarios.sheet import sheet_models_batch
from holofold.design.scenarios.strip import strip_models
from holofold.mechanics import _compiled as ck

MID = dict(tcrease=0.75e-3, tpanel=3.5e-3, W=2.5e-3)
SIZES = ["single", "arch8", "arch16", "arch24", "sheet12x4", "sheet24x8", "sheet36x12"]


def structure(size: str):
    if size == "single":
        return sheet_models_batch(single_miura.SETTING, [dict(MID, gama=1.1)])[0][0][0]
    if size.startswith("arch"):
        row = dict(MID, offset=0.2, stripeWidth=0.025, extrude=0.15, m=int(size[4:]))
        return strip_models(arch.SETTING, [row])[0][0]
    m, n = map(int, size[5:].split("x"))
    row = dict(MID, pattern=1, m=m, n=n, creaseE=2e9, panelE=2e9)
    return sheet_models_batch(canopy.SETTING, [row])[0][0][0]


@njit(cache=True)
def gather(ptr_a, src_a, val_a, ptr_b, src_b, val_b, ptr_c, src_c, val_c, dest, out):
    """The sums target by target (the assembler's code before the scatter)."""
    for p in range(dest.shape[0]):
        sa = 0.0
        for q in range(ptr_a[p], ptr_a[p + 1]):
            sa += val_a[src_a[q]]
        sb = 0.0
        for q in range(ptr_b[p], ptr_b[p + 1]):
            sb += val_b[src_b[q]]
        sc = 0.0
        for q in range(ptr_c[p], ptr_c[p + 1]):
            sc += val_c[src_c[q]]
        out[dest[p]] = (sa + sb) + sc


def gather_lists(lists):
    """:func:`assembly._sum_lists` (scatter form) as gather lists: per family the pointers
    into the sources, target by target, each target's sources in their flat order."""
    out = []
    n = lists[6].size
    for src, pos in (lists[0:2], lists[2:4], lists[4:6]):
        order = np.argsort(pos, kind="stable")
        ptr = np.zeros(n + 1, np.int32)
        ptr[1:] = np.cumsum(np.bincount(pos, minlength=n))
        out += [ptr, np.ascontiguousarray(src[order])]
    return (*out, lists[6])


def step(st):
    """(solver path, entries summed, (kernels, kernels + gathers, kernels + scatters)) of one
    Newton step of ``st``."""
    a = assembly.Assembler(st)
    red = a.reduction
    path = assembly.solver_path(red, a.dense_max)
    tl, size = red.tangent_sums("dense" if path == "dense" else "banded")
    fl = a.pattern.force_sums
    tg, fg = gather_lists(tl), gather_lists(fl)
    views, flats = assembly._scratch_buffers(len(a.bars), len(a.springs))
    eb, fb, Kb, es, fs, Ks, th = views
    out, f = np.zeros(size), np.zeros(a.n_dof)
    acc = np.empty(3 * max(tl[6].size, fl[6].size))
    U = np.full_like(a._X, 1e-4)

    def kernels():
        ck.bar_elements(a._X, U, a._b0, a._b1, a._D0, a._L0, a._EA, True, eb, fb, Kb)
        ck.spring_elements(a._X, U, a._sT, a._k, a.theta0, a._k_nonneg, True, es, fs, Ks, th)

    def by_gather():
        kernels()
        out[:] = 0.0
        f[:] = 0.0
        gather(*tg[:2], flats[2], *tg[2:4], flats[5], *tg[4:6], flats[5], tg[6], out)
        gather(*fg[:2], flats[1], *fg[2:4], flats[4], *fg[4:6], flats[4], fg[6], f)
        return np.concatenate([out, f])

    def by_scatter():
        kernels()
        out[:] = 0.0
        f[:] = 0.0
        ck.scatter(*tl[:2], flats[2], *tl[2:4], flats[5], *tl[4:6], flats[5], tl[6], acc, out)
        ck.scatter(*fl[:2], flats[1], *fl[2:4], flats[4], *fl[4:6], flats[4], fl[6], acc, f)
        return np.concatenate([out, f])

    n = tl[0].size + tl[2].size + tl[4].size
    return path, n, (kernels, by_gather, by_scatter)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=60)
    ap.add_argument("--sizes", nargs="*", default=SIZES)
    args = ap.parse_args(argv)
    print(f"best of {args.rounds} interleaved rounds, us per step: the kernels alone, and the")
    print("kernels with the tangent and force sums by gather (target by target) and by scatter")
    head = (
        f"{'model':<12} {'target':>7} {'entries':>8} {'kernels':>8} {'+gather':>8} "
        f"{'+scatter':>9} {'sums g':>7} {'sums s':>7} {'step s/g':>9}"
    )
    print(head)
    print("-" * len(head))
    with threadpool_limits(1):
        for size in args.sizes:
            st = structure(size)
            path, n, fns = step(st)
            if fns[1]().tobytes() != fns[2]().tobytes():
                raise SystemExit(f"{size}: the gather and the scatter give different bits")
            best = [np.inf] * 3
            rounds = args.rounds * (10 if size == "single" else 1)
            for _ in range(rounds):
                for i, fn in enumerate(fns):
                    t = time.perf_counter()
                    fn()
                    best[i] = min(best[i], time.perf_counter() - t)
            k, g, s = (1e6 * b for b in best)
            print(
                f"{size:<12} {path:>7} {n:>8d} {k:>8.1f} {g:>8.1f} {s:>9.1f} {g - k:>7.1f} "
                f"{s - k:>7.1f} {s / g:>9.2f}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
