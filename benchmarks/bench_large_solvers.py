"""Linear solvers of the reduced tangent by model size, 12 x 4 to 100 x 100 panels (issue 22, 6).

For concentrated-hinge Miura sheets (clamped at x = min; the tangent at rest, symmetric positive
definite), every path factorises the same free-free tangent and solves one right-hand side:

    dense LU         LAPACK dgetrf/dgetrs (up to --dense-max free DOFs)
    banded Cholesky  LAPACK dpbtrf/dpbtrs on the reverse Cuthill-McKee band (the assembler's)
    SuperLU          scipy's LU, minimum-degree ordering once, natural order at factorisation
                     time, the assembler's options
    sparse Cholesky  CHOLMOD, supernodal (mechanics.sparse_cholesky; ordering and symbolic
                     analysis once per pattern: AMD, and from 10,000 DOFs METIS's nested
                     dissection where pymetis is installed, CHOLMOD keeping the cheaper)
    ... AMD only     the same with CHOLMOD's AMD alone, as where pymetis is missing (aarch64)
    supernodal       holofold's own multifrontal Cholesky (mechanics.supernodal: numba, scipy's
                     BLAS/LAPACK; MMD ordering, and from 10,000 DOFs METIS's where pymetis is
                     installed, keeping the cheaper): the "cholesky" path without cvxopt
    ... MMD only     the same with MMD alone: what a plain ``pip install holofold`` runs
    sparse LDL^T     with ``--indefinite`` (the tangent at a random 0.1 mm displacement, not
                     definite: the Cholesky paths drop out): SupernodalCholesky.factor_ldl,
                     what the "cholesky" path takes where the Cholesky fails

Rounds interleave the paths (each round times every path once, in a rotating order) so that a
machine whose speed drifts with other jobs slows them alike. Times are the CPU time of this
thread (every path runs on one thread: BLAS limited to one, CHOLMOD's ATLAS is serial), which
other jobs disturb far less than the wall clock; min and median over the rounds, plus the
wall-clock median. ``iteration`` adds the assembly of the tangent (element kernels and the
scatter into the CSR data, ``Assembler.evaluate_reduced``, its min) to the path's min: one
Newton iteration on that path. ``peak MB`` is the growth of the process's peak resident
memory while the path is set up afresh and factorises and solves once (the factor, its
workspace and the path's cached ordering; /proc/self/clear_refs resets the peak first).
``setup`` is the path's one-time CPU cost per topology (ordering, symbolic analysis, band
layout). ``ratio`` is the path's min over the best min at that size; ``*`` marks the path the
assembler takes (``mechanics.linear.solver_path``), ``+`` the one a plain install takes (no
cvxopt, no pymetis).

    python benchmarks/bench_large_solvers.py [--rounds 5] [--sizes 12x4 100x100] [--out F.md]
        [--indefinite]
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import ctypes  # noqa: E402
import gc  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402
from scipy.linalg import lapack  # noqa: E402
from scipy.sparse.csgraph import reverse_cuthill_mckee  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from holofold.geometry.miura import miura_sheet  # noqa: E402
from holofold.mechanics import sparse_cholesky  # noqa: E402
from holofold.mechanics.assembly import Assembler  # noqa: E402
from holofold.mechanics.hinges import build_concentrated  # noqa: E402
from holofold.mechanics.linear import (  # noqa: E402
    CHOLESKY_MIN_WORK,
    cholesky_backend,
    solver_path,
)
from holofold.mechanics.supernodal import SupernodalCholesky  # noqa: E402

SIZES = ["12x4", "24x8", "36x12", "48x16", "72x24", "100x30", "120x40", "100x50", "150x50",
         "100x75", "100x100"]  # fmt: skip
AMD = "sparse Cholesky, AMD order only"
OWN = "supernodal (holofold)"
MMD = "supernodal, MMD order only"
LDL = "sparse LDL^T (holofold)"
PATHS = ["dense LU", "banded Cholesky", "SuperLU", "sparse Cholesky", AMD, OWN, MMD, LDL]
_LIBC = ctypes.CDLL("libc.so.6")


def model(m: int, n: int):
    """A concentrated-hinge Miura sheet of m x n panels, clamped at x = min."""
    p = miura_sheet(m, n, 0.2 / m, 0.2 / n, np.deg2rad(70.0), 0.6)
    s = build_concentrated(p, crease_width=2.5e-3, crease_thickness=7.5e-4, panel_thickness=3.5e-3)
    x = s.nodes[:, 0]
    return s.fixed(np.flatnonzero(np.isclose(x, x.min())))


def band_work(K: sp.csr_matrix) -> tuple[np.ndarray, int, float]:
    """(RCM permutation, half bandwidth, work n (bw + 1)^2) of the tangent's pattern."""
    perm = reverse_cuthill_mckee(K, symmetric_mode=True)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(perm.size)
    C = K.tocoo()
    bw = int(np.abs(inv[C.row] - inv[C.col]).max())
    return perm, bw, K.shape[0] * (bw + 1) ** 2


def fallback_path(nf: int, work: float) -> str:
    """The path a plain install takes (no cvxopt, no pymetis; mechanics.linear's thresholds)."""
    if nf <= 200:
        return "dense LU"
    return "banded Cholesky" if work <= CHOLESKY_MIN_WORK else MMD


def assembler_path(asm: Assembler) -> str:
    """The path the assembler takes here (mechanics.linear.solver_path)."""
    own = "sparse Cholesky" if cholesky_backend() == "cholmod" else OWN
    return {"dense": "dense LU", "banded": "banded Cholesky", "cholesky": own,
            "superlu": "SuperLU"}[solver_path(asm.reduction)]  # fmt: skip


def path_makers(K: sp.csr_matrix, perm, bw: int, args) -> dict:
    """Path -> ``make()``: the path's one-time setup for this pattern (ordering, symbolic
    analysis, band layout), returning a call that factorises K and solves one right-hand
    side, as the assembler does it on every Newton iteration."""
    nf = K.shape[0]
    b = np.random.default_rng(0).standard_normal(nf)
    makers = {}
    if nf <= args.dense_max:

        def make_dense():
            A = np.asfortranarray(K.toarray())

            def dense():
                lu, piv, _ = lapack.dgetrf(A, overwrite_a=0)
                return lapack.dgetrs(lu, piv, b)[0]

            return dense

        makers["dense LU"] = make_dense
    if nf * (bw + 1) ** 2 <= args.band_limit:

        def make_band():
            inv = np.empty_like(perm)
            inv[perm] = np.arange(nf)
            C = sp.triu(K).tocoo()
            r, c = inv[C.row], inv[C.col]
            lo, hi = np.minimum(r, c), np.maximum(r, c)
            flat = (hi * (bw + 1) + bw + lo - hi).astype(np.intp)  # column-major upper band

            def band():  # the assembler scatters into a new band and factorises it in place
                ab = np.zeros((bw + 1) * nf)
                ab[flat] = C.data
                c_, info = lapack.dpbtrf(ab.reshape(nf, bw + 1).T, lower=0, overwrite_ab=1)
                if info:
                    raise np.linalg.LinAlgError("not positive definite")
                y = lapack.dpbtrs(c_, b[perm], lower=0)[0]
                x = np.empty_like(y)
                x[perm] = y
                return x

            return band

        makers["banded Cholesky"] = make_band

    def make_superlu():
        coo = K.tocoo()
        vals = np.where(coo.row == coo.col, float(nf + 1), -1.0 / nf)
        A0 = sp.csc_matrix((vals, K.indices, K.indptr), shape=(nf, nf))
        lu0 = spla.splu(
            A0, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )  # fmt: skip
        order = np.argsort(lu0.perm_c)
        KpT = K[order][:, order].T.tocsc()

        def superlu():
            lu = spla.splu(
                KpT, permc_spec="NATURAL", diag_pivot_thresh=0.01, relax=3, panel_size=10,
                options={"SymmetricMode": True},
            )  # fmt: skip
            y = lu.solve(b[order], trans="T")
            x = np.empty_like(y)
            x[order] = y
            return x

        return superlu

    makers["SuperLU"] = make_superlu

    def make_cholesky(ordering=None):
        chol = sparse_cholesky.SparseCholesky(K.indptr, K.indices, ordering=ordering)

        def cholesky():
            f = chol.factor(K.data)
            if f is None:
                raise np.linalg.LinAlgError("not positive definite")
            return f.solve(b)

        return cholesky

    if sparse_cholesky.available():
        makers["sparse Cholesky"] = make_cholesky

        def make_amd():  # CHOLMOD's AMD alone: the ordering where pymetis is missing (aarch64)
            return make_cholesky("amd")

        makers[AMD] = make_amd

    def make_own(ordering=None, ldl=False):
        chol = SupernodalCholesky(K.indptr, K.indices, ordering=ordering)
        factor = chol.factor_ldl if ldl else chol.factor

        def own():
            f = factor(K.data)
            if f is None:
                raise np.linalg.LinAlgError("LDL^T refused" if ldl else "not positive definite")
            return f.solve(b)

        return own

    makers[OWN] = make_own

    def make_mmd():  # MMD alone: the ordering of a plain install (no pymetis)
        return make_own("mmd")

    makers[MMD] = make_mmd

    def make_ldl():  # holofold's sparse LDL^T: the indefinite tangent's path without LU
        return make_own(ldl=True)

    makers[LDL] = make_ldl
    if args.indefinite:  # the Cholesky paths cannot factorise it
        for p in ("banded Cholesky", "sparse Cholesky", AMD, OWN, MMD):
            makers.pop(p, None)
    else:
        makers.pop(LDL)
    return makers


def check(K, call) -> None:
    """The path solves the system: backward error at round-off."""
    b = np.random.default_rng(0).standard_normal(K.shape[0])
    x = call()
    err = np.linalg.norm(K @ x - b) / (spla.norm(K, 1) * np.linalg.norm(x, 1))
    if not err < 1e-12:
        raise RuntimeError(f"backward error {err:.1e}")


def _rss_kb(field: str) -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field):
                return int(line.split()[1])
    return 0


def peak_growth_mb(fn) -> float:
    """Growth of the peak resident memory (MB) during ``fn()``."""
    gc.collect()
    _LIBC.malloc_trim(0)
    base = _rss_kb("VmRSS:")
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")  # reset VmHWM to the current RSS
    except OSError:
        return float("nan")
    fn()
    return (_rss_kb("VmHWM:") - base) / 1024.0


def measure(size: str, args) -> list[dict]:
    m, n = (int(v) for v in size.split("x"))
    s = model(m, n)
    asm = Assembler(s)
    U = np.zeros((s.n_nodes, 3))
    if args.indefinite:  # displaced at random by 0.1 mm: compressed bars, indefinite
        U = 1e-4 * np.random.default_rng(1).standard_normal((s.n_nodes, 3))
        U[s.supports] = 0.0
    _, _, K = asm.evaluate_reduced(U, dense=False)
    K = K.tocsr()
    K.sort_indices()
    perm, bw, work = band_work(K)
    makers = path_makers(K, perm, bw, args)
    mem = {p: peak_growth_mb(lambda p=p: makers[p]()()) for p in makers}
    calls, setup = {}, {}
    for p, make in makers.items():
        t0 = time.thread_time()
        calls[p] = make()
        setup[p] = time.thread_time() - t0
        check(K, calls[p])
    names = list(calls)
    cpu = {p: [] for p in names}
    wall = {p: [] for p in names}
    asm_cpu = []
    rounds = args.rounds if K.shape[0] < 40000 else max(3, args.rounds // 2)
    for r in range(rounds):
        t0 = time.thread_time()
        asm.evaluate_reduced(U, dense=False)
        asm_cpu.append(time.thread_time() - t0)
        for p in names[r % len(names) :] + names[: r % len(names)]:
            if p == "banded Cholesky" and r >= 2 and work > args.band_slow:
                continue  # 5-12 s a factorisation: two rounds are enough
            w0, c0 = time.perf_counter(), time.thread_time()
            calls[p]()
            cpu[p].append(time.thread_time() - c0)
            wall[p].append(time.perf_counter() - w0)
    best = min(min(cpu[p]) for p in names)
    t_asm = min(asm_cpu)
    chosen = assembler_path(asm)
    without = fallback_path(K.shape[0], work)
    if args.indefinite:  # where the Cholesky fails: LDL^T after the sparse one, LU after the band
        to = {"sparse Cholesky": LDL, OWN: LDL, MMD: LDL, "banded Cholesky": "SuperLU"}
        chosen, without = to.get(chosen, chosen), to.get(without, without)
    rows = []
    for p in PATHS:
        if p not in calls:
            continue
        mark = ("*" if p == chosen else "") + ("+" if p == without else "")
        t = min(cpu[p])
        rows.append(
            dict(size=size, nf=K.shape[0], nnz=K.nnz, bw=bw, work=work, path=p, mark=mark,
                 min=t, med=statistics.median(cpu[p]), wall=statistics.median(wall[p]),
                 it=t_asm + t, mem=mem[p], setup=setup[p], ratio=t / best)
        )  # fmt: skip
    return rows


def table(rows: list[dict]) -> str:
    head = (
        "| Miura | free DOF | band work | path | factor+solve ms min / med (wall med) "
        "| iteration ms | peak MB | setup ms | ratio |\n"
        "|---|---:|---:|---|---:|---:|---:|---:|---:|"
    )
    lines = [head]
    for r in rows:
        lines.append(
            f"| {r['size']} | {r['nf']} | {r['work']:.1e} | {r['mark']:>1} {r['path']} "
            f"| {1e3 * r['min']:.1f} / {1e3 * r['med']:.1f} ({1e3 * r['wall']:.1f}) "
            f"| {1e3 * r['it']:.1f} | {r['mem']:.0f} | {1e3 * r['setup']:.0f} "
            f"| {r['ratio']:.2f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", nargs="*", default=SIZES)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--dense-max", type=int, default=1500, help="dense LU up to this many DOFs")
    ap.add_argument("--band-limit", type=float, default=1e11, help="skip the band above this")
    ap.add_argument("--band-slow", type=float, default=2e10, help="band work timed twice only")
    ap.add_argument("--out", help="also write the table (markdown) to this file")
    ap.add_argument(
        "--indefinite", action="store_true",
        help="the tangent at a random 0.1 mm displacement (indefinite): LU and LDL^T paths",
    )  # fmt: skip
    args = ap.parse_args(argv)
    rows = []
    with threadpool_limits(1):
        for size in args.sizes:
            got = measure(size, args)
            rows += got
            print(table(got).split("\n", 2)[2], flush=True)
    load = os.getloadavg()
    text = (
        f"{table(rows)}\n\nload average {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} "
        f"(1 / 5 / 15 min) at the end; {os.cpu_count()} CPUs; rounds {args.rounds}\n"
    )
    print("\n" + text)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text)


if __name__ == "__main__":
    main()
