"""Fit Miura-like strips to three different curves and render them side by side.

Usage::

    python examples/fit_curves.py [output-folder]    # default: docs/

1. the paper's half circle of radius 2 m (paper sampling, m = 12, l_o = 0.2 m),
2. a catenary arch (span 4 m, height 2 m) with m and offset chosen by ``fit_auto`` for a
   closest-point error of 2 cm,
3. a roof profile given as points (a spline through 7 (x, z) points, arc-length sampling).

Writes ``fit_curves.png`` (pyvista off-screen; matplotlib when pyvista cannot render) and
prints one line per strip. ``RESULT`` holds the numbers of the last run.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from holofold.fitting import PlanarCurve, fit_strip, parse_curve_spec
from holofold.fitting.auto import fit_auto

#: filled by :func:`main`: {"backend": ..., "png": ..., "strips": [dict per strip]}
RESULT: dict = {}

ROOF = np.array([[0, 0], [0.5, 1.2], [1.5, 2.0], [2.5, 2.2], [3.5, 2.0], [4.5, 1.2], [5, 0]])


def fit_three():
    """The three fits: list of (title, StripFit)."""
    half = fit_strip(parse_curve_spec("half-circle:radius=2"), 12, 0.2, 0.02, 0.1)
    cat = fit_auto("catenary:span=4,height=2", 0.02, m_range=range(2, 31, 2), extrude=0.15).strip
    roof = fit_strip(PlanarCurve.from_points(ROOF, name="roof"), 10, 0.15, 0.015, 0.12)
    return [
        ("half circle R=2 (paper)", half),
        (f"catenary, fit_auto (m={cat.m})", cat),
        ("roof profile from points", roof),
    ]


def _triangles(fit):
    X = fit.pattern.coords
    faces = np.stack(fit.pattern.faces)
    tri = np.concatenate([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]])
    return X, tri


def _render_pyvista(fits, png: Path) -> None:
    import pyvista as pv

    pl = pv.Plotter(shape=(1, len(fits)), off_screen=True, window_size=(1500, 500))
    for k, (title, fit) in enumerate(fits):
        pl.subplot(0, k)
        X, tri = _triangles(fit)
        cells = np.column_stack([np.full(len(tri), 3), tri]).ravel()
        pl.add_mesh(pv.PolyData(X, cells), color="#f2c14e", show_edges=True, edge_color="k")
        c = fit.curve.polyline(200)
        line = np.column_stack([c[:, 0], np.zeros(len(c)), c[:, 1]])
        pl.add_mesh(pv.lines_from_points(line), color="#1f77b4", line_width=3)
        pl.add_text(title, font_size=10)
        centre = X.mean(axis=0)
        d = float(np.ptp(X, axis=0).max())
        pl.camera_position = [
            tuple(centre + d * np.array([0.6, -2.2, 0.9])),
            tuple(centre),
            (0, 0, 1),
        ]
        pl.reset_camera()
    pl.screenshot(str(png))
    pl.close()


def _render_matplotlib(fits, png: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = plt.figure(figsize=(15, 5))
    for k, (title, fit) in enumerate(fits):
        ax = fig.add_subplot(1, len(fits), k + 1, projection="3d")
        X = fit.pattern.coords
        polys = [X[f] for f in fit.pattern.faces]
        ax.add_collection3d(Poly3DCollection(polys, facecolor="#f2c14e", edgecolor="k", lw=0.3))
        c = fit.curve.polyline(200)
        ax.plot(c[:, 0], np.zeros(len(c)), c[:, 1], color="#1f77b4")
        lo, hi = X.min(axis=0), X.max(axis=0)
        ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]), title=title)
        ax.set_box_aspect(hi - lo)
    fig.savefig(png, dpi=100)
    plt.close(fig)


def main(out_dir: str | Path = "docs", render: bool = True) -> dict:
    """Fit, render to ``out_dir/fit_curves.png`` and return (and store) the numbers."""
    out = Path(out_dir)
    fits = fit_three()
    strips = []
    for title, fit in fits:
        row = {"title": title, "m": fit.m, "offset": fit.offset, **fit.errors}
        strips.append(row)
        print(
            f"{title:32s} m={fit.m:3d} offset={fit.offset:.3f} m "
            f"closest max={fit.closest.max:.4f} m mean={fit.closest.mean:.4f} m "
            f"warp max={fit.warp.max():.3%}"
        )
    backend, png = None, None
    if render:
        out.mkdir(parents=True, exist_ok=True)
        png = out / "fit_curves.png"
        try:
            _render_pyvista(fits, png)
            backend = "pyvista"
        except Exception as exc:  # noqa: BLE001 - any rendering failure: fall back
            print(f"pyvista could not render ({exc}); using matplotlib")
            _render_matplotlib(fits, png)
            backend = "matplotlib"
        print(f"wrote {png} ({backend})")
    RESULT.clear()
    RESULT.update(backend=backend, png=None if png is None else str(png), strips=strips)
    return RESULT


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs")
