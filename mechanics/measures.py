"""Where a deformed bar-and-hinge model stores its energy: per panel and per crease.

:func:`model_energy` splits the elastic energy of a :class:`~holofold.mechanics.structure.Structure`
at a displacement ``U`` (and rest angles) over the pattern's panels and creases, and gives the
largest strains of each panel::

    panel_energy   (nf,) J   the panel's bars (a bar on an edge shared by two panels split in
                             half) and its bending springs
    panel_strain   (nf,) -   largest |Green-Lagrange strain| of the panel's bars
    triangle_strain (nf,) -  largest |principal Green-Lagrange strain| of its triangles
    panel_bend     (nf,) rad largest turn of the panel's bending springs from their rest angle
    crease_energy  (ne,) J   per pattern edge: its hinge (concentrated) or its strip's bars and
                             springs (compliant); 0 for edges that are not creases

Bars and springs are assigned through the model's triangles (``tri_panel``, ``tri_crease``):
a bar belongs to the panels or creases whose triangles have it as a side, a panel spring to
the panel of its hinge bar, a crease spring to ``spring_crease``. A rigid-folding pattern keeps
almost all of its energy in the creases; panels that carry a large share bend or stretch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.mechanics.bars import bar_strain
from holofold.mechanics.structure import SpringRole, Structure

__all__ = ["ModelEnergy", "model_energy", "triangle_strain"]


@dataclass(frozen=True)
class ModelEnergy:
    """Energy of a deformed model by panel and by crease (see the module docstring).

    Attributes
    ----------
    panel_energy : (nf,) float
        J.
    panel_strain : (nf,) float
        Largest |strain| of each panel's bars (dimensionless).
    panel_bend : (nf,) float
        Largest turn of each panel's bending springs away from their rest angle, rad: how far
        the panel is from flat (0 for a rigid panel, whatever the stiffness).
    crease_energy : (ne,) float
        J, per pattern edge (0 where the edge is not a crease).
    triangle_strain : (nf,) float
        Largest |principal Green-Lagrange strain| of each panel's triangles: the in-plane
        strain the three bars of a triangle prescribe (:func:`triangle_strain`). At least the
        largest bar strain, and far larger in a thin triangle squeezed or opened across (a 0.4
        mm high sliver at a third of its height under 0.9 % bar strains: 0.45): what the mesh,
        not the sheet, does there.
    total : float
        Energy of the whole model, J (the sum of the two splits up to bars of no panel or
        crease, which the builders do not make).
    """

    panel_energy: np.ndarray
    panel_strain: np.ndarray
    crease_energy: np.ndarray
    total: float
    panel_bend: np.ndarray | None = None
    triangle_strain: np.ndarray | None = None

    @property
    def panel_share(self) -> float:
        """Fraction of the total energy stored in the panels (0 when there is no energy)."""
        return float(self.panel_energy.sum() / self.total) if self.total > 0 else 0.0


def _bar_owners(structure: Structure):
    """For each triangle side that is a bar: (bar id, panel or -1, crease or -1)."""
    tri = structure.triangles
    nn = structure.n_nodes
    sides = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    owner_p = np.tile(structure.tri_panel, 3)
    owner_c = np.tile(structure.tri_crease, 3)
    keys = np.minimum(sides[:, 0], sides[:, 1]).astype(np.int64) * nn + sides.max(axis=1)
    b = structure.bars
    bkeys = np.minimum(b[:, 0], b[:, 1]).astype(np.int64) * nn + b.max(axis=1)
    order = np.argsort(bkeys)
    pos = np.minimum(np.searchsorted(bkeys[order], keys), len(order) - 1)
    bar = order[pos]
    hit = bkeys[bar] == keys
    return bar[hit], owner_p[hit], owner_c[hit]


def triangle_strain(X, U, triangles) -> np.ndarray:
    """(nt,) largest |principal Green-Lagrange strain| of each triangle (``X`` reference and
    ``U`` displacement (nn, 3) m, ``triangles`` (nt, 3) node ids): the strain of the linear
    map taking the reference triangle to the deformed one, ``E = (F^T F - I) / 2`` in the
    reference triangle's plane; 0 for a degenerate reference triangle."""
    X = np.asarray(X, float)
    x = X + np.asarray(U, float).reshape(X.shape)
    t = np.asarray(triangles, np.intp)
    e1, e2 = X[t[:, 1]] - X[t[:, 0]], X[t[:, 2]] - X[t[:, 0]]
    d1, d2 = x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]
    # reference edges in the triangle's own plane: D = [[a, b], [0, c]] (columns e1, e2)
    a = np.linalg.norm(e1, axis=1)
    b = np.einsum("ij,ij->i", e1, e2) / np.where(a > 0, a, 1.0)
    c = np.linalg.norm(np.cross(e1, e2), axis=1) / np.where(a > 0, a, 1.0)
    ok = (a > 0) & (c > 0)
    a, c = np.where(ok, a, 1.0), np.where(ok, c, 1.0)
    g11, g12, g22 = (d1 * d1).sum(1), (d1 * d2).sum(1), (d2 * d2).sum(1)
    # C = D^-T g D^-1 with D^-1 = [[1/a, -b/(a c)], [0, 1/c]]
    p, q = 1.0 / a, -b / (a * c)
    r = 1.0 / c
    c11 = p * p * g11
    c12 = p * (q * g11 + r * g12)
    c22 = q * q * g11 + 2.0 * q * r * g12 + r * r * g22
    e11, e12, e22 = 0.5 * (c11 - 1.0), 0.5 * c12, 0.5 * (c22 - 1.0)
    mean, rad = 0.5 * (e11 + e22), np.hypot(0.5 * (e11 - e22), e12)
    return np.where(ok, np.maximum(np.abs(mean + rad), np.abs(mean - rad)), 0.0)


def model_energy(
    structure: Structure, U, spring_rest=None, *, n_edges: int | None = None
) -> ModelEnergy:
    """Energy by panel and crease, and the largest strains per panel, at displacement ``U``.

    Parameters
    ----------
    structure : Structure
        Built by :func:`~holofold.mechanics.hinges.build_concentrated` or
        :func:`~holofold.mechanics.hinges.build_compliant` (it needs ``tri_panel`` and
        ``tri_crease``).
    U : (nn, 3) float
        Displacement, m.
    spring_rest : (ns,) float, optional
        Rest angles (default ``structure.spring_rest``), rad.
    n_edges : int, optional
        Number of pattern edges (length of ``crease_energy``; default: the largest crease id
        + 1).
    """
    from holofold.mechanics.assembly import Assembler

    U = np.asarray(U, float).reshape(-1, 3)
    bar_resp, spring_resp = Assembler(structure).element_response(U, spring_rest, tangent=False)
    eb = np.asarray(bar_resp.energy, float).reshape(-1)
    es = np.asarray(spring_resp.energy, float).reshape(-1)
    nf = len(structure.panel_centres) if structure.panel_centres is not None else 0
    nf = max(nf, int(structure.tri_panel.max(initial=-1)) + 1)
    if n_edges is None:
        top = max(structure.spring_crease.max(initial=-1), structure.tri_crease.max(initial=-1))
        n_edges = int(top) + 1
    strain = np.abs(bar_strain(structure.nodes, U, structure.bars, structure.bar_length))

    bar, pan, cre = _bar_owners(structure)
    # a bar shared by k owners gives each 1/k of its energy
    _, inv, counts = np.unique(bar, return_inverse=True, return_counts=True)
    share = eb[bar] / counts[inv]
    panel_energy = np.zeros(nf)
    crease_energy = np.zeros(n_edges)
    on_p, on_c = pan >= 0, (pan < 0) & (cre >= 0)
    np.add.at(panel_energy, pan[on_p], share[on_p])
    np.add.at(crease_energy, cre[on_c], share[on_c])
    panel_strain = np.zeros(nf)
    np.maximum.at(panel_strain, pan[on_p], strain[bar[on_p]])
    tri_strain = panel_strain.copy()
    on_t = structure.tri_panel >= 0
    if on_t.any():
        ts = triangle_strain(structure.nodes, U, structure.triangles[on_t])
        np.maximum.at(tri_strain, structure.tri_panel[on_t], ts)

    # springs: panel springs to the panel of their hinge bar, crease springs to their crease
    role = structure.spring_role
    is_panel = role == SpringRole.PANEL
    if is_panel.any():
        hinge = structure.springs[is_panel][:, 1:3]
        nn = structure.n_nodes
        hk = hinge.min(axis=1).astype(np.int64) * nn + hinge.max(axis=1)
        tri = structure.triangles
        sides = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        sk = sides.min(axis=1).astype(np.int64) * nn + sides.max(axis=1)
        sp_owner = np.tile(structure.tri_panel, 3)
        keep = sp_owner >= 0
        sk, sp_owner = sk[keep], sp_owner[keep]
        order = np.argsort(sk, kind="stable")
        pos = np.minimum(np.searchsorted(sk[order], hk), len(order) - 1)
        owner = np.where(sk[order][pos] == hk, sp_owner[order][pos], -1)
        ok = owner >= 0
        np.add.at(panel_energy, owner[ok], es[is_panel][ok])
        from holofold.mechanics.springs import dihedral_angle

        rest = structure.spring_rest if spring_rest is None else np.asarray(spring_rest, float)
        theta = dihedral_angle(structure.nodes + U, structure.springs[is_panel])
        turn = np.abs(np.angle(np.exp(1j * (theta - rest[is_panel]))))  # wrapped to [0, pi]
        panel_bend = np.zeros(nf)
        np.maximum.at(panel_bend, owner[ok], turn[ok])
    else:
        panel_bend = np.zeros(nf)
    crease_spring = ~is_panel & (structure.spring_crease >= 0)
    np.add.at(crease_energy, structure.spring_crease[crease_spring], es[crease_spring])
    return ModelEnergy(
        panel_energy=panel_energy,
        panel_strain=panel_strain,
        crease_energy=crease_energy,
        total=float(eb.sum() + es.sum()),
        panel_bend=panel_bend,
        triangle_strain=tri_strain,
    )
