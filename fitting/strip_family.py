"""The Miura strip over a planar curve as a pattern family (``strip``).

Registered in :mod:`holofold.geometry.families` through holofold's own entry point (the
geometry layer cannot import this one): ``holofold pattern strip --curve half-circle:radius=2
--m 12 --offset 0.2 --strip-width 0.02 --extrude 0.1 -o out``.
"""

from __future__ import annotations

from holofold.geometry.families import Parameter, PatternFamily

__all__ = ["FAMILY"]


def _build(v: dict, label):
    from holofold.fitting.curve_files import load_curve
    from holofold.fitting.strip_fit import fit_strip

    return fit_strip(
        load_curve(v["curve"]), v["m"], v["offset"], v["strip_width"], v["extrude"]
    ).pattern


FAMILY = PatternFamily(
    "strip",
    "Miura-like strip fitted to a planar curve (the paper's arch)",
    (
        Parameter(
            "curve",
            "text",
            "built-in curve (half-circle:radius=2), points.csv or drawing.svg#path",
            required=True,
        ),  # fmt: skip
        Parameter("m", "-", "number of Miura units", low=2, required=True, integer=True),
        Parameter(
            "offset",
            "m",
            "zig-zag offset of the middle vertices",
            low=0.0,
            open_low=True,
            required=True,
        ),  # fmt: skip
        Parameter("strip_width", "m", "side-line shift", low=0.0, open_low=True, required=True),
        Parameter(
            "extrude", "m", "half-width of the strip", low=0.0, open_low=True, required=True
        ),  # fmt: skip
    ),
    _build,
    {"ends": "side:-x", "other end": "side:+x"},
    describe=lambda v: f"strip m={v['m']} over {v['curve']}",
)
