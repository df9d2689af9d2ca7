"""``holofold pattern KIND``: generate a crease pattern of any registered family and export it.

The kinds are the pattern families of :mod:`holofold.geometry.families` (``miura``, ``tmp``,
``gripper``, ``strip``, ``file``, and any a package adds); each kind's options are its
parameters (``holofold pattern miura --help``).

Examples::

    holofold pattern miura --m 4 --n 4 --gamma 60 --ext 0.6 --a 0.02 --b 0.02 -o out/
    holofold pattern miura --m 4 --n 4 --gamma 60 --ext 0.6 --size 0.2 \\
        --thickness 0.5e-3 --crease-width 2e-3 -o out/
    holofold pattern tmp --m 6 --n 6 --size 0.2 --ext 0.6 -o out/
    holofold pattern strip --curve half-circle:radius=2 --m 12 --offset 0.2 \\
        --strip-width 0.02 --extrude 0.1 -o out/
    holofold pattern gripper --kind 3 --L1 0.02 --L2 0.01 --rate 0.5 -o out/
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

from holofold.cli._fabrication import add_part_arguments, part_options, say_part


def _option(name: str) -> str:
    return "--" + name.replace("_", "-")


def _fabrication_arguments(p) -> None:
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
    add_part_arguments(p)


HELP = "generate a crease pattern (miura, tmp, gripper, strip, file, ...) and export it"
DESCRIPTION = __doc__.split("\n\n")[0]
EPILOG = "Lengths in metres, angles in degrees."


def add_arguments(p: argparse.ArgumentParser) -> None:
    from holofold.geometry import pattern_families

    kinds = p.add_subparsers(dest="kind", metavar="KIND")
    kinds.required = True
    for name, fam in pattern_families().items():
        k = kinds.add_parser(name, help=fam.description, description=fam.description,
                             epilog=EPILOG)  # fmt: skip
        for par in fam.parameters:
            unit = par.given_in or par.unit
            unit = "" if unit in ("-", "text") else f", {unit}"
            kind = str if par.unit == "text" else (int if par.integer else float)
            k.add_argument(_option(par.name), dest=f"p_{par.name}", type=kind,
                           required=par.required, help=f"{par.description}{unit}")  # fmt: skip
        _fabrication_arguments(k)
        k.set_defaults(_family=name)


def _build(args):
    """The family and the pattern the arguments describe (checked in the options' terms)."""
    from holofold.geometry import get_family

    fam = get_family(args._family)
    given = {par.name: getattr(args, f"p_{par.name}", None) for par in fam.parameters}
    values = fam.values(given, _option)
    return fam, values, fam.build(values, _option)


def run(args) -> int:
    import numpy as np

    from holofold.geometry import ParameterError, check_range, write_fabrication_set

    cutter, bed = part_options(args)
    fam, values, pattern = _build(args)
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
    if args.thick != "centred" and args.thickness is None:
        raise ParameterError(
            f"--thick {args.thick} needs --thickness: without a panel "
            "thickness there are no thick panels to offset"
        )
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
    label = fam.describe(values) if fam.describe else fam.name
    print(
        f"{label}: {pattern.n_vertices} vertices, "
        f"{int(pattern.interior.sum())} creases, {pattern.n_faces} panels, extent "
        f"{ext[0]:.4g} x {ext[1]:.4g} x {ext[2]:.4g} m; wrote "
        + ", ".join(f.path.name for f in written)
        + f" to {args.output}"
    )
    for note in written.notes:
        print(f"  note: {note}")
    if args.printable and pattern.flat is not None:
        from holofold.design import PrintablePart

        part = PrintablePart(pattern, args.thickness, args.crease_thickness, args.crease_width,
                             thick=args.thick)  # fmt: skip
        say_part(written, bed, part, args.units, None)
    return 0
