"""Simulation time against its linear-algebra floor (issue 14): one table, every workload.

For each workload the table gives the time per sample (min and median of ``--repeat`` runs,
BLAS limited to one thread; CPU time of this thread, which a busy machine disturbs far less
than the wall clock, and the wall-clock median) and its floor measured in the same run, in the
same CPU time, the two interleaved (each round: one run alone, one batch, one run of the
floor's computation), so that a machine whose speed drifts with other jobs slows the workload
and its floor alike:

    floor = sum over the Newton iterations of (cheapest factorisation + solve of the tangent)

``run ms`` times that computation itself as one run per round (as many samples' worth as the
batch holds, each captured tangent for its share of the iterations), the best round. A run
as long as the workload's meets the same share of other jobs, where the best of many short
timings (``floor ms``, the one the ratios use) catches the gaps between them. In the calmest
runs on this project's shared 2-core machine the two agreed within 10 %; in busy ones the
run took up to 60 % longer, a measure of how much the workload's own times (and so the
ratios) are inflated then.

The tangents are the actual ones: every ``Assembler.evaluate_factorized`` call of one sample
(and every compiled Newton step, ``Assembler.dense_stepper`` and
``BatchAssembler.newton_step``) is counted and every ``--every``-th free-free tangent
captured; each captured tangent is factorised and solved (one right-hand side) by every
applicable LAPACK/SuperLU path called directly (dense Cholesky dpotrf/dpotrs, dense LU
dgetrf/dgetrs, banded Cholesky dpbtrf/dpbtrs on the reverse Cuthill-McKee ordering, SuperLU
with the cached minimum-degree ordering, and CHOLMOD's supernodal sparse Cholesky where cvxopt
is installed), the best of the rounds' timings each. A
structure's floor per iteration is the cheapest path's best timing over its captured
tangents (one size and sparsity: a busy machine only adds to a timing), so a sample's floor
is sum(iterations x that cost). ``solver`` names the path the assembler takes (on the dense
path the Cholesky it tries first); ``--before-lu`` adds a ``[LU]`` row per workload, its
designs run with the dense path forced onto LU (before issue 37), interleaved with the other
runs and against the same floor. ``batch ms`` is the time per design of a
batch of 16 copies of the design (4 for the canopy) through ``scenario.evaluate_batch``, the
path the runner takes for databases, and ``batch/floor`` its ratio, the one the targets are
read against where it exists. The database row runs ``evaluate_designs`` on the 3000
published arch rows (data3) on 2 worker processes (wall clock, and the CPU time of the
workers / 2, which other jobs on the machine disturb less) and prints the floor beside it
(per-row floors of 120 rows spread over the file, scaled to 3000 rows and divided by the 2
cores).

``--stages`` prints instead where one single Miura design's CPU time goes: the sheet nodes,
the 3 models, the ``BatchAssembler``, the Newton kernel call and the rest (the path's own
Python), us per design and against the floor.

    python benchmarks/bench_floor.py [--repeat 7] [--no-db] [--only arch] [--before-lu]
    python benchmarks/bench_floor.py --stages
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from _timing import machine_speed
from scipy.linalg import lapack
from threadpoolctl import threadpool_limits

import holofold.mechanics.assembly as assembly
from holofold import mechanics as threads
from holofold.design.scenarios import arch, canopy, gripper, single_miura
from holofold.mechanics import linear, sparse_cholesky
from holofold.mechanics.solvers import newton as newton_solvers
from holofold.mechanics.solvers import selffold as selffold_solver

ROOT = Path(__file__).resolve().parents[1]
REF = Path(os.environ.get("HOLOFOLD_REFERENCE_DATA", ROOT.parent / "shared" / "reference-data"))
MID = dict(tcrease=0.75e-3, tpanel=3.5e-3, W=2.5e-3)
ARCH = dict(MID, offset=0.2, stripeWidth=0.025, extrude=0.15)
GRIP = ["Pattern", "L1", "L2", "t1", "t2", "tpanel", "rate", "W"]
#: issue 22's targets (restated from issue 14's): time / floor
TARGET = {
    "arch m=24": 2.5,
    "arch m=8": 2.5,
    "single Miura": 5.0,
    "gripper two-panel": 3.0,
    "canopy Miura 36x12": 1.5,
}


def _published(stem: str, i: int, names) -> dict:
    arr = np.loadtxt(REF / f"{stem}.txt", delimiter=",", ndmin=2)
    return dict(zip(names, map(float, arr[i, : len(names)]), strict=True))


#: workloads whose floor is that of the solver they use, not the cheapest factorisation (the
#: gripper's was, while it kept the dense LU; since issue 37 it takes the banded Cholesky and
#: its target is against the cheapest floor)
OWN_SOLVER_FLOOR: set[str] = set()

#: designs per batch for the batched time (the runner sends up to 16 rows of one key per task)
BATCH = {"canopy Miura 36x12": 4}


def _rows():
    rows = {
        "arch m=24": (arch.SCENARIO, dict(ARCH, m=24)),
        "arch m=8": (arch.SCENARIO, dict(ARCH, m=8)),
        "single Miura": (single_miura.SCENARIO, dict(MID, gama=1.1)),
        "canopy Miura 36x12": (
            canopy.SCENARIO,
            dict(MID, pattern=1, m=36, n=12, creaseE=2e9, panelE=2e9),
        ),
    }
    if (REF / "data2_TwoPanel_sample.txt").exists():
        rows["gripper two-panel"] = (gripper.SCENARIO, _published("data2_TwoPanel_sample", 1, GRIP))
    return rows


def workloads():
    """name -> one evaluation of the workload's design (``scenario.evaluate``)."""
    return {name: (lambda sc=sc, row=row: sc.evaluate(row)) for name, (sc, row) in _rows().items()}


def batched_workloads():
    """name -> (designs, one ``evaluate_batch`` of that many copies of the design), for the
    scenarios that evaluate batches (the path the runner takes for databases)."""
    out = {}
    for name, (sc, row) in _rows().items():
        if sc.evaluate_batch is not None:
            n = BATCH.get(name, 16)
            out[name] = (n, lambda sc=sc, rows=[row] * n: sc.evaluate_batch(rows))
    return out


# ------------------------------------------------------------------------- capture
class Capture:
    """Counts ``evaluate_factorized`` calls per structure and keeps some free-free tangents."""

    def __init__(self, every: int):
        self.every = every
        self.calls: dict = defaultdict(int)
        self.K: dict = defaultdict(list)
        self.red: dict = {}
        self.inside_step = False

    def _record(self, asm, U, spring_rest):
        key = (id(asm.reduction), asm.reduction.n_free)
        n = self.calls[key]
        self.calls[key] += 1
        if n % self.every == 0 and len(self.K[key]) < 12:
            _, _, K = asm.evaluate_reduced(U, spring_rest, dense=False)
            self.K[key].append(sp.csr_matrix(K))
            self.red[key] = asm.reduction

    def _record_iterations(self, asm, Us, counts):
        """``counts[r]`` iterations that ended at displacement ``Us[r]`` (one row per
        increment, from a whole-increments kernel call)."""
        for U, n in zip(Us, counts, strict=True):
            for _ in range(int(n)):
                self._record(asm, U, None)

    def __enter__(self):
        cap = self
        self.orig = assembly.Assembler.evaluate_factorized
        self.orig_incr = newton_solvers.batch_newton_increments

        def spy_incr(b, U, F0, P, increments, tol, max_iter):
            rec = cap.orig_incr(b, U, F0, P, increments, tol, max_iter)
            if rec is not None:
                for s in range(b.n):
                    code, at = int(rec.failed[s, 0]), int(rec.failed[s, 1])
                    count = at if code else rec.U.shape[1]
                    asm = b.assemblers[s]
                    Us = rec.U[s, :count].reshape(count, -1, 3)
                    cap._record_iterations(asm, Us, rec.iterations[s, :count])
            return rec

        newton_solvers.batch_newton_increments = spy_incr
        self.orig_self = selffold_solver.selffold_increments

        def spy_self(asm, U, F0, start, target, increments, tol, max_iter):
            rec = cap.orig_self(asm, U, F0, start, target, increments, tol, max_iter)
            if rec is not None:  # each increment's iterations at its own rest angles
                code, at = int(rec.failed[0, 0]), int(rec.failed[0, 1])
                for i in range(1, (at if code else increments) + 1):
                    t = i / increments
                    rest = (1.0 - t) * np.asarray(start) + t * np.asarray(target)
                    for _ in range(int(rec.iters[0, i - 1])):
                        cap._record(asm, rec.U[0, i - 1].reshape(-1, 3), rest)
            return rec

        selffold_solver.selffold_increments = spy_self
        self.orig_load = getattr(newton_solvers, "load_increments", None)
        if self.orig_load is not None:  # one design's load control in one kernel call

            def spy_load(asm, U, F0, P, increments, tol, max_iter):
                rec = cap.orig_load(asm, U, F0, P, increments, tol, max_iter)
                if rec is not None:  # each increment's iterations at its end state
                    code, at = int(rec.failed[0, 0]), int(rec.failed[0, 1])
                    count = at if code else increments
                    Us = rec.U[0, :count].reshape(count, -1, 3)
                    cap._record_iterations(asm, Us, rec.iters[0, :count])
                return rec

            newton_solvers.load_increments = spy_load

        def spy(asm, U, spring_rest=None):
            cap._record(asm, U, spring_rest)
            return cap.orig(asm, U, spring_rest)

        assembly.Assembler.evaluate_factorized = spy
        self.orig_stepper = getattr(assembly.Assembler, "dense_stepper", None)
        if self.orig_stepper is not None:  # the compiled dense step of one design

            def spy_stepper(asm, U, F, spring_rest=None, r=None):
                step = cap.orig_stepper(asm, U, F, spring_rest, r)
                if step is None:
                    return None

                def counted():
                    cap._record(asm, U, spring_rest)
                    return step()

                return counted

            assembly.Assembler.dense_stepper = spy_stepper
        batch = getattr(assembly, "BatchAssembler", None)  # the batched path (issue 14)
        if batch is not None:
            self.orig_batch = batch.factorized

            def spy_batch(b, U, active, spring_rest=None):
                U = np.asarray(U, float).reshape(b.n, -1, 3)
                if not cap.inside_step:
                    for s in np.flatnonzero(active):
                        rest = None if spring_rest is None else spring_rest[s]
                        cap._record(b.assemblers[s], U[s], rest)
                return cap.orig_batch(b, U, active, spring_rest)

            batch.factorized = spy_batch
            self.orig_step = getattr(batch, "newton_step", None)
            if self.orig_step is not None:  # the compiled Newton step (banded samples)

                def spy_step(b, U, rhs_force, active):
                    U3 = np.asarray(U, float).reshape(b.n, -1, 3)
                    for s in np.flatnonzero(active):
                        cap._record(b.assemblers[s], U3[s], None)
                    cap.inside_step = True  # its factorized() fallback is counted here
                    try:
                        return cap.orig_step(b, U, rhs_force, active)
                    finally:
                        cap.inside_step = False

                batch.newton_step = spy_step
        return self

    def __exit__(self, *exc):
        assembly.Assembler.evaluate_factorized = self.orig
        newton_solvers.batch_newton_increments = self.orig_incr
        selffold_solver.selffold_increments = self.orig_self
        if self.orig_load is not None:
            newton_solvers.load_increments = self.orig_load
        if self.orig_stepper is not None:
            assembly.Assembler.dense_stepper = self.orig_stepper
        if getattr(assembly, "BatchAssembler", None) is not None:
            assembly.BatchAssembler.factorized = self.orig_batch
            if self.orig_step is not None:
                assembly.BatchAssembler.newton_step = self.orig_step


clock = time.thread_time


def _best(fn, n: int = 5) -> float:
    """Best CPU time of ``n`` calls of ``fn`` (each timed over enough repetitions to be
    longer than 0.2 ms)."""
    reps = 1
    t = clock()
    fn()
    one = clock() - t
    if one < 2e-4:
        reps = int(2e-4 / max(one, 1e-7)) + 1
    ts = []
    for _ in range(n):
        t = clock()
        for _ in range(reps):
            fn()
        ts.append((clock() - t) / reps)
    return min(ts)


def path_costs(K: sp.csr_matrix, red, n: int = 5) -> dict:
    """Seconds for factorisation + one solve of ``K`` by every applicable path (best of ``n``
    timings each)."""
    return {path: _best(fn, n) for path, fn in path_fns(K, red).items()}


def path_fns(K: sp.csr_matrix, red) -> dict:
    """Path -> a call that factorises ``K`` and solves one right-hand side by it, for every
    path that applies (positive definite for the Cholesky paths)."""
    nf = K.shape[0]
    b = np.ones(nf)
    out = {}
    if nf <= 1500:
        A = np.asfortranarray(K.toarray())

        def chol():
            c, info = lapack.dpotrf(A, lower=0, clean=0, overwrite_a=0)
            if info:
                raise np.linalg.LinAlgError
            lapack.dpotrs(c, b, lower=0)

        def lu():
            lu_, piv, _ = lapack.dgetrf(A, overwrite_a=0)
            lapack.dgetrs(lu_, piv, b)

        try:
            chol()
            out["dense Cholesky"] = chol
        except np.linalg.LinAlgError:
            pass
        out["dense LU"] = lu
    perm, bw = red.band.perm, red.band.bandwidth
    if nf * (bw + 1) ** 2 <= 2e10:
        Kp = K[perm][:, perm].tocoo()
        up = Kp.row <= Kp.col
        ab = np.zeros((bw + 1, nf), order="F")
        ab[bw + Kp.row[up] - Kp.col[up], Kp.col[up]] = Kp.data[up]

        def band():
            c, info = lapack.dpbtrf(ab, lower=0, overwrite_ab=0)
            if info:
                raise np.linalg.LinAlgError
            lapack.dpbtrs(c, b, lower=0)

        try:
            band()
            out["banded Cholesky"] = band
        except np.linalg.LinAlgError:
            pass
    order = red.symbolic("superlu", linear._fill_ordering).order
    Ko = sp.csc_matrix(K[order][:, order])

    def slu():
        lu_ = spla.splu(Ko, permc_spec="NATURAL", diag_pivot_thresh=0.01, relax=3,
                        panel_size=10, options={"SymmetricMode": True})  # fmt: skip
        lu_.solve(b)

    out["SuperLU"] = slu
    if sparse_cholesky.available():  # CHOLMOD, the reduction's pattern analysed once
        chol = red.symbolic(
            "cholesky_reduced", lambda r: sparse_cholesky.SparseCholesky(r.indptr, r.indices)
        )

        def cholesky():
            f = chol.factor(K.data)
            if f is None:
                raise np.linalg.LinAlgError
            f.solve(b)

        try:
            cholesky()
            out["sparse Cholesky"] = cholesky
        except np.linalg.LinAlgError:
            pass
    return out


_PATHS = {
    "dense": "dense LU", "banded": "banded Cholesky", "cholesky": "sparse Cholesky",
    "superlu": "SuperLU", "none": "none",
}  # fmt: skip


def solver_path(red) -> str:
    path = linear.solver_path(red)
    if path == "dense":  # the Cholesky it tries first (the LU only where that fails)
        return f"{linear.small_cholesky(red)} Cholesky"
    return _PATHS[path]


class forced_lu:
    """Context: the dense path's Newton steps factorise by LU, as before issue 37 (each
    :class:`~holofold.mechanics.newton_step.DenseStepper` starts with its LU flag set; the
    self-fold stages and load control take the per-increment loop of steppers, not the
    one-call kernels)."""

    def __enter__(self):
        from holofold.mechanics import newton_step

        self.orig = orig = newton_step.DenseStepper.__init__
        self.orig_self = selffold_solver.selffold_increments

        def init(step, *args, **kwargs):
            orig(step, *args, **kwargs)
            step.lu[0] = 1

        newton_step.DenseStepper.__init__ = init
        selffold_solver.selffold_increments = lambda *args: None
        self.orig_load = getattr(newton_solvers, "load_increments", None)
        if self.orig_load is not None:
            newton_solvers.load_increments = lambda *args: None
        return self

    def __exit__(self, *exc):
        from holofold.mechanics import newton_step

        newton_step.DenseStepper.__init__ = self.orig
        selffold_solver.selffold_increments = self.orig_self
        if self.orig_load is not None:
            newton_solvers.load_increments = self.orig_load


class Floor:
    """The floor of one call of ``fn``: its tangents captured once (:class:`Capture`), their
    factorisations timed in rounds (:meth:`round`, one timing per path and tangent each) that
    can be interleaved with the workload's own runs, so that both meet the same machine."""

    def __init__(self, fn, every: int = 4):
        with Capture(every) as cap:
            fn()
        self.cases = [  # (iterations, tangents, reduction) per structure
            (n, cap.K[key], cap.red[key]) for key, n in cap.calls.items()
        ]
        self.best: list[list[dict]] = [[{} for _ in Ks] for _, Ks, _ in self.cases]
        self._fns = None  # the path calls of every tangent, for block(): built on first use

    def round(self) -> None:
        """Time every path of every captured tangent once more, keeping the best."""
        for (_, Ks, red), best in zip(self.cases, self.best, strict=True):
            for K, b in zip(Ks, best, strict=True):
                for path, t in path_costs(K, red, n=1).items():
                    b[path] = min(t, b.get(path, np.inf))

    def block(self, reps: int = 1, own: bool = False) -> float:
        """CPU seconds per sample of the floor's computation itself: ``reps`` samples' worth
        of factorisations + solves (each structure's iteration count, shared among its
        captured tangents) by the cheapest path (``own``: the assembler's), timed as one run,
        as a workload's run is. Needs :meth:`round` first (the path choice)."""
        if self._fns is None:
            self._fns = [[path_fns(K, red) for K in Ks] for _, Ks, red in self.cases]
        calls = []
        for (n, Ks, red), costs, fns in zip(self.cases, self.best, self._fns, strict=True):
            path = solver_path(red)
            if not own or not all(path in c for c in costs):
                path = min(costs[0], key=lambda p: min(c.get(p, np.inf) for c in costs))
            # each tangent for its share of the iterations in a row: its factorisation then
            # finds its matrix in cache, as the workload's finds the tangent just assembled
            counts = np.diff(np.linspace(0, n * reps, len(Ks) + 1).round().astype(int))
            calls += [f[path] for f, c in zip(fns, counts, strict=True) for _ in range(c)]
        t = clock()
        for call in calls:
            call()
        return (clock() - t) / reps

    def totals(self):
        """(iterations, floor s, floor s with the assembler's own path, paths used)."""
        iters = total = used_total = 0.0
        used = set()
        for (n, _, red), costs in zip(self.cases, self.best, strict=True):
            # the tangents of one structure have one size and sparsity: the best timing of
            # any is the least disturbed estimate of the cost of each (a busy machine only adds)
            best = min(min(c.values()) for c in costs)
            path = solver_path(red)
            used.add(path)
            mine = min(c.get(path, min(c.values())) for c in costs)
            iters += n
            total += n * best
            used_total += n * mine
        return int(iters), total, used_total, used


def floor_of(fn, every: int = 4, rounds: int = 5):
    """(iterations, floor s, floor s with the assembler's own path, paths used) of one call."""
    floor = Floor(fn, every)
    for _ in range(rounds):
        floor.round()
    return floor.totals()


def _workers_cpu() -> float:
    """CPU seconds used so far by this process's child processes that are alive (the joblib
    workers, which outlive a call for reuse); 0 without psutil."""
    try:
        import psutil
    except ImportError:
        return 0.0
    total = 0.0
    for c in psutil.Process().children(recursive=True):
        try:
            t = c.cpu_times()
            total += t.user + t.system
        except psutil.Error:
            pass
    return total


def database(floor_rows: int = 120):
    """(wall s, workers' CPU s / 2, floor s, rows, converged share) of the 3000 published arch
    rows on 2 joblib workers; the floor is the mean per-row floor of ``floor_rows`` evenly
    spaced rows (BLAS on 1 thread, as the workers run) times 3000 / 2."""
    import pandas as pd

    from holofold.design.database.runner import evaluate_designs

    cols = open(REF / "data3_FeatureName.txt").read().split()
    df = pd.DataFrame(np.loadtxt(REF / "data3_ShapeFit.txt", delimiter=","), columns=cols)
    feats = [c.name for c in arch.SCENARIO.features]
    table = df[feats]
    cpu0 = _workers_cpu()
    t = time.perf_counter()
    res = evaluate_designs("arch", table, workers=2, progress=False)
    wall = time.perf_counter() - t
    cpu = (_workers_cpu() - cpu0) / 2
    idx = np.linspace(0, len(table) - 1, floor_rows).astype(int)
    with threadpool_limits(1):  # several BLAS threads would inflate the floor's CPU time 4x
        floors = [
            floor_of(lambda r=r: arch.evaluate(r))[1] for r in table.iloc[idx].to_dict("records")
        ]
    floor = statistics.mean(floors) * len(table) / 2
    ok = (res["status"] == "converged").mean()
    return wall, cpu, floor, len(table), ok


class _Stages:
    """Context: CPU time spent in some named calls of one design's path, accumulated (each
    wrapped where the path looks it up: ``(module, attribute)``)."""

    def __init__(self, spots: dict):
        self.spots = spots  # stage -> (module, attribute)
        self.spent = dict.fromkeys(spots, 0.0)

    def __enter__(self):
        self.orig = {}
        for stage, (mod, attr) in self.spots.items():
            fn = self.orig[stage] = getattr(mod, attr)

            def timed(*a, _fn=fn, _stage=stage, **k):
                t = clock()
                try:
                    return _fn(*a, **k)
                finally:
                    self.spent[_stage] += clock() - t

            setattr(mod, attr, timed)
        return self

    def __exit__(self, *exc):
        for stage, (mod, attr) in self.spots.items():
            setattr(mod, attr, self.orig[stage])


def stages(designs: int = 200, rounds: int = 7) -> None:
    """Where one single Miura design's CPU time goes (``scenario.evaluate``, BLAS 1 thread):
    per stage, us per design, the best of ``rounds`` rounds of ``designs`` designs each (the
    stages timed by wrapping the calls; the rest is the evaluate path's own Python)."""
    from holofold.design.scenarios import sheet
    from holofold.geometry import miura

    sc, row = _rows()["single Miura"]
    spots = {
        "sheet nodes (geometry.miura_nodes_batch)": (miura, "miura_nodes_batch"),
        "3 models (build_concentrated_batch)": (sheet, "build_concentrated_batch"),
        "BatchAssembler of the 3": (sheet, "BatchAssembler"),
        "Newton: one kernel call for the 3 (batch_newton_increments)": (
            newton_solvers, "batch_newton_increments"),
    }  # fmt: skip
    with threadpool_limits(1):
        sc.evaluate(row)
        iters, floor, _, _ = floor_of(lambda: sc.evaluate(row))
        best: dict = {}
        for _ in range(rounds):
            with _Stages(spots) as st:
                t = clock()
                for _ in range(designs):
                    sc.evaluate(row)
                total = clock() - t
            parts = {k: v / designs for k, v in st.spent.items()}
            parts["rest: the evaluate path's own Python"] = total / designs - sum(parts.values())
            parts["one design (scenario.evaluate)"] = total / designs
            for k, v in parts.items():
                best[k] = min(v, best.get(k, np.inf))
    print(f"single Miura, one design: CPU us per design, best of {rounds} rounds of {designs}; "
          f"floor {1e6 * floor:.1f} us ({iters} iterations)")  # fmt: skip
    for k, v in best.items():
        print(f"  {k:<62} {1e6 * v:>8.1f} us {v / floor:>6.2f} x floor")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="time per sample against its floor (issue 14)")
    ap.add_argument("--repeat", type=int, default=7, help="timed runs per workload")
    ap.add_argument("--no-db", action="store_true", help="skip the 3000-row arch database")
    ap.add_argument("--only", default="", help="only workloads whose name contains this")
    ap.add_argument(
        "--before-lu",
        action="store_true",
        help="also time each design with its dense-path steps forced onto LU (before issue "
        "37), interleaved with the other runs: a second row '<name> [LU]' against the same floor",
    )
    ap.add_argument(
        "--stages",
        action="store_true",
        help="only print where one single Miura design's CPU time goes, stage by stage",
    )
    args = ap.parse_args(argv)
    print(machine_speed())
    if args.stages:
        stages()
        return 0
    print(f"per sample, BLAS 1 thread, CPU time min / median of {args.repeat} runs (and wall")
    print("median); floor = iterations x (cheapest factorisation + solve of the actual tangents),")
    print("CPU time, measured in this run (the sum of each factorisation's best timing; run ms:")
    print("the same computation timed as one run per round, like the workload, the best round)")
    print("min ms: one design alone (scenario.evaluate); batch ms: per design of a batch of 16")
    print("copies (4 for the canopy) through scenario.evaluate_batch, the path the runner takes")
    print("for databases. The ratio to the target is batch/floor where there is a batch time")
    print("(min/floor otherwise)")
    head = (
        f"{'workload':<20} {'iters':>6} {'min ms':>9} {'median ms':>10} {'wall ms':>9} "
        f"{'batch ms':>9} {'floor ms':>9} {'run ms':>9} {'min/floor':>10} {'batch/floor':>12} "
        f"{'target':>7}  "
        "solver (floor with it)"
    )
    print(head)
    print("-" * len(head))
    batched = batched_workloads()
    with threadpool_limits(1):
        for name, fn in workloads().items():
            if args.only not in name:
                continue
            # single runs, batch runs and floor runs interleaved: a machine whose speed drifts
            # (other jobs) slows all three alike, and each keeps its best
            fn()  # warm-up: topology, sparse pattern and compiled-kernel caches
            floor_run = Floor(fn)
            floor_run.round()  # the path choice: every path of every tangent timed
            bfn = batched[name][1] if name in batched else None
            reps = batched[name][0] if bfn is not None else 1
            if bfn is not None:
                bfn()
            own = name in OWN_SOLVER_FLOOR  # the target is against the solver it keeps
            cpu, wall, tbs, blocks, lus = [], [], [], [], []
            for _ in range(args.repeat):
                t, w = clock(), time.perf_counter()
                fn()
                cpu.append(clock() - t)
                wall.append(time.perf_counter() - w)
                if args.before_lu:
                    with forced_lu():
                        t = clock()
                        fn()
                        lus.append(clock() - t)
                if bfn is not None:
                    t = clock()
                    bfn()
                    tbs.append(clock() - t)
                blocks.append(floor_run.block(reps, own=own))
                floor_run.round()
            tmin, tmed, wall = min(cpu), statistics.median(cpu), statistics.median(wall)
            iters, floor, used_floor, used = floor_run.totals()
            run = min(blocks)
            extra = ""
            if own:
                extra = f" (cheapest path: {1e3 * floor:.2f} ms)"
                floor = used_floor
            bms, bratio = "-", "-"
            if bfn is not None:
                tb = min(tbs) / reps
                bms, bratio = f"{1e3 * tb:.2f}", f"{tb / floor:.1f}"
            paths = ", ".join(sorted(used))
            print(
                f"{name:<20} {iters:>6d} {1e3 * tmin:>9.2f} {1e3 * tmed:>10.2f} {1e3 * wall:>9.2f} "
                f"{bms:>9} {1e3 * floor:>9.2f} {1e3 * run:>9.2f} {tmin / floor:>10.1f} "
                f"{bratio:>12} "
                f"{TARGET.get(name, ''):>7}  {paths}{extra}",
                flush=True,
            )
            if lus:
                lmin, lmed = min(lus), statistics.median(lus)
                print(
                    f"{name + ' [LU]':<20} {iters:>6d} {1e3 * lmin:>9.2f} {1e3 * lmed:>10.2f} "
                    f"{'-':>9} {'-':>9} {1e3 * floor:>9.2f} {'-':>9} {lmin / floor:>10.1f} "
                    f"{'-':>12} {TARGET.get(name, ''):>7}  dense LU (forced, as before)",
                    flush=True,
                )
    limit = getattr(threads, "single_thread", None)
    if limit is not None:  # the default BLAS limit of every simulating entry point
        with threadpool_limits(2):
            outer = _best(lambda: limit().__enter__() and limit().__exit__(None, None, None))
            with limit():
                inner = _best(lambda: limit().__enter__() and limit().__exit__(None, None, None))
        print(f"single_thread(): {1e6 * outer:.1f} us outermost (BLAS 2 -> 1 -> 2 threads), "
              f"{1e6 * inner:.2f} us nested")  # fmt: skip
    if not args.no_db and (not args.only or args.only in "arch database"):
        wall, cpu, floor, n, ok = database()
        print(
            f"{'arch database':<20} {n:>6d} rows, 2 workers: wall {wall:.1f} s, workers' CPU / 2 "
            f"{cpu:.1f} s; floor {floor:.1f} s (CPU ratio {cpu / floor:.1f}; target <= 20 s); "
            f"{100 * ok:.1f} % converged"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
