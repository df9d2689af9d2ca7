"""Heat two electro-thermal origami grippers until they close and draw how they close.

    python examples/gripper_closing.py [output.png]     # default: docs/gripper.png

Simulates one two-panel gripper (pattern 3) and one splitted-Miura gripper (pattern 2) of the
paper's scenario 3 (``design.scenarios.gripper``, repeatable ``converged=True`` solves): every
heating step adds power to the bimorph creases, the creases curl and fold the two arms up until
their tips are closer than 1 mm. Writes one PNG (matplotlib, 1400 x 900 px) with, per gripper,
the closed shape coloured by temperature over the faint flat outline, and the tip distance and
highest temperature per heating step. Prints one line per gripper; ``RESULT`` holds the numbers
of the last run. Each simulation takes about 0.5-1 s.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import colors, ticker  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from holofold.design.scenarios.gripper import (  # noqa: E402
    CLOSURE,
    ROOM_T,
    GripperOptions,
    gripper_model,
    simulate,
)

DEFAULT = Path(__file__).resolve().parents[1] / "docs" / "gripper.png"
SIZE_IN, DPI = (14, 9), 100  # 1400 x 900 px

#: two designs inside the paper's sampling ranges (SI units; after the first sample rows)
DESIGNS = {
    3: dict(
        name="two-panel",
        Pattern=3, L1=4.1e-3, L2=3.1e-3, t1=0.22e-6, t2=0.97e-6, tpanel=28e-6, rate=0.49, W=150e-6,
    ),
    2: dict(
        name="splitted Miura",
        Pattern=2, L1=6.3e-3, L2=2.7e-3, t1=0.24e-6, t2=0.69e-6, tpanel=26e-6, rate=0.22, W=240e-6,
    ),
}  # fmt: skip

#: filled by :func:`main`: {pattern: {"name", "design", "closing_step", "finalQ", "Tmax",
#: "stiff", "seconds", "png", "result" (GripperResult), "tips" (2,) node ids}}
RESULT: dict = {}


def _design(pattern: int) -> dict:
    return {k: v for k, v in DESIGNS[pattern].items() if k != "name"}


def run(pattern: int):
    """Simulate one of :data:`DESIGNS` with history; returns (GripperResult, seconds)."""
    t0 = time.perf_counter()
    res = simulate(_design(pattern), GripperOptions(converged=True, keep_history=True))
    return res, time.perf_counter() - t0


def _outline(flat: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Outer boundary (k + 1, 3) of the flat sheet (z = 0), closed: the largest loop of the mesh
    edges that belong to one triangle only (the small gaps where creases meet are loops too)."""
    pairs = np.sort(triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    edges, count = np.unique(pairs, axis=0, return_counts=True)
    nbr: dict[int, list[int]] = {}
    for a, b in edges[count == 1].tolist():
        nbr.setdefault(a, []).append(b)
        nbr.setdefault(b, []).append(a)
    if any(len(v) != 2 for v in nbr.values()):
        raise ValueError("the sheet's boundary edges do not form simple loops")
    loops, seen = [], set()
    for start in nbr:
        if start in seen:
            continue
        loop, prev, node = [start], start, nbr[start][0]
        while node != start:
            loop.append(node)
            a, b = nbr[node]
            prev, node = node, (b if a == prev else a)
        seen.update(loop)
        loops.append(np.array(loop))

    def area(loop):
        x, y = flat[loop, 0], flat[loop, 1]
        return abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2

    outer = max(loops, key=area)
    xy = flat[np.append(outer, outer[0]), :2]
    return np.column_stack([xy, np.zeros(len(xy))])


def _title(pattern: int, res) -> str:
    return (
        f"Pattern {pattern}, {DESIGNS[pattern]['name']} gripper: closes at heating step "
        f"{res.closing_step}   |   finalQ = {res.finalQ:.3f} W,  stiff = {res.stiff:.2e} N/m,  "
        f"Tmax = {res.Tmax:.0f} °C"
    )


def _draw_shape(fig, ax, cax, pattern: int, res, tips) -> None:
    """Closed shape (mm) coloured by temperature, flat outline faint, ``tips`` (2,) marked."""
    flat = res.nodes * 1e3
    x = (res.nodes + res.displacement) * 1e3
    tri = res.triangles
    norm = colors.Normalize(ROOM_T, res.Tmax)
    cmap = plt.get_cmap("plasma")
    face_t = res.temperature[tri].mean(axis=1)
    ax.add_collection3d(
        Poly3DCollection(
            x[tri],
            facecolors=cmap(norm(face_t)),
            edgecolors="#333333",
            linewidths=0.25,
        )
    )
    ax.add_collection3d(
        Poly3DCollection(flat[tri], facecolors="#9e9e9e", edgecolors="none", alpha=0.12)
    )
    ax.plot(*_outline(flat, tri).T, color="#6e6e6e", lw=1.0, alpha=0.8)
    ax.plot(*x[tips].T, color="#1f77b4", lw=1.5, marker="o", ms=4, zorder=10)
    lo = np.minimum(flat.min(axis=0), x.min(axis=0))
    hi = np.maximum(flat.max(axis=0), x.max(axis=0))
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]))
    ax.set_box_aspect(hi - lo, zoom=1.1)  # equal scaling
    ax.set_xlabel("x (mm)", labelpad=2)
    ax.set_ylabel("y (mm)", labelpad=6)
    ax.set_zlabel("z (mm)", labelpad=2)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(ticker.MaxNLocator(4, steps=[1, 2, 5, 10]))
    ax.tick_params(labelsize=8, pad=0)
    ax.view_init(elev=20, azim=-28)
    ax.text2D(
        0.5, 0.93, "closed shape (flat sheet in grey, arm tips in blue)",
        transform=ax.transAxes, ha="center", fontsize=10,
    )  # fmt: skip
    cb = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), cax=cax)
    cb.set_label("temperature (°C)")


def _draw_history(ax, res) -> None:
    """Tip distance (mm) and Tmax (°C) against the heating step."""
    steps = np.arange(1, len(res.tip_distance) + 1)
    dist = res.tip_distance * 1e3
    (l1,) = ax.plot(steps, dist, color="#1f77b4", lw=2, label="tip distance")
    l2 = ax.axhline(CLOSURE * 1e3, color="#1f77b4", ls="--", lw=1, label="1 mm closure threshold")
    l4 = ax.axvline(
        res.closing_step, color="k", ls=":", lw=1.2, label=f"closing step {res.closing_step}"
    )
    ax.plot(res.closing_step, dist[-1], "o", color="#1f77b4", ms=6)
    ax.set_xlabel("heating step")
    ax.set_ylabel("tip distance (mm)", color="#1f77b4")
    ax.set_ylim(0, dist.max() * 1.05)
    ax.set_xlim(0, steps[-1] * 1.03)
    ax.grid(alpha=0.3)
    tw = ax.twinx()
    (l3,) = tw.plot(steps, res.Tmax_history, color="#d62728", lw=2, label="Tmax")
    tw.set_ylabel("Tmax (°C)", color="#d62728")
    tw.set_ylim(ROOM_T - 5, res.Tmax * 1.08)
    ax.legend(handles=[l1, l2, l3, l4], loc="center left", fontsize=9, framealpha=0.9)
    ax.set_title("heating history", fontsize=10)


def draw(results: dict, png: Path) -> None:
    """One figure: a row per gripper (``results``: {pattern: (GripperResult, tips)})."""
    fig = plt.figure(figsize=SIZE_IN, dpi=DPI)
    subfigs = fig.subfigures(len(results), 1, hspace=0.02)
    for sub, (pattern, (res, tips)) in zip(np.atleast_1d(subfigs), results.items(), strict=True):
        sub.suptitle(_title(pattern, res), fontsize=12, fontweight="bold")
        ax3 = sub.add_axes((-0.05, -0.06, 0.6, 1.04), projection="3d")
        cax = sub.add_axes((0.53, 0.16, 0.012, 0.66))
        _draw_shape(sub, ax3, cax, pattern, res, tips)
        _draw_history(sub.add_axes((0.645, 0.14, 0.3, 0.72)), res)
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=DPI)
    plt.close(fig)


def main(png: str | Path = DEFAULT) -> dict:
    """Simulate both grippers, write ``png`` and return (and store) the numbers."""
    png = Path(png)
    results = {}
    RESULT.clear()
    for pattern in DESIGNS:
        res, sec = run(pattern)
        if res.closing_step is None:
            raise RuntimeError(f"pattern {pattern} did not close: {res.status}")
        tips = gripper_model(_design(pattern)).nodes.tips  # the closure pair, by name
        results[pattern] = res, tips
        RESULT[pattern] = dict(
            name=DESIGNS[pattern]["name"],
            design=_design(pattern),
            closing_step=res.closing_step,
            finalQ=res.finalQ,
            Tmax=res.Tmax,
            stiff=res.stiff,
            seconds=sec,
            png=png,
            result=res,
            tips=tips,
        )
        print(
            f"pattern {pattern} ({DESIGNS[pattern]['name']}): closed at heating step "
            f"{res.closing_step}, finalQ = {res.finalQ:.4f} W, Tmax = {res.Tmax:.1f} °C, "
            f"stiff = {res.stiff:.3e} N/m ({sec:.1f} s)"
        )
    draw(results, png)
    print(f"wrote {png}")
    return RESULT


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else DEFAULT)
