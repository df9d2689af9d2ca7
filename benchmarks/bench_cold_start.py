"""Cold and warm start: the time to a fresh environment's first result (issue 22, item 4).

Each case is a new process of the command line with its own kernel cache folder
(``HOLOFOLD_KERNEL_CACHE``): ``cold`` starts from an empty folder (the default ``auto`` kernel
path: numpy while one background process compiles), ``warm`` from the folder the cold run's
background compile filled, ``cold, compiled`` is an empty folder with ``HOLOFOLD_KERNELS=compiled``
(the process compiles before its first row: what every fresh environment paid before), and
``numpy`` never compiles. The commands: ``holofold evaluate arch`` of one row (wall clock of
the process) and ``holofold demo`` (wall clock to its first simulated row, read from the
progress of its database, and to the end).

    python benchmarks/bench_cold_start.py [--demo] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROW = "m,tcrease,tpanel,W,offset,stripeWidth,extrude\n12,8e-4,3e-3,2e-3,0.2,0.02,0.1\n"


def _holofold() -> list[str]:
    exe = shutil.which("holofold", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "holofold.cli"]


def _env(cache: Path, kernels: str = "auto") -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("HOLOFOLD_", "NUMBA_"))}
    env["HOLOFOLD_KERNEL_CACHE"] = str(cache)
    env["HOLOFOLD_KERNELS"] = kernels
    return env


def _wait_ready(cache: Path, timeout: float = 900.0) -> float:
    t0 = time.perf_counter()
    while not any(cache.glob("kernels-*/ready")):
        if any(cache.glob("kernels-*/failed")) or time.perf_counter() - t0 > timeout:
            raise RuntimeError(f"the background compile in {cache} did not finish")
        time.sleep(0.5)
    return time.perf_counter() - t0


def evaluate_one(work: Path, cache: Path, kernels: str) -> float:
    rows = work / "row.csv"
    rows.write_text(ROW)
    t0 = time.perf_counter()
    subprocess.run(
        [*_holofold(), "evaluate", "arch", str(rows), "-o", str(work / "out.csv")],
        env=_env(cache, kernels), check=True, capture_output=True, cwd=work,
    )  # fmt: skip
    return time.perf_counter() - t0


def demo(work: Path, cache: Path, kernels: str) -> tuple[float, float]:
    """(seconds to the first simulated row, seconds to the end) of ``holofold demo``."""
    out = work / "demo"
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [*_holofold(), "demo", "-o", str(out)], env=_env(cache, kernels), cwd=work,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    first = None
    while proc.poll() is None:
        if first is None and any(out.glob("**/chunks/part-*.parquet")):
            first = time.perf_counter() - t0
        time.sleep(0.05)
    if proc.returncode:
        raise RuntimeError(f"holofold demo failed ({proc.returncode})")
    end = time.perf_counter() - t0
    return (end if first is None else first), end


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--demo", action="store_true", help="also time holofold demo")
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.1f}; {os.cpu_count()} cores")
    print(
        "| case | evaluate arch, 1 row (s) |"
        + (" demo: first chunk / end (s) |" if args.demo else "")
    )
    print("|---|---|" + ("---|" if args.demo else ""))
    results: dict[str, list] = {}
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            cache = tmp / "cache"
            results.setdefault("cold (auto: numpy while compiling)", []).append(
                evaluate_one(tmp, cache, "auto"))  # fmt: skip
            compile_s = _wait_ready(cache)
            results.setdefault("warm (compiled, cache ready)", []).append(
                evaluate_one(tmp, cache, "auto"))  # fmt: skip
            results.setdefault("numpy (never compiles)", []).append(
                evaluate_one(tmp, cache, "numpy"))  # fmt: skip
            results.setdefault("cold, compiled in the process (before)", []).append(
                evaluate_one(tmp, tmp / "cache2", "compiled"))  # fmt: skip
            results.setdefault("background compile, from the cold run (s)", []).append(compile_s)
            if args.demo:
                results.setdefault("demo cold", []).append(demo(tmp, tmp / "cache3", "auto"))
                results.setdefault("demo warm", []).append(demo(tmp, tmp / "cache3", "auto"))
    for case, vals in results.items():
        if case.startswith("demo"):
            first = statistics.median(v[0] for v in vals)
            end = statistics.median(v[1] for v in vals)
            print(f"| {case} | | {first:.1f} / {end:.1f} |")
        else:
            print(f"| {case} | {statistics.median(vals):.1f} (min {min(vals):.1f}) |"
                  + (" |" if args.demo else ""))  # fmt: skip


if __name__ == "__main__":
    main()
