"""Spring rows against element-major spring memory in the batch path: where
``SPRING_ROWS_MAX`` comes from (issue 14).

The batch path runs the bar and spring kernels of a design into one scratch memory and the
gathers read the tangent from it. With the springs' entries as contiguous rows over the
springs (the kernels' own layout) the spring loop runs vectorised; with each spring's 90
entries together (element-major) it runs scalar, but a gather target's sources lie closer.
For concentrated-hinge models of growing size this times, in one process and interleaved
round by round (so that a machine whose speed drifts meets both alike), the kernels plus the
band gather of one Newton step in each memory, and checks that both give the same band bit
for bit. The assembler keeps rows up to ``SPRING_ROWS_MAX`` springs.

    python benchmarks/bench_scratch_layout.py [--rounds 60] [--sizes arch8 sheet24x8 ...]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

import holofold.mechanics.assembly as assembly
from holofold.design.scenarios import arch, canopy
from holofold.design.scenarios.sheet import sheet_models_batch
from holofold.design.scenarios.strip import strip_models
from holofold.mechanics import _compiled as ck

MID = dict(tcrease=0.75e-3, tpanel=3.5e-3, W=2.5e-3)
SIZES = ["arch8", "arch16", "arch24", "sheet12x4", "sheet18x6", "sheet24x8", "sheet36x12"]


def structure(size: str):
    if size.startswith("arch"):
        row = dict(MID, offset=0.2, stripeWidth=0.025, extrude=0.15, m=int(size[4:]))
        return strip_models(arch.SETTING, [row])[0][0]
    m, n = map(int, size[5:].split("x"))
    row = dict(MID, pattern=1, m=m, n=n, creaseE=2e9, panelE=2e9)
    return sheet_models_batch(canopy.SETTING, [row])[0][0][0]


def step(st, rows: bool):
    """Kernels + band gather of one step of ``st`` in one memory (``rows``: spring rows)."""
    a = assembly.Assembler(st)
    red = a.reduction
    nb, ns = len(a.bars), len(a.springs)
    saved = assembly.SPRING_ROWS_MAX
    assembly.SPRING_ROWS_MAX = ns if rows else -1
    try:
        lists = assembly._scratch_lists(red.band_gather, nb, ns, True)
        views, flats = assembly._scratch_buffers(nb, ns)
    finally:
        assembly.SPRING_ROWS_MAX = saved
    eb, fb, Kb, es, fs, Ks, th = views
    p, sp, q, sq, r, sr, dest = lists
    out = np.zeros(assembly._band_size(red))
    U = np.full_like(a._X, 1e-4)

    def springs():
        ck.spring_elements(a._X, U, a._sT, a._k, a.theta0, a._k_nonneg, True, es, fs, Ks, th)

    def run():
        ck.bar_elements(a._X, U, a._b0, a._b1, a._D0, a._L0, a._EA, True, eb, fb, Kb)
        springs()
        out[:] = 0.0
        ck.gather(p, sp, flats[2], q, sq, flats[5], r, sr, flats[5], dest, out)
        return out

    return run, springs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=60)
    ap.add_argument("--sizes", nargs="*", default=SIZES)
    args = ap.parse_args(argv)
    print(f"best of {args.rounds} interleaved rounds, us: the spring kernel alone (vectorised in")
    print("rows, scalar element-major) and the kernels + band gather of one step")
    print(f"SPRING_ROWS_MAX = {assembly.SPRING_ROWS_MAX}")
    head = (
        f"{'model':<12} {'springs':>8} {'kernel rows':>12} {'kernel em':>10} "
        f"{'step rows':>10} {'step em':>8} {'rows/em':>8}"
    )
    print(head)
    print("-" * len(head))
    with threadpool_limits(1):
        for size in args.sizes:
            st = structure(size)
            fns = {True: step(st, True), False: step(st, False)}
            if not np.array_equal(fns[True][0]().copy(), fns[False][0]()):
                raise SystemExit(f"{size}: the two memories give different bands")
            best = {(k, part): np.inf for k in fns for part in (0, 1)}
            for _ in range(args.rounds):
                for k, pair in fns.items():
                    for part, fn in enumerate(pair):
                        t = time.perf_counter()
                        fn()
                        best[k, part] = min(best[k, part], time.perf_counter() - t)
            us = {key: 1e6 * v for key, v in best.items()}
            print(
                f"{size:<12} {len(st.springs):>8d} {us[True, 1]:>12.1f} {us[False, 1]:>10.1f} "
                f"{us[True, 0]:>10.1f} {us[False, 0]:>8.1f} {us[True, 0] / us[False, 0]:>8.2f}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
