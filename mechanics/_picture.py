"""The picture of a pattern simulation (``picture.png``), drawn with Pillow alone.

matplotlib with pyplot and mplot3d cost 0.35-0.5 s CPU to import and about 1 s to lay out and
draw this figure (its 3-D axes' ticks above all); a ``holofold simulate`` run paid both (issue
37 item 4). Here the same two panels are drawn on a Pillow canvas at twice the size and scaled
down (anti-aliased lines): the crease pattern as read, in millimetres with ticks, and the folded
state as an orthographic view from matplotlib's former angle (elevation 28 deg, azimuth -60
deg), its panels sorted by depth (far ones first) and coloured by their bend (viridis), with
the box of the folded state, the x, y, z directions, a scale bar and a colour bar.
"""

from __future__ import annotations

import math
import textwrap
from functools import cache
from pathlib import Path

import numpy as np

__all__ = ["simulation_picture"]

#: viridis at 65 even steps (matplotlib's table; linear between them: within 0.6/255)
_VIRIDIS = bytes.fromhex(
    "44015446075a470d6047136548186a481d6f482374482878472d7b46327e453781443b84424086404588"
    "3e49893d4e8a3b528b39568c375b8d355f8d33638d31678e2f6b8e2e6f8e2c728e2a768e297a8e277e8e"
    "26828e25858e23898e228d8d21918c20938c1f978b1e9b8a1f9f881fa28721a68524aa8327ad812cb17e"
    "31b57b37b8783dbc7444bf704cc26c54c5685cc86365cb5e6ece5877d15381d34d8bd64695d840a0da39"
    "aadc32b5de2bc0df25cae11fd5e21adfe318eae51af4e61efde725"
)
_ANCHORS = np.frombuffer(_VIRIDIS, np.uint8).reshape(-1, 3).astype(float)

W, H = 1320, 682  # px (the former 12 x 6.2 in at 110 dpi)
S = 2  # drawn at S x the size, then scaled down
DPI = 110


def viridis(x) -> np.ndarray:
    """(n, 3) uint8 colours of ``x`` in [0, 1] (clipped)."""
    x = np.clip(np.asarray(x, float), 0.0, 1.0)
    t = np.linspace(0.0, 1.0, len(_ANCHORS))
    rgb = np.stack([np.interp(x, t, _ANCHORS[:, k]) for k in range(3)], axis=-1)
    return rgb.round().astype(np.uint8)


def nice_ticks(lo: float, hi: float, n: int = 7) -> np.ndarray:
    """Round tick values (1, 2, 2.5, 5 x 10^k) inside [lo, hi], about ``n`` of them."""
    span = hi - lo
    if not span > 0:
        return np.array([lo])
    raw = span / max(n - 1, 1)
    mag = 10.0 ** math.floor(math.log10(raw))
    step = next(s * mag for s in (1, 2, 2.5, 5, 10) if s * mag >= raw * 0.999)
    first = math.ceil(lo / step - 1e-9) * step
    ticks = np.arange(first, hi + step * 1e-9, step)
    return ticks[(ticks >= lo - 1e-9 * span) & (ticks <= hi + 1e-9 * span)]


def _label(v: float) -> str:
    text = f"{v:.6g}"
    return "0" if text in ("-0", "0") else text.replace("-", "\u2212")


@cache
def _font(points: float):
    """A scalable sans-serif font of ``points`` pt at the picture's resolution: matplotlib's
    DejaVu Sans where it is installed (found without importing it), else Pillow's own."""
    from importlib.util import find_spec

    from PIL import ImageFont

    size = max(1, round(points * DPI / 72 * S))
    try:
        spec = find_spec("matplotlib")
        if spec and spec.submodule_search_locations:
            for where in spec.submodule_search_locations:
                ttf = Path(where) / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
                if ttf.exists():
                    return ImageFont.truetype(str(ttf), size)
    except (OSError, ImportError, ValueError):
        pass
    try:
        return ImageFont.load_default(size)
    except TypeError:  # Pillow < 10.1
        return ImageFont.load_default()


class _Canvas:
    """A white RGB canvas in final-picture pixels (drawn at :data:`S` x)."""

    def __init__(self):
        from PIL import Image, ImageDraw

        self.Image = Image
        self.img = Image.new("RGB", (W * S, H * S), "white")
        self.draw = ImageDraw.Draw(self.img)

    @staticmethod
    def _xy(points):
        return [(float(x) * S, float(y) * S) for x, y in points]

    def line(self, points, colour, width=1.0):
        self.draw.line(self._xy(points), fill=colour, width=max(1, round(width * S)))

    def polygon(self, points, fill, outline=None):
        self.draw.polygon(self._xy(points), fill=fill, outline=outline, width=1)

    def rect(self, box, outline="black", fill=None):
        x0, y0, x1, y1 = box
        self.draw.rectangle((x0 * S, y0 * S, x1 * S, y1 * S), outline=outline, fill=fill,
                            width=S)  # fmt: skip

    def text(self, x, y, s, points=10.0, anchor="mm", colour="black", angle=0):
        font = _font(points)
        if not angle:
            self.draw.text((x * S, y * S), s, fill=colour, font=font, anchor=anchor)
            return
        from PIL import ImageDraw

        box = self.draw.textbbox((0, 0), s, font=font, anchor="lt")
        w, h = box[2] - box[0] + 4, box[3] - box[1] + 4
        label = self.Image.new("L", (w, h), 0)
        ImageDraw.Draw(label).text((2, 2), s, fill=255, font=font, anchor="lt")
        label = label.rotate(angle, expand=True)
        ink = self.Image.new("RGB", label.size, colour)
        self.img.paste(ink, (round(x * S - label.size[0] / 2), round(y * S - label.size[1] / 2)),
                       label)  # fmt: skip

    def png(self, path):
        self.img.resize((W, H), self.Image.Resampling.LANCZOS).save(path, format="PNG")


def _axes_2d(cv: _Canvas, box, xlim, ylim, xlabel, ylabel):
    """A framed 2-D axes (equal scale) in ``box`` (final px); returns the data -> px map."""
    x0, y0, x1, y1 = box
    sx = (x1 - x0) / (xlim[1] - xlim[0])
    sy = (y1 - y0) / (ylim[1] - ylim[0])

    def to_px(xy):
        xy = np.asarray(xy, float)
        return np.stack([x0 + (xy[..., 0] - xlim[0]) * sx, y1 - (xy[..., 1] - ylim[0]) * sy], -1)

    cv.rect(box)
    for t in nice_ticks(*xlim):
        px = x0 + (t - xlim[0]) * sx
        cv.line([(px, y1), (px, y1 + 3.5)], "black", 0.8)
        cv.text(px, y1 + 6, _label(t), 10, anchor="mt")
    for t in nice_ticks(*ylim):
        py = y1 - (t - ylim[0]) * sy
        cv.line([(x0 - 3.5, py), (x0, py)], "black", 0.8)
        cv.text(x0 - 6, py, _label(t), 10, anchor="rm")
    cv.text((x0 + x1) / 2, y1 + 30, xlabel, 10, anchor="mt")
    cv.text(x0 - 48, (y0 + y1) / 2, ylabel, 10, angle=90)
    return to_px


def _fit(lo, hi, box, margin=0.05):
    """Equal-scale limits of data bounds ``lo``, ``hi`` (2,) in ``box`` and the box they fill."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    span = np.maximum(hi - lo, 1e-12)
    lo, hi = lo - margin * span, hi + margin * span
    span = hi - lo
    bw, bh = box[2] - box[0], box[3] - box[1]
    scale = min(bw / span[0], bh / span[1])
    w, h = span[0] * scale, span[1] * scale
    cx, cy = (box[0] + box[2]) / 2, (box[1] + box[3]) / 2
    return (lo[0], hi[0]), (lo[1], hi[1]), (cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)


def _view(elev_deg: float = 28.0, azim_deg: float = -60.0):
    """(right, up, towards the eye) unit vectors of matplotlib's view at these angles."""
    e, a = math.radians(elev_deg), math.radians(azim_deg)
    eye = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    right = np.array([-math.sin(a), math.cos(a), 0.0])
    up = np.array([-math.sin(e) * math.cos(a), -math.sin(e) * math.sin(a), math.cos(e)])
    return right, up, eye


def simulation_picture(
    path, *, flat_xy, edges, assignment, colours, folded, faces, bend_deg, reached, title
) -> None:
    """Write the PNG: the crease pattern ``flat_xy`` (n, 2) mm with ``edges`` (e, 2) coloured by
    ``assignment`` (``colours``: code -> colour), and the ``folded`` state (n, 3) mm, its
    ``faces`` coloured by ``bend_deg`` (f,), folded to ``reached`` (fraction); ``title`` on
    top."""
    cv = _Canvas()
    for k, line in enumerate(textwrap.wrap(title, 150)):
        cv.text(W / 2, 14 + 16 * k, line, 8, anchor="mt")

    # the crease pattern as read
    xy = np.asarray(flat_xy, float)
    xlim, ylim, box = _fit(xy.min(axis=0), xy.max(axis=0), (80, 95, 680, 585))
    to_px = _axes_2d(cv, box, xlim, ylim, "x (mm)", "y (mm)")
    cv.text((box[0] + box[2]) / 2, box[1] - 8, "crease pattern: mountain red, valley blue, cut "
            "green", 9, anchor="md")  # fmt: skip
    edges = np.asarray(edges, np.int64)
    assignment = np.asarray(assignment)
    for code in ("J", "F", "U", "B", "C", "V", "M"):
        sel = edges[assignment == code]
        width = 0.5 if code in "FJ" else 1.0
        for a, b in to_px(xy[sel]):
            cv.line([a, b], colours[code], width)

    # the folded state, orthographic, far panels first
    X = np.asarray(folded, float)
    right, up, eye = _view()
    lo, hi = X.min(axis=0), X.max(axis=0)
    corners = np.array([[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]]
                        for i in (0, 1) for j in (0, 1) for k in (0, 1)])  # fmt: skip
    P = np.stack([X @ right, X @ up], axis=1)
    C = np.stack([corners @ right, corners @ up], axis=1)
    plo, phi = C.min(axis=0), C.max(axis=0)
    _, _, fbox = _fit(plo, phi, (745, 95, 1165, 560), margin=0.04)
    scale = (fbox[2] - fbox[0]) / ((phi[0] - plo[0]) * 1.08)
    mid_px = np.array([(fbox[0] + fbox[2]) / 2, (fbox[1] + fbox[3]) / 2])
    mid = (plo + phi) / 2

    def proj(p):
        q = (np.asarray(p, float) - mid) * scale
        return np.stack([mid_px[0] + q[..., 0], mid_px[1] - q[..., 1]], -1)

    cv.text((fbox[0] + fbox[2]) / 2, 80, f"folded to {100 * reached:.0f} %", 9, anchor="md")
    Cp = proj(C)
    for i in range(8):
        for j in range(i + 1, 8):
            if bin(i ^ j).count("1") == 1:  # the box's 12 edges
                cv.line([Cp[i], Cp[j]], (176, 176, 176), 0.6)
    bend = np.asarray(bend_deg, float)
    top = max(float(bend.max(initial=0.0)), 3.0)
    colour = viridis(bend / top)
    depth = np.array([X[f].mean(axis=0) @ eye for f in faces])
    Pp = proj(P)
    for k in np.argsort(depth, kind="stable"):
        cv.polygon(Pp[faces[k]], tuple(int(c) for c in colour[k]), outline=(20, 20, 20))

    # directions and a scale bar
    ox, oy = 760, 605
    for name, axis in (("x", 0), ("y", 1), ("z", 2)):
        d = np.array([right[axis], -up[axis]])
        d = 26 * d / max(np.linalg.norm(d), 1e-9)
        cv.line([(ox, oy), (ox + d[0], oy + d[1])], "black", 1.0)
        cv.text(ox + 1.45 * d[0], oy + 1.45 * d[1], name, 9)
    extent = float(phi[0] - plo[0])
    bar = nice_ticks(0.0, extent / 3, 3)[-1] if extent > 0 else 0.0
    if bar > 0:
        x0, y0 = 1165 - bar * scale, 605
        cv.line([(x0, y0), (1165, y0)], "black", 1.5)
        for x in (x0, 1165):
            cv.line([(x, y0 - 4), (x, y0 + 4)], "black", 1.0)
        cv.text((x0 + 1165) / 2, y0 - 7, f"{_label(bar)} mm", 9, anchor="md")

    # colour bar
    bx0, by0, bx1, by1 = 1215, 185, 1233, 545
    ramp = viridis(np.linspace(1.0, 0.0, (by1 - by0) * S))
    strip = cv.Image.fromarray(np.repeat(ramp[:, None, :], (bx1 - bx0) * S, axis=1), "RGB")
    cv.img.paste(strip, (bx0 * S, by0 * S))
    cv.rect((bx0, by0, bx1, by1))
    for t in nice_ticks(0.0, top, 7):
        y = by1 - (t / top) * (by1 - by0)
        cv.line([(bx1, y), (bx1 + 3.5, y)], "black", 0.8)
        cv.text(bx1 + 6, y, _label(t), 10, anchor="lm")
    cv.text(bx1 + 48, (by0 + by1) / 2, "panel bend (deg)", 10, angle=90)
    cv.png(path)
