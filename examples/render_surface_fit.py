"""Pictures of surface fits: the README's (target, folded pattern, flat pattern) and the
docs' gallery of targets (docs/surface-fit.md).

    python examples/render_surface_fit.py            # docs/surface-fit.png, surface-fit-targets.png

Each fit is also folded from flat by the bar-and-hinge simulator (holofold.mechanics.check_fold)
and the figure says how close the simulated fold came.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

import holofold as hf  # noqa: E402
from holofold.fitting import Placement  # noqa: E402

DOCS = Path(__file__).resolve().parent.parent / "docs"


def _shade(coords, quads, base):
    """Face colours: ``base`` lit by the quads' normals (a fixed light)."""
    p = coords[quads]
    n = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    light = np.array([0.3, -0.5, 0.8])
    light /= np.linalg.norm(light)
    k = 0.35 + 0.65 * np.abs(n @ light)
    return np.clip(np.asarray(base)[None, :3] * k[:, None], 0, 1)


def draw_folded(ax, fit, title, target=True):
    q = fit.grid.quads
    X = fit.coords
    if target:
        m = fit.target.mesh
        ax.plot_trisurf(*m.vertices.T, triangles=m.faces, color=(0.55, 0.75, 0.95), alpha=0.25,
                        linewidth=0)  # fmt: skip
    poly = Poly3DCollection(X[q], facecolors=_shade(X, q, (0.95, 0.8, 0.55)),
                            edgecolors=(0.25, 0.2, 0.15), linewidths=0.15)  # fmt: skip
    ax.add_collection3d(poly)
    lo, hi = X.min(axis=0), X.max(axis=0)
    c, r = 0.5 * (lo + hi), 0.55 * (hi - lo).max()
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=28, azim=-60)
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)


def draw_flat(ax, fit, title):
    p = fit.pattern
    colours = {"M": "#d62728", "V": "#1f4fd6", "B": "#000000"}
    for code, col in colours.items():
        e = p.edges[p.assignment == code]
        seg = p.flat[e]
        ax.plot(seg[:, :, 0].T, seg[:, :, 1].T, color=col, lw=0.6 if code != "B" else 0.9)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)


def readme_figure(path: Path) -> None:
    dome = hf.builtin_surface("sphere-cap", radius=1.0, rim=0.45)
    fit = hf.fit_surface(dome, (16, 16), placement=Placement(size=(0.73, 0.78)))
    fc = hf.check_fold(fit)
    fig = plt.figure(figsize=(12, 4.2))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    m = dome.mesh
    ax.plot_trisurf(*m.vertices.T, triangles=m.faces, color=(0.55, 0.75, 0.95), linewidth=0)
    ax.set_box_aspect((1, 1, 0.35))
    ax.view_init(elev=28, azim=-60)
    ax.set_axis_off()
    ax.set_title("target: spherical cap, R = 1 m", fontsize=9)
    ax = fig.add_subplot(1, 3, 2, projection="3d")
    draw_folded(ax, fit, f"fitted 16 x 16 generalised Miura-ori, RMS {fit.rms:.1e} m;\n"
                f"folded from flat by simulation to {fc.deviation_max:.0e} m of it")  # fmt: skip
    ax = fig.add_subplot(1, 3, 3)
    w, h = fit.flat_size
    draw_flat(ax, fit, f"flat crease pattern {w:.2f} x {h:.2f} m (mountain red, valley blue)")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(path, fit, fc.reached)


def gallery(path: Path) -> None:
    cases = [
        ("sphere cap R = 1 (K > 0)", hf.builtin_surface("sphere-cap", radius=1.0, rim=0.45),
         (0.73, 0.78)),
        ("saddle R = 1 (K < 0)", hf.builtin_surface("saddle", radius=1.0, width=0.8, depth=0.8),
         (0.73, 0.73)),
        ("cylinder R = 1 (K = 0)", hf.builtin_surface("cylinder", radius=1.0, length=0.8,
                                                      angle=50), (0.8, 0.73)),
        ("wave a = 0.02, 0.8 m (K of both signs)", hf.builtin_surface(
            "wave", amplitude=0.02, wavelength=0.8, width=0.8, depth=0.8), (0.73, 0.73)),
    ]  # fmt: skip
    fig = plt.figure(figsize=(13, 6.6))
    for k, (name, target, size) in enumerate(cases):
        fit = hf.fit_surface(target, (16, 16), placement=Placement(size=size))
        ax = fig.add_subplot(2, 4, k + 1, projection="3d")
        status = f"RMS {fit.rms / target.size:.1e} of size" if fit.ok else "FAILED"
        draw_folded(ax, fit, f"{name}\n16 x 16: {status}")
        ax = fig.add_subplot(2, 4, k + 5)
        # distance of the fitted side, in the plan
        side = fit.coords[fit.side]
        sc = ax.scatter(side[:, 0], side[:, 1], c=fit.distance / target.size, cmap="coolwarm",
                        s=9, vmin=-np.abs(fit.distance).max() / target.size,
                        vmax=np.abs(fit.distance).max() / target.size)  # fmt: skip
        ax.set_aspect("equal")
        ax.set_axis_off()
        fig.colorbar(sc, ax=ax, shrink=0.7, label="signed distance / size")
        print(name, fit)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else DOCS
    readme_figure(out / "surface-fit.png")
    gallery(out / "surface-fit-targets.png")
    print(f"gamma default {math.degrees(math.radians(60)):.0f} deg")
