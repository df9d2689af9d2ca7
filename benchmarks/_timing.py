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


def machine_speed() -> str:
    """The CPU speed of this machine in two fixed workloads, for comparing figures measured
    on different machines or under different loads: the least CPU seconds (best of 3) of a
    pure-Python loop of 10^7 additions (the interpreter: glue, model building) and of five
    1000 x 1000 matrix products on one BLAS thread (compiled code). On the 2-core machine of
    2026-12-07 (later) the loop took 0.42-1.68 s and the products 0.26-0.38 s within one hour,
    idle or not (benchmarks/speed_targets.md): the host's speed moves, so every timing table
    should carry this line beside its load."""
    import numpy as np
    from threadpoolctl import threadpool_limits

    def loop():
        s = 0
        for i in range(10_000_000):
            s += i
        return s

    a = np.random.default_rng(0).random((1000, 1000))

    def blas():
        for _ in range(5):
            a @ a

    out = []
    with threadpool_limits(1):
        for fn in (loop, blas):
            best = float("inf")
            for _ in range(3):
                c0 = time.process_time()
                fn()
                best = min(best, time.process_time() - c0)
            out.append(best)
    return f"machine: Python loop 1e7 {out[0]:.2f} s CPU, 5 matrix products {out[1]:.2f} s CPU"
