"""Issue 34's "Done when", end to end: the four problems of validation/last_mile/ on the defaults.

Runs ``holofold design FILE --target ... --bed 250x210 -o OUT`` for the square twist (pattern
kind, a FOLD file drawn in Rabbit Ear), the hyperbolic-paraboloid roof (surface kind, an
OpenSCAD slab STL), the parabolic arch (strip kind, a CSV in cm) and the PETG Miura sheet with a
stiffness window (sheet kind); then slices every piece of the part to print with PrusaSlicer
and loads each report.html in headless Chromium (the 3D view must say it is ready, and no
JavaScript error may be logged). Prints the table of validation/last_mile.md.

    python validation/last_mile.py [--out DIR] [--workers 1] [--only NAME ...] [--no-run]

A run resumes from its folder (``holofold design`` does), so a second call only redoes the
cheap stages, the slicing and the browser check. The budgets are lowered from the default 6000
so that the four fit in about half an hour on a shared two-core machine (the table says so).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from datetime import UTC, datetime
from pathlib import Path

HERE = Path(__file__).resolve().parent / "last_mile"
BED = "250x210"

# name, scenario file, target, extra options (budgets lowered from the default 6000: see above)
PROBLEMS = [
    ("square twist", "square_twist.toml", "tipstiff > 400", ["--budget", "500"]),
    (
        "hypar roof",
        "hypar_roof.toml",
        "Zstiff > 100000 & rms_error < 1e-4",
        ["-n", "100", "--budget", "250"],
    ),
    ("parabolic arch", "parabolic_arch.toml", "Vstiff > 4000 & error < 0.02", ["--budget", "600"]),
    (
        "PETG Miura sheet (window)",
        "petg_miura_sheet.toml",
        "3000 < axialstiff50 < 4000 & bendstiff80 > 3000",
        ["--budget", "2500"],
    ),
]
TECHNIQUES = {0: "centred", 1: "offset", 2: "tapered"}


def run_design(toml: str, target: str, extra: list[str], out: Path, workers: int) -> dict:
    """``holofold design`` on one problem; its exit status, wall time and last lines."""
    cmd = ["holofold", "design", str(HERE / toml), "--target", target, "--bed", BED,
           "--workers", str(workers), "--no-progress", "-o", str(out), *extra]  # fmt: skip
    start = time.monotonic()
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    (out / "last_mile.log").parent.mkdir(parents=True, exist_ok=True)
    (out / "last_mile.log").write_text(done.stdout + done.stderr)
    return {"rc": done.returncode, "seconds": time.monotonic() - start, "cmd": cmd}


def pieces_of(out: Path) -> list[Path]:
    """The STL files to print: the pieces when the part was cut, else the part itself."""
    segments = sorted((out / "files" / "segments").glob("segment_*.stl"))
    if segments:
        return segments
    for name in ("printable.stl", "thick.stl"):
        if (out / "files" / name).is_file():
            return [out / "files" / name]
    return []


def slice_piece(stl: Path) -> tuple[bool, float, str]:
    """PrusaSlicer's G-code for ``stl``: (sliced, print time in hours, its message if not)."""
    exe = shutil.which("prusa-slicer")
    if exe is None:
        return False, float("nan"), "prusa-slicer not on PATH"
    with tempfile.TemporaryDirectory() as tmp:
        gcode = Path(tmp) / (stl.stem + ".gcode")
        done = subprocess.run(
            [exe, "--export-gcode", "--layer-height", "0.2", "--first-layer-height", "0.2",
             "--bed-shape", "0x0,250x0,250x210,0x210", str(stl), "-o", str(gcode)],
            capture_output=True, text=True, timeout=1800, check=False,
        )  # fmt: skip
        if done.returncode != 0 or not gcode.is_file():
            return False, float("nan"), (done.stdout + done.stderr).strip().splitlines()[-1:]
        when = re.search(r"estimated printing time \(normal mode\) = (.+)", gcode.read_text())
    return True, _hours(when.group(1)) if when else float("nan"), ""


def _hours(text: str) -> float:
    """'1d 2h 3m 4s' -> hours."""
    scale = {"d": 24.0, "h": 1.0, "m": 1 / 60, "s": 1 / 3600}
    return sum(float(v) * scale[u] for v, u in re.findall(r"(\d+)([dhms])", text))


def view_in_chromium(report: Path) -> str:
    """'ready, no JS error' or what went wrong, from headless Chromium's DOM and console."""
    exe = shutil.which("chromium")
    if exe is None:
        return "chromium not installed"
    with tempfile.TemporaryDirectory() as profile:
        done = subprocess.run(
            [exe, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={profile}", "--enable-logging=stderr", "--v=0",
             "--dump-dom", report.as_uri()],
            capture_output=True, text=True, timeout=120, check=False,
        )  # fmt: skip
    viewers = re.findall(r'<div class="viewer"[^>]*>', done.stdout)
    ready = [re.search(r'data-viewer-ready="(\d)"', v) for v in viewers]
    if done.returncode != 0:
        return f"chromium exit {done.returncode}"
    if "Uncaught" in done.stderr:
        return "JS error: " + done.stderr[done.stderr.index("Uncaught") :][:200]
    if not viewers:
        return "no 3D view in the page"
    if not all(r and r.group(1) == "1" for r in ready):
        return "3D view not ready"
    return f"{len(viewers)} view(s) ready, no JS error"


def summarise(name: str, out: Path, run: dict | None) -> dict:
    """One row of the table from OUT/design.json, the sliced pieces and the browser check."""
    doc = json.loads((out / "design.json").read_text())
    rule = doc.get("rule") or {}
    feats = doc.get("features") or {}
    perf = doc.get("performance") or {}
    thick = perf.get("thick")
    if thick is not None:
        technique = TECHNIQUES.get(int(thick), str(thick))
    else:  # a kind without a thick column (the strip) builds with its file's thick key
        setting = tomllib.loads((HERE / doc["scenario"]["source"]).read_text())
        technique = str(setting.get("thick", "centred")) + " (fixed)"
    fab = doc.get("fabrication") or {}
    pieces = pieces_of(out)
    sliced = [slice_piece(p) for p in pieces]
    return {
        "problem": name,
        "rc": None if run is None else run["rc"],
        "seconds": None if run is None else round(run["seconds"]),
        "simulations": doc.get("database", {}).get("rows"),
        "answer": doc.get("answer"),
        "headline": doc.get("headline"),
        "verified_precision": doc.get("verified_precision"),
        "verified": [
            rule.get("verified_meeting"),
            rule.get("verified_n"),
            rule.get("verified_failed"),
        ],
        "verified_95ci": rule.get("verified_95ci"),
        "meets_bar": doc.get("rule_meets_bar"),
        "rule": rule.get("rule"),
        "features": feats,
        "performance": perf,
        "meets": doc.get("meets_target"),
        "buildable": doc.get("buildable"),
        "technique": technique,
        "fabrication": fab,
        "pieces": len(pieces),
        "pieces_sliced": sum(s[0] for s in sliced),
        "slicer_hours": sum(s[1] for s in sliced if s[0]),
        "slicer_errors": [s[2] for s in sliced if not s[0]],
        "view": view_in_chromium(out / "report.html"),
    }


def table(rows: list[dict]) -> str:
    """The markdown table of validation/last_mile.md (without its 'differs' column)."""
    head = ("| problem | simulations | verified precision | chosen design | technique | pieces "
            "| slicer time | 3D view |")  # fmt: skip
    lines = [head, "|" + "---|" * 8]
    for r in rows:
        vp = r["verified_precision"]
        if vp is None:
            vp = "none"
        else:
            meeting, n, failed = r["verified"]
            low = r["verified_95ci"][0]
            bar = "meets the bar" if r["meets_bar"] else "below the bar"
            vp = f"{vp:.2f} ({meeting}/{n + failed}, {failed} failed; 95 % from {low:.2f}; {bar})"
        design = "none" if not r["features"] else (
            f"{r['answer']}: " + ("meets, " if r["meets"] else "misses, ")
            + ("buildable" if r["buildable"] else "not buildable")
        )  # fmt: skip
        fab = r["fabrication"]
        if fab:
            if fab.get("fits"):
                where = "fits whole"
            elif fab.get("pieces"):
                where = "cut to fit"
            else:
                where = "not cut: " + str(fab.get("problem") or "no cut fits")
            pieces = f"{fab.get('pieces')} ({fab.get('extent')}, {where})"
        else:
            pieces = "no part"
        hours = f"{r['slicer_hours']:.1f} h" if r["pieces_sliced"] else "-"
        lines.append(
            f"| {r['problem']} | {r['simulations']} | {vp} | {design} | {r['technique']} "
            f"| {pieces} | {hours} ({r['pieces_sliced']} of {r['pieces']} sliced) | {r['view']} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("last-mile-runs"))
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--only", nargs="*", default=None, help="scenario file stems to run")
    ap.add_argument("--no-run", action="store_true", help="summarise existing folders only")
    ap.add_argument("--json", type=Path, default=None, help="write the rows here too")
    args = ap.parse_args(argv)
    rows = []
    for name, toml, target, extra in PROBLEMS:
        stem = Path(toml).stem
        if args.only is not None and stem not in args.only:
            continue
        out = args.out / stem
        run = None if args.no_run else run_design(toml, target, extra, out, args.workers)
        if not (out / "design.json").is_file():
            print(f"{name}: no design.json in {out}", file=sys.stderr)
            continue
        rows.append(summarise(name, out, run))
        print(f"{name}: {rows[-1]['headline']}", flush=True)
    load = os.getloadavg()
    print(f"\n{datetime.now(UTC):%Y-%m-%d %H:%M} UTC, load average "
          f"{load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")  # fmt: skip
    print(table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
