"""``holofold fit``: fit a Miura-like strip to a planar curve and export it.

Examples::

    holofold fit --curve half-circle:radius=2 --m 12 --offset 0.2 --strip-width 0.02 \\
        --extrude 0.1 -o out/
    holofold fit --curve points.csv --m 8 --offset 0.1 --strip-width 0.01 --extrude 0.1 -o out/
    holofold fit --curve drawing.svg#arch --curve-scale 0.01 --auto --tolerance 0.05 -o out/

Writes ``strip.fold`` (FOLD 1.2: the flat sector-angle development as crease pattern plus the
3-D strip as a folded-form frame, published node numbering; side-B panel loops are reversed so
that every panel is counter-clockwise in the layout), ``strip.svg`` (that development as an
Origami-Simulator-coloured crease pattern in mm; the x-z plan view of centre and side lines if
no development exists), ``strip.stl`` and ``strip.obj`` (the 3-D strip surface, each quad
fanned from its centre), ``candidates.csv`` with ``--auto``, and ``strip_solid.stl`` (panel
prisms with hinge gaps, geometry.solid) when ``--panel-thickness`` and ``--crease-width`` are
given. The last line printed is a JSON object
with the fit parameters, the errors and the files written. All inputs are validated before any
file is created.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from holofold.fitting import DEFAULT_M_RANGE, SAMPLINGS
from holofold.geometry import ParameterError, check_range


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "fit",
        help="fit a Miura-like strip to a planar curve and export it",
        description=__doc__.split("\n\n")[0]
        + " Curves: a built-in spec (half-circle:radius=2, arc:radius=..,angle=.., "
        "parabola:span=..,height=.., sine:span=..,amplitude=..,periods=.., "
        "catenary:span=..,height=..), a CSV of x,z points, or an SVG file[#path-id].",
    )
    p.add_argument("--curve", required=True, help="built-in spec, points.csv or drawing.svg[#id]")
    p.add_argument(
        "--curve-scale",
        type=float,
        default=1.0,
        help="scale factor applied to the curve (e.g. SVG units to metres; default 1)",
    )
    p.add_argument("--m", type=float, help="number of Miura units (integer >= 2)")
    p.add_argument("--offset", type=float, help="offset l_o of the middle vertices, m")
    p.add_argument("--strip-width", type=float, help="side-line shift parameter W_s, m")
    p.add_argument("--extrude", type=float, help="half-width l_e of the strip in y, m")
    p.add_argument(
        "--sampling",
        choices=SAMPLINGS,
        default=None,
        help="sample spacing (default: paper for the half circle, else arclength)",
    )
    p.add_argument("--auto", action="store_true", help="choose m and offset for --tolerance")
    p.add_argument("--tolerance", type=float, help="closest-point error tolerance for --auto, m")
    p.add_argument(
        "--m-range",
        default=None,
        help="m values for --auto as start:stop[:step], stop included (default 2:60:2)",
    )
    p.add_argument(
        "--metric",
        choices=("max", "mean"),
        default="max",
        help="closest-point error that --auto compares with --tolerance (default max)",
    )
    p.add_argument("--panel-thickness", type=float, help="write a thick solid of this thickness, m")
    p.add_argument("--crease-width", type=float, help="crease width of the thick solid, m")
    p.add_argument("-o", "--output", required=True, help="output folder (created if needed)")
    return p


# ---------------------------------------------------------------------- validation
def _m_range(text: str | None) -> list[int]:
    if text is None:
        return list(DEFAULT_M_RANGE)
    parts = text.split(":")
    try:
        nums = [int(p) for p in parts]
    except ValueError:
        raise ParameterError(
            f"--m-range must be start:stop[:step] integers, got {text!r}"
        ) from None
    if len(nums) == 1:
        return nums
    if len(nums) not in (2, 3) or (len(nums) == 3 and nums[2] <= 0):
        raise ParameterError(f"--m-range must be start:stop[:step] with step > 0, got {text!r}")
    step = nums[2] if len(nums) == 3 else 1
    values = list(range(nums[0], nums[1] + 1, step))
    if not values:
        raise ParameterError(f"--m-range {text!r} is empty")
    return values


def _validate(args) -> dict:
    opts: dict = {}
    for name in ("strip_width", "extrude", "offset", "tolerance"):
        v = getattr(args, name)
        if v is not None:
            opts[name] = check_range(f"--{name.replace('_', '-')}", v, 0.0, None, low_open=True)
    if args.auto:
        if args.tolerance is None:
            raise ParameterError("--auto needs --tolerance (metres)")
        if args.m is not None or args.offset is not None:
            raise ParameterError("--auto chooses --m and --offset itself; do not give them")
        opts["m_range"] = _m_range(args.m_range)
    else:
        missing = [
            f"--{n.replace('_', '-')}"
            for n in ("m", "offset", "strip_width", "extrude")
            if getattr(args, n) is None
        ]
        if missing:
            raise ParameterError(f"missing {', '.join(missing)} (or use --auto --tolerance)")
        m = args.m
        if not (math.isfinite(m) and m == round(m) and m >= 2):
            raise ParameterError(f"--m must be an integer >= 2, got {m!r}")
        opts["m"] = int(m)
    thick = (args.panel_thickness, args.crease_width)
    if any(v is not None for v in thick):
        if any(v is None for v in thick):
            raise ParameterError("a thick solid needs both --panel-thickness and --crease-width")
        check_range("--panel-thickness", args.panel_thickness, 0.0, None, low_open=True)
        check_range("--crease-width", args.crease_width, 0.0, None, low_open=True)
        opts["solid"] = True
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--output {str(out)!r} exists and is not a folder")
    return opts


def run(args) -> int:
    import json

    from holofold.fitting import export_strip_files, fit_auto, fit_strip, load_curve

    opts = _validate(args)
    curve = load_curve(args.curve)
    if args.curve_scale != 1.0:
        curve = curve.scaled(args.curve_scale)
    table = None
    if args.auto:
        res = fit_auto(
            curve,
            opts["tolerance"],
            m_range=opts["m_range"],
            strip_width=opts.get("strip_width"),
            extrude=opts.get("extrude"),
            sampling=args.sampling,
            metric=args.metric,
        )
        fit, table = res.strip, res.candidates
    else:
        fit = fit_strip(
            curve, opts["m"], opts["offset"], opts["strip_width"], opts["extrude"],
            sampling=args.sampling,
        )  # fmt: skip
    written = export_strip_files(
        fit,
        args.output,
        panel_thickness=args.panel_thickness,
        crease_width=args.crease_width,
        candidates=table,
    )
    summary = {**fit.parameters, **fit.errors, "files": [str(w) for w in written]}
    print(f"fitted m={fit.m} strip ({fit.pattern.n_vertices} nodes) to {fit.curve.name}")
    print(json.dumps(summary))
    return 0
