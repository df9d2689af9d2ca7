"""``holofold pattern``: generate a Miura or Tachi-Miura polyhedron sheet and export it.

Examples::

    holofold pattern miura --m 4 --n 4 --gamma 60 --ext 0.6 --a 0.02 --b 0.02 -o out/
    holofold pattern miura --m 4 --n 4 --gamma 60 --ext 0.6 --size 0.2 \\
        --thickness 0.5e-3 --crease-width 2e-3 -o out/
    holofold pattern tmp --m 6 --n 6 --size 0.2 --ext 0.6 -o out/
    holofold pattern miura --m 4 --n 4 --gamma 60 --ext 0.6 --size 0.1 --printable \
        --panel-thickness 2e-3 --crease-thickness 0.6e-3 --crease-width 2e-3 -o out/

Writes ``pattern.fold`` (flat crease pattern + folded frame, m), ``pattern.svg`` and
``pattern.dxf`` (the flat pattern for ``--profile``, mm), ``folded.stl`` and ``folded.obj``
(folded surface) and, with ``--thickness``,
``thick.stl`` (the folded panels with hinge gaps, loose bodies) and, with ``--printable``,
``printable.stl``: the flat part to print and then fold, panels joined by hinge strips of
``--crease-thickness`` and ``--crease-width``. Meshes in ``--units`` (default mm, what slicers
read). Angles in degrees here, lengths in metres.
"""

from __future__ import annotations

import argparse
import math

from holofold.cli._fabrication import add_cutter_arguments, add_thick_argument, cutter_options


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "pattern",
        help="generate a Miura or TMP sheet folded to an extension, and export it",
        description=__doc__.split("\n\n")[0],
        epilog="Lengths in metres, angles in degrees.",
    )
    p.add_argument("kind", choices=["miura", "tmp"], help="pattern type")
    p.add_argument("--m", type=int, required=True, help="panels along x (TMP: even)")
    p.add_argument("--n", type=int, required=True, help="panels along y (TMP: multiple of 3)")
    p.add_argument("--ext", type=float, required=True, help="extension ratio in (0, 1]")
    p.add_argument("--gamma", type=float, help="Miura sector angle, degrees in (0, 90)")
    p.add_argument("--a", type=float, help="Miura panel side a, m")
    p.add_argument("--b", type=float, help="Miura panel side b, m")
    p.add_argument(
        "--size", type=float, help="sheet size L, m (Miura: b = L/m, a = (L - b cot g)/n)"
    )
    p.add_argument(
        "--thickness", "--panel-thickness", dest="thickness", type=float,
        help="panel thickness t_p for thick.stl and printable.stl, m",
    )  # fmt: skip
    p.add_argument("--crease-width", type=float, default=0.0, help="hinge gap W, m (default 0)")
    p.add_argument("--crease-thickness", type=float, help="hinge thickness t_c, m (--printable)")
    p.add_argument(
        "--printable",
        action="store_true",
        help="write printable.stl: the flat part, panels joined by hinge strips",
    )
    p.add_argument(
        "--units",
        choices=("mm", "m"),
        default="mm",
        help="length unit of the STL/OBJ files (default mm, as slicers and CAD read them)",
    )
    p.add_argument("-o", "--output", required=True, help="output folder")
    add_thick_argument(p)
    add_cutter_arguments(p)
    return p


def _build(args):
    """The pattern the arguments describe (checked in the options' own terms and units)."""
    from holofold.geometry import MAX_PANELS, ParameterError, check_range, miura_sheet, tmp_sheet

    # the largest sheet the command writes (geometry.MAX_PANELS): larger ones take minutes
    if args.m > 0 and args.n > 0 and args.m * args.n > MAX_PANELS:
        raise ParameterError(
            f"--m {args.m} x --n {args.n} = {args.m * args.n} panels; at most {MAX_PANELS} "
            "(a 100 x 100 sheet takes 2 s; use the Python API for larger ones)"
        )
    check_range("--ext", args.ext, 0.0, 1.0, low_open=True)
    if args.kind == "miura":
        if args.gamma is None:
            raise ParameterError("--gamma is required for a Miura sheet (degrees in (0, 90))")
        check_range("--gamma", args.gamma, 0.0, 90.0, low_open=True, high_open=True)
        if args.size is None and (args.a is None or args.b is None):
            raise ParameterError("give --size, or both --a and --b, for a Miura sheet")
        for name in ("a", "b", "size"):
            v = getattr(args, name)
            if v is not None:
                check_range(f"--{name}", v, 0.0, None, low_open=True)
        return miura_sheet(
            args.m, args.n, a=args.a, b=args.b, gamma=math.radians(args.gamma), ext=args.ext,
            size=args.size,
        )  # fmt: skip
    if args.size is None:
        raise ParameterError("--size (sheet size L, m) is required for a TMP sheet")
    check_range("--size", args.size, 0.0, None, low_open=True)
    return tmp_sheet(args.m, args.n, args.size, args.ext)


def run(args) -> int:
    import numpy as np

    from holofold.geometry import ParameterError, check_range, write_fabrication_set

    cutter = cutter_options(args)
    pattern = _build(args)
    check_range("--crease-width", args.crease_width, 0.0, None)
    if args.thickness is not None:
        check_range("--thickness", args.thickness, 0.0, None, low_open=True)
    if args.printable:
        given = {"--panel-thickness": args.thickness, "--crease-thickness": args.crease_thickness}
        missing = [name for name, v in given.items() if v is None]
        if args.crease_width <= 0:
            missing.append("--crease-width > 0")
        if missing:
            raise ParameterError(f"--printable needs {', '.join(missing)}")
        check_range("--crease-thickness", args.crease_thickness, 0.0, None, low_open=True)
    elif args.crease_thickness is not None:
        raise ParameterError("--crease-thickness is for --printable; add --printable")
    written = write_fabrication_set(
        pattern,
        args.output,
        panel_thickness=args.thickness,
        crease_width=args.crease_width,
        crease_thickness=args.crease_thickness if args.printable else None,
        units=args.units,
        cutter=cutter,
        thick=args.thick,
    )
    ext = np.ptp(pattern.coords, axis=0)
    print(
        f"{args.kind} {args.m}x{args.n} at ext {args.ext:g}: {pattern.n_vertices} vertices, "
        f"{int(pattern.interior.sum())} creases, {pattern.n_faces} panels, extent "
        f"{ext[0]:.4g} x {ext[1]:.4g} x {ext[2]:.4g} m; wrote "
        + ", ".join(f.path.name for f in written)
        + f" to {args.output}"
    )
    for note in written.notes:
        print(f"  note: {note}")
    return 0
