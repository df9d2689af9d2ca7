"""``holofold simulate PATTERN``: fold a crease pattern from a file, load it, write the results.

Examples::

    holofold simulate waterbomb.svg --fold 0.5 -o out/waterbomb
    holofold simulate sheet.fold --material petg --panel-thickness 1e-3 \\
        --crease-thickness 0.3e-3 --crease-width 1e-3 --size 0.2 \\
        --support side:-x --load side:+x --direction 0,0,-1 --force 0.5 -o out/sheet
    holofold simulate cp.dxf --fold 1 --support near:50%,50%,4 --load near:0%,100% -o out/cp

PATTERN is a FOLD, SVG (Origami Simulator's colours), DXF (layers or colours), ORIPA .opx or
.cp file. The pattern folds by rest-angle actuation towards ``--fold`` x its fold angles (as
Origami Simulator's fold percent), then every ``--load`` (a named vertex set: side:-x,
near:X,Y[,K], box:X0,Y0,X1,Y1, ids:..., coordinates in metres or % of the pattern's box) pushes
on the folded pattern held at the ``--support`` sets. Writes ``folded.fold`` (the crease pattern
and the fold path as frames), ``folded.stl``/``folded.obj`` (mm), ``panels.csv`` (energy,
strain, bend per panel), ``simulation.json`` and ``picture.png``, and prints one status line.
Lengths in metres.

Several patterns, a folder (searched recursively for the readable formats) or ``-o`` ending in
``.jsonl`` check every pattern instead and write one JSON line each to ``-o``, resuming a file
already there (:mod:`holofold.design.database.pattern_batch`)::

    holofold simulate A.svg B.fold FOLDER/ -o checks.jsonl --workers 2 --time-limit 120
"""

from __future__ import annotations

import argparse

HELP = "fold a crease pattern file (FOLD, SVG, DXF, ORIPA), load it, write the results"
DESCRIPTION = __doc__.split("\n\n")[0]
EPILOG = (
    "Lengths in metres, forces in newtons. Exit status 1 when the fold stops short "
    "of --fold (the status line says where), 2 on bad input; with several patterns 0 once "
    "every one has its line (failed ones too), 2 on bad input."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "pattern", nargs="+",
        help="crease pattern file: .fold, .svg, .dxf, .opx or .cp; several files or a folder "
        "(searched recursively for those) check them all: -o is then a JSON-lines file",
    )  # fmt: skip
    p.add_argument("--fold", type=float, default=1.0, help="fold fraction 0-1 (default 1)")
    p.add_argument("--material", default="pp", help="material name (default pp); see --E")
    p.add_argument("--E", type=float, help="Young's modulus, Pa (overrides the material's)")
    p.add_argument("--nu", type=float, help="Poisson's ratio (overrides the material's)")
    p.add_argument("--density", type=float, help="density, kg/m^3 (overrides the material's)")
    p.add_argument("--panel-thickness", type=float, default=1e-3, help="m (default 1e-3)")
    p.add_argument("--crease-thickness", type=float, default=0.3e-3, help="m (default 0.3e-3)")
    p.add_argument("--crease-width", type=float, default=1e-3, help="m (default 1e-3)")
    p.add_argument("--model", choices=("concentrated", "compliant"), default="concentrated")
    size = p.add_mutually_exclusive_group()
    size.add_argument("--size", type=float, help="scale the pattern so its larger side is this, m")
    size.add_argument("--scale", type=float, help="multiply every length of the pattern by this")
    p.add_argument("--unit", type=float, help="metres per drawing unit (instead of the file's)")
    p.add_argument("--tol", type=float, help="merge distance of a drawing, drawing units")
    p.add_argument("--frame", type=int, help="FOLD frame to read (0 = key frame)")
    p.add_argument(
        "--split", choices=("as-needed", "all", "none"), default="as-needed",
        help="which faces to triangulate (default: the non-convex ones)",
    )  # fmt: skip
    p.add_argument(
        "--curves", choices=("refuse", "flatten", "keep"), help="curved creases (SVG, DXF)"
    )
    p.add_argument("--support", action="append", default=[], help="vertex set held (repeat)")
    p.add_argument("--support-dofs", default="xyz", help="fixed directions (default xyz)")
    p.add_argument("--load", action="append", default=[], help="vertex set loaded (repeat)")
    p.add_argument(
        "--direction", action="append", default=[],
        help="load direction x,y,z (one, or one per --load; default 0,0,-1)",
    )  # fmt: skip
    p.add_argument(
        "--force", action="append", type=float, default=[],
        help="total force per load, N (one, or one per --load; default 1)",
    )  # fmt: skip
    p.add_argument("--increments", type=int, default=5, help="load increments (default 5)")
    p.add_argument("--no-collisions", action="store_true", help="skip the collision check")
    p.add_argument(
        "--contact", action="store_const", const=True, default="auto",
        help="barrier contact between the thick panels while folding (the default where "
        "IPC Toolkit is installed: holofold[contact]; refused without it)",
    )  # fmt: skip
    p.add_argument(
        "--no-contact", action="store_const", const=False, dest="contact",
        help="fold without contact (the intersection check still stops a fold where panels "
        "would pass through each other)",
    )  # fmt: skip
    p.add_argument("--units", choices=("mm", "m"), default="mm", help="STL/OBJ unit (mm)")
    p.add_argument(
        "-o", "--output", required=True,
        help="output folder; with several patterns (or a .jsonl name) the JSON-lines file of "
        "their records, resumed when it exists",
    )  # fmt: skip
    p.add_argument(
        "--workers", type=int, default=1,
        help="several patterns: worker processes (default 1; -1 = every core)",
    )  # fmt: skip
    p.add_argument(
        "--time-limit", metavar="S", default=None,
        help="several patterns: seconds per pattern, past which its line says 'timeout' and "
        "the batch goes on (default: none)",
    )  # fmt: skip


def _per_load(values, n, name, default):
    if not values:
        return [default] * n
    if len(values) == 1:
        return values * n
    if len(values) != n:
        raise ValueError(f"give one {name} or one per --load ({n}), got {len(values)}")
    return values


def _direction(text: str):
    try:
        d = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise ValueError(f"--direction {text!r}: expected x,y,z numbers") from None
    if len(d) != 3:
        raise ValueError(f"--direction {text!r}: expected three numbers x,y,z")
    return d


def run(args) -> int:
    from dataclasses import replace
    from pathlib import Path

    import numpy as np

    from holofold.geometry import check_output_folder, check_range, read_pattern, reader_for
    from holofold.mechanics import scaled_pattern, simulate_pattern, small_model, write_simulation

    if _is_batch(args):
        return _run_batch(args)
    if args.workers != 1 or args.time_limit is not None:
        raise ValueError(
            "--workers and --time-limit are for several patterns (or a folder, or -o *.jsonl)"
        )
    args.pattern = args.pattern[0]
    out = Path(args.output)
    check_output_folder(out, "-o")
    reader = reader_for(args.pattern)
    options = {"unit": args.unit, "tol": args.tol, "frame": args.frame, "curves": args.curves}
    bad = [k for k, v in options.items() if v is not None and k not in reader.options]
    if bad:
        raise ValueError(f"{reader.name} files take no --{bad[0]}")
    given = {k: v for k, v in options.items() if v is not None}
    given["split"] = args.split
    setting = _setting(args)
    pattern = _read_sized(read_pattern, args, given)
    if args.size is not None:
        check_range("--size", args.size, 0.0, None, low_open=True)
        span = float(
            np.ptp(pattern.flat if pattern.flat is not None else pattern.coords, axis=0).max()
        )
        pattern = scaled_pattern(pattern, args.size / span)
    elif args.scale is not None:
        pattern = scaled_pattern(pattern, args.scale)
    pattern = replace(pattern, meta={**pattern.meta, "source": Path(args.pattern).name})
    with small_model(pattern.n_faces):  # one run: numba only where it pays (issue 37)
        sim = simulate_pattern(pattern, setting)
    written = write_simulation(sim, out, units=args.units)
    size = np.ptp(pattern.flat if pattern.flat is not None else pattern.coords, axis=0)
    print(
        f"{Path(args.pattern).name}: {pattern.n_vertices} vertices, {pattern.n_faces} panels, "
        f"{1e3 * size[0]:.4g} x {1e3 * size[1]:.4g} mm, {sim.mass * 1e3:.4g} g; "
        f"{sim.seconds:.1f} s; wrote {', '.join(p.name for p in written)} to {out}"
    )
    print(sim.status_line())
    return 0 if sim.fold.complete else 1  # 1: the fold stopped short (the status says where)


def _setting(args):
    """The PatternSetting of the parsed arguments."""
    from holofold.mechanics import Material, PatternLoad, PatternSetting, get_material

    mat = get_material(args.material)
    if args.E is not None or args.nu is not None or args.density is not None:
        mat = Material(
            mat.name if args.E is None else "custom",
            mat.E if args.E is None else args.E,
            mat.nu if args.nu is None else args.nu,
            mat.density if args.density is None else args.density,
        )
    n = len(args.load)
    dirs = [_direction(d) for d in _per_load(args.direction, n, "--direction", "0,0,-1")]
    forces = _per_load(args.force, n, "--force", 1.0)
    loads = tuple(
        PatternLoad(f"load{k + 1}" if n > 1 else "load", at, d, f, args.increments)
        for k, (at, d, f) in enumerate(zip(args.load, dirs, forces, strict=True))
    )
    setting = PatternSetting(
        material=mat, panel_thickness=args.panel_thickness,
        crease_thickness=args.crease_thickness, crease_width=args.crease_width, fold=args.fold,
        model=args.model, supports=tuple(args.support), support_dofs=args.support_dofs,
        loads=loads, collisions=not args.no_collisions, contact=args.contact,
    )  # fmt: skip
    return setting


def _is_batch(args) -> bool:
    """Several patterns, a folder, or a ``.jsonl`` output: the batch mode."""
    from pathlib import Path

    return (
        len(args.pattern) > 1
        or Path(args.pattern[0]).is_dir()
        or Path(args.output).suffix.lower() == ".jsonl"
    )


def _run_batch(args) -> int:
    """Check every pattern, one JSON line each in ``-o`` (resumed); progress on stderr."""
    import sys
    from pathlib import Path

    from holofold.design import check_workers, pattern_files, run_pattern_batch
    from holofold.geometry import check_range, check_writable_folder

    out = Path(args.output)
    if out.is_dir():
        raise ValueError(f"-o {out}: a folder; several patterns need a JSON-lines file (.jsonl)")
    if not out.parent.is_dir():
        raise ValueError(f"-o {out}: no folder {out.parent}")
    check_writable_folder(out.parent, f"-o {out}")
    try:
        workers = check_workers(args.workers)
    except ValueError:
        raise ValueError(f"--workers {args.workers}: must be >= 1 or -1 (every core)") from None
    limit = None
    if args.time_limit is not None and str(args.time_limit).lower() not in ("0", "none"):
        try:
            limit = float(args.time_limit)
        except ValueError:
            raise ValueError(f"--time-limit {args.time_limit!r}: expected seconds") from None
        check_range("--time-limit", limit, 0.0, None, low_open=True)
    if args.size is not None:
        check_range("--size", args.size, 0.0, None, low_open=True)
    files = pattern_files(args.pattern)
    if not files:
        raise ValueError(f"no crease-pattern files in {', '.join(args.pattern)}")
    setting = _setting(args)
    options = {"unit": args.unit, "tol": args.tol, "frame": args.frame, "curves": args.curves}
    options["split"] = args.split

    def progress(done, total, failed, rec):
        what = rec["verdict"] if rec["reason"] is None else f"failed: {rec['reason']}"
        print(f"[{done}/{total}, {failed} failed] {rec['file']}: {what}", file=sys.stderr)

    counts = run_pattern_batch(
        files, out, setting, options, size=args.size, scale=args.scale, time_limit=limit,
        workers=workers, progress=progress,
    )  # fmt: skip
    print(
        f"{counts['total']} patterns: {counts['checked']} checked ({counts['failed']} failed), "
        f"{counts['skipped']} already in {out}"
    )
    return 0


def _read_sized(read_pattern, args, given):
    """The pattern read, its readers' unit notes said with this command's options: none when
    ``--size`` or ``--scale`` sets the size anyway, else naming ``--unit`` and ``--size``."""
    import warnings

    from holofold.geometry import PatternWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pattern = read_pattern(args.pattern, **given)
    sized = args.size is not None or args.scale is not None
    for w in caught:
        text = str(w.message)
        if text.endswith("give unit") and issubclass(w.category, PatternWarning):
            if sized:
                continue  # --size / --scale sets the lengths: the file's unit does not matter
            text = text[: -len("give unit")] + (
                "give --unit (metres per drawing unit) or --size (the larger side, m)"
            )
        warnings.warn_explicit(text, w.category, w.filename, w.lineno)
    return pattern
