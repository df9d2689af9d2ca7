"""Compare the paper's snap flag (NR, |U_z| > 1 m at 5 N) with an MGDCM limit-point check.

Runs :func:`~holofold.mechanics.analyses.snap_check_mgdcm` (path following, limit point below 5 N)
on the arch rows of data3 that snap in the published data and on the non-snapping rows closest to
the threshold (smallest Zstiff), and prints the confusion table.

    python validation/snap_compare.py [--near 100] [--workers 2]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
import pandas as pd
from reproduce import emit, load, reference_folder


def _check(row: dict) -> tuple[bool, float, float, str]:
    from threadpoolctl import threadpool_limits

    from holofold.design.scenarios.arch import arch_model
    from holofold.mechanics.analyses import load_group, snap_check_mgdcm

    with threadpool_limits(1):
        s, apex, _ = arch_model(row)
        r = snap_check_mgdcm(s, load_group([apex], "-z"), 5.0)
    return r.snaps, r.limit_load, r.reached_load, r.status


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--near", type=int, default=100, help="non-snapping rows nearest the flag")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--data", default=None)
    args = ap.parse_args(argv)
    d = load(reference_folder(args.data), "data3_ShapeFit")
    snap = d[d["Zsnap"] == 1]
    near = d[d["Zsnap"] == 0].nsmallest(args.near, "Zstiff")
    sel = pd.concat([snap, near])
    feats = ["m", "tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"]
    rows = sel[feats].to_dict("records")
    t0 = time.perf_counter()
    if args.workers == 1:
        out = [_check(r) for r in rows]
    else:
        from joblib import Parallel, delayed

        out = Parallel(n_jobs=args.workers)(delayed(_check)(r) for r in rows)
    dt = time.perf_counter() - t0
    mg = np.array([o[0] for o in out])
    nr = sel["Zsnap"].to_numpy() == 1
    emit(f"{len(rows)} rows ({nr.sum()} published snaps, {(~nr).sum()} nearest non-snaps) "
         f"in {dt:.0f} s")  # fmt: skip
    emit(f"  NR snap & MGDCM snap:       {(nr & mg).sum()}")
    emit(f"  NR snap & MGDCM no snap:    {(nr & ~mg).sum()}")
    emit(f"  NR no snap & MGDCM snap:    {(~nr & mg).sum()}")
    emit(f"  NR no snap & MGDCM no snap: {(~nr & ~mg).sum()}")
    lim = np.array([o[1] for o in out])
    if (nr & mg).any():
        q = np.percentile(lim[nr & mg], [0, 50, 100])
        emit(f"  MGDCM limit load of the snapping rows: min {q[0]:.2f} N, median {q[1]:.2f} N, "
             f"max {q[2]:.2f} N")  # fmt: skip
    for i in np.flatnonzero(nr != mg)[:20]:
        r = sel.iloc[i]
        emit(f"  disagree: data3 row {sel.index[i] + 1} m={r['m']:.0f} Zstiff={r['Zstiff']:.3f} "
             f"NR={int(nr[i])} MGDCM={int(mg[i])} limit={lim[i]:.3f} N")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
