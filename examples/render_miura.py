"""Render a folded Miura-ori sheet and its printable thick version to PNG (matplotlib, no display).

    python examples/render_miura.py [output.png]

Writes ``docs/miura.png`` by default: left, the folded surface with mountain creases in red
and valley creases in blue; right, the thick panels with hinge gaps (``thick_solid``), as they
would be 3-D printed. Works without a display (matplotlib's Agg backend).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

from holofold.geometry.mesh import folded_mesh  # noqa: E402
from holofold.geometry.miura import miura_sheet  # noqa: E402
from holofold.geometry.solid import thick_solid  # noqa: E402

DEFAULT = Path(__file__).resolve().parents[1] / "docs" / "miura.png"
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT
WINDOW = (1400, 600)  # pixels

pattern = miura_sheet(6, 6, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
surface = folded_mesh(pattern)
solid = thick_solid(pattern, 0.5e-3, 2e-3)


def _shaded(mesh, color):
    """Faces of a trimesh, shaded by the angle of their normal to a light from above-left."""
    v = np.asarray(mesh.vertices) * 1e3  # mm
    tri = v[np.asarray(mesh.faces)]
    light = np.array([-0.4, -0.3, 1.0]) / np.linalg.norm([-0.4, -0.3, 1.0])
    shade = 0.55 + 0.45 * np.abs(np.asarray(mesh.face_normals) @ light)
    rgb = np.asarray(matplotlib.colors.to_rgb(color))
    return Poly3DCollection(tri, facecolors=shade[:, None] * rgb, edgecolors="none")


def _equal_box(ax, pts):
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set(xlim=(c[0] - r, c[0] + r), ylim=(c[1] - r, c[1] + r), zlim=(c[2] - r, c[2] + r))
    ax.set_box_aspect((1, 1, 1), zoom=1.6)
    ax.set_axis_off()
    ax.view_init(elev=30, azim=-60)


fig = plt.figure(figsize=(WINDOW[0] / 100, WINDOW[1] / 100), dpi=100)
fig.subplots_adjust(left=0, right=1, bottom=0, top=0.92, wspace=0)
ax = fig.add_subplot(1, 2, 1, projection="3d", computed_zorder=False)  # creases drawn on top
ax.set_title("folded Miura-ori, ext = 0.6 (M red, V blue)", fontsize=10)
ax.add_collection3d(_shaded(surface, "#f2efe6"))
for code, colour in (("M", "red"), ("V", "blue")):
    e = pattern.edges[pattern.assignment == code]
    ax.add_collection3d(Line3DCollection(pattern.coords[e] * 1e3, colors=colour, linewidths=2))
_equal_box(ax, pattern.coords * 1e3)
ax = fig.add_subplot(1, 2, 2, projection="3d")
ax.set_title("printable panels: 0.5 mm thick, 2 mm hinge gaps", fontsize=10)
ax.add_collection3d(_shaded(solid, "#9fb7c9"))
_equal_box(ax, np.asarray(solid.vertices) * 1e3)
OUT.parent.mkdir(parents=True, exist_ok=True)
fig.savefig(OUT, dpi=100)
plt.close(fig)

#: checked by tests/test_examples.py
RESULT = {"png": OUT, "watertight": bool(solid.is_watertight), "panels": pattern.n_faces}

if __name__ == "__main__":
    print(f"wrote {OUT}")
