"""Worker for ``bench_surface_fit.py --rffqm PATH``: RFFQM's own spherical-cap construction, timed.

Runs in a separate process with an RFFQMOrigami checkout (github.com/AlonSardas/RFFQMOrigami,
GPL-3.0) on its path; holofold never imports it and nothing of it is copied here: this file
only calls its public functions, as its ``plotsandcalcs/designexamples.py`` spherical cap does
(principal curvatures kx = ky = -1/R turned into the alternating perturbations by
``curvatures.get_delta_func_for_kx`` / ``get_Delta_func_for_ky``, the crease pattern by
``alternatingpert.utils.create_perturbed_origami``, folded by ``RFFQM.set_gamma`` to
omega = W0), with that example's theta = 1.1, W0 = 2.4, F0 = 0.2, M0 = 0.5 and R = 1.

Protocol: one line per request on stdin, ``k`` (k x k quads); one JSON line back with the CPU
seconds of the construction (this process's user + sys), the folded extent and the RMS / max
distance of one vertex side (every other row) to the sphere fitted to it. The pattern's total
lengths (L_tot, C_tot) are calibrated per k, untimed, so that the folded footprint is
0.73 x 0.78 (the benchmark's placement).
"""

from __future__ import annotations

import json
import math
import sys
import time

import numpy as np

R, THETA, W0, F0, M0 = 1.0, 1.1, 2.4, 0.2, 0.5
FOOTPRINT = (0.73, 0.78)


def build(k: int, Ltot: float, Ctot: float):
    from origami.alternatingpert import curvatures
    from origami.alternatingpert.utils import create_perturbed_origami

    N = k // 2
    kx = ky = -1.0 / R
    dfun = curvatures.get_delta_func_for_kx(Ltot, Ctot, W0, THETA, kx, F0)
    Dfun = curvatures.get_Delta_func_for_ky(Ltot, Ctot, W0, THETA, ky, M0)
    ori = create_perturbed_origami(THETA, N, N, Ltot, Ctot, dfun, Dfun)
    ori.set_gamma(ori.calc_gamma_by_omega(W0))
    return ori


def sphere_fit(P: np.ndarray) -> tuple[float, float]:
    A = np.column_stack([2 * P, np.ones(len(P))])
    sol, *_ = np.linalg.lstsq(A, (P * P).sum(axis=1), rcond=None)
    c = sol[:3]
    d = np.linalg.norm(P - c, axis=1) - math.sqrt(sol[3] + c @ c)
    return float(np.sqrt(np.mean(d**2))), float(np.abs(d).max())


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    build(4, 0.5, 1.1)  # imports and sympy's one-time set-up, untimed
    cal: dict[int, tuple[float, float]] = {}
    for line in sys.stdin:
        k = int(line)
        if k not in cal:
            Ltot, Ctot = 0.49, 1.1
            for _ in range(3):
                ext = np.ptp(build(k, Ltot, Ctot).dots.dots, axis=1)
                Ctot *= FOOTPRINT[0] / ext[0]
                Ltot *= FOOTPRINT[1] / ext[1]
            cal[k] = (Ltot, Ctot)
        c0 = time.process_time()
        ori = build(k, *cal[k])
        cpu = time.process_time() - c0
        d, idx = ori.dots.dots, ori.dots.indexes
        rms, mx = sphere_fit(d[:, idx[::2, :].ravel()].T)
        print(json.dumps({"k": k, "cpu": cpu, "extent": np.ptp(d, axis=1).tolist(),
                          "rms": rms, "max": mx, "L_tot": cal[k][0], "C_tot": cal[k][1]}),
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
