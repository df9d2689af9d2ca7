"""Origami Simulator's example patterns: import every one, fold each to 50 % and 100 %.

The acceptance set of issue 26: the SVG and FOLD files under ``assets/`` of Origami Simulator
(github.com/amandaghassaei/OrigamiSimulator, MIT licence). Give the folder of a checkout (or of
its ``assets``)::

    python validation/origami_simulator_examples.py path/to/OrigamiSimulator [--limit 300]

For each file: imported (yes, or the one-line reason), panels, then one fold by rest-angle
actuation to 100 % of the file's fold angles, whose path passes through the 50 % state (the
rest angles grow linearly, so the state at 50 % is the end of a fold to 50 %): the fraction
reached, the verdict at the end and the seconds to reach 50 % and 100 %. Every pattern is
scaled to 200 mm and folded with the same section: PP (E 1.5 GPa, nu 0.42), panels 1 mm,
creases 0.2 mm thick and 1 mm wide, the concentrated-hinge model. Prints a Markdown table and a
summary (how many import, how many fold to 100 %, median and worst time); ``--csv`` writes the
rows too.
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from holofold.geometry import read_pattern
from holofold.mechanics import fold_pattern, scaled_pattern

SECTION = dict(panel_thickness=1e-3, crease_thickness=0.2e-3, crease_width=1e-3, E=1.5e9, nu=0.42)
SIZE = 0.2  # m


def _files(root: Path) -> list[Path]:
    assets = root / "assets" if (root / "assets").is_dir() else root
    return sorted(p for p in assets.rglob("*") if p.suffix.lower() in (".svg", ".fold"))


#: the columns of a row, in the CSV's order
COLUMNS = ("file", "imported", "panels", "reached", "verdict", "t50", "t100", "touch_at",
           "wrong_at", "intersecting", "note", "read_s", "cpu_s", "contact")  # fmt: skip


def run(
    root: Path, limit: float, check: bool = True, only: str = "", contact: bool = False,
    csv_path: Path | None = None,
) -> list[dict]:  # fmt: skip
    """Fold every file (``contact``: with panel contact); each row appended to ``csv_path``
    as soon as it is done, and the files already there skipped (a killed run resumes)."""
    rows, done = [], set()
    if csv_path is not None and csv_path.exists():
        with open(csv_path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        done = {r["file"] for r in rows}
    for path in _files(root):
        if only not in path.as_posix():
            continue
        rel = path.relative_to(path.parents[1]).as_posix()
        if rel in done:
            continue
        row = dict.fromkeys(COLUMNS, "")
        row.update(file=rel, contact="yes" if contact else "no")
        rows.append(_row(path, row, limit, check, contact))
        if csv_path is not None:
            new = not csv_path.exists()
            with open(csv_path, "a", newline="", encoding="utf-8") as fh:
                w = csv.DictWriter(fh, fieldnames=COLUMNS)
                if new:
                    w.writeheader()
                w.writerow(rows[-1])
    return rows


def _row(path: Path, row: dict, limit: float, check: bool, contact: bool) -> dict:
    """One file folded: ``row`` filled in."""
    rel = row["file"]
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = read_pattern(path)
    except ValueError as exc:
        row["imported"] = "no: " + str(exc).split(": ", 1)[-1]
        print(f"{rel}: {row['imported']}", file=sys.stderr, flush=True)
        return row
    t_read = time.perf_counter() - t0
    p = scaled_pattern(p, SIZE / float(np.ptp(p.flat, axis=0).max()))
    row.update(imported="yes", panels=p.n_faces, read_s=round(t_read, 2))
    cpu = time.process_time()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = fold_pattern(p, 1.0, time_limit=limit, check_intersections=check,
                             contact=contact or None, **SECTION)  # fmt: skip
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        row.update(verdict="error", note=f"{type(exc).__name__}: {exc}")
        return row
    row["cpu_s"] = round(time.process_time() - cpu, 2)
    k50 = np.flatnonzero(r.fractions >= 0.5 - 1e-12)
    row.update(
        reached=round(r.reached, 3),
        verdict=r.verdict,
        t50=round(float(r.elapsed[k50[0]]), 1) if k50.size else "",
        t100=round(float(r.elapsed[-1]), 1) if r.complete else "",
        touch_at=round(r.touch_at, 3) if np.isfinite(r.touch_at) else "",
        wrong_at=round(r.wrong_at, 3) if np.isfinite(r.wrong_at) else "",
        # checked independently of the fold's own check: the numpy test on every state
        intersecting=_intersecting(p, r.coords),
        note=r.note,
    )
    print(f"{rel}: {r.summary()} [{r.elapsed[-1]:.1f} s]", file=sys.stderr, flush=True)
    return row


def _intersecting(p, coords) -> str:
    """'' when every stored state is clean, else the fraction index of the first that is not
    (numpy test, independent of IPC Toolkit)."""
    from holofold.mechanics.intersection import intersecting_faces

    bad = [k for k in range(len(coords)) if len(intersecting_faces(coords[k], p.faces))]
    return f"state {bad[0]} of {len(coords) - 1}" if bad else "no"


def table(rows: list[dict]) -> str:
    head = (
        "| file | imported | panels | 50 % (s) | 100 % (s) | reached | verdict at the end | "
        "touch at | wrong at | intersecting |"
    )
    out = [head, "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(
            f"| {r['file']} | {r['imported']} | {r['panels']} | {r['t50'] or '-'} | "
            f"{r['t100'] or '-'} | {r['reached']} | {r['verdict']} | {r['touch_at'] or '-'} | "
            f"{r['wrong_at'] or '-'} | {r['intersecting'] or '-'} |"
        )
    return "\n".join(out)


def summary(rows: list[dict]) -> str:
    imported = [r for r in rows if r["imported"] == "yes"]
    half = [r for r in imported if r["t50"] != ""]
    full = [r for r in imported if r["t100"] != ""]
    times = [float(r["t100"]) for r in full]
    lines = [
        f"{len(rows)} files; {len(imported)} import; {len(half)} fold to 50 %, "
        f"{len(full)} to 100 %",
    ]
    if times:
        worst = max(full, key=lambda r: float(r["t100"]))
        lines.append(
            f"time to fold to 100 %: median {statistics.median(times):.1f} s, worst "
            f"{worst['t100']} s ({worst['file']}, {worst['panels']} panels)"
        )
    verdicts: dict[str, int] = {}
    for r in imported:
        verdicts[r["verdict"]] = verdicts.get(r["verdict"], 0) + 1
    lines.append("verdicts: " + ", ".join(f"{k} {v}" for k, v in sorted(verdicts.items())))
    crossed = [r for r in imported if str(r["intersecting"]).startswith("state")]
    good = ("folds rigidly", "does not fold rigidly", "folds off target")
    lines.append(
        f"contact stops {sum(r['touch_at'] != '' for r in imported)}; wrong-way "
        f"{sum(r['wrong_at'] != '' for r in imported)}; paths with an intersecting state "
        f"{len(crossed)}, of them with a success verdict "
        f"{sum(r['verdict'] in good for r in crossed)}"
    )
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines.append(f"load average during the run (1 min, at the end): {load:.2f}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("root", type=Path, help="Origami Simulator checkout or its assets folder")
    ap.add_argument("--limit", type=float, default=300.0, help="seconds per fold (default 300)")
    ap.add_argument(
        "--csv", type=Path,
        help="append each row to this CSV file as it is done; files already in it are skipped",
    )  # fmt: skip
    ap.add_argument("--contact", action="store_true", help="fold with panel contact (ipctk)")
    ap.add_argument("--only", default="", help="only files whose path contains this")
    ap.add_argument(
        "--no-intersections", action="store_true",
        help="fold without stopping where panels pass through each other (the old behaviour)",
    )  # fmt: skip
    args = ap.parse_args(argv)
    rows = run(args.root, args.limit, not args.no_intersections, args.only, args.contact,
               args.csv)  # fmt: skip
    print(table(rows))
    print()
    print(summary(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
