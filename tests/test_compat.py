"""Profiles of reference quirks: field set, validation, and the effect the spec documents."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from holofold.design.scenarios.single_miura import EXTENSIONS, cell_models
from holofold.mechanics.analyses import secant_stiffness
from holofold.mechanics.compat import (
    PAPER,
    PHYSICAL,
    Profile,
    gripper_air_gap,
    gripper_closing_step,
    gripper_final_q,
    gripper_prying_stiffness,
)

FIELDS = {
    "edge_bar_area_last_panel",
    "panel_spring_width_is_crease_width",
    "approximate_corner_offset",
    "polarity_z_only",
    "mass_skip_first_triangles",
    "mass_centre_share",
    "reset_non_crease_rest_angles",
    "thermal_reinterpolate_from_stage_start",
    "raw_crease_polarity",
    "dissipation_pi_314",
    "published_gripper_stiffness",
}


def test_profiles_have_every_switch():
    names = {f.name for f in dataclasses.fields(Profile)}
    assert FIELDS <= names
    for f in FIELDS - {"mass_centre_share"}:
        assert getattr(PAPER, f) is True, f
        assert getattr(PHYSICAL, f) is False, f
    assert PAPER.mass_centre_share == PHYSICAL.mass_centre_share == pytest.approx(1 / 3)
    assert PAPER.arccos_dihedral is PHYSICAL.arccos_dihedral is False  # opt-in, see its doc
    with pytest.raises(dataclasses.FrozenInstanceError):
        PAPER.polarity_z_only = False  # type: ignore[misc]
    with pytest.raises(ValueError, match="mass_centre_share"):
        Profile(mass_centre_share=1.5)


def _stiffness(row, profile):
    models = cell_models(*row, profile=profile)
    return np.array([secant_stiffness(s, g, increments=3, tol=1e-7).stiffness for s, g in models])


def test_edge_area_quirk_moves_data0_row1_as_documented(reference_data):
    """docs/bar-and-hinge.md §8.2: accumulating the edge areas gives 5870.5 / 11683.2 /
    70595.0 for data0 row 1 instead of the published 6004.7 / 11762.5 / 71445.7."""
    d = reference_data.load("data0_SingleMiura")
    row = d.iloc[0][["tcrease", "tpanel", "W", "gama"]].to_numpy()
    published = d.iloc[0][["axialstiff30", "axialstiff60", "axialstiff90"]].to_numpy()
    paper = _stiffness(row, PAPER)
    assert np.allclose(paper, published, rtol=2e-5)
    summed = _stiffness(row, dataclasses.replace(PAPER, edge_bar_area_last_panel=False))
    assert np.allclose(summed, [5870.5, 11683.2, 70595.0], rtol=2e-5)
    assert len(EXTENSIONS) == 3


def test_arccos_dihedral_matches_exact_angle_and_rounds_near_flat():
    """compat.arccos_dihedral: the reference's arccos angle, applied by the assembly."""
    from holofold.mechanics.assembly import Assembler
    from holofold.mechanics.springs import dihedral_angle
    from holofold.mechanics.structure import Structure

    def arccos_dihedral(x, springs):
        return dihedral_angle(x, springs, form="acos")

    # hinge j-k on the x axis, wing i in the xy plane, wing l rotated by phi about the hinge
    def quad(phi):
        return np.array(
            [[0.5, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0],
             [0.5, -np.cos(phi), np.sin(phi)]]
        )  # fmt: skip

    springs = np.array([[0, 1, 2, 3]])
    for phi in (0.3, 1.0, 2.0, -0.7):
        x = quad(phi)
        assert arccos_dihedral(x, springs)[0] == pytest.approx(dihedral_angle(x, springs)[0],
                                                               abs=1e-12)  # fmt: skip
    # 1e-9 rad from flat: the exact angle sees it, arccos (resolution ~1e-8 rad) does not
    x = quad(1e-9)
    assert abs(dihedral_angle(x, springs)[0] - np.pi) == pytest.approx(1e-9, rel=1e-6)
    d = abs(arccos_dihedral(x, springs)[0] - np.pi)
    assert d < 1e-12 or d > 1e-8
    # the assembler's spring moment uses the arccos angle: force = k (theta_acos - theta0) grad
    s = Structure(
        nodes=quad(0.0),
        bars=np.array([[0, 1], [1, 2], [2, 0], [1, 3], [2, 3]]),
        bar_area=np.full(5, 1e-6),
        bar_E=np.full(5, 1e9),
        springs=springs,
        spring_k=np.array([2.0]),
        spring_rest=np.array([np.pi - 0.1]),
    )
    s_acos = s.replace(profile=dataclasses.replace(PAPER, arccos_dihedral=True))
    U = quad(0.5) - quad(0.0)
    _, f_exact, _ = Assembler(s).evaluate(U)
    _, f_acos, _ = Assembler(s_acos).evaluate(U)
    np.testing.assert_allclose(f_acos, f_exact, rtol=1e-9, atol=1e-12)
    # near flat the arccos rounding reaches the moment: f scales with (theta_acos - theta0)
    U = quad(3e-9) - quad(0.0)
    x = quad(3e-9)
    t_exact, t_acos = dihedral_angle(x, springs)[0], arccos_dihedral(x, springs)[0]
    assert abs(t_exact - t_acos) > 1e-10  # the two angles differ measurably here
    _, f_exact, _ = Assembler(s).evaluate(U)
    _, f_acos, _ = Assembler(s_acos).evaluate(U)
    ratio = (t_acos - s.spring_rest[0]) / (t_exact - s.spring_rest[0])
    np.testing.assert_allclose(f_acos[9:], ratio * f_exact[9:], rtol=1e-9)


# ---------------------------------------------------------------- gripper reporting formulas
# values of the formulas as the gripper scenario computed them before they moved here (exact)
GRIPPER_L1, GRIPPER_L2 = 5.2e-3, 2.9e-3
GRIPPER_RANGE = {1: 2e-3, 2: 1e-3, 3: 2e-3}
FINAL_Q_AT_120 = {1: 0.24848978302101427, 2: 0.344102801487493, 3: 0.1392}
AIR_GAP = {1: 0.002783679421445268, 2: 0.002509257181483906, 3: 0.00435}


@pytest.mark.parametrize("kind", [1, 2, 3])
def test_gripper_final_q_closing_step_and_air_gap_keep_their_values(kind):
    r = GRIPPER_RANGE[kind]
    q = gripper_final_q(kind, GRIPPER_L1, GRIPPER_L2, 120, r)
    assert float(q) == FINAL_Q_AT_120[kind]
    step = gripper_closing_step(kind, GRIPPER_L1, GRIPPER_L2, q, r)
    assert step == pytest.approx(120, abs=1e-12)
    assert gripper_air_gap(kind, GRIPPER_L1, GRIPPER_L2, r) == AIR_GAP[kind]
    # arrays broadcast; the step offsets are the cumulative heating ramp (17 / 26.5 / 0 steps)
    steps = np.array([30.0, 31.0])
    q2 = gripper_final_q(kind, GRIPPER_L1, GRIPPER_L2, steps, r)
    offset = {1: 17.0, 2: 26.5, 3: 0.0}[kind]
    np.testing.assert_allclose(q2 / (steps - offset), q2[0] / (30 - offset), rtol=1e-14)
    np.testing.assert_allclose(gripper_closing_step(kind, GRIPPER_L1, GRIPPER_L2, q2, r), steps)


def test_gripper_final_q_undercounts_the_pattern_1_base_diagonals():
    """Pattern 1's length sum has sqrt(r^2 + L2^2) once; the four base diagonals applied are
    twice that (each half of it)."""
    r, L1, L2 = 2e-3, GRIPPER_L1, GRIPPER_L2
    applied = r + 4 * 0.5 * np.hypot(r, L2) + 2 * L1 + 2 * np.sqrt(2) * L2
    per_step = gripper_final_q(1, L1, L2, 18, r) - gripper_final_q(1, L1, L2, 17, r)
    assert per_step == pytest.approx(0.1 * (applied - np.hypot(r, L2)), rel=1e-14)
    assert gripper_air_gap(1, L1, L2, r) == pytest.approx(1.5 * per_step / 0.1 / 13, rel=1e-14)
    with pytest.raises(ValueError, match="kind"):
        gripper_final_q(4, L1, L2, 18, r)


def test_gripper_prying_stiffness_published_and_plain():
    du = 3.7e-6
    pattern12 = dict(force=1e-8, increments=3)
    pattern3 = dict(force=1e-10, increments=49, run_increments=50)
    # published formulas (values of the scenario before the move, exact)
    assert gripper_prying_stiffness(1, du, **pattern12, run_increments=5) == 0.027027027027027025
    assert gripper_prying_stiffness(2, du, **pattern12, run_increments=3) == 0.016216216216216217
    assert gripper_prying_stiffness(3, du, **pattern3) == 0.0013243243243243243
    # the plain secant stiffness: total force of an arm's two nodes over du
    plain = dataclasses.replace(PAPER, published_gripper_stiffness=False)
    assert PHYSICAL.published_gripper_stiffness is False
    k1 = gripper_prying_stiffness(1, du, **pattern12, run_increments=5, profile=plain)
    k3 = gripper_prying_stiffness(3, du, **pattern3, profile=plain)
    assert k1 == 0.016216216216216217 and k3 == 0.0026486486486486487
    assert k1 == pytest.approx(3 * 2 * 1e-8 / du, rel=1e-15)
    # pattern 1 publishes 5/3 and pattern 3 1/2 of it; pattern 2 is the plain one
    assert gripper_prying_stiffness(1, du, **pattern12, run_increments=5) == pytest.approx(
        5 / 3 * k1, rel=1e-15
    )
    assert gripper_prying_stiffness(3, du, **pattern3) == pytest.approx(k3 / 2, rel=1e-15)
    k2 = gripper_prying_stiffness(2, du, **pattern12, run_increments=3, profile=plain)
    assert k2 == gripper_prying_stiffness(2, du, **pattern12, run_increments=3)
