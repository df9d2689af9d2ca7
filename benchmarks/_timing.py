"""Timing helpers shared by the benchmark scripts (run as ``python benchmarks/bench_x.py``)."""

from __future__ import annotations

import argparse
import statistics
import time


def median_times(fn, repeat: int) -> tuple[float, float]:
    """Median wall-clock and CPU (all threads of this process) seconds of ``fn()`` over
    ``repeat`` runs, after one warm-up run (caches, imports)."""
    fn()  # warm-up
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)


def one_core_repeats(description: str, default: int, least: int, what: str, argv=None) -> int:
    """Parse a benchmark's only option ``--repeat`` (at least ``least`` timed runs per
    ``what``), say that medians of that many one-core runs follow, and return it."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--repeat", type=int, default=default,
                    help=f"timed runs per {what} (>= {least})")  # fmt: skip
    repeat = max(least, ap.parse_args(argv).repeat)
    print(f"medians of {repeat} runs, one core (BLAS 1 thread)")
    return repeat
