"""Cold and warm start, the demo and the command start-up, as whole processes (issues 22, 37).

Every case is a new process of the command line, timed by the wall clock from outside, with
its own kernel cache folder (``HOLOFOLD_KERNEL_CACHE``) and its own output folder, new for
every run unless the case says otherwise. The cases run side by side: each repeat runs every
case once, so a machine whose load drifts meets them alike. Each case prints the median, min
and max of its runs and the 1-minute load average before its runs (min-max): on a shared
machine only figures measured at a low load count against a target.

``evaluate``: ``holofold evaluate arch`` of one row.

* ``cold``: an empty cache (the default ``auto`` kernel path: numpy while one background
  process compiles);
* ``warm``: the cache the cold run's background compile filled;
* ``numpy``: ``HOLOFOLD_KERNELS=numpy``, never compiles;
* ``cold, compiled in the process``: an empty cache with ``HOLOFOLD_KERNELS=compiled``.

``demo`` (``--demo``): ``holofold demo``, the time to its first simulated chunk and to its end.

* ``cold, fresh folder``: an empty cache, a new output folder;
* ``warm, fresh folder``: a ready cache, a new output folder (everything simulated);
* ``resumed``: the warm run's command again into its own folder: the loop resumes and
  re-simulates nothing (not a start-up time; shown so it is never mistaken for one).

``simulate`` (``--simulate``): ``holofold simulate PATTERN [--sim-args ...]`` with a ready
cache, the whole process, beside the same command run inside one process that has run it
before (``main`` called twice, the second timed by the wall clock and by the process's CPU
time, ``getrusage``): their difference, per repeat, is the start-up overhead (interpreter,
imports, kernel loading, first-call caches; issue 37 item 4), printed as wall and CPU rows
(median, min, max), and ``holofold --help`` the bare start-up. The command's exit status 1 (the
fold stopped short) is a result, not a failure. ``--cache DIR`` reuses a ready kernel cache
(no priming run).

    python benchmarks/bench_cold_start.py [--repeat 7] [--demo] [--simulate PATTERN]
        [--sim-args=--no-contact] [--cache DIR] [--no-evaluate]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from _timing import machine_speed

ROW = "m,tcrease,tpanel,W,offset,stripeWidth,extrude\n12,8e-4,3e-3,2e-3,0.2,0.02,0.1\n"
ROOT = Path(__file__).resolve().parents[1]
#: the pattern of the start-up figure: Origami Simulator's waterbomb (330 panels, MIT; issue 37's
#: figure was of a 156-panel pattern it does not name)
PATTERN = Path("/work/os-examples/assets/Tessellations/waterbomb.svg")


EVAL_COLD = "evaluate arch, 1 row: cold (auto: numpy while compiling)"
COMPILE = "background compile after the cold row (s to ready)"
EVAL_WARM = "evaluate arch, 1 row: warm (cache ready)"
EVAL_NUMPY = "evaluate arch, 1 row: numpy (never compiles)"
EVAL_COMPILED = "evaluate arch, 1 row: cold, compiled in the process"
DEMO_COLD = "demo: cold (empty cache), fresh folder"
DEMO_WARM = "demo: warm (cache ready), fresh folder"
DEMO_RESUMED = "demo: resumed (re-run into the warm run's folder, simulates nothing)"
HELP = "holofold --help (bare start-up)"
SIM = "simulate: whole process (cache ready)"
SIM_IN = "simulate: in a process that ran it before"


def _holofold() -> list[str]:
    exe = shutil.which("holofold", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "holofold.cli"]


def _env(cache: Path, kernels: str = "auto") -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("HOLOFOLD_", "NUMBA_"))}
    env["HOLOFOLD_KERNEL_CACHE"] = str(cache)
    env["HOLOFOLD_KERNELS"] = kernels
    return env


def _load() -> float:
    return os.getloadavg()[0]


@dataclass
class Case:
    """The runs of one case: seconds (or tuples of seconds) and the load before each."""

    runs: list = field(default_factory=list)
    loads: list = field(default_factory=list)
    cpu: list = field(default_factory=list)

    def add(self, fn, *args):
        self.loads.append(_load())
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        value = fn(*args)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.cpu.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
        self.runs.append(value)
        return value

    def line(self, name: str, part: int | None = None) -> str:
        vals = [v if part is None else v[part] for v in self.runs]
        med, lo, hi = statistics.median(vals), min(vals), max(vals)
        load = f"{min(self.loads):.1f}-{max(self.loads):.1f}"
        cpu = statistics.median(self.cpu)
        return f"| {name} | {med:.2f} | {lo:.2f} | {hi:.2f} | {cpu:.2f} | {len(vals)} | {load} |"


def _wait_ready(cache: Path, timeout: float = 1800.0) -> float:
    t0 = time.perf_counter()
    while not any(cache.glob("kernels-*/ready")):
        if any(cache.glob("kernels-*/failed")) or time.perf_counter() - t0 > timeout:
            raise RuntimeError(f"the background compile in {cache} did not finish")
        time.sleep(0.5)
    return time.perf_counter() - t0


def _run(cmd: list[str], cache: Path, kernels: str, cwd: Path, ok=(0,)) -> float:
    t0 = time.perf_counter()
    out = subprocess.run(cmd, env=_env(cache, kernels), check=False, capture_output=True, cwd=cwd)
    if out.returncode not in ok:
        raise RuntimeError(f"{' '.join(cmd)} failed ({out.returncode}): {out.stderr[-500:]!r}")
    return time.perf_counter() - t0


def _simulate(cmd: list[str], cache: Path, cwd: Path) -> float:
    """Wall seconds of one ``holofold simulate`` process (exit 1, a fold stopped short, is a
    result)."""
    return _run(cmd, cache, "auto", cwd, ok=(0, 1))


def evaluate_one(work: Path, cache: Path, kernels: str) -> float:
    work.mkdir(parents=True, exist_ok=True)
    rows = work / "row.csv"
    rows.write_text(ROW)
    cmd = [*_holofold(), "evaluate", "arch", str(rows), "-o", str(work / "out.csv")]
    return _run(cmd, cache, kernels, work)


def demo(out: Path, cache: Path, kernels: str = "auto") -> tuple[float, float]:
    """(seconds to the first simulated chunk, seconds to the end) of ``holofold demo -o out``
    (the end twice where no new chunk appears: a resumed run)."""
    before = set(out.glob("**/chunks/part-*.parquet"))
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [*_holofold(), "demo", "-o", str(out)], env=_env(cache, kernels), cwd=out.parent,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    first = None
    while proc.poll() is None:
        if first is None and set(out.glob("**/chunks/part-*.parquet")) - before:
            first = time.perf_counter() - t0
        time.sleep(0.05)
    if proc.returncode:
        raise RuntimeError(f"holofold demo failed ({proc.returncode})")
    end = time.perf_counter() - t0
    return (end if first is None else first), end


_IN_PROCESS = """
import resource, sys, time
from holofold.cli import main
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
args = sys.argv[1:]
out = []
for tag in "ab":
    t, c = time.perf_counter(), cpu()
    main(args[:-1] + [args[-1] + "-" + tag])
    out += [time.perf_counter() - t, cpu() - c]
print(*out)
"""


def simulate_in_process(pattern: Path, work: Path, cache: Path, extra=()) -> tuple:
    """(wall s, CPU s) of ``holofold simulate`` inside a process that has run it once before,
    then (wall s, CPU s) of that first run."""
    work.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-c", _IN_PROCESS, "simulate", str(pattern), *extra]
    out = subprocess.run(
        [*cmd, "-o", str(work / "out")],
        env=_env(cache), check=False, capture_output=True, text=True, cwd=work,
    )  # fmt: skip
    try:
        w1, c1, w2, c2 = (float(x) for x in out.stdout.strip().splitlines()[-1].split())
    except (ValueError, IndexError):
        raise RuntimeError(f"in-process simulate failed: {out.stderr[-500:]}") from None
    return w2, c2, w1, c1


def _table(cases: dict) -> None:
    print("wall seconds, whole processes; CPU: the median CPU s of the process and the children")
    print("it waited for (not the detached background compile); load: the 1-minute load average")
    print("before the runs, min-max")
    print("| case | median | min | max | CPU | runs | load |")
    print("|---|---:|---:|---:|---:|---:|---|")
    for name, c in cases.items():
        if name.startswith("demo"):
            print(c.line(name + ": first chunk", 0))
            print(c.line(name + ": end", 1))
        elif name == SIM_IN:  # the CPU column: this run's own CPU time, not the process's
            print(c.line(name + " (2nd run)", 0).rsplit("|", 4)[0] + "| "
                  f"{statistics.median(v[1] for v in c.runs):.2f} | {len(c.runs)} | "
                  f"{min(c.loads):.1f}-{max(c.loads):.1f} |")  # fmt: skip
            print(c.line(name + " (1st run, wall)", 2).rsplit("|", 4)[0] + "| "
                  f"{statistics.median(v[3] for v in c.runs):.2f} | {len(c.runs)} | "
                  f"{min(c.loads):.1f}-{max(c.loads):.1f} |")  # fmt: skip
        else:
            print(c.line(name))
    whole, inner = cases.get(SIM), cases.get(SIM_IN)
    if whole and inner:
        load = f"{min(whole.loads):.1f}-{max(whole.loads):.1f}"
        n = min(len(whole.runs), len(inner.runs))
        for what, over in (
            ("wall", [whole.runs[k] - inner.runs[k][0] for k in range(n)]),
            ("CPU", [whole.cpu[k] - inner.runs[k][1] for k in range(n)]),
        ):
            print(f"| simulate start-up overhead, {what} s (whole process - 2nd run in process, "
                  f"per repeat) | {statistics.median(over):.2f} | {min(over):.2f} | "
                  f"{max(over):.2f} | - | {n} | {load} |")  # fmt: skip
    sys.stdout.flush()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--demo", action="store_true", help="also time holofold demo")
    ap.add_argument("--simulate", nargs="?", const=str(PATTERN), default=None,
                    help="also time holofold simulate of a pattern (waterbomb)")  # fmt: skip
    ap.add_argument("--sim-args", default="",
                    help="more simulate options, with = (--sim-args=--no-contact)")  # fmt: skip
    ap.add_argument("--cache", default=None, help="a ready kernel cache folder (no priming)")
    ap.add_argument("--no-evaluate", action="store_true", help="skip holofold evaluate")
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()}; {os.cpu_count()} cores; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")  # fmt: skip
    print(machine_speed())
    cases: dict[str, Case] = {}

    def case(name: str) -> Case:
        return cases.setdefault(name, Case())

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        ready = Path(args.cache) if args.cache else tmp / "ready-cache"  # for the warm cases
        compile_s = 0.0
        if not any(ready.glob("kernels-*/ready")):
            evaluate_one(tmp / "prime", ready, "auto")
            compile_s = _wait_ready(ready)
        if args.simulate:
            pattern = Path(args.simulate).resolve()
            extra = args.sim_args.split()
            sim = [*_holofold(), "simulate", str(pattern), *extra]
            print(f"simulate: {' '.join(sim[-1 - len(extra) :])}", flush=True)
            _simulate([*sim, "-o", str(tmp / "sim-prime")], ready, tmp)
        for r in range(args.repeat):
            rep = tmp / f"r{r}"
            rep.mkdir(parents=True)
            if not args.no_evaluate:
                cold, compiled = rep / "cache-cold", rep / "cache-compiled"
                case(EVAL_COLD).add(evaluate_one, rep / "e1", cold, "auto")
                case(COMPILE).add(_wait_ready, cold)
                case(EVAL_WARM).add(evaluate_one, rep / "e2", cold, "auto")
                case(EVAL_NUMPY).add(evaluate_one, rep / "e3", cold, "numpy")
                case(EVAL_COMPILED).add(evaluate_one, rep / "e4", compiled, "compiled")
            if args.demo:
                case(DEMO_COLD).add(demo, rep / "demo-cold", rep / "cache-demo")
                _wait_ready(rep / "cache-demo")  # its background compile ends before the next
                case(DEMO_WARM).add(demo, rep / "demo-warm", ready)
                case(DEMO_RESUMED).add(demo, rep / "demo-warm", ready)
            if args.simulate:
                case(HELP).add(_run, [*_holofold(), "--help"], ready, "auto", rep)
                case(SIM).add(_simulate, [*sim, "-o", str(rep / "sim")], ready, rep)
                case(SIM_IN).add(simulate_in_process, pattern, rep / "sim-in", ready, extra)
            print(f"\nafter {r + 1} of {args.repeat} repeats:", flush=True)
            _table(cases)
        print(f"(a first background compile took {compile_s:.1f} s wall)")
    print(json.dumps({"load_average_end": os.getloadavg()}))


if __name__ == "__main__":
    main()
