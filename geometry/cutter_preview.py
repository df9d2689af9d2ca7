"""A PNG preview of a cutter drawing with visible strokes.

A laser profile's SVG draws 0.01 mm hairlines (what laser drivers read as "cut"), which a
viewer shows as a blank page; the preview draws the same segments (:func:`cutter_drawing`) in
the profile's colours at a visible width. Cutters read the SVG and DXF, not this picture.
"""

from __future__ import annotations

import os
from pathlib import Path

from holofold.geometry.cutter import CutterProfile, cutter_drawing
from holofold.geometry.pattern import CreasePattern

__all__ = ["write_cutter_preview", "needs_preview", "PREVIEW_LINE_PT", "HAIRLINE_MM"]

#: stroke width of the preview, points (visible at any zoom, unlike a 0.01 mm hairline)
PREVIEW_LINE_PT = 0.8
#: a profile with a stroke thinner than this (mm) draws hairlines: its files get a preview
HAIRLINE_MM = 0.1


def needs_preview(profile: str | CutterProfile) -> bool:
    """Whether ``profile`` draws a hairline (the laser's 0.01 mm), which viewers hardly show."""
    from holofold.geometry.cutter import get_profile

    return min(s.width for s in get_profile(profile).strokes.values()) < HAIRLINE_MM


def write_cutter_preview(
    pattern: CreasePattern, path: str | os.PathLike, profile: str | CutterProfile, *,
    dash=None, gap=None, vertex_gap=None, dpi: int = 150,
) -> Path:  # fmt: skip
    """Write ``path`` (PNG): the drawing of ``pattern`` under ``profile`` (page mm, y down),
    each role in its profile colour at :data:`PREVIEW_LINE_PT`; returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    draw = cutter_drawing(pattern, profile, dash=dash, gap=gap, vertex_gap=vertex_gap)
    w, h = float(draw.width), float(draw.height)
    scale = 8.0 / max(w, h)  # inches per mm: the longer side 8 inches
    fig = plt.figure(figsize=(max(w * scale, 1.0), max(h * scale, 1.0)))
    ax = fig.add_axes((0, 0, 1, 1))
    for role, segs in draw.lines.items():
        if len(segs):
            colour = draw.profile.strokes[role].colour
            ax.add_collection(LineCollection(segs, colors=colour, linewidths=PREVIEW_LINE_PT))
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)  # page y points down
    ax.set_aspect("equal")
    ax.axis("off")
    path = Path(path)
    fig.savefig(path, dpi=dpi, facecolor="white")
    plt.close(fig)
    return path
