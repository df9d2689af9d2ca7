"""The concentrated model's J joins against plate theory on flat triangulated rectangles
(docs/curved-creases.md "Convergence": where the energy is).

* ``bend``: a strip 100 x 30 mm held at one end (two rungs) and bent by a couple at the other
  (E 1.5 GPa, nu 0.42, t 1 mm); its curvature over the constant-moment length (a parabola
  fitted to the mean deflection of every rung) over the plate's ``M / (D b)``;
* ``twist``: a square (or 2:1) plate 50 mm held at three corners and loaded at the fourth
  (the corner-force twist, E 2 GPa, nu 0.3, t 0.2 mm): the corner deflection over the plate's
  ``P a b / (2 D (1 - nu))``.

Both report the model's compliance over the plate's (1 is the plate). Every quad is split by a
diagonal alternating per column (``column``) or per quad (``chequer``, as the curved pleat's
mesh). Run::

    python validation/hinge_plate_checks.py
"""

from __future__ import annotations

import numpy as np

from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.hinges import build_concentrated


def rectangle(xs: np.ndarray, ny: int, width: float, split: str = "column"):
    """A flat triangulated rectangle: rungs at ``xs`` (m), ``ny`` quads across ``width`` (m),
    each quad split by a diagonal alternating per column or per quad (``split``); inner edges
    J, the outline B. Returns the pattern and the (nx + 1, ny + 1) vertex ids."""
    nx = len(xs) - 1
    x, y = np.meshgrid(xs, np.linspace(0.0, width, ny + 1), indexing="ij")
    xy = np.c_[x.ravel(), y.ravel()]
    vid = np.arange(len(xy)).reshape(nx + 1, ny + 1)
    faces = []
    for i in range(nx):
        for j in range(ny):
            a, b, c, d = vid[i, j], vid[i + 1, j], vid[i + 1, j + 1], vid[i, j + 1]
            even = (i if split == "column" else i + j) % 2 == 0
            faces += [[a, b, c], [a, c, d]] if even else [[a, b, d], [b, c, d]]
    sides: dict[tuple[int, int], int] = {}
    for f in faces:
        for k in range(3):
            key = (min(f[k], f[(k + 1) % 3]), max(f[k], f[(k + 1) % 3]))
            sides[key] = sides.get(key, 0) + 1
    edges = np.array(sorted(sides))
    asg = np.array(["J" if sides[tuple(e)] == 2 else "B" for e in edges.tolist()])
    p = CreasePattern(np.c_[xy, np.zeros(len(xy))], faces, edges, asg, np.zeros(len(edges)),
                      flat=xy)  # fmt: skip
    return p, vid


def _solve(p, t, E, nu, sup, load):
    """Linear displacement (n_nodes, 3) of the flat pattern under ``load`` (vertex -> force)."""
    s = build_concentrated(
        p, crease_width=1e-3, crease_thickness=t, panel_thickness=t, E_panel=E, E_crease=E,
        nu_panel=nu, supports=sup,
    )  # fmt: skip
    asm = Assembler(s)
    _, _, solve = asm.evaluate_factorized(np.zeros_like(s.nodes))
    f = np.zeros_like(s.nodes)
    for v, fz in load:
        f[v, 2] += fz
    u = np.zeros(s.nodes.size)
    u[asm.free_dofs] = solve(f.ravel()[asm.free_dofs])
    return u.reshape(-1, 3)


def bend(nx: int, ny: int, split: str = "column") -> float:
    """Compliance of the strip under a couple over the plate's (module docstring)."""
    E, nu, t, width, M = 1.5e9, 0.42, 1e-3, 0.03, 1e-3
    D = E * t**3 / (12 * (1 - nu**2))
    xs = np.linspace(0.0, 0.1, nx + 1)
    p, vid = rectangle(xs, ny, width, split)
    sup = np.zeros((p.n_vertices + p.n_faces, 3), bool)
    sup[vid[0]] = sup[vid[1]] = True
    fz = M / (xs[-1] - xs[-2]) / (ny + 1)  # a couple M: opposite forces on the last two rungs
    load = [(v, fz) for v in vid[-1]] + [(v, -fz) for v in vid[-2]]
    u = _solve(p, t, E, nu, sup, load)
    z = u[vid[1:nx], 2].mean(axis=1)
    kappa = 2.0 * np.polyfit(xs[1:nx], z, 2)[0]
    return float(kappa / (M / (D * width)))


def twist(n: int, aspect: float = 1.0, split: str = "column") -> float:
    """Compliance of the corner-loaded plate over the plate's (module docstring)."""
    E, nu, t, a, P = 2e9, 0.3, 0.2e-3, 0.05, 1e-3
    D = E * t**3 / (12 * (1 - nu**2))
    b = a * aspect
    p, vid = rectangle(np.linspace(0.0, a, n + 1), max(1, round(n * aspect)), b, split)
    sup = np.zeros((p.n_vertices + p.n_faces, 3), bool)
    sup[[vid[0, 0], vid[-1, 0], vid[0, -1]], 2] = True
    sup[vid[0, 0], :2] = sup[vid[-1, 0], 1] = True
    u = _solve(p, t, E, nu, sup, [(vid[-1, -1], P)])
    return float(u[vid[-1, -1], 2] / (P * a * b / (2 * D * (1 - nu))))


def main() -> None:
    for split in ("column", "chequer"):
        for nx, ny in ((16, 5), (32, 10), (32, 4), (64, 8)):
            print(f"bend {split} {nx}x{ny} (quads {100 / nx:.2f} x {30 / ny:.2f} mm): "
                  f"{bend(nx, ny, split):.3f}")  # fmt: skip
        for aspect in (1.0, 0.5):
            r = [round(twist(n, aspect, split), 3) for n in (4, 8, 16, 32)]
            print(f"twist {split} {aspect:g}:1, 4-32 quads: {r}")


if __name__ == "__main__":
    main()
