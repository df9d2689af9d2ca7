"""Options shared by the commands that write fabrication files (pattern, fit, design, demo):
the cutter profile of the flat pattern's SVG and DXF."""

from __future__ import annotations

__all__ = ["add_cutter_arguments", "cutter_options", "add_thick_argument"]


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
