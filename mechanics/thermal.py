"""Electro-thermal actuation: steady heat conduction, bimorph curvature, thermal folding stage.

Model (docs/electro-thermal.md §1-5, SWOMPS ``Thermal_*.m``):

* In-plane conduction: one linear 3-node element per mesh triangle (panel fans and crease
  triangles), ``K_pq = k t (e_p . e_q) / (4 A)`` with ``e_p`` the edge vector opposite node p.
* Heat loss to the room: every structural node has a chain of ``L`` air layers to a sink at
  room temperature. Link ``q`` of triangle ``e`` has conductance
  ``g_e(q) = k_env Ac_e(q) L / h_e`` with ``Ac_e(q) = 2/3 A_e + 2/3 P_e h_e tan(phi) (q - 1/2)/L``
  and is shared by the triangle's three nodes. In steady state each chain is a series of
  conductances, so it reduces exactly to one conductance per node,
  ``1/G_v = sum_q 1/G_{v,q}`` with ``G_{v,q} = sum_{e ∋ v} g_e(q)`` (7.3).
* Heat input per crease (W) goes 1/8 to each of the 4 crease-edge nodes, 1/12 to each of the
  two centre-line end nodes and 1/3 to the crease centre (7.4).
* Temperature rise -> crease rest angle: Timoshenko bimorph curvature, times crease width (7.5).
* :func:`electrothermal_stage` adds heat and re-solves equilibrium by self-folding (7.6).

Units: W, m, K (temperatures in °C as the reference; only differences matter), W/(m K).
Array shapes: ``nn`` structural nodes, ``nt`` triangles, ``nci`` compliant creases.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg.lapack import dpotrf, dpotrs

try:  # scipy's private csr loops (a fast path of _csr_times; scipy's @ where they are gone)
    from scipy.sparse import _sparsetools
except ImportError:  # pragma: no cover - depends on the scipy release
    _sparsetools = None

from holofold.mechanics import kernels
from holofold.mechanics.compat import Profile
from holofold.mechanics.hinges import crease_rest_targets
from holofold.mechanics.solvers._common import (
    check_controls,
    get_assembler,
    nodal_array,
    spring_array,
)
from holofold.mechanics.solvers.selffold import solve_selffold_checked
from holofold.mechanics.threads import single_threaded

__all__ = [
    "ThermalModel",
    "thermal_model",
    "triangle_edges",
    "conduction_matrix",
    "air_link_conductances",
    "chain_conductance",
    "steady_temperature",
    "layered_system",
    "solve_layered",
    "heat_input_matrix",
    "crease_temperature_matrix",
    "HeatMatrices",
    "timoshenko_curvature",
    "Bimorph",
    "ThermalState",
    "initial_thermal_state",
    "electrothermal_stage",
]

log = logging.getLogger(__name__)

_DENSE_MAX = 1500  # use dense Cholesky up to this many unknowns


class CompiledPieces(NamedTuple):
    """The fixed arguments of ``_compiled.thermal_system`` (a named tuple: the kernel takes it
    whole). Per triangle (nt,): ``Lab``, ``Lac`` rest side lengths (m),
    ``half_ab_ac`` 0.5 Lab Lac (m^2), ``k_th`` conductivity x thickness (W/K), ``side`` the
    air-link perimeter term (nt, L); ``slots`` (9 nt,) dense positions of the element matrices;
    ``k_env`` air conductivity (W/(m K)), ``layers`` air layers, ``h`` air thickness (m, (nt,)
    or scalar); ``ptr``, ``idx``, ``data`` the node-triangle incidence (CSR)."""

    Lab: np.ndarray
    Lac: np.ndarray
    half_ab_ac: np.ndarray
    k_th: np.ndarray
    slots: np.ndarray
    side: np.ndarray
    k_env: float
    layers: float
    h: np.ndarray
    ptr: np.ndarray
    idx: np.ndarray
    data: np.ndarray


@dataclass(frozen=True, eq=False)
class ThermalModel:
    """Thermal data of a meshed structure (plain arrays).

    Attributes
    ----------
    triangles : (nt, 3) int
        Conduction elements (node ids).
    conductivity : (nt,) float
        Thermal conductivity k_e, W/(m K).
    thickness : (nt,) float
        Element thickness t_e, m.
    air_thickness : (nt,) float
        Thickness h_e of the air gap to the room-temperature sink, m.
    rest_edges : (nt, 3) float
        Reference lengths of the sides (a,b), (a,c), (b,c) of each triangle, m (used by the
        reference geometry form of the element).
    n_nodes : int
        Number of structural nodes nn.
    env_conductivity : float
        Conductivity of the air, W/(m K) (0.026).
    env_layers : int
        Number L of air layers in each chain (10).
    dissipation_angle : float
        Heat-spreading cone half angle phi, rad (20 deg).
    room_temperature : float
        Sink and room-temperature-node temperature, °C (21).
    room_temp_nodes : (nr,) int
        Structural nodes held at room temperature.
    reference_geometry : bool
        True (reference simulator): element geometry from the reference side lengths
        |ab|, |ac| and the current angle at a, perimeter from the reference lengths.
        False: the current 3-D edge vectors.
    """

    triangles: np.ndarray
    conductivity: np.ndarray
    thickness: np.ndarray
    air_thickness: np.ndarray
    rest_edges: np.ndarray
    n_nodes: int
    env_conductivity: float = 0.026
    env_layers: int = 10
    dissipation_angle: float = float(np.deg2rad(20.0))
    room_temperature: float = 21.0
    room_temp_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, np.intp))
    reference_geometry: bool = True

    def __post_init__(self):
        s = object.__setattr__
        tri = np.asarray(self.triangles, np.intp).reshape(-1, 3)
        nt = len(tri)
        s(self, "triangles", tri)
        for name in ("conductivity", "thickness", "air_thickness"):
            a = np.broadcast_to(np.asarray(getattr(self, name), float), (nt,)).copy()
            if not (np.isfinite(a).all() and (a >= 0).all()):
                raise ValueError(f"{name} must be finite and >= 0 for every triangle")
            s(self, name, a)
        if not (self.air_thickness > 0).all():
            raise ValueError("air_thickness must be > 0 for every triangle")
        s(self, "rest_edges", np.asarray(self.rest_edges, float).reshape(nt, 3))
        if int(self.env_layers) < 1:
            raise ValueError(f"env_layers = {self.env_layers!r} must be >= 1")
        s(self, "env_layers", int(self.env_layers))
        s(self, "room_temp_nodes", np.unique(np.asarray(self.room_temp_nodes, np.intp)))
        if nt and (tri.min() < 0 or tri.max() >= self.n_nodes):
            raise ValueError(f"triangles reference nodes outside 0..{self.n_nodes - 1}")

    # scatter maps of the mesh, built once per model (not per heating step)
    @cached_property
    def node_incidence(self) -> sp.csr_matrix:
        """(nn, nt) csr: 1 where node v is a corner of triangle e; ``node_incidence @ g`` sums
        per-triangle rows to the nodes in triangle order (as ``np.add.at`` would)."""
        nt = len(self.triangles)
        cols = np.repeat(np.arange(nt), 3)
        ones = np.ones(3 * nt)
        return sp.csr_matrix((ones, (self.triangles.ravel(), cols)), shape=(self.n_nodes, nt))

    @cached_property
    def reference_pieces(self):
        """The parts of :func:`triangle_edges` (reference form) and of the air links that do
        not depend on the shape, built once per model: ``pa`` (nt, 2) zeros, ``pb`` (nt, 2),
        ``Lac`` (nt, 1), ``0.5 Lab Lac`` (nt,), the perimeters (nt,) and the perimeter term of
        the air-link sections (nt, L), each by the operations the per-step code did."""
        Lab, Lac, Lbc = self.rest_edges.T
        nt = len(Lab)
        pb = np.column_stack([Lab, np.zeros_like(Lab)])
        perim = Lab + Lac + Lbc
        return (
            np.zeros((nt, 2)), pb, Lac[:, None], 0.5 * Lab * Lac, perim,
            _air_perimeter_term(self, perim),
        )  # fmt: skip

    @cached_property
    def compiled_pieces(self) -> CompiledPieces:
        """The fixed arguments of ``_compiled.thermal_system`` (reference geometry)."""
        _, _, Lac, half_ab_ac, _, side = self.reference_pieces
        inc = self.node_incidence
        return CompiledPieces(
            Lab=np.ascontiguousarray(self.rest_edges[:, 0]),
            Lac=np.ascontiguousarray(Lac[:, 0]),
            half_ab_ac=half_ab_ac,
            k_th=self.conductivity * self.thickness,
            slots=self.dense_slots,
            side=np.ascontiguousarray(side),
            k_env=float(self.env_conductivity),
            layers=float(self.env_layers),
            h=self.air_thickness,
            ptr=inc.indptr,
            idx=inc.indices,
            data=inc.data,
        )

    @cached_property
    def dense_slots(self) -> np.ndarray:
        """(9 nt,) int: flat position ``p n + q`` in a dense (nn, nn) matrix of every entry of
        the element matrices (nt, 3, 3)."""
        t = self.triangles
        return (np.repeat(t, 3, axis=1) * self.n_nodes + np.tile(t, (1, 3))).ravel()


def thermal_model(
    structure,
    *,
    panel_conductivity,
    crease_conductivity,
    air_thickness,
    env_conductivity: float = 0.026,
    env_layers: int = 10,
    dissipation_deg: float = 20.0,
    room_temperature: float = 21.0,
    room_temp_nodes=(),
    reference_geometry: bool = True,
    profile: Profile | None = None,
) -> ThermalModel:
    """Thermal model of a compliant-crease :class:`~holofold.mechanics.structure.Structure`.

    Triangles with ``tri_crease >= 0`` use ``crease_conductivity``, the others
    ``panel_conductivity`` (scalar or per panel, indexed by ``tri_panel``). Thicknesses are
    ``structure.tri_thickness``. ``air_thickness`` (m) is a scalar or per triangle (the
    reference's ``t2RT``; no substrate panels). The spreading angle is
    ``dissipation_deg * pi / 180`` rad, with pi = 3.14 where ``profile.dissipation_pi_314``
    (default: the structure's profile), as the reference converts it.
    """
    profile = profile or structure.profile
    pi_value = 3.14 if profile.dissipation_pi_314 else np.pi
    tri = structure.triangles
    pc = np.asarray(panel_conductivity, float)
    k_panel = pc[np.maximum(structure.tri_panel, 0)] if pc.ndim else np.full(len(tri), pc)
    k = np.where(structure.tri_crease >= 0, float(crease_conductivity), k_panel)
    X = structure.nodes
    a, b, c = X[tri[:, 0]], X[tri[:, 1]], X[tri[:, 2]]
    rest = np.column_stack(
        [
            np.linalg.norm(b - a, axis=1),
            np.linalg.norm(c - a, axis=1),
            np.linalg.norm(c - b, axis=1),
        ]
    )
    return ThermalModel(
        triangles=tri,
        conductivity=k,
        thickness=structure.tri_thickness,
        air_thickness=np.broadcast_to(np.asarray(air_thickness, float), (len(tri),)),
        rest_edges=rest,
        n_nodes=structure.n_nodes,
        env_conductivity=env_conductivity,
        env_layers=env_layers,
        dissipation_angle=float(dissipation_deg) * float(pi_value) / 180.0,
        room_temperature=room_temperature,
        room_temp_nodes=np.asarray(room_temp_nodes, np.intp),
        reference_geometry=reference_geometry,
    )


def triangle_edges(model: ThermalModel, x: np.ndarray):
    """Edge vectors opposite each vertex, areas and perimeters of all triangles.

    Parameters
    ----------
    x : (nn, 3) float
        Current node coordinates, m.

    Returns
    -------
    e : (nt, 3, d) float
        ``e[:, p]`` is the side opposite vertex p, oriented cyclically (d = 2 in the reference
        form, 3 otherwise).
    area : (nt,) float, m^2
    perimeter : (nt,) float, m
    """
    tri = model.triangles
    xa, xb, xc = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    if model.reference_geometry:
        u, v = xb - xa, xc - xa
        # |u x v| as np.linalg.norm(np.cross(u, v), axis=1) computes it, op for op
        c = np.empty_like(u)
        c[:, 0] = u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]
        c[:, 1] = u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]
        c[:, 2] = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
        cross = np.sqrt(np.add.reduce(c * c, axis=1))
        alpha = np.arctan2(cross, np.einsum("ij,ij->i", u, v))
        pa, pb, Lac, half_ab_ac, perimeter, _ = model.reference_pieces
        sin = np.sin(alpha)
        cs = np.empty((len(tri), 2))
        cs[:, 0] = np.cos(alpha)
        cs[:, 1] = sin
        pc = Lac * cs
        area = half_ab_ac * sin
    else:
        pa, pb, pc = xa, xb, xc
        area = 0.5 * np.linalg.norm(np.cross(pb - pa, pc - pa), axis=1)
        perimeter = (
            np.linalg.norm(pb - pa, axis=1)
            + np.linalg.norm(pc - pb, axis=1)
            + np.linalg.norm(pa - pc, axis=1)
        )
    e = np.stack([pc - pb, pa - pc, pb - pa], axis=1)
    return e, area, perimeter


def _scatter_nodal(model: ThermalModel, ke: np.ndarray) -> sp.csr_matrix:
    tri = model.triangles
    rows = np.repeat(tri, 3, axis=1).ravel()
    cols = np.tile(tri, (1, 3)).ravel()
    n = model.n_nodes
    return sp.csr_matrix((ke.ravel(), (rows, cols)), shape=(n, n))


def _element_matrices(model: ThermalModel, e, area) -> np.ndarray:
    if (area <= 0).any():
        k = int(np.argmin(area))
        raise ValueError(f"triangle {k} {model.triangles[k].tolist()} has zero area")
    coef = model.conductivity * model.thickness / (4.0 * area)
    return coef[:, None, None] * np.einsum("tpd,tqd->tpq", e, e)


def conduction_matrix(model: ThermalModel, x: np.ndarray) -> sp.csr_matrix:
    """In-plane conduction matrix (nn, nn), W/K, at coordinates ``x`` (nn, 3)."""
    e, area, _ = triangle_edges(model, x)
    return _scatter_nodal(model, _element_matrices(model, e, area))


def air_link_conductances(model: ThermalModel, x: np.ndarray) -> np.ndarray:
    """Per-triangle air-link conductances g_e(q), (nt, L), W/K, for links q = 1..L."""
    _, area, perim = triangle_edges(model, x)
    return _air_links(model, area, perim)


def _air_links(model: ThermalModel, area, perim) -> np.ndarray:
    if model.reference_geometry and perim is model.reference_pieces[4]:
        side = model.reference_pieces[5]  # the perimeters do not change with the shape
    else:
        side = _air_perimeter_term(model, perim)
    Ac = (2.0 / 3.0) * area[:, None] + side
    return model.env_conductivity * Ac * model.env_layers / model.air_thickness[:, None]


def _air_perimeter_term(model: ThermalModel, perim) -> np.ndarray:
    """(nt, L): the perimeter term of the air-link sections."""
    L = model.env_layers
    h = model.air_thickness
    depth = (np.arange(1, L + 1) - 0.5) / L
    return (2.0 / 3.0) * (perim * h * np.tan(model.dissipation_angle))[:, None] * depth[None, :]


def _node_link_conductances(model: ThermalModel, x: np.ndarray, geometry=None) -> np.ndarray:
    """G_{v,q} = sum over triangles at v of g_e(q), (nn, L)."""
    _, area, perim = triangle_edges(model, x) if geometry is None else geometry
    return _csr_times(model.node_incidence, _air_links(model, area, perim))


def chain_conductance(model: ThermalModel, x: np.ndarray, *, _geometry=None) -> np.ndarray:
    """Exact series conductance of each node's air chain to the sink, (nn,), W/K.

    Nodes that belong to no triangle get 0.
    """
    return _series(_node_link_conductances(model, x, _geometry))


def _series(Gq: np.ndarray) -> np.ndarray:
    """Series conductance (nn,) of the node-layer conductances ``Gq`` (nn, L); 0 where a row
    has no positive entry."""
    with np.errstate(divide="ignore"):
        inv = np.where(Gq > 0, 1.0 / np.where(Gq > 0, Gq, 1.0), np.inf).sum(axis=1)
    return np.where(np.isfinite(inv), 1.0 / inv, 0.0)


def _csr_times(M, x: np.ndarray) -> np.ndarray:
    """``M @ x``; for a float csr matrix and a float (n,) or C-contiguous (n, k) ``x``, the
    sparsetools loop scipy's ``@`` runs (the same numbers) without its dispatch, which costs
    more than the loop at these sizes."""
    if _sparsetools is None or not (
        isinstance(M, sp.csr_matrix) and M.dtype == np.float64 and isinstance(x, np.ndarray)
        and x.dtype == np.float64 and x.flags.c_contiguous and x.ndim in (1, 2)
        and x.shape[0] == M.shape[1]
    ):  # fmt: skip
        return M @ x
    m, n = M.shape
    if x.ndim == 1:
        out = np.zeros(m)
        _sparsetools.csr_matvec(m, n, M.indptr, M.indices, M.data, x, out)
    else:
        out = np.zeros((m, x.shape[1]))
        _sparsetools.csr_matvecs(
            m, n, x.shape[1], M.indptr, M.indices, M.data, x.ravel(), out.ravel()
        )
    return out


def _solve_spd(A: sp.spmatrix, b: np.ndarray) -> np.ndarray:
    n = A.shape[0]
    if n <= _DENSE_MAX:
        return sla.cho_solve(sla.cho_factor(A.toarray(), lower=False, check_finite=False), b)
    return spla.splu(sp.csc_matrix(A)).solve(b)


def _compiled_system(model: ThermalModel, x: np.ndarray):
    """The dense conduction matrix (nn, nn) and the chain conductances G (nn,) of the small
    model fast path in the reference geometry on the compiled kernel path: those of
    :func:`triangle_edges`, :func:`_element_matrices` + ``np.bincount`` and
    :func:`chain_conductance` to round-off (two compiled calls around numpy's einsum, arctan2,
    cos and sin)."""
    ck = kernels.active().module
    tri = model.triangles
    nt, n = len(tri), model.n_nodes
    x = np.ascontiguousarray(x, dtype=float)
    u, v, cross = np.empty((nt, 3)), np.empty((nt, 3)), np.empty(nt)
    ck.thermal_sides(x, tri, u, v, cross)
    alpha = np.arctan2(cross, np.einsum("ij,ij->i", u, v))
    area, A, Gq = np.empty(nt), np.zeros(n * n), np.empty((n, model.env_layers))
    if not ck.thermal_system(np.cos(alpha), np.sin(alpha), model.compiled_pieces, area, A, Gq):
        _element_matrices(model, None, area)  # raises, naming the triangle
    return A.reshape(n, n), _series(Gq)


def _compiled_steady(model: ThermalModel, x: np.ndarray, q: np.ndarray, ck) -> np.ndarray:
    """:func:`steady_temperature`'s small-model path: numpy's angles (einsum, arctan2, cos,
    sin, as :func:`_compiled_system`), the rest in one compiled call
    (``_compiled.thermal_steady``): the numpy path's numbers to round-off."""
    tri = model.triangles
    nt, n = len(tri), model.n_nodes
    x = np.ascontiguousarray(x, dtype=float)
    u, v, cross = np.empty((nt, 3)), np.empty((nt, 3)), np.empty(nt)
    ck.thermal_sides(x, tri, u, v, cross)
    alpha = np.arctan2(cross, np.einsum("ij,ij->i", u, v))
    area, T = np.empty(nt), np.empty(n)
    info = ck.thermal_steady(
        np.cos(alpha), np.sin(alpha), model.compiled_pieces, np.ascontiguousarray(q, float),
        float(model.room_temperature), ck.lapack_addresses("dpotrf", "dpotrs"), area,
        np.empty(n * n), T,
    )  # fmt: skip
    if info < 0:
        _element_matrices(model, None, area)  # raises, naming the triangle
    if info > 0:
        raise np.linalg.LinAlgError(
            f"{info}-th leading minor of the array is not positive definite"
        )
    return T


@single_threaded
def steady_temperature(
    model: ThermalModel,
    x: np.ndarray,
    q: np.ndarray,
    *,
    K_cond: sp.spmatrix | None = None,
    G: np.ndarray | None = None,
) -> np.ndarray:
    """Steady nodal temperatures (nn,), °C, for nodal heat input ``q`` (nn,), W.

    Solves ``(K_cond + diag(G)) T = q + G RT`` with T = RT at ``room_temp_nodes`` (the exact
    reduction of the layered air model, docs/electro-thermal.md §3.2-3.3). ``K_cond`` and ``G``
    may be passed if already computed at ``x``.
    """
    n = model.n_nodes
    q = np.asarray(q, float)
    if q.shape != (n,):
        raise ValueError(f"q must have shape ({n},), got {q.shape}")
    RT = model.room_temperature
    if K_cond is None and G is None and n <= _DENSE_MAX and not len(model.room_temp_nodes):
        # fast path for small models: one geometry pass, dense assembly, Cholesky
        path = kernels.active()
        if model.reference_geometry and path.compiled:
            return _compiled_steady(model, x, q, path.module)
        else:
            geo = triangle_edges(model, x)
            G = chain_conductance(model, x, _geometry=geo)
            ke = _element_matrices(model, geo[0], geo[1])
            A = np.bincount(model.dense_slots, weights=ke.ravel(), minlength=n * n)
            A = A.reshape(n, n)
        A.flat[:: n + 1] += G
        # sla.cho_factor / cho_solve (check_finite=False) without their wrappers: the same
        # LAPACK calls on the same arrays
        c, info = dpotrf(A, lower=0, clean=0)
        if info > 0:
            raise np.linalg.LinAlgError(
                f"{info}-th leading minor of the array is not positive definite"
            )
        T, info = dpotrs(c, q + G * RT, lower=0)
        if info != 0:  # pragma: no cover - only for invalid arguments
            raise ValueError(f"illegal value in {-info}th argument of internal potrs")
        return T
    K = conduction_matrix(model, x) if K_cond is None else K_cond
    G = chain_conductance(model, x) if G is None else G
    A = (K + sp.diags(G)).tocsr()
    rhs = q + G * RT
    T = np.full(n, RT)
    fixed = np.zeros(n, bool)
    fixed[model.room_temp_nodes] = True
    free = np.flatnonzero(~fixed)
    if fixed.any():
        rhs = rhs - A[:, np.flatnonzero(fixed)] @ T[fixed]
    Aff = A[free][:, free]
    T[free] = _solve_spd(Aff, rhs[free])
    return T


def layered_system(model: ThermalModel, x: np.ndarray) -> sp.csr_matrix:
    """Full conductance matrix ((L+1) nn, (L+1) nn) with the explicit air layers.

    DOF ``q nn + v`` is node v in layer q (layer 0 = structure, layer L = sink).
    """
    n, L = model.n_nodes, model.env_layers
    Gq = _node_link_conductances(model, x)  # (n, L) link between layer q-1 and q
    Kc = conduction_matrix(model, x)
    v = np.arange(n)
    rows, cols, vals = [], [], []
    for q in range(1, L + 1):
        i, j, g = (q - 1) * n + v, q * n + v, Gq[:, q - 1]
        rows += [i, j, i, j]
        cols += [i, j, j, i]
        vals += [g, g, -g, -g]
    Kair = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=((L + 1) * n, (L + 1) * n),
    )
    Kfull = sp.block_diag([Kc, sp.csr_matrix((L * n, L * n))], format="csr") + Kair
    return Kfull.tocsr()


def solve_layered(model: ThermalModel, x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Steady temperatures of all layers, ((L+1) nn,), by the full layered solve (7.2-7.3)."""
    n, L = model.n_nodes, model.env_layers
    K = layered_system(model, x)
    N = (L + 1) * n
    T = np.full(N, model.room_temperature)
    fixed = np.zeros(N, bool)
    fixed[L * n :] = True
    fixed[model.room_temp_nodes] = True
    rhs = np.zeros(N)
    rhs[:n] = q
    free = np.flatnonzero(~fixed)
    rhs = rhs - K[:, np.flatnonzero(fixed)] @ T[fixed]
    T[free] = spla.spsolve(sp.csc_matrix(K[free][:, free]), rhs[free])
    return T


def _check_crease_nodes(crease_nodes, n_nodes):
    cn = np.asarray(crease_nodes, np.intp)
    if cn.ndim != 2 or cn.shape[1] != 7:
        raise ValueError(f"crease_nodes must have shape (nci, 7), got {cn.shape}")
    if cn.size and (cn.min() < 0 or cn.max() >= n_nodes):
        raise ValueError(f"crease_nodes reference nodes outside 0..{n_nodes - 1}")
    return cn


_HEAT_SHARE = np.array([1 / 8, 1 / 8, 1 / 8, 1 / 8, 1 / 12, 1 / 12, 1 / 3])
_TEMP_WEIGHT = np.array([1 / 8, 1 / 8, 1 / 8, 1 / 8, 1 / 6, 1 / 6, 1 / 6])


def heat_input_matrix(crease_nodes, n_nodes: int) -> sp.csr_matrix:
    """(nn, nci) matrix H mapping per-crease power (W) to nodal heat input: ``q = H Q``.

    ``crease_nodes`` (nci, 7) = [N11, N12, N21, N22, p1, p2, c] (``Structure.creases.nodes``). Each
    crease gives 1/8 to each edge node, 1/12 to p1 and p2 and 1/3 to c; contributions of
    creases sharing a node add up.
    """
    cn = _check_crease_nodes(crease_nodes, n_nodes)
    nci = len(cn)
    cols = np.repeat(np.arange(nci), 7)
    return sp.csr_matrix((np.tile(_HEAT_SHARE, nci), (cn.ravel(), cols)), shape=(n_nodes, nci))


def crease_temperature_matrix(crease_nodes, n_nodes: int) -> sp.csr_matrix:
    """(nci, nn) matrix A giving each crease's mean temperature rise: ``dT_c = A dT``.

    ``dT_c = 1/2 mean(dT at p1, p2, c) + 1/2 mean(dT at N11, N12, N21, N22)`` (7.5).
    """
    cn = _check_crease_nodes(crease_nodes, n_nodes)
    nci = len(cn)
    rows = np.repeat(np.arange(nci), 7)
    return sp.csr_matrix((np.tile(_TEMP_WEIGHT, nci), (rows, cn.ravel())), shape=(nci, n_nodes))


@dataclass(frozen=True, eq=False)
class HeatMatrices:
    """The two crease matrices of a structure's electro-thermal stages, which depend on its
    crease nodes only (made once, used at every heating step): ``heat`` (nn, nci), W of each
    crease to nodal heat (:func:`heat_input_matrix`), and ``temperature`` (nci, nn), nodal
    temperature rises to each crease's (:func:`crease_temperature_matrix`)."""

    heat: sp.csr_matrix
    temperature: sp.csr_matrix

    @classmethod
    def of(cls, structure) -> HeatMatrices:
        """The matrices of ``structure`` (its ``creases.nodes`` and ``n_nodes``)."""
        cn, nn = structure.creases.nodes, structure.n_nodes
        return cls(heat_input_matrix(cn, nn), crease_temperature_matrix(cn, nn))


def timoshenko_curvature(dT, d_alpha, t1, t2, E1=1.0, E2=1.0):
    """Bimorph curvature (1/m) for a temperature rise ``dT`` (K), Timoshenko (1925).

    ``kappa = 6 d_alpha dT (1+m)^2 / (h [3 (1+m)^2 + (1 + m n)(m^2 + 1/(m n))])`` with
    ``m = t1/t2``, ``n = E1/E2``, ``h = t1 + t2``; ``d_alpha`` (1/K) is the expansion mismatch.
    All arguments broadcast.
    """
    a, c, d = _timoshenko_factors(d_alpha, t1, t2, E1, E2)
    return a * np.asarray(dT, float) * c / d


def _timoshenko_factors(d_alpha, t1, t2, E1, E2):
    """``(6 d_alpha, (1+m)^2, h [...])``: :func:`timoshenko_curvature` is
    ``6 d_alpha * dT * (1+m)^2 / (h [...])``, evaluated left to right."""
    t1, t2, E1, E2 = (np.asarray(v, float) for v in (t1, t2, E1, E2))
    if (t1 <= 0).any() or (t2 <= 0).any() or (E1 <= 0).any() or (E2 <= 0).any():
        raise ValueError("bimorph layer thicknesses and moduli must be > 0")
    m = t1 / t2
    n = E1 / E2
    h = t1 + t2
    return (
        6.0 * np.asarray(d_alpha, float),
        (1 + m) ** 2,
        h * (3 * (1 + m) ** 2 + (1 + m * n) * (m**2 + 1 / (m * n))),
    )


# --------------------------------------------------------------------------- folding stage
@dataclass(frozen=True, eq=False)
class Bimorph:
    """Bimorph coating of the compliant creases (per crease in ``Structure.creases.ids`` order).

    Attributes
    ----------
    d_alpha : (nci,) float
        Thermal-expansion mismatch of the two layers, 1/K; its sign sets the fold direction
        (positive folds toward +z for the default spring polarity).
    t1, t2 : float
        Layer thicknesses, m.
    E1, E2 : float
        Layer moduli, Pa (only their ratio matters).
    width : (nci,) float
        Crease width W, m: the rest-angle change is ``W kappa``.
    """

    d_alpha: np.ndarray
    t1: float
    t2: float
    E1: float
    E2: float
    width: np.ndarray

    def fold_increment(self, dT_crease: np.ndarray) -> np.ndarray:
        """Rest-angle change (nci,), rad, for crease temperature rises ``dT_crease`` (nci,), K."""
        a, c, d = self._factors  # timoshenko_curvature's, built once
        return self.width * (a * np.asarray(dT_crease, float) * c / d)

    @cached_property
    def _factors(self):
        return _timoshenko_factors(self.d_alpha, self.t1, self.t2, self.E1, self.E2)


@dataclass(frozen=True, eq=False)
class ThermalState:
    """State carried between loading stages (the reference's ``current*`` fields).

    Attributes
    ----------
    U : (nn, 3) float
        Displacement, m.
    force : (nn, 3) float
        External force currently applied, N.
    q : (nn,) float
        Cumulative nodal heat input, W.
    T : (nn,) float
        Temperatures at the end of the last thermal stage, °C.
    crease_angle : (nci,) float
        Stress-free fold angle of each compliant crease, rad (pi = flat).
    spring_rest : (ns,) float
        Spring rest angles, rad.
    """

    U: np.ndarray
    force: np.ndarray
    q: np.ndarray
    T: np.ndarray
    crease_angle: np.ndarray
    spring_rest: np.ndarray

    def replace(self, **kw) -> ThermalState:
        return replace(self, **kw)


def initial_thermal_state(structure, room_temperature: float = 21.0) -> ThermalState:
    """Unloaded state: U = 0, no force or heat, T = room temperature, creases flat (pi)."""
    nn = structure.n_nodes
    nci = len(structure.creases)
    return ThermalState(
        U=np.zeros((nn, 3)),
        force=np.zeros((nn, 3)),
        q=np.zeros(nn),
        T=np.full(nn, float(room_temperature)),
        crease_angle=np.full(nci, np.pi),
        spring_rest=structure.spring_rest.copy(),
    )


@single_threaded
@single_threaded
def electrothermal_stage(
    structure,
    model: ThermalModel,
    bimorph: Bimorph,
    state: ThermalState,
    crease_heat,
    *,
    steps: int = 1,
    increments: int = 1,
    tol: float = 1e-5,
    max_iter: int = 30,
    profile=None,
    assembler=None,
    matrices: HeatMatrices | None = None,
):
    """Add heat to the creases and fold quasi-statically (docs/electro-thermal.md §5.3).

    For s = 1..steps: nodal heat ``q = state.q + (s/steps) H crease_heat``; steady temperatures at
    the current shape; crease fold angles ``theta = theta_start + W kappa(dT)`` with dT relative to
    the stage start; spring targets (:func:`~holofold.mechanics.hinges.crease_rest_targets`); one
    self-folding solve (``increments`` sub-increments, supports of ``structure``) keeping
    ``state.force`` applied.

    Parameters
    ----------
    structure : Structure
        Compliant-crease model with the stage's supports.
    model : ThermalModel
        Thermal model of ``structure``.
    bimorph : Bimorph
    state : ThermalState
        State at the stage start.
    crease_heat : (nci,) float
        Extra power of each compliant crease added by this stage, W.
    profile : Profile, optional
        Quirk switches (default: the structure's): ``thermal_reinterpolate_from_stage_start``
        and ``reset_non_crease_rest_angles``.
    assembler : Assembler, optional
        The self-folding solves' assembler (default: one made for ``structure``).
    matrices : HeatMatrices, optional
        ``structure``'s crease matrices (default: made here; pass them to share them between
        stages).

    Returns
    -------
    state : ThermalState
        State at the stage end.
    results : list of SolveResult
        The self-folding solve of each thermal step.
    """
    profile = profile or structure.profile
    cid = structure.creases.ids
    nci = len(cid)
    Q = np.asarray(crease_heat, float)
    if Q.shape != (nci,):
        raise ValueError(f"crease_heat must have shape ({nci},), got {Q.shape}")
    steps = int(steps)
    if steps < 1:
        raise ValueError(f"steps = {steps!r} must be >= 1")
    if matrices is None:
        matrices = HeatMatrices.of(structure)
    H, A = matrices.heat, matrices.temperature
    q_stage = _csr_times(H, Q)
    # the solves' arguments checked once for the stage (solve_selffold_checked does not)
    asm = get_assembler(structure, assembler)
    increments, tol, max_iter = check_controls(increments, tol, max_iter)
    nn, ns = structure.n_nodes, len(structure.springs)
    F0v = nodal_array("F0", state.force, nn).ravel()
    U = nodal_array("U0", state.U, nn).ravel()  # a copy, updated in place by the solves
    rest_prev = spring_array("start_rest", state.spring_rest, ns)
    stage_start = rest_prev
    T = state.T
    theta = state.crease_angle
    full = np.full(int(cid.max()) + 1 if nci else 0, np.pi)
    results = []
    for s in range(1, steps + 1):
        q = state.q + (s / steps) * q_stage
        T = steady_temperature(model, structure.nodes + U.reshape(nn, 3), q)
        dTc = _csr_times(A, T - state.T)
        theta = state.crease_angle + bimorph.fold_increment(dTc)
        full[cid] = theta
        target = crease_rest_targets(structure, full, profile=profile)
        if target.shape != (ns,) or not np.isfinite(target).all():
            spring_array("target_rest", target, ns)  # raises, naming the problem
        start = stage_start if profile.thermal_reinterpolate_from_stage_start else rest_prev
        res = solve_selffold_checked(asm, U, F0v, start, target, increments, tol, max_iter)
        results.append(res)
        rest_prev = target
        if res.failed:
            break
    new = ThermalState(
        U=U.reshape(nn, 3), force=state.force, q=state.q + q_stage, T=T, crease_angle=theta,
        spring_rest=np.array(rest_prev),
    )  # fmt: skip
    return new, results
