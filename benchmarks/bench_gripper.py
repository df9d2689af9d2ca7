"""Speed of the gripper scenario (issue 5, section 5): one published sample per pattern.

Prints the median of ``--repeat`` full runs (default 3) on one core (BLAS limited to one thread)
of one published row per pattern -- natural frequency, pre-bias, heating until closure and the
prying stiffness -- with its closing heating step, the time per heating step, the reference
simulator's Octave figures of the issue and the target of 2 s per sample; the last column is the
same run with every Newton solve converged tightly (``GripperOptions(converged=True)``).

    python benchmarks/bench_gripper.py [--repeat 3]
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from _timing import one_core_repeats
from threadpoolctl import threadpool_limits

from holofold.design.scenarios.gripper import GripperOptions, simulate

ROOT = Path(__file__).resolve().parents[1]

#: (file, 0-based row): published rows closing at heating steps 145, 117 and 88
SAMPLES = {
    "Miura-based": ("data2_MiuraBased_sample", 1),
    "splitted Miura": ("data2_SplittedMiura_sample", 0),
    "two-panel": ("data2_TwoPanel_sample", 1),
}
OCTAVE = {"splitted Miura": 600.0, "two-panel": 80.0}  #: seconds, issue 5 section 5
TARGET = 2.0
NAMES = ["Pattern", "L1", "L2", "t1", "t2", "tpanel", "rate", "W"]


def _row(stem: str, i: int) -> dict:
    folder = Path(os.environ.get("HOLOFOLD_REFERENCE_DATA", ROOT.parent / "shared/reference-data"))
    arr = np.loadtxt(folder / f"{stem}.txt", delimiter=",", ndmin=2)
    return dict(zip(NAMES, arr[i, :8], strict=True))


def _median_time(row: dict, options: GripperOptions, repeat: int) -> float:
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        simulate(row, options)
        ts.append(time.perf_counter() - t)
    return statistics.median(ts)


def main(argv=None) -> int:
    repeat = one_core_repeats(
        "holofold gripper benchmark (issue 5, section 5)", 3, 3, "sample", argv
    )
    head = (
        f"{'pattern':<16} {'steps':>6} {'total s':>8} {'ms/step':>8} {'target s':>9} "
        f"{'Octave s':>9} {'speed-up':>9} {'converged s':>12}"
    )
    print(head)
    print("-" * len(head))
    with threadpool_limits(1):
        for name, (stem, i) in SAMPLES.items():
            row = _row(stem, i)
            res = simulate(row)  # warm-up (sparse patterns, imports)
            t = _median_time(row, GripperOptions(), repeat)
            tc = _median_time(row, GripperOptions(converged=True), repeat)
            steps = res.closing_step or 0
            ref = OCTAVE.get(name)
            print(
                f"{name:<16} {steps:>6d} {t:>8.2f} {1e3 * t / max(steps, 1):>8.1f} "
                f"{TARGET:>9.1f} {'' if ref is None else f'{ref:.0f}':>9} "
                f"{'' if ref is None else f'{ref / t:.0f}x':>9} {tc:>12.2f}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
