"""Bar element: St Venant-Kirchhoff material, Green-Lagrange strain (docs/bar-and-hinge.md §2.1).

For a bar a-b with reference vector ``D0 = X_b - X_a``, rest length ``L0`` and displacement
difference ``d = u_b - u_a`` (current vector ``x = D0 + d``)::

    strain    eps = (D0 . d + d . d / 2) / L0^2        (= (|x|^2 - L0^2) / (2 L0^2) if |D0| = L0)
    stress    S   = E eps                              (second Piola-Kirchhoff)
    energy    W   = E A L0 eps^2 / 2
    force     f   = (S A / L0) [-x; x]                 on [u_a; u_b]
    tangent   K   = (E A / L0^3) [[xx', -xx'], [-xx', xx']] + (S A / L0) [[I, -I], [-I, I]]

The strain is evaluated from ``D0`` and ``d`` (the reference simulator's form), which avoids the
cancellation of ``|x|^2 - L0^2`` at small strain. All functions accept an optional leading sample
axis: ``X`` and ``U`` may be ``(..., nn, 3)`` and the outputs then gain the same leading axes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["ElementResponse", "bar_strain", "bar_forces", "bar_kernel"]

_BLOCK = np.array([[1.0, -1.0], [-1.0, 1.0]])[:, :, None]
_EYE = np.eye(3)[:, :, None]


class ElementResponse(NamedTuple):
    """Element-level output of a kernel (unpacks as ``energy, force, tangent``).

    energy   energy of each element, J
    force    internal force on the element DOFs, N
    tangent  tangent stiffness, N/m (None if not requested)

    Shapes depend on the function that returns it (see its docstring).
    """

    energy: np.ndarray
    force: np.ndarray
    tangent: np.ndarray | None


def _bar_vectors(X, U, bars):
    D0 = X[..., bars[:, 1], :] - X[..., bars[:, 0], :]
    d = U[..., bars[:, 1], :] - U[..., bars[:, 0], :]
    return D0, d


def bar_strain(X, U, bars, L0) -> np.ndarray:
    """Green-Lagrange strain of every bar.

    Parameters
    ----------
    X : (..., nn, 3) float
        Reference nodal coordinates, m.
    U : (..., nn, 3) float
        Nodal displacements, m.
    bars : (nb, 2) int
        Node pairs.
    L0 : (nb,) float
        Rest lengths, m.

    Returns
    -------
    (..., nb) float
    """
    D0, d = _bar_vectors(np.asarray(X, float), np.asarray(U, float), bars)
    return ((D0 * d).sum(-1) + 0.5 * (d * d).sum(-1)) / (L0 * L0)


def bar_forces(X, U, bars, L0, EA, *, tangent: bool = True) -> ElementResponse:
    """Energy, internal force and tangent stiffness of every bar.

    Parameters
    ----------
    X : (..., nn, 3) float
        Reference nodal coordinates, m.
    U : (..., nn, 3) float
        Nodal displacements, m.
    bars : (nb, 2) int
        Node pairs (a, b); local DOF order is (a_x, a_y, a_z, b_x, b_y, b_z).
    L0 : (nb,) float
        Rest lengths, m.
    EA : (nb,) float
        Axial rigidity E * A, N.
    tangent : bool
        Also compute the (material + geometric) tangent.

    Returns
    -------
    ElementResponse
        energy (..., nb) J, force (..., nb, 6) N, tangent (..., nb, 6, 6) N/m or None.
    """
    X = np.asarray(X, float)
    U = np.asarray(U, float)
    D0, d = _bar_vectors(X, U, bars)
    res = bar_kernel(np.swapaxes(D0, -1, -2), np.swapaxes(d, -1, -2), L0, EA, tangent=tangent)
    force = np.swapaxes(res.force, -1, -3).reshape(*res.energy.shape, 6)
    K = None
    if res.tangent is not None:
        # (..., i, j, a, b, e) -> (..., e, a, i, b, j)
        K = np.moveaxis(res.tangent, (-5, -4, -3, -2, -1), (-3, -1, -4, -2, -5))
        K = K.reshape(*res.energy.shape, 6, 6)
    return ElementResponse(res.energy, force, K)


def bar_kernel(D0, d, L0, EA, *, tangent: bool = True) -> ElementResponse:
    """Bar kernel on component-major arrays (the layout the assembly scatters).

    Parameters
    ----------
    D0, d : (..., 3, nb) float
        Reference bar vectors ``X_b - X_a`` and displacement differences ``u_b - u_a``, m.
    L0, EA : (nb,) float

    Returns
    -------
    ElementResponse
        energy (..., nb); force (..., 3, 2, nb) indexed [component, node a/b, bar];
        tangent (..., 3, 3, 2, 2, nb) indexed [i, j, node a, node b, bar] or None.
    """
    inv_L2 = 1.0 / (L0 * L0)
    x = D0 + d
    eps = ((D0 * d).sum(-2) + 0.5 * (d * d).sum(-2)) * inv_L2
    SA = EA * eps  # S * A, N
    energy = 0.5 * EA * L0 * eps * eps
    fb = (SA / L0)[..., None, :] * x
    force = np.stack([-fb, fb], axis=-2)
    if not tangent:
        return ElementResponse(energy, force, None)
    # 3x3 block k3 = EA/L0^3 x x' + S A / L0 I; block [a, b] = sign(a, b) k3
    k3 = (EA * inv_L2 / L0) * (x[..., :, None, :] * x[..., None, :, :])
    k3 += (SA / L0)[..., None, None, :] * _EYE
    K = k3[..., :, :, None, None, :] * _BLOCK
    return ElementResponse(energy, force, K)
