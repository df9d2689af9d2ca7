"""Render the README's Miura sheet in each cutter profile (SVG through librsvg, DXF through
ezdxf's drawing add-on) into one PNG.

    python examples/render_cutter_profiles.py [output.png]

Writes ``docs/cutter-profiles.png`` by default: the origami-simulator, laser and cricut SVGs,
the laser DXF read back with ezdxf, and the two faces of a two-pass laser job. The laser's
0.01 mm hairlines are drawn 0.25 mm wide for the picture (a stylesheet given to rsvg-convert);
the files keep their hairlines. Needs ``rsvg-convert`` (Debian: librsvg2-bin).
"""

from __future__ import annotations

import math
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

from holofold.geometry import export_dxf, export_svg, miura_sheet  # noqa: E402

DEFAULT = Path(__file__).resolve().parents[1] / "docs" / "cutter-profiles.png"
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT

pattern = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
panels = [
    ("origami-simulator (default)", export_svg(pattern)),
    ("laser", export_svg(pattern, profile="laser")),
    ("cricut", export_svg(pattern, profile="cricut")),
    ("laser, pass 1: front", export_svg(pattern, profile="laser", side="front")),
    ("laser, pass 2: back (mirrored)", export_svg(pattern, profile="laser", side="back")),
]
with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    css = tmp / "wide.css"
    css.write_text("path { stroke-width: 0.25 !important; }\n")
    images = []
    for k, (title, svg) in enumerate(panels):
        src, png = tmp / f"{k}.svg", tmp / f"{k}.png"
        src.write_text(svg)
        cmd = ["rsvg-convert", "-d", "200", "-p", "200", "-b", "white", str(src), "-o", str(png)]
        if "laser" in title:
            cmd[1:1] = ["-s", str(css)]
        subprocess.run(cmd, check=True)
        images.append((title, mpimg.imread(png)))
    import ezdxf
    from ezdxf.addons.drawing import matplotlib as dxf_draw

    dxf = tmp / "laser.dxf"
    dxf.write_text(export_dxf(pattern, profile="laser"))
    dxf_png = tmp / "dxf.png"
    dxf_draw.qsave(ezdxf.readfile(dxf).modelspace(), str(dxf_png), bg="#FFFFFF", dpi=200)
    images.insert(3, ("laser DXF (ezdxf): SCORE_M, SCORE_V, BOUNDARY", mpimg.imread(dxf_png)))

fig, axes = plt.subplots(2, 3, figsize=(13, 9))
for ax, (title, img) in zip(axes.ravel(), images, strict=True):
    ax.imshow(img)
    ax.set_title(title, fontsize=10)
    ax.axis("off")
fig.suptitle("A 4 x 4 Miura sheet (20 mm panels) in holofold's cutter profiles", fontsize=12)
fig.tight_layout()
fig.savefig(OUT, dpi=90)
print(f"wrote {OUT}")
