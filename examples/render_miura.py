"""Render a folded Miura-ori sheet and its printable thick version to PNG (pyvista, off-screen).

    python examples/render_miura.py [output.png]

Writes ``docs/miura.png`` by default: left, the folded surface with mountain creases in red
and valley creases in blue; right, the thick panels with hinge gaps (``thick_solid``), as they
would be 3-D printed. Works without a display (VTK renders off-screen).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pyvista as pv

from holofold.geometry.mesh import folded_mesh
from holofold.geometry.miura import miura_sheet
from holofold.geometry.solid import thick_solid

pv.OFF_SCREEN = True
DEFAULT = Path(__file__).resolve().parents[1] / "docs" / "miura.png"
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT
WINDOW = (1400, 600)

pattern = miura_sheet(6, 6, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
surface = folded_mesh(pattern)
solid = thick_solid(pattern, 0.5e-3, 2e-3)


def _polydata(mesh):
    faces = np.column_stack([np.full(len(mesh.faces), 3), mesh.faces]).ravel()
    return pv.PolyData(np.asarray(mesh.vertices), faces)


def _crease_lines(code: str) -> pv.PolyData:
    e = pattern.edges[pattern.assignment == code]
    lines = np.column_stack([np.full(len(e), 2), e]).ravel()
    return pv.PolyData(pattern.coords, lines=lines)


plotter = pv.Plotter(shape=(1, 2), off_screen=True, window_size=WINDOW)
plotter.subplot(0, 0)
plotter.add_text("folded Miura-ori, ext = 0.6 (M red, V blue)", font_size=10)
plotter.add_mesh(_polydata(surface), color="#f2efe6", smooth_shading=False)
plotter.add_mesh(_crease_lines("M"), color="red", line_width=3)
plotter.add_mesh(_crease_lines("V"), color="blue", line_width=3)
plotter.view_isometric()
plotter.subplot(0, 1)
plotter.add_text("printable panels: 0.5 mm thick, 2 mm hinge gaps", font_size=10)
plotter.add_mesh(_polydata(solid), color="#9fb7c9")
plotter.view_isometric()
OUT.parent.mkdir(parents=True, exist_ok=True)
plotter.screenshot(str(OUT))
plotter.close()

#: checked by tests/test_examples.py
RESULT = {"png": OUT, "watertight": bool(solid.is_watertight), "panels": pattern.n_faces}

if __name__ == "__main__":
    print(f"wrote {OUT}")
