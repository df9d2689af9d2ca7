"""Re-simulate the published databases row by row and print the relative-error distribution.

Usage (from the repository root)::

    python validation/reproduce.py                      # every file, all rows
    python validation/reproduce.py --files data0 --rows 100 --workers 2
    python validation/reproduce.py --save out/            # per-row CSVs too

Files: data0_SingleMiura (1000 rows), data1_{Miura,TMP}Sheet_sample (2 x 200),
data4_{Miura,TMP}SheetMat_sample (2 x 200), data3_ShapeFit (3000). The reference folder is
``../shared/reference-data`` next to the repository, ``$HOLOFOLD_REFERENCE_DATA`` or ``--data``.
For each performance column the script prints the median, 90th and 99th percentile and the
maximum of |ours - published| / |published|; for the arch it also gives the Zsnap agreement and
the Zstiff/Xstiff errors restricted to the non-snapping rows (the acceptance set of issue 4).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.database.runner import evaluate_designs
from holofold.design.database.tables import read_table
from holofold.design.scenarios import get_scenario

ROOT = Path(__file__).resolve().parents[1]

FILES = {
    "data0": [("data0_SingleMiura", "single-miura")],
    "data1": [("data1_MiuraSheet_sample", "canopy"), ("data1_TMPSheet_sample", "canopy")],
    "data4": [("data4_MiuraSheetMat_sample", "canopy"), ("data4_TMPSheetMat_sample", "canopy")],
    "data3": [("data3_ShapeFit", "arch")],
}


def emit(text: str) -> None:
    """One line to stdout (a script, not library code)."""
    sys.stdout.write(text + "\n")


def reference_folder(arg: str | None) -> Path:
    default = ROOT.parent / "shared" / "reference-data"
    for c in (arg, os.environ.get("HOLOFOLD_REFERENCE_DATA"), default):
        if c and (Path(c) / "README.md").is_file():
            return Path(c)
    raise SystemExit("reference data not found: pass --data or set HOLOFOLD_REFERENCE_DATA")


def load(folder: Path, stem: str) -> pd.DataFrame:
    """A published file with its column names (from the sibling *_FeatureName.txt)."""
    return read_table(folder / f"{stem}.txt")


def rel_err(ours, ref) -> np.ndarray:
    ours, ref = np.asarray(ours, float), np.asarray(ref, float)
    return np.abs(ours - ref) / np.abs(ref)


def stats_line(label: str, e: np.ndarray, *, width: int = 28, count_width: int = 5) -> str:
    """One line of the finite relative errors ``e``: count, median, p90, p99 and max, the
    label in ``width`` columns and the count in ``count_width``."""
    e = e[np.isfinite(e)] if e.size else e
    if e.size == 0:
        return f"  {label:<{width}} (no rows)"
    q = np.percentile(e, [50, 90, 99])
    return (
        f"  {label:<{width}} n={e.size:<{count_width}d} median {q[0]:.2e}  p90 {q[1]:.2e}  "
        f"p99 {q[2]:.2e}  max {e.max():.2e}"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--files", nargs="*", default=list(FILES), choices=list(FILES))
    ap.add_argument("--rows", type=int, default=None, help="only the first N rows of each file")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--data", default=None, help="reference folder")
    ap.add_argument("--save", default=None, help="folder for per-row result CSVs")
    args = ap.parse_args(argv)
    folder = reference_folder(args.data)
    for key in args.files:
        for stem, name in FILES[key]:
            sc = get_scenario(name)
            ref = load(folder, stem)
            if args.rows:
                ref = ref.iloc[: args.rows]
            feats = [c for c in sc.feature_names if c in ref.columns]
            t0 = time.perf_counter()
            res = evaluate_designs(sc, ref[feats], workers=args.workers, progress=False)
            dt = time.perf_counter() - t0
            emit(f"{stem}: {len(ref)} rows in {dt:.1f} s ({1e3 * dt / len(ref):.0f} ms/row)")
            st = res["status"]
            emit(
                f"  status: {(st == 'converged').sum()} converged, "
                f"{st.str.startswith('not converged').sum()} not converged, "
                f"{st.str.startswith('failed').sum()} failed"
            )
            for c in sc.performance_names:
                if c == "Zsnap":
                    agree = (res[c].to_numpy() == ref[c].to_numpy()).mean()
                    emit(
                        f"  {'Zsnap agreement':<28} {100 * agree:.2f} % "
                        f"(published snaps {int(ref[c].sum())}, ours {int(np.nansum(res[c]))})"
                    )
                    continue
                emit(stats_line(c, rel_err(res[c], ref[c])))
            if "Zsnap" in ref.columns:
                ok = ref["Zsnap"].to_numpy() == 0
                for c in ("Zstiff", "Xstiff"):
                    emit(stats_line(f"{c} (Zsnap = 0 rows)", rel_err(res[c][ok], ref[c][ok])))
                snap = ~ok
                e = rel_err(res["Zstiff"][snap], ref["Zstiff"][snap])
                emit(stats_line("Zstiff (Zsnap = 1 rows)", e))
            if args.save:
                out = Path(args.save)
                out.mkdir(parents=True, exist_ok=True)
                both = res.join(ref[sc.performance_names].add_prefix("published_"))
                both.to_csv(out / f"{stem}_reproduced.csv", index=False, float_format="%.12g")
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
