"""Banded Cholesky against SuperLU by model size: where ``BANDED_MAX_WORK`` comes from (issue 14).

For concentrated-hinge Miura sheets of growing size (clamped at x = min, the tangent at the
stress-free state), prints the band work ``nf (bw + 1)^2`` of the reverse Cuthill-McKee
ordering and the best of ``--repeat`` timings of factorisation + one solve by LAPACK's banded
Cholesky (dpbtrf/dpbtrs) and by SuperLU with the assembler's cached ordering, BLAS limited to
one thread. The assembler takes the banded path up to ``BANDED_MAX_WORK``.

    python benchmarks/bench_solvers.py [--repeat 5] [--sizes 36x12 72x24]
"""

from __future__ import annotations

import argparse

import numpy as np
from threadpoolctl import threadpool_limits

from holofold.geometry.miura import miura_sheet
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.hinges import build_concentrated
from holofold.mechanics.linear import BANDED_MAX_WORK

SIZES = ["24x8", "36x12", "48x16", "60x20", "72x24", "84x28", "96x32"]


def model(m: int, n: int):
    p = miura_sheet(m, n, 0.2 / m, 0.2 / n, np.deg2rad(70.0), 0.6)
    s = build_concentrated(p, crease_width=2.5e-3, crease_thickness=7.5e-4, panel_thickness=3.5e-3)
    x = s.nodes[:, 0]
    return s.fixed(np.flatnonzero(np.isclose(x, x.min())))


def main(argv=None) -> None:
    import bench_floor  # the same timing of the same LAPACK/SuperLU calls

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", nargs="*", default=SIZES)
    args = ap.parse_args(argv)
    print(f"BANDED_MAX_WORK = {BANDED_MAX_WORK:.1e}; factorisation + one solve, best of 5, ms")
    print(f"{'Miura m x n':<12} {'free':>6} {'bw':>5} {'work':>9} {'banded':>8} {'SuperLU':>8} "
          f"{'SuperLU/banded':>15}  assembler")  # fmt: skip
    with threadpool_limits(1):
        for size in args.sizes:
            m, n = (int(v) for v in size.split("x"))
            s = model(m, n)
            asm = Assembler(s)
            red = asm.reduction
            _, _, K = asm.evaluate_reduced(np.zeros((s.n_nodes, 3)), dense=False)
            costs = bench_floor.path_costs(K, red)
            bw = red.band.bandwidth
            work = red.n_free * (bw + 1) ** 2
            band, slu = costs.get("banded Cholesky", np.nan), costs["SuperLU"]
            path = "banded" if work <= BANDED_MAX_WORK else "SuperLU"
            print(f"{size:<12} {red.n_free:>6d} {bw:>5d} {work:>9.2e} {1e3 * band:>8.2f} "
                  f"{1e3 * slu:>8.2f} {slu / band:>15.2f}  {path}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
