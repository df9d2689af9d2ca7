"""Options shared by the commands that write fabrication files (pattern, fit, design, demo):
the cutter profile of the flat pattern's SVG and DXF, the printer's bed the printable part is
fitted on (and cut into pieces for when larger)."""

from __future__ import annotations

__all__ = [
    "add_cutter_arguments",
    "cutter_options",
    "add_thick_argument",
    "add_bed_argument",
    "bed_of",
    "say_part",
    "add_part_arguments",
    "part_options",
]


def add_cutter_arguments(p) -> None:
    """``--profile``, ``--dash``, ``--gap``, ``--vertex-gap`` and ``--two-sided`` (the
    profiles are the registry's, :data:`holofold.geometry.PROFILES`, asked when the parser is
    built)."""
    from holofold.geometry import DEFAULT_PROFILE, PROFILES

    g = p.add_argument_group("cutter files (SVG and DXF of the flat pattern; docs/fabrication.md)")
    g.add_argument(
        "--profile", choices=tuple(PROFILES), default=DEFAULT_PROFILE,
        help="colours, strokes and layers of the SVG and DXF: origami-simulator (default: "
        "Origami Simulator's import convention), laser (red hairline cuts, blue mountain and "
        "green valley scores, dashed) or cricut (cut and score layers)",
    )  # fmt: skip
    g.add_argument("--dash", type=float, help="crease dash length, mm (0: whole lines)")
    g.add_argument("--gap", type=float, help="gap between crease dashes, mm")
    g.add_argument("--vertex-gap", type=float, help="crease left clear at each vertex, mm")
    g.add_argument(
        "--two-sided", action="store_true",
        help="also write the two faces of a two-pass job: *_front.svg (mountains) and "
        "*_back.svg (valleys and cuts, mirrored), with registration holes",
    )  # fmt: skip


def cutter_options(args):
    """The :class:`~holofold.geometry.CutterOptions` the arguments describe (checked)."""
    from holofold.geometry import CutterOptions

    return CutterOptions(
        args.profile, dash=args.dash, gap=args.gap, vertex_gap=args.vertex_gap,
        two_sided=args.two_sided,
    )  # fmt: skip


def add_thick_argument(p) -> None:
    """``--thick centred|offset|tapered``: the thickness accommodation of the solids."""
    p.add_argument(
        "--thick", choices=("centred", "offset", "tapered"), default="centred",
        help="thick panels: centred on the mid-surface (default), offset (on one side, hinges "
        "at the panel face, bevelled where a fold closes on the material) or tapered (centred, "
        "bevelled on both faces); the hinges stay on the simulated surface "
        "(docs/fabrication.md)",
    )  # fmt: skip


def add_bed_argument(p) -> None:
    """``--bed WxD``: the printer's bed the printable part is fitted on."""
    p.add_argument(
        "--bed", default=None, metavar="WxD",
        help="printer bed WIDTHxDEPTH in mm (default 250x210): the printable part is fitted on "
        "it and, when larger, cut at panel boundaries into pieces that each fit "
        "(segments/segment_NN.stl and assembly.svg beside printable.stl)",
    )  # fmt: skip


def bed_of(args):
    """The :class:`~holofold.geometry.Bed` of ``--bed`` (checked before any work)."""
    from holofold.design import DEFAULT_BED, parse_bed

    text = getattr(args, "bed", None)
    return DEFAULT_BED if text is None else parse_bed(text)


def say_part(files, bed, part, units: str, root) -> dict | None:
    """If ``files`` (a fabrication set) holds ``printable``: its fit on ``bed``, cut into pieces
    when larger (``part``: a :class:`~holofold.design.loop.buildability.PrintablePart`), said in one
    line; its JSON record (None without a printable part)."""
    from holofold.design import part_fit

    path = next((f.path for f in files.files if f.key == "printable"), None)
    if path is None:
        return None
    fit = part_fit(path, bed, units=units, root=root, part=part)
    print(fit.line())
    return fit.to_json()


def add_part_arguments(p) -> None:
    """The options of the commands that write a printable part (pattern, fit): ``--thick``,
    ``--bed`` and the cutter options, in that order."""
    add_thick_argument(p)
    add_bed_argument(p)
    add_cutter_arguments(p)


def part_options(args):
    """(:func:`cutter_options`, :func:`bed_of`) of the arguments, both checked."""
    return cutter_options(args), bed_of(args)
