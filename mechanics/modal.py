"""Lumped mass and natural frequencies (docs/electro-thermal.md §6; docs/scenarios.md §4.3).

The eigenproblem is ``K phi = lambda M phi`` on the free DOFs, with ``K`` the tangent stiffness
at the current state and ``M`` the diagonal lumped mass. ``lambda = omega^2``: the returned
:func:`natural_frequencies` are **angular frequencies omega = sqrt(lambda) in rad/s** (the
published gripper ``freqFinal`` is this number; divide by 2 pi for Hz).

Massless free DOFs (crease nodes whose triangles got no mass under the data-era quirk) carry
infinite eigenvalues and are left out. See :func:`eigenvalues` for how the low eigenvalues are
kept accurate despite the huge stiffness contrast of bar-and-hinge models.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from holofold.mechanics.threads import single_threaded

__all__ = ["lumped_mass", "natural_frequencies", "eigenvalues"]


def lumped_mass(
    structure,
    density,
    *,
    centre_share: float = 1.0 / 3.0,
    skip_first: int = 0,
) -> np.ndarray:
    """Nodal masses (nn,), kg, lumped from the structure's triangles.

    Parameters
    ----------
    structure : Structure
        Uses ``triangles``, ``tri_thickness``, ``tri_panel`` and reference ``nodes``; panel
        centre nodes are ``structure.panel_centres`` (else the first vertex of each panel
        triangle); a panel without one (-1, a bare triangle) gives a third to each corner.
    density : float or (nt,) float
        Mass density rho, kg/m^3 (per triangle if an array).
    centre_share : float
        Share of a panel triangle's mass given to its panel-centre vertex; the other two get
        ``(1 - centre_share)/2`` each. Crease triangles always split 1/3 each. 1/3 is the
        data-era reference; later SWOMPS versions use 4/6 (docs/electro-thermal.md §6.1).
    skip_first : int
        Number of leading triangles that get no mass (data-era quirk: the number of pattern
        panels, docs/scenarios.md §4.3).
    """
    tri = structure.triangles
    nt = len(tri)
    if not 0 <= int(skip_first) <= nt:
        raise ValueError(f"skip_first = {skip_first!r} is outside the allowed range [0, {nt}]")
    if not 0.0 <= centre_share <= 1.0:
        raise ValueError(f"centre_share = {centre_share!r} is outside the allowed range [0, 1]")
    rho = np.broadcast_to(np.asarray(density, float), (nt,))
    if (rho < 0).any():
        raise ValueError("density must be >= 0")
    X = structure.nodes
    a, b, c = X[tri[:, 0]], X[tri[:, 1]], X[tri[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    m = area * rho * structure.tri_thickness
    m[: int(skip_first)] = 0.0
    share = np.full((nt, 3), 1.0 / 3.0)
    panel = structure.tri_panel >= 0
    if panel.any() and centre_share != 1.0 / 3.0:
        centres = structure.panel_centres
        if centres is not None:
            cnode = np.asarray(centres)[structure.tri_panel[panel]]
            is_c = tri[panel] == cnode[:, None]  # none for a triangle panel without a centre
        else:
            is_c = np.zeros((panel.sum(), 3), bool)
            is_c[:, 0] = True
        share[panel] = np.where(is_c, centre_share, 0.5 * (1.0 - centre_share))
        if centres is not None:  # a panel that is one triangle: a third to each corner
            share[np.flatnonzero(panel)[cnode < 0]] = 1.0 / 3.0
    out = np.zeros(structure.n_nodes)
    np.add.at(out, tri.ravel(), (m[:, None] * share).ravel())
    return out


@single_threaded
def eigenvalues(K, mass_dof: np.ndarray, free_dofs: np.ndarray | None = None) -> np.ndarray:
    """Finite eigenvalues lambda of ``K phi = lambda M phi`` on the free DOFs, ascending.

    Parameters
    ----------
    K : (ndof, ndof) array or sparse matrix
        Symmetric tangent stiffness, N/m.
    mass_dof : (ndof,) float
        Diagonal of M per DOF, kg.
    free_dofs : (nf,) int, optional
        DOFs kept (default: all).

    Returns
    -------
    (nm,) float
        lambda = omega^2, (rad/s)^2, one per free DOF with mass (massless DOFs have infinite
        eigenvalues and are left out).

    Notes
    -----
    Bar-and-hinge stiffness matrices mix stiff bars with soft hinges (condition numbers of
    1e12 and more), so a direct dense solve of the pencil loses the low eigenvalues to
    round-off (relative errors ~1e-5). When K is non-singular the eigenvalues are instead
    taken from the symmetric matrix ``B = M^1/2 K^-1 M^1/2`` (``lambda = 1/mu``), whose
    largest eigenvalues -- the lowest frequencies -- are accurate to ~1e-12 relative. A
    singular K (a mechanism) falls back to the direct form with massless DOFs condensed out.
    """
    K = K.toarray() if sp.issparse(K) else np.array(K, float)
    m = np.asarray(mass_dof, float)
    if free_dofs is not None:
        f = np.asarray(free_dofs)
        K = K[np.ix_(f, f)]
        m = m[f]
    if K.shape != (len(m), len(m)):
        raise ValueError(f"K must be ({len(m)}, {len(m)}) on the kept DOFs, got {K.shape}")
    if (m < 0).any():
        raise ValueError("masses must be >= 0")
    K = 0.5 * (K + K.T)
    has = m > 0
    nm = int(has.sum())
    if nm == 0:
        return np.zeros(0)
    s = np.sqrt(m)
    mu = _inverse_form(K, s, nm)
    if mu is not None:
        return np.sort(1.0 / mu)
    if not has.all():  # direct form: condense massless DOFs out
        i, o = np.flatnonzero(has), np.flatnonzero(~has)
        Koi = K[np.ix_(o, i)]
        K = K[np.ix_(i, i)] - Koi.T @ sla.lstsq(K[np.ix_(o, o)], Koi)[0]
        s = s[i]
    A = K / s[:, None] / s[None, :]
    return sla.eigvalsh(0.5 * (A + A.T))


def _inverse_form(K: np.ndarray, s: np.ndarray, nm: int) -> np.ndarray | None:
    """The ``nm`` largest-magnitude eigenvalues mu of ``B = S K^-1 S`` (S = diag(s)), or None
    when K is singular (a mechanism) or the result is not finite and nonzero."""
    try:
        X = sla.cho_solve(sla.cho_factor(K, check_finite=False), np.diag(s))
    except sla.LinAlgError:  # not positive definite: a symmetric indefinite solve
        try:
            X = sla.solve(K, np.diag(s), assume_a="sym")
        except sla.LinAlgError:  # singular
            return None
    if not np.isfinite(X).all():
        return None
    B = s[:, None] * X
    mu = sla.eigvalsh(0.5 * (B + B.T))
    mu = mu[np.argsort(-np.abs(mu))][:nm]
    return mu if (np.isfinite(mu).all() and (np.abs(mu) > 0).all()) else None


@single_threaded
def natural_frequencies(
    K, mass_dof: np.ndarray, free_dofs: np.ndarray | None = None, n: int | None = None
) -> np.ndarray:
    """Angular natural frequencies omega = sqrt(|lambda|), rad/s, sorted by |lambda|.

    ``n`` limits the output to the lowest ``n`` modes. Near-zero or slightly negative
    eigenvalues (mechanisms, prestress) give sqrt(|lambda|), as the reference examples do.
    """
    lam = eigenvalues(K, mass_dof, free_dofs)
    w = np.sqrt(np.sort(np.abs(lam)))
    return w if n is None else w[:n]
