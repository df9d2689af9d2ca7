"""Modelling profiles: every reference-simulator quirk behind one named switch.

The published databases of Zhu & Filipov (2022) were computed with the MATLAB simulator SWOMPS,
which has a few slips that move the numbers by up to a few per cent (docs/bar-and-hinge.md §8,
docs/electro-thermal.md §7, docs/scenarios.md §7). A :class:`Profile` names each of them:

* :data:`PAPER` keeps every quirk: it reproduces the published rows (to ~1e-6) and is what the
  paper's scenarios (:mod:`design.scenarios`) use.
* :data:`PHYSICAL` makes the physically right choice for each switch; use it for new designs
  whose numbers need not match the published databases.

Which value of each switch is physically right is stated in the field's description below.
Build your own mix with ``dataclasses.replace(PAPER, edge_bar_area_last_panel=False)``.

The gripper scripts also report their outputs through closed-form formulas with slips of their
own; :func:`gripper_final_q`, :func:`gripper_closing_step`, :func:`gripper_air_gap` and
:func:`gripper_prying_stiffness` reproduce them (patterns 1 Miura-based, 2 splitted Miura,
3 two-panel; lengths in m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Profile",
    "PAPER",
    "PHYSICAL",
    "gripper_final_q",
    "gripper_closing_step",
    "gripper_air_gap",
    "gripper_prying_stiffness",
]


@dataclass(frozen=True)
class Profile:
    """Switches for the reference simulator's quirks (True = keep the quirk, unless noted).

    Attributes
    ----------
    name : str
        Label of the profile (a structure records its profile in ``Structure.profile``).
    edge_bar_area_last_panel : bool
        Concentrated hinges: the reference sets every panel-edge bar to ``2 A_p`` of the *last*
        panel (in panel order) that contains the edge, overwriting instead of accumulating
        (SWOMPS ``Mesh_MechanicalProperty.m``). Physically right (False): the sum of the
        ``A_p`` of the panels sharing the edge (a border edge gets one ``A_p``). Keeping it
        is needed for the published data (data0 row 1 moves by -2.2 % without it).
    panel_spring_width_is_crease_width : bool
        The panel bending spring on each spoke is ``k = E_p t_p^3 L / (12 w)``; the reference
        scripts set ``w`` to the crease width ``W`` (``panelW = W``). Physically right (False):
        ``w`` is a length of the panel itself; holofold then uses ``panel_width`` when given,
        else the panel's mean spoke length (the span over which the panel bends).
    approximate_corner_offset : bool
        Compliant creases: a panel corner between two creases is moved by
        ``(W1/2) v2 + (W2/2) v1``, which is the exact offset times ``sin(beta)`` (exact only for
        right angles). Physically right (False): ``(W1 v2 + W2 v1) / (2 sin beta)``, which
        puts the corner at distance ``W/2`` from both crease lines.
    polarity_z_only : bool
        Spring orientation (docs/bar-and-hinge.md §2.5): the reference swaps i and l when the z
        component of ``(x_j - x_i) x (x_k - x_j)`` is positive and leaves springs with a zero z
        component unchanged. False adds the fallback to the y, then the x component (springs
        on vertical panels get a defined orientation). Neither changes any mechanics (the
        energy is invariant and rest angles are measured); it only fixes the meaning of
        user-given target angles. False is the better-defined choice.
    mass_skip_first_triangles : bool
        Data-era lumped mass (SWOMPS ``Dynamic_MassVector.m`` before 2022): the triangle loop
        starts after the first P triangles (P = number of panels), so those triangles get no
        mass. Physically right: False (every triangle has mass). Effect on the published
        gripper frequencies ~1e-7 relative.
    mass_centre_share : float
        Share of a panel fan triangle's mass given to the panel-centre node (the other two
        nodes share the rest equally). The data-era simulator uses 1/3 (uniform); later
        versions use 4/6. 1/3 is the consistent lumping of a triangle and is used by both
        profiles.
    reset_non_crease_rest_angles : bool
        Self-folding, thermal and dynamic stages: the reference builds the target rest angles
        from a vector of pi, so panel and diagonal springs are driven to flat (pi) rather than
        kept at their stress-free measured values. Harmless for flat panels; for warped panels
        it adds a spurious load. Physically right: False (keep their current rest angles).
    centre_triangle_aspect : float
        Concentrated hinges: a triangle panel whose aspect (longest side over height) is above
        this has no centre node: its three bars hold it flat and rigid (Origami Simulator,
        MERLIN, N5B8 keep triangles whole); the others get a centre node and a fan with panel
        bending springs. The reference gives every panel one (inf), needed for the published
        data (sheet pattern 2 has triangle panels). In a sliver the fan's sub-triangle next to
        the long side folds flat and its spring angle turns singular (Origami Simulator's
        hypar, 1:48, stalled at 13.2 %). Physically right: 10, measured on Origami
        Simulator's files (docs/bar-and-hinge.md §3.3): 0 (no triangle gets a centre) makes
        patterns whose triangles must bend stop earlier (flat_crane), 20 leaves the hypars
        stalling at 19-30 %.
    thermal_reinterpolate_from_stage_start : bool
        Electro-thermal stage: within each thermal step the self-fold interpolation restarts
        from the rest angles at the *stage* start rather than from the previous step's
        target. End points agree. Physically right: False (interpolate from the previous
        step).
    """

    name: str = "paper"
    edge_bar_area_last_panel: bool = True
    panel_spring_width_is_crease_width: bool = True
    approximate_corner_offset: bool = True
    polarity_z_only: bool = True
    mass_skip_first_triangles: bool = True
    mass_centre_share: float = 1.0 / 3.0
    reset_non_crease_rest_angles: bool = True
    thermal_reinterpolate_from_stage_start: bool = True
    centre_triangle_aspect: float = math.inf
    arccos_dihedral: bool = False
    raw_crease_polarity: bool = True
    dissipation_pi_314: bool = True
    published_gripper_stiffness: bool = True

    def __post_init__(self):
        if not float(self.centre_triangle_aspect) >= 0.0:
            raise ValueError(
                f"centre_triangle_aspect = {self.centre_triangle_aspect!r} must be >= 0 (inf: all)"
            )
        share = float(self.mass_centre_share)
        if not 0.0 <= share <= 1.0:
            raise ValueError(f"mass_centre_share = {share!r} is outside the allowed range [0, 1]")


#: Reproduces the published databases (every quirk kept).
PAPER = Profile()

#: The physically right choice for every switch.
PHYSICAL = Profile(
    name="physical",
    edge_bar_area_last_panel=False,
    panel_spring_width_is_crease_width=False,
    approximate_corner_offset=False,
    polarity_z_only=False,
    mass_skip_first_triangles=False,
    mass_centre_share=1.0 / 3.0,
    reset_non_crease_rest_angles=False,
    thermal_reinterpolate_from_stage_start=False,
    centre_triangle_aspect=10.0,
    arccos_dihedral=False,
    raw_crease_polarity=False,
    dissipation_pi_314=False,
    published_gripper_stiffness=False,
)


# --------------------------------------------------------------------------- gripper formulas
#: heating steps lost to the gripper scripts' heating ramp, per pattern (see gripper_final_q)
_RAMP_OFFSET = {1: 17.0, 2: 26.5, 3: 0.0}


def gripper_final_q(kind: int, L1, L2, step, range_: float, *, rate: float = 0.1):
    """finalQ, W: the heating power the gripper scripts report for closure at ``step``.

    ``L1``, ``L2`` (arm length and width, m) and ``step`` (closing heating step, 1-based)
    broadcast; ``range_`` is the gap between the arm roots, m; ``rate`` the heating per metre of
    crease and step, W/m. The scripts write the power in closed form: ``rate`` x the summed
    active-crease length x the cumulative ramp factor, ``step - 17`` for pattern 1 (10 steps at
    0.1, 10 at 0.2, then 1 per step), ``step - 26.5`` for pattern 2 (10 steps each at 0.05, 0.1
    and 0.2) and ``step`` for pattern 3 (no ramp). Pattern 1's sum counts the four
    base-diagonal creases (sqrt(r^2 + L2^2) / 2 each) once instead of twice, so its finalQ is
    short of the power applied. Kept: the published finalQ column is this formula (every
    published row decodes to a whole heating step).
    """
    r = float(range_)
    L1, L2, step = (np.asarray(v, float) for v in (L1, L2, step))
    s2 = np.sqrt(2.0)
    if kind == 1:
        return rate * (r + 2 * L1 + np.hypot(r, L2) + 2 * s2 * L2) * (step - 17)
    if kind == 2:
        return rate * (4 * L1 + 2 * s2 * L2 + 2 * L2 + 2 * r) * (step - 26.5)
    if kind == 3:
        return rate * 4 * L2 * step
    raise ValueError(f"gripper kind = {kind!r}; allowed: 1, 2, 3")


def gripper_closing_step(kind: int, L1, L2, final_q, range_: float, *, rate: float = 0.1):
    """Inverse of :func:`gripper_final_q`: the (real-valued) closing heating step of a
    published ``final_q`` (W); arrays broadcast. Whole numbers for the published rows."""
    unit = gripper_final_q(kind, L1, L2, 1.0, range_, rate=rate) - gripper_final_q(
        kind, L1, L2, 0.0, range_, rate=rate
    )
    return np.asarray(final_q, float) / unit + _RAMP_OFFSET[kind]


def gripper_air_gap(kind: int, L1: float, L2: float, range_: float) -> float:
    """Thickness of the air layer between a gripper and the room-temperature sink, m.

    The scripts' ``t2RT``: 1.5 x the mean active-crease length, from the summed length of
    :func:`gripper_final_q` over the 13 (pattern 1) or 22 (pattern 2) active creases, and
    1.5 L2 for pattern 3. Pattern 1's sum carries the same single count of the base diagonals;
    kept because the published temperatures were computed with it.
    """
    r = range_
    if kind == 1:
        return 1.5 * (r + 2 * L1 + math.hypot(r, L2) + 2 * math.sqrt(2) * L2) / 13
    if kind == 2:
        return 1.5 * (4 * L1 + 2 * math.sqrt(2) * L2 + 2 * L2 + 2 * r) / 22
    if kind == 3:
        return 1.5 * L2
    raise ValueError(f"gripper kind = {kind!r}; allowed: 1, 2, 3")


def gripper_prying_stiffness(
    kind: int,
    du: float,
    *,
    force: float,
    increments: int,
    run_increments: int,
    nodes: int = 2,
    profile: Profile = PAPER,
) -> float:
    """Prying stiffness of a closed gripper, N/m, as the gripper scripts report it.

    ``du`` (m) is the displacement of the probe node along the arm axis over ``increments``
    load increments of ``force`` (N on each of the ``nodes`` loaded nodes of an arm) of a
    Newton run of ``run_increments`` increments. The plain secant stiffness is
    ``increments * nodes * force / du``. With ``profile.published_gripper_stiffness`` the
    scripts' formulas instead, kept because the published stiff column is theirs:

    * pattern 1 divides the force of all ``run_increments`` (5) increments by the displacement
      after ``increments`` (3): 5/3 of the secant stiffness;
    * pattern 3 counts the force of one node, not of the arm's two: half of it;
    * pattern 2 is the secant stiffness (its run has 3 increments).
    """
    if kind not in (1, 2, 3):
        raise ValueError(f"gripper kind = {kind!r}; allowed: 1, 2, 3")
    if profile.published_gripper_stiffness and kind == 1:
        return run_increments * nodes * force / du
    if profile.published_gripper_stiffness and kind == 3:
        return increments * force / du
    return increments * nodes * force / du
