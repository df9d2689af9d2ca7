"""Speed of the paper's scenario evaluations (issue 4, section 6).

Prints a table of medians over ``--repeat`` runs (default 7) on one core (BLAS limited to one
thread) for one arch sample at m = 8, 12, 16, 24 (both load cases), one single Miura sample
(three extensions) and one canopy sample at 36 x 12 (six analyses, Miura and TMP), with the
reference simulator's Octave figures of the issue and the speed-up. ``build`` is the part spent
building the models (geometry + bar-and-hinge model), the rest is the nonlinear solves.

    python benchmarks/bench_mechanics.py [--repeat 7]
"""

from __future__ import annotations

import statistics
import sys
import time

from _timing import one_core_repeats
from threadpoolctl import threadpool_limits

from holofold.design.scenarios import arch, canopy, single_miura

# a design in the middle of the paper's sampling ranges (SI units)
MID = dict(tcrease=0.75e-3, tpanel=3.5e-3, W=2.5e-3)
ARCH = dict(**MID, offset=0.2, stripeWidth=0.025, extrude=0.15)

#: reference simulator under Octave on this kind of machine (issue 4, section 6), seconds
OCTAVE = {"arch m=8": 13.0, "arch m=12": 24.0, "arch m=24": 65.0, "single Miura": 1.1}
TARGET = {"arch m=24": 0.1, "single Miura": 0.02, "canopy Miura 36x12": 1.0,
          "canopy TMP 36x12": 1.0}  # fmt: skip


def _median_time(fn, repeat: int) -> float:
    fn()  # warm-up: caches of topology and sparse pattern
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts)


def cases():
    out = []
    for m in (8, 12, 16, 24):
        row = dict(ARCH, m=m)
        out.append(
            (f"arch m={m}", lambda r=row: arch.evaluate(r), lambda r=row: arch.arch_model(r))
        )
    sm = dict(MID, gama=1.1)
    out.append(
        (
            "single Miura",
            lambda: single_miura.evaluate(sm),
            lambda: single_miura.cell_models(sm["tcrease"], sm["tpanel"], sm["W"], sm["gama"]),
        )
    )
    for pat, label in ((1, "Miura"), (2, "TMP")):
        row = dict(MID, pattern=pat, m=36, n=12, creaseE=2e9, panelE=2e9)
        out.append(
            (
                f"canopy {label} 36x12",
                lambda r=row: canopy.evaluate(r),
                lambda r=row: canopy.sheet_models(r),
            )
        )
    return out


def main(argv=None) -> int:
    repeat = one_core_repeats(
        "holofold mechanics benchmark (issue 4, section 6)", 7, 5, "case", argv
    )
    cols = ("total ms", 10), ("build ms", 9), ("target ms", 10), ("Octave s", 9), ("speed-up", 9)
    head = f"{'case':<20} " + " ".join(f"{c:>{w}}" for c, w in cols)
    print(head)
    print("-" * len(head))
    with threadpool_limits(1):
        for name, full, build in cases():
            t = _median_time(full, repeat)
            tb = _median_time(build, repeat)
            ref = OCTAVE.get(name)
            tgt = TARGET.get(name)
            print(
                f"{name:<20} {1e3 * t:>10.1f} {1e3 * tb:>9.1f} "
                f"{'' if tgt is None else f'{1e3 * tgt:.0f}':>10} "
                f"{'' if ref is None else f'{ref:.1f}':>9} "
                f"{'' if ref is None else f'{ref / t:.0f}x':>9}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
