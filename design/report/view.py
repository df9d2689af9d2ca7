"""A 3D view of a design that the reader can turn, from flat to folded, in any browser offline.

A :class:`DesignView` is plain data: the design's vertices in a few states along its folding
(``frames``: flat first, the modelled folded states after), its faces and fold lines, the
supported vertices, the loads (vertex, direction, label), the target curve, an optional value
per vertex and state (the gripper's temperature) and a few facts in words. Each kind of
scenario makes its own (``Scenario.view``).

:func:`view_html` turns one (as its :meth:`DesignView.to_json`) into a piece of HTML: a canvas,
a slider from flat to folded, and about 200 lines of inline JavaScript with no library: drag to
turn, wheel to zoom, the triangles drawn back to front with Lambert shading, mountain folds red,
valleys blue, supports as dark triangles, loads as orange arrows, the target curve green. After
its first drawing the container carries ``data-viewer-ready="1"`` and the number of triangles
drawn (for tests in a headless browser).
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Load", "DesignView", "view_html"]


@dataclass(frozen=True)
class Load:
    """A force on one vertex: ``direction`` (3,) (normalised when drawn) and a label."""

    vertex: int
    direction: tuple[float, float, float]
    label: str = ""


@dataclass(frozen=True)
class DesignView:
    """One design to look at (module docstring). Lengths in m, z up.

    Attributes
    ----------
    frames : (K, nv, 3) float
        Vertex positions, flat first; K >= 1.
    labels : tuple of str
        One per frame ("flat", "Ext 0.9", "closed at 143 degC").
    faces : sequence of int sequences
        Polygons (vertex ids), fanned into triangles.
    edges : (ne, 2) int
        Lines drawn over the faces; ``kinds`` one letter each: M, V (folds), B (boundary),
        anything else thin grey.
    supports : (ns,) int
    loads : tuple of Load
    curve : (P, 3) float or None
        The target curve (or a surface's grid lines as one polyline), drawn over every frame.
    curve_name : str
        What the legend calls it ("target curve", "target surface").
    scalar : (K, nv) float or None
        A value per vertex and frame, coloured (``scalar_name`` in ``scalar_unit``).
    facts : tuple of (str, str)
        Label and text pairs for the report.
    """

    frames: np.ndarray
    labels: tuple[str, ...]
    faces: Sequence
    edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), int))
    kinds: str = ""
    supports: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    loads: tuple[Load, ...] = ()
    curve: np.ndarray | None = None
    curve_name: str = "target curve"
    scalar: np.ndarray | None = None
    scalar_name: str = ""
    scalar_unit: str = ""
    facts: tuple[tuple[str, str], ...] = ()

    def __post_init__(self):
        F = np.asarray(self.frames, float)
        if F.ndim != 3 or F.shape[2] != 3 or len(F) < 1 or not np.isfinite(F).all():
            raise ValueError(f"frames must be a finite (K, nv, 3) array, got {F.shape}")
        if len(self.labels) != len(F):
            raise ValueError(f"{len(self.labels)} labels for {len(F)} frames")
        nv = F.shape[1]
        E = np.asarray(self.edges, int).reshape(-1, 2)
        ids = [np.asarray(f, int) for f in self.faces]
        for name, arr in (
            ("faces", np.concatenate(ids) if ids else np.zeros(0, int)),
            ("edges", E.ravel()),
            ("supports", np.asarray(self.supports, int)),
            ("loads", np.array([ld.vertex for ld in self.loads], int)),
        ):
            if len(arr) and (arr.min() < 0 or arr.max() >= nv):
                raise ValueError(f"{name} name a vertex outside 0..{nv - 1}")
        if len(self.kinds) not in (0, len(E)):
            raise ValueError(f"{len(self.kinds)} edge kinds for {len(E)} edges")
        if self.scalar is not None and np.shape(self.scalar) != F.shape[:2]:
            raise ValueError(f"scalar must be (K, nv) = {F.shape[:2]}, got {np.shape(self.scalar)}")
        object.__setattr__(self, "frames", F)
        object.__setattr__(self, "edges", E)

    def triangles(self) -> np.ndarray:
        """(nt, 3) the faces fanned from their first vertex."""
        tris = [(f[0], f[k], f[k + 1]) for f in self.faces for k in range(1, len(f) - 1)]
        return np.asarray(tris, int).reshape(-1, 3)

    def to_json(self) -> dict:
        """JSON-ready, lengths in mm (rounded to 1e-5 of the model's size)."""
        mm = self.frames * 1e3
        size = float(np.ptp(mm.reshape(-1, 3), axis=0).max()) or 1.0
        step = 10.0 ** np.floor(np.log10(size * 1e-5))
        digits = max(0, int(-np.log10(step)))

        def r(a):
            return np.round(np.asarray(a, float), digits).tolist()

        out = {
            "frames": r(mm),
            "labels": list(self.labels),
            "triangles": self.triangles().tolist(),
            "edges": self.edges.tolist(),
            "kinds": self.kinds,
            "supports": np.asarray(self.supports, int).tolist(),
            "loads": [
                {
                    "vertex": int(ld.vertex),
                    "direction": [float(v) for v in ld.direction],
                    "label": ld.label,
                }
                for ld in self.loads
            ],
            "curve": None if self.curve is None else r(np.asarray(self.curve) * 1e3),
            "curve_name": self.curve_name,
            "scalar": None
            if self.scalar is None
            else np.round(np.asarray(self.scalar, float), 4).tolist(),
            "scalar_name": self.scalar_name,
            "scalar_unit": self.scalar_unit,
            "facts": [list(f) for f in self.facts],
        }
        return out

    def facts_json(self) -> dict:
        """The facts for the summary's ``extras`` (label -> text)."""
        return {"facts": dict(self.facts)} if self.facts else {}


_CSS = """
.viewer { border: 1px solid #d7dee6; border-radius: 4px; padding: 8px; margin: 12px 0;
  background: #fbfcfd; }
.viewer canvas { width: 100%; height: 420px; display: block; cursor: grab; background: #fff;
  touch-action: none; }
.viewer .controls { display: flex; align-items: center; gap: 10px; font-size: 14px;
  margin-top: 6px; flex-wrap: wrap; }
.viewer .controls input[type=range] { flex: 1; min-width: 160px; }
.viewer .legend { font-size: 13px; color: #3d4650; margin-top: 4px; }
.viewer .legend span { margin-right: 14px; white-space: nowrap; }
.viewer .sw { display: inline-block; width: 14px; height: 4px; vertical-align: middle;
  margin-right: 4px; }
"""


def _script() -> str:
    """The viewer's JavaScript (``viewer.js`` beside this module, inlined into the page)."""
    from importlib.resources import files

    return files("holofold.design.report").joinpath("viewer.js").read_text(encoding="utf-8")


def view_html(view: Mapping | DesignView, element_id: str = "design-view") -> str:
    """The viewer as an HTML fragment (a ``<div>`` with its data, canvas, controls and script;
    :data:`view_css` goes in the page's style)."""
    data = view.to_json() if isinstance(view, DesignView) else dict(view)
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    legend = []
    if "M" in data.get("kinds", ""):
        legend.append(
            '<span><span class="sw" style="background:#c0392b"></span>mountain fold</span>'
        )
    if "V" in data.get("kinds", ""):
        legend.append('<span><span class="sw" style="background:#1f5fa8"></span>valley fold</span>')
    if data.get("supports"):
        legend.append("<span>&#9650; supported vertex</span>")
    if data.get("loads"):
        legend.append('<span><span class="sw" style="background:#e67e22"></span>load</span>')
    if data.get("curve"):
        legend.append(
            '<span><span class="sw" style="background:#1e8c45"></span>'
            f"{html.escape(str(data.get('curve_name') or 'target curve'))}</span>"
        )
    eid = json.dumps(element_id)
    return (
        f'<div class="viewer" id="{element_id}">'
        f'<script type="application/json">{payload}</script>'
        '<canvas aria-label="3D view of the design: drag to turn, wheel to zoom"></canvas>'
        '<div class="controls"><button type="button" data-go="flat">flat</button>'
        '<input type="range" min="0" aria-label="from flat to folded">'
        '<button type="button" data-go="folded">folded</button>'
        '<button type="button" data-go="play">play</button>'
        '<span class="state"></span></div>'
        f'<div class="legend">{"".join(legend)} <span>drag to turn, wheel to zoom (mm)</span>'
        "</div>"
        f"<script>{_script().replace('__ID__', eid)}</script></div>"
    )


view_css = _CSS
