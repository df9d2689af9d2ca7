"""Thermal model: analytic fin, energy balance, exact air-chain reduction, Timoshenko, folding."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.geometry.gripper import two_panel_gripper
from holofold.mechanics.hinges import build_compliant
from holofold.mechanics.structure import Structure
from holofold.mechanics.thermal import (
    Bimorph,
    HeatMatrices,
    ThermalModel,
    chain_conductance,
    conduction_matrix,
    crease_temperature_matrix,
    electrothermal_stage,
    heat_input_matrix,
    initial_thermal_state,
    solve_layered,
    steady_temperature,
    thermal_model,
    timoshenko_curvature,
)


def _strip(n, length, width):
    """Nodes (2 rows along x) and 2 n triangles, diagonals alternating (mirror symmetric)."""
    x = np.linspace(0.0, length, n + 1)
    nodes = np.zeros((2 * (n + 1), 3))
    nodes[: n + 1, 0] = x
    nodes[n + 1 :, 0] = x
    nodes[n + 1 :, 1] = width
    tris = []
    for i in range(n):
        a, b, c, d = i, i + 1, n + 2 + i, n + 1 + i  # bottom-left, bottom-right, top-r, top-l
        tris += [(a, b, c), (a, c, d)] if i % 2 == 0 else [(a, b, d), (b, c, d)]
    return nodes, np.array(tris)


def _rest_edges(nodes, tri):
    a, b, c = nodes[tri[:, 0]], nodes[tri[:, 1]], nodes[tri[:, 2]]
    return np.column_stack(
        [
            np.linalg.norm(b - a, axis=1),
            np.linalg.norm(c - a, axis=1),
            np.linalg.norm(c - b, axis=1),
        ]
    )


def test_fin_matches_analytic_cosh_profile():
    """Strip heated at x = 0, insulated at x = l, losing heat through the air to RT.

    With no heat spreading the air chain of each face is k_env / h per area, two faces, so
    theta'' = m^2 theta with m^2 = 2 k_env / (h k t) and
    theta(x) = Q cosh(m (l - x)) / (k t b m sinh(m l)).
    """
    n, length, width, t, k, h, kenv = 200, 1e-3, 0.1e-3, 20e-6, 0.3, 2e-3, 0.026
    nodes, tri = _strip(n, length, width)
    model = ThermalModel(
        triangles=tri,
        conductivity=k,
        thickness=t,
        air_thickness=h,
        rest_edges=_rest_edges(nodes, tri),
        n_nodes=len(nodes),
        env_conductivity=kenv,
        env_layers=10,
        dissipation_angle=0.0,
        room_temperature=21.0,
    )
    Q = 0.01
    q = np.zeros(len(nodes))
    q[[0, n + 1]] = Q / 2
    T = steady_temperature(model, nodes, q)
    m = np.sqrt(2 * kenv / (h * k * t))
    x = nodes[: n + 1, 0]
    exact = Q * np.cosh(m * (length - x)) / (k * t * width * m * np.sinh(m * length))
    theta = 0.5 * (T[: n + 1] + T[n + 1 :]) - 21.0
    assert m * length > 1.5  # a real fin, not a uniform plate
    np.testing.assert_allclose(theta, exact, rtol=1e-4)  # discretisation ~ (m dx)^2 / 10
    # and the two edges of the strip carry the same temperatures (symmetric mesh)
    np.testing.assert_allclose(T[: n + 1], T[n + 1 :], rtol=1e-4)


def _gripper_structure():
    pat = two_panel_gripper(4.1e-3, 3.1e-3, 0.49).pattern
    s = build_compliant(
        pat,
        crease_width=150e-6,
        crease_thickness=1.2e-6,
        panel_thickness=27e-6,
        E_panel=2e9,
        E_crease=2e9,
        nu_panel=0.3,
        nu_crease=0.3,
        diagonal_rate=100.0,
    )
    return pat, s


@pytest.mark.parametrize("room_nodes", [(), (0, 1, 2, 3)])
def test_energy_balance_and_chain_reduction(room_nodes):
    _, s = _gripper_structure()
    model = thermal_model(
        s,
        panel_conductivity=0.3,
        crease_conductivity=0.3,
        air_thickness=4.6e-3,
        room_temp_nodes=room_nodes,
    )
    rng = np.random.default_rng(1)
    H = heat_input_matrix(s.creases.nodes, s.n_nodes)
    q = H @ rng.uniform(0.01, 0.05, len(s.creases.ids))
    x = s.nodes + rng.normal(0, 1e-6, s.nodes.shape)  # a slightly deformed state
    T = steady_temperature(model, x, q)
    G = chain_conductance(model, x)
    RT = model.room_temperature
    out_air = G @ (T - RT)
    K = conduction_matrix(model, x)
    r = list(room_nodes)
    out_room = q[r].sum() - (K @ T)[r].sum()  # heat drawn off to hold them at RT
    q_in = q.sum()
    assert abs(q_in - out_air - out_room) <= 1e-9 * q_in
    if room_nodes:
        assert out_room > 0.01 * q_in
        np.testing.assert_array_equal(T[list(room_nodes)], RT)
    # the exact reduction reproduces the explicit 10-layer air model
    full = solve_layered(model, x, q)
    np.testing.assert_allclose(full[: s.n_nodes], T, rtol=1e-11, atol=0)
    assert np.all(np.diff(full.reshape(11, -1)[:, 30]) < 0)  # cooling through the layers


def test_conduction_matrix_properties():
    _, s = _gripper_structure()
    m_ref = thermal_model(s, panel_conductivity=0.3, crease_conductivity=0.3, air_thickness=1e-3)
    m_3d = thermal_model(
        s,
        panel_conductivity=0.3,
        crease_conductivity=0.3,
        air_thickness=1e-3,
        reference_geometry=False,
    )
    K = conduction_matrix(m_ref, s.nodes).toarray()
    np.testing.assert_allclose(K, K.T, atol=1e-15)
    np.testing.assert_allclose(K.sum(axis=1), 0, atol=1e-12 * np.abs(K).max())
    # the 3-D edge-vector form equals the reference's (rest lengths, current angle) form
    # when the geometry is unstrained, also after a rigid rotation
    R = np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])
    K3 = conduction_matrix(m_3d, s.nodes @ R.T).toarray()
    np.testing.assert_allclose(K3, K, rtol=1e-9, atol=1e-12 * np.abs(K).max())


def test_heat_and_temperature_matrices():
    _, s = _gripper_structure()
    cn = s.creases.nodes
    H = heat_input_matrix(cn, s.n_nodes).toarray()
    A = crease_temperature_matrix(cn, s.n_nodes).toarray()
    np.testing.assert_allclose(H.sum(axis=0), 1.0)  # every watt lands on a node
    np.testing.assert_allclose(A.sum(axis=1), 1.0)  # a weighted mean
    assert H[cn[0, 6], 0] == pytest.approx(1 / 3)
    assert H[cn[0, 4], 0] == pytest.approx(1 / 12)
    assert H[cn[0, 0], 0] == pytest.approx(1 / 8)
    assert A[0, cn[0, 4]] == pytest.approx(1 / 6)
    assert A[0, cn[0, 0]] == pytest.approx(1 / 8)


def test_timoshenko():
    d_alpha, dT, t = 50e-6, 80.0, 0.5e-6
    k = timoshenko_curvature(dT, d_alpha, t, t)
    assert k == pytest.approx(1.5 * d_alpha * dT / (2 * t), rel=1e-14)
    # general case against the formula written out, m = 0.25, n = 2
    t1, t2, E1, E2 = 0.2e-6, 0.8e-6, 4e9, 2e9
    m, n, h = 0.25, 2.0, 1e-6
    ref = (
        6
        * d_alpha
        * dT
        * (1 + m) ** 2
        / (h * (3 * (1 + m) ** 2 + (1 + m * n) * (m**2 + 1 / (m * n))))
    )
    assert timoshenko_curvature(dT, d_alpha, t1, t2, E1, E2) == pytest.approx(ref, rel=1e-14)
    assert timoshenko_curvature(dT, -d_alpha, t1, t2, E1, E2) == pytest.approx(-ref, rel=1e-14)
    with pytest.raises(ValueError):
        timoshenko_curvature(dT, d_alpha, 0.0, t2)


def test_thermal_model_rejects_bad_input():
    nodes, tri = _strip(3, 1.0, 1.0)
    with pytest.raises(ValueError, match="air_thickness"):
        ThermalModel(tri, 1.0, 1.0, 0.0, _rest_edges(nodes, tri), len(nodes))
    with pytest.raises(ValueError, match="env_layers"):
        ThermalModel(tri, 1.0, 1.0, 1.0, _rest_edges(nodes, tri), len(nodes), env_layers=0)
    with pytest.raises(ValueError, match="outside"):
        ThermalModel(tri, 1.0, 1.0, 1.0, _rest_edges(nodes, tri), 3)


def test_electrothermal_stage_folds_toward_plus_z():
    """Positive mismatch on every crease: the two arms of the two-panel gripper lift (+z),
    symmetrically, and the crease fold angles grow by W kappa(dT)."""
    pat, s = _gripper_structure()
    sup = np.zeros((s.n_nodes, 3), bool)
    sup[:4] = True
    s = s.with_supports(sup)
    model = thermal_model(s, panel_conductivity=0.3, crease_conductivity=0.3, air_thickness=4.6e-3)
    nci = len(s.creases.ids)
    bim = Bimorph(np.full(nci, 50e-6), 0.2e-6, 1.0e-6, 2e9, 2e9, np.full(nci, 150e-6))
    state = initial_thermal_state(s)
    Q = np.full(nci, 0.1 * 3.1e-3 * 20)  # 20 heating steps at once
    new, results = electrothermal_stage(s, model, bim, state, Q, steps=2, tol=5e-7)
    assert all(r.ok for r in results)
    tips = [10, 11, 16, 17]  # meshed ids 11, 12, 17, 18
    z = new.U[tips, 2]
    assert np.all(z > 1e-5)
    np.testing.assert_allclose(z, z[0], rtol=1e-6)
    dT = crease_temperature_matrix(s.creases.nodes, s.n_nodes) @ (new.T - 21.0)
    np.testing.assert_allclose(new.crease_angle - np.pi, bim.fold_increment(dT), rtol=1e-12)
    assert np.all(new.crease_angle > np.pi)
    np.testing.assert_allclose(new.q.sum(), Q.sum(), rtol=1e-12)


def test_a_stage_given_its_heat_matrices_folds_the_same():
    """``matrices=HeatMatrices.of(s)`` (made once, shared by the gripper's heating steps) is
    what the stage makes itself: the same matrices, the same state to 1e-12."""
    pat, s = _gripper_structure()
    sup = np.zeros((s.n_nodes, 3), bool)
    sup[:4] = True
    s = s.with_supports(sup)
    mats = HeatMatrices.of(s)
    cn = s.creases.nodes
    assert abs(mats.heat - heat_input_matrix(cn, s.n_nodes)).max() == 0
    assert abs(mats.temperature - crease_temperature_matrix(cn, s.n_nodes)).max() == 0
    assert mats.heat.shape == (s.n_nodes, len(s.creases.ids)) == mats.temperature.T.shape
    model = thermal_model(s, panel_conductivity=0.3, crease_conductivity=0.3, air_thickness=4.6e-3)
    nci = len(s.creases.ids)
    bim = Bimorph(np.full(nci, 50e-6), 0.2e-6, 1.0e-6, 2e9, 2e9, np.full(nci, 150e-6))
    Q = np.full(nci, 0.1 * 3.1e-3 * 5)
    state = initial_thermal_state(s)
    a, _ = electrothermal_stage(s, model, bim, state, Q, tol=5e-7)
    b, _ = electrothermal_stage(s, model, bim, state, Q, tol=5e-7, matrices=mats)
    for name in ("U", "T", "q", "crease_angle", "spring_rest"):
        x, y = getattr(a, name), getattr(b, name)
        np.testing.assert_allclose(y, x, rtol=1e-12, atol=1e-12 * np.abs(x).max(), err_msg=name)
    assert np.abs(a.U).max() > 1e-6  # it did fold


def test_structure_without_triangles_gives_empty_model():
    s = Structure(nodes=np.zeros((2, 3)) + [[0, 0, 0], [1, 0, 0]], bars=[[0, 1]], bar_area=1.0,
                  bar_E=1.0, springs=np.zeros((0, 4)), spring_k=[], spring_rest=[])  # fmt: skip
    m = thermal_model(s, panel_conductivity=1.0, crease_conductivity=1.0, air_thickness=1.0)
    assert m.triangles.shape == (0, 3)
    np.testing.assert_array_equal(chain_conductance(m, s.nodes), 0.0)


def test_compiled_system_is_the_numpy_one(monkeypatch):
    # steady_temperature's small-model path assembles in compiled code (reference geometry):
    # the numpy assembly's numbers to round-off (1e-12 of the matrices' scale)
    from holofold.mechanics import kernels
    from holofold.mechanics.thermal import _compiled_system, _element_matrices, triangle_edges

    try:
        kernels.kernel_path("compiled")
    except Exception as exc:
        pytest.skip(f"compiled path: {exc}")
    monkeypatch.setenv(kernels.ENV, "compiled")

    _, s = _gripper_structure()
    model = thermal_model(s, panel_conductivity=0.3, crease_conductivity=0.2, air_thickness=4e-3)
    rng = np.random.default_rng(3)
    n = s.n_nodes
    for scale in (0.0, 1e-6, 1e-4):
        x = s.nodes + rng.normal(0, scale, s.nodes.shape)
        e, area, _ = triangle_edges(model, x)
        ke = _element_matrices(model, e, area)
        A = np.bincount(model.dense_slots, weights=ke.ravel(), minlength=n * n).reshape(n, n)
        Ac, Gc = _compiled_system(model, x)
        G = chain_conductance(model, x)
        np.testing.assert_allclose(Ac, A, rtol=0, atol=1e-12 * np.abs(A).max())
        np.testing.assert_allclose(Gc, G, rtol=0, atol=1e-12 * np.abs(G).max())
    x = s.nodes.copy()
    a, _, c = model.triangles[5]
    x[c] = x[a]  # triangle 5 collapsed
    with pytest.raises(ValueError, match="triangle 5 .* zero area"):
        steady_temperature(model, x, np.ones(n))
