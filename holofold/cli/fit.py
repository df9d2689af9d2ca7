"""``holofold fit``: fit a Miura-like strip to a planar curve, or a generalised Miura-ori to a
surface, and export it.

Examples::

    holofold fit --curve half-circle:radius=2 --m 12 --offset 0.2 --strip-width 0.02 \\
        --extrude 0.1 -o out/
    holofold fit --curve points.csv --m 8 --offset 0.1 --strip-width 0.01 --extrude 0.1 -o out/
    holofold fit --curve drawing.svg#arch --auto --tolerance 0.05 -o out/
    holofold fit --curve points_mm.csv --curve-units mm --auto --tolerance 0.005 \
        --panel-thickness 0.002 --crease-width 0.002 --crease-thickness 0.0006 --printable \
        --no-overlap -o out/

Writes ``strip.fold`` (FOLD 1.2, metres: the flat sector-angle development as crease pattern
plus the 3-D strip as a folded-form frame, published node numbering; side-B panel loops are
reversed so that every panel is counter-clockwise in the layout), ``strip.svg`` (that
development as an Origami-Simulator-coloured crease pattern in mm; the x-z plan view of centre
and side lines if no development exists), ``strip.stl`` and ``strip.obj`` (the 3-D strip
surface, each quad fanned from its centre), ``candidates.csv`` with ``--auto``,
``strip_solid.stl`` (the folded panel prisms with hinge gaps, loose bodies) when
``--panel-thickness`` and ``--crease-width`` are given, and ``printable.stl`` (the flat part to
print and fold: panels joined by hinge strips of ``--crease-thickness``) with ``--printable``.
Meshes are in ``--units`` (default mm, what slicers read). An SVG curve is read in its
document's units (``width="400mm"``, viewBox and transforms applied); ``--curve-units`` says
what one unit of a CSV or of the SVG's user coordinates is. The last line printed is a JSON
object with the fit parameters, the errors (warp relative), the units and the files written.
All inputs are validated before any file is created.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from holofold.cli._fabrication import add_part_arguments, part_options, say_part
from holofold.cli._surface_fit import SURFACE_ONLY, add_surface_arguments, run_surface
from holofold.fitting import DEFAULT_M_RANGE, MAX_M, PUBLISHED_MAX_WARP, SAMPLINGS
from holofold.geometry import LENGTH_UNITS, ParameterError, check_range

#: options of the strip fit (--curve) and their defaults: given with --surface, they are refused
STRIP_ONLY = {
    "curve_units": None,
    "curve_scale": 1.0,
    "m": None,
    "offset": None,
    "strip_width": None,
    "extrude": None,
    "sampling": None,
    "auto": False,
    "tolerance": None,
    "m_range": None,
    "metric": "max",
    "max_warp": PUBLISHED_MAX_WARP,
    "no_overlap": False,
}


HELP = "fit a Miura-like strip to a planar curve and export it"
DESCRIPTION = (
    __doc__.split("\n\n")[0]
    + " Curves: a built-in spec (half-circle:radius=2, arc:radius=..,angle=.., "
    "parabola:span=..,height=.., sine:span=..,amplitude=..,periods=.., "
    "catenary:span=..,height=..), a CSV of x,z points, or an SVG file[#path-id]."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--curve", help="built-in spec, points.csv or drawing.svg[#id]")
    p.add_argument(
        "--surface",
        help="fit a generalised Miura-ori to a surface instead: a mesh file (.stl .obj .ply "
        ".off, numbers in --units, default mm) or a built-in spec (sphere-cap:radius=1,rim=0.4, "
        "cylinder:radius=..,length=..,angle=.., saddle:radius=..,width=..,depth=.., "
        "paraboloid:radius=.., wave:amplitude=..,wavelength=..); see docs/surface-fit.md",
    )
    add_surface_arguments(p)
    p.add_argument(
        "--curve-units",
        choices=tuple(LENGTH_UNITS),
        default=STRIP_ONLY["curve_units"],
        help="unit of the numbers of a CSV (default m) or of an SVG's user units (default: "
        "the SVG's own width/height units, else m)",
    )
    p.add_argument(
        "--curve-scale",
        type=float,
        default=STRIP_ONLY["curve_scale"],
        help="further scale factor applied to the curve (e.g. a 1:10 model; default 1)",
    )
    p.add_argument("--m", type=float, help="number of Miura units (integer >= 2)")
    p.add_argument("--offset", type=float, help="offset l_o of the middle vertices, m")
    p.add_argument("--strip-width", type=float, help="side-line shift parameter W_s, m")
    p.add_argument("--extrude", type=float, help="half-width l_e of the strip in y, m")
    p.add_argument(
        "--sampling",
        choices=SAMPLINGS,
        default=STRIP_ONLY["sampling"],
        help="sample spacing (default: paper for the half circle, else arclength)",
    )
    p.add_argument("--auto", action="store_true", help="choose m and offset for --tolerance")
    p.add_argument("--tolerance", type=float, help="closest-point error tolerance for --auto, m")
    p.add_argument(
        "--m-range",
        default=STRIP_ONLY["m_range"],
        help="m values for --auto as start:stop[:step], stop included (default 2:60:2)",
    )
    p.add_argument(
        "--metric",
        choices=("max", "mean"),
        default=STRIP_ONLY["metric"],
        help="closest-point error that --auto compares with --tolerance (default max)",
    )
    p.add_argument(
        "--max-warp",
        type=float,
        default=STRIP_ONLY["max_warp"],
        help="largest relative quad warp --auto accepts (default %(default)s, the most the "
        "published arch designs reach)",
    )
    p.add_argument(
        "--no-overlap",
        action="store_true",
        help="--auto refuses strips whose folded thick panels overlap (needs --panel-thickness "
        "and --crease-width)",
    )
    p.add_argument("--panel-thickness", type=float, help="panel thickness t_p, m")
    p.add_argument("--crease-width", type=float, help="crease (hinge) width W, m")
    p.add_argument("--crease-thickness", type=float, help="hinge thickness t_c, m (--printable)")
    p.add_argument(
        "--printable",
        action="store_true",
        help="write printable.stl: the flat part, panels joined by hinge strips (needs the "
        "three thicknesses and widths)",
    )
    p.add_argument(
        "--units",
        choices=tuple(LENGTH_UNITS),
        default=None,
        help="length unit of the STL/OBJ files (default mm, as slicers and CAD read them); with "
        "a --surface file, the unit of its numbers too (the errors and meshes are in it)",
    )
    p.add_argument("-o", "--output", required=True, help="output folder (created if needed)")
    add_part_arguments(p)


# ---------------------------------------------------------------------- validation
# the largest m the command fits: fitting.MAX_M (a strip of 4m panels; m = 2000 takes 4 s)


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
    if max(values) > MAX_M or len(values) > MAX_M:
        raise ParameterError(f"--m-range {text!r} goes beyond m = {MAX_M} or {MAX_M} values")
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
        check_range("--max-warp", args.max_warp, 0.0, None, low_open=True)
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
        if m > MAX_M:
            raise ParameterError(f"--m = {m:g} is more than {MAX_M} units (4m panels)")
        opts["m"] = int(m)
    thick = (args.panel_thickness, args.crease_width)
    if any(v is not None for v in thick):
        if any(v is None for v in thick):
            raise ParameterError("a thick solid needs both --panel-thickness and --crease-width")
        check_range("--panel-thickness", args.panel_thickness, 0.0, None, low_open=True)
        check_range("--crease-width", args.crease_width, 0.0, None, low_open=True)
        opts["solid"] = True
    if args.thick != "centred" and args.panel_thickness is None:
        raise ParameterError(
            f"--thick {args.thick} needs --panel-thickness and --crease-width: "
            "without a panel thickness there are no thick panels to offset"
        )
    if args.no_overlap and not (args.auto and opts.get("solid")):
        raise ParameterError("--no-overlap needs --auto, --panel-thickness and --crease-width")
    if args.printable:
        missing = [
            f"--{n.replace('_', '-')}"
            for n in ("panel_thickness", "crease_width", "crease_thickness")
            if getattr(args, n) is None
        ]
        if missing:
            raise ParameterError(f"--printable needs {', '.join(missing)}")
        check_range("--crease-thickness", args.crease_thickness, 0.0, None, low_open=True)
    elif args.crease_thickness is not None:
        raise ParameterError("--crease-thickness is for --printable; add --printable")
    check_range("--curve-scale", args.curve_scale, 0.0, None, low_open=True)
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--output {str(out)!r} exists and is not a folder")
    return opts


def _refuse_others(args, defaults: dict, mode: str, other: str) -> None:
    """One line naming the options of ``other`` that were given with ``mode``."""
    given = [f"--{k.replace('_', '-')}" for k, v in defaults.items() if getattr(args, k) != v]
    if given:
        raise ParameterError(f"{', '.join(given)} {'is' if len(given) == 1 else 'are'} for "
                             f"{other}, not {mode}")  # fmt: skip


def run(args) -> int:
    import json

    if (args.curve is None) == (args.surface is None):
        raise ParameterError("give one of --curve (a strip) or --surface (a surface fit)")
    if args.surface is not None:
        _refuse_others(args, STRIP_ONLY, "--surface", "--curve (a strip)")
        return run_surface(args)
    _refuse_others(args, SURFACE_ONLY, "--curve", "--surface (a surface fit)")
    args.units = args.units or "mm"

    from holofold.fitting import (
        check_curve_size,
        fit_auto,
        fit_strip,
        load_curve,
        write_strip_set,
    )

    opts = _validate(args)
    cutter, bed = part_options(args)
    scaled = args.curve_scale != 1.0
    curve = load_curve(args.curve, units=args.curve_units, check_size=not scaled)
    if scaled:
        per = curve.params.get("metres_per_unit", 1.0) * args.curve_scale
        curve = curve.scaled(args.curve_scale)
        unit = curve.params.get("units", "m")
        check_curve_size(curve, f"{unit} x {args.curve_scale:g}", per, "")
    table = None
    thick = {"panel_thickness": args.panel_thickness, "crease_width": args.crease_width}
    if args.auto:
        res = fit_auto(
            curve,
            opts["tolerance"],
            m_range=opts["m_range"],
            strip_width=opts.get("strip_width"),
            extrude=opts.get("extrude"),
            sampling=args.sampling,
            metric=args.metric,
            max_warp=args.max_warp,
            require_no_overlap=args.no_overlap,
            thick=args.thick,
            **(thick if opts.get("solid") else {}),
        )
        fit, table = res.strip, res.candidates
    else:
        fit = fit_strip(
            curve, opts["m"], opts["offset"], opts["strip_width"], opts["extrude"],
            sampling=args.sampling,
        )  # fmt: skip
    written = write_strip_set(
        fit,
        args.output,
        **thick,
        crease_thickness=args.crease_thickness if args.printable else None,
        candidates=table,
        units=args.units,
        cutter=cutter,
        thick=args.thick,
    )
    part = None
    if args.printable and fit.flat is not None:
        from holofold.design import PrintablePart

        part = PrintablePart(fit.flat_pattern, args.panel_thickness, args.crease_thickness,
                             args.crease_width, thick=args.thick)  # fmt: skip
    fabrication = say_part(written, bed, part, args.units, None)
    units = {"lengths": "m", "errors": "m", "warp": "relative (1 = 100 %)",
             "mesh files": args.units, "strip.fold": "m", "strip.svg": "mm",
             "strip.dxf": "mm"}  # fmt: skip
    summary = {
        **fit.parameters,
        **fit.errors,
        "units": units,
        "files": [str(f.path) for f in written],
        "notes": list(written.notes),
        **({"fabrication": fabrication} if fabrication else {}),
    }
    warp = fit.errors["warp_max"]
    limit = f" (limit {100 * args.max_warp:.3g} %)" if args.auto else ""
    print(
        f"fitted m={fit.m} strip ({fit.pattern.n_vertices} nodes) to {fit.curve.name}: "
        f"closest-point error max {fit.closest.max:.4g} m, quads warp up to {100 * warp:.3g} %"
        + limit
    )
    print(json.dumps(summary))
    return 0
