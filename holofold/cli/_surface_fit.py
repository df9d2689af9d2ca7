"""``holofold fit --surface``: a generalised Miura-ori fitted to a surface, checked by folding.

Examples::

    holofold fit --surface dome.stl --units mm --cells 16x16 -o out/
    holofold fit --surface sphere-cap:radius=1,rim=0.45 --cells 32x32 --size 0.73,0.78 -o out/

Writes the fabrication set (``pattern.fold``, ``pattern.svg``, ``pattern.dxf``, ``folded.stl``,
``folded.obj``; ``thick.stl`` and ``printable.stl`` with thicknesses), ``target.stl`` and
``errors.json``; the last line printed is that JSON summary. Unless ``--no-check``, the flat
pattern is folded by the bar-and-hinge simulator and the fit counts as failed (exit status 1,
files written, the reason in ``errors.json`` and on stderr) when the simulated shape does not
reach the fitted one, or as not verified (exit status 1 too) when the fold runs over
``--fold-time-limit`` (docs/surface-fit.md §4). Options of the strip fit (``--m``, ``--offset``,
...) are refused with ``--surface``, and these with ``--curve``.
"""

from __future__ import annotations

import math
import sys

from holofold.cli._fabrication import part_options, say_part
from holofold.geometry import MAX_PANELS, ParameterError, check_range

__all__ = ["SURFACE_ONLY", "add_surface_arguments", "run_surface"]

#: options of the surface fit and their defaults: given with --curve, they are refused
SURFACE_ONLY = {
    "cells": None,
    "gamma": 60.0,
    "ext": 0.7,
    "side": "below",
    "centre": None,
    "size": None,
    "angle": 0.0,
    "no_check": False,
    "fold_tolerance": None,
    "fold_time_limit": None,
}


def add_surface_arguments(p) -> None:
    d = SURFACE_ONLY
    g = p.add_argument_group("surface fit (--surface)")
    g.add_argument("--cells", help="quads along the zig-zag direction x across it, e.g. 16x16")
    g.add_argument("--gamma", type=float, default=d["gamma"],
                   help="sector angle of the starting Miura-ori, deg (default 60)")  # fmt: skip
    g.add_argument("--ext", type=float, default=d["ext"],
                   help="how far the starting Miura-ori is folded, (0, 1)")  # fmt: skip
    g.add_argument("--side", choices=("below", "above"), default=d["side"],
                   help="which way the corrugation hangs from the fitted side")  # fmt: skip
    g.add_argument("--centre", help="placement centre u,v on the surface's chart, m")
    g.add_argument("--size", help="placement size (folded footprint) Lu,Lv, m (default: the "
                   "whole chart)")  # fmt: skip
    g.add_argument("--angle", type=float, default=d["angle"],
                   help="placement angle of the zig-zag direction, deg (default 0)")  # fmt: skip
    g.add_argument("--no-check", action="store_true",
                   help="skip folding the flat pattern by simulation")  # fmt: skip
    g.add_argument("--fold-tolerance", type=float, default=d["fold_tolerance"],
                   help="largest simulated-vs-fitted distance, relative to the target's size "
                   "(default 1e-3)")  # fmt: skip
    g.add_argument("--fold-time-limit", type=float, default=d["fold_time_limit"],
                   help="wall seconds the fold by simulation may take before the fit is "
                   "reported not verified (default 600)")  # fmt: skip


def _pair(name: str, text: str | None):
    if text is None:
        return None
    try:
        a, b = (float(t) for t in text.split(","))
    except ValueError:
        raise ParameterError(f"{name} must be two numbers a,b (metres), got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ParameterError(f"{name} must be finite, got {text!r}")
    return a, b


def _cells(text: str | None) -> tuple[int, int]:
    if text is None:
        raise ParameterError("--surface needs --cells MxN (quads along and across, e.g. 16x16)")
    parts = text.lower().split("x")
    try:
        m, n = (int(t) for t in parts)
    except ValueError:
        raise ParameterError(f"--cells must be MxN integers, e.g. 16x16, got {text!r}") from None
    if m < 2 or n < 2 or m * n > MAX_PANELS:
        raise ParameterError(f"--cells {text}: m, n >= 2 and m n <= {MAX_PANELS} panels")
    return m, n


def run_surface(args) -> int:
    import json

    from holofold.fitting import Placement, export_surface_files, fit_surface, load_surface

    cells = _cells(args.cells)
    cutter, bed = part_options(args)
    gamma = check_range("--gamma", args.gamma, 0.0, 90.0, low_open=True, high_open=True)
    check_range("--ext", args.ext, 0.0, 1.0, low_open=True, high_open=True)
    angle = math.radians(check_range("--angle", args.angle, -360.0, 360.0))
    placement = Placement(_pair("--centre", args.centre), _pair("--size", args.size), angle)
    tol = None
    if args.fold_tolerance is not None:
        tol = check_range("--fold-tolerance", args.fold_tolerance, 0.0, None, low_open=True)
    limit = None
    if args.fold_time_limit is not None:
        limit = check_range("--fold-time-limit", args.fold_time_limit, 0.0, None, low_open=True)
    if getattr(args, "thick", "centred") != "centred" and args.panel_thickness is None:
        raise ParameterError(
            f"--thick {args.thick} needs --panel-thickness and --crease-width: "
            "without a panel thickness there are no thick panels to offset"
        )
    if getattr(args, "printable", False):
        missing = [f"--{n.replace('_', '-')}" for n in ("panel_thickness", "crease_width",
                   "crease_thickness") if getattr(args, n) is None]  # fmt: skip
        if missing:
            raise ParameterError(f"--printable needs {', '.join(missing)}")
    from pathlib import Path

    from holofold.fitting import MESH_SURFACE_TYPES

    spec = args.surface
    is_file = Path(spec).suffix.lower().lstrip(".") in MESH_SURFACE_TYPES
    target = load_surface(spec, (args.units or "mm") if is_file else None)
    units = args.units or (target.units if is_file else "mm")
    fit = fit_surface(target, cells, placement=placement, gamma=math.radians(gamma),
                      ext=args.ext, side=args.side)  # fmt: skip
    check = None
    if not args.no_check and fit.ok:
        from holofold.mechanics import FOLD_TIME_LIMIT, FOLD_TOLERANCE, check_fold

        fc = check_fold(fit, tolerance=tol or FOLD_TOLERANCE, time_limit=limit or FOLD_TIME_LIMIT)
        check = fc.summary
    files = export_surface_files(
        fit, args.output, units=units,
        panel_thickness=args.panel_thickness, crease_width=args.crease_width or 0.0,
        crease_thickness=args.crease_thickness if getattr(args, "printable", False) else None,
        thick=args.thick, cutter=cutter, fold_check=check,
    )  # fmt: skip
    e = fit.errors
    print(
        f"fitted a {fit.m}x{fit.n} generalised Miura-ori to {fit.target.name}: RMS distance "
        f"{e['rms_error_rel']:.3g} of its size ({e[f'rms_error_{fit.target.units}']:.4g} "
        f"{fit.target.units}), max {e['max_error_rel']:.3g}; flat pattern {e['flat_width']:.4g} x "
        f"{e['flat_height']:.4g} m; {fit.seconds:.2f} s"
    )
    failed = None
    if not fit.ok:
        failed = f"the fit failed: {fit.message}"
    elif check is not None and check["fold_timed_out"]:
        failed = f"the fit is {check['fold_reason']}"
    elif check is not None and not check["fold_reached"]:
        failed = f"the fit does not fold: {check['fold_reason']}"
    elif check is not None:
        print(f"folded by simulation to within {check['fold_deviation_max']:.3g} m of the fit "
              f"({check['fold_seconds']:.1f} s)")  # fmt: skip
    part = None
    if getattr(args, "printable", False) and fit.ok:
        from holofold.design import PrintablePart

        part = PrintablePart(fit.pattern, args.panel_thickness, args.crease_thickness,
                             args.crease_width, thick=args.thick)  # fmt: skip
    fabrication = say_part(files, bed, part, units, None)
    summary = {**fit.summary, **(check or {}), "files": [str(p) for p in files.paths]}
    if fabrication:
        summary["fabrication"] = fabrication
    print(json.dumps(summary))
    if failed:
        print(f"holofold fit: {failed}", file=sys.stderr)
        return 1
    return 0
