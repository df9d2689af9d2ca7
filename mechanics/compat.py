"""Modelling profiles: every reference-simulator quirk behind one named switch.

The published databases of Zhu & Filipov (2022) were computed with the MATLAB simulator SWOMPS,
which has a few slips that move the numbers by up to a few per cent (specs/mechanics.md 10,
specs/scenarios.md 1.3 and 7.2). A :class:`Profile` names each of them:

* :data:`PAPER` keeps every quirk: it reproduces the published rows (to ~1e-6) and is what the
  paper's scenarios (:mod:`design.scenarios`) use.
* :data:`PHYSICAL` makes the physically right choice for each switch; use it for new designs
  whose numbers need not match the published databases.

Which value of each switch is physically right is stated in the field's description below.
Build your own mix with ``dataclasses.replace(PAPER, edge_bar_area_last_panel=False)``.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Profile", "PAPER", "PHYSICAL"]


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
        Spring orientation (specs/mechanics.md 2.2-E): the reference swaps i and l when the z
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
    arccos_dihedral: bool = False
    raw_crease_polarity: bool = True
    dissipation_pi_314: bool = True
    published_gripper_stiffness: bool = True

    def __post_init__(self):
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
    arccos_dihedral=False,
    raw_crease_polarity=False,
    dissipation_pi_314=False,
    published_gripper_stiffness=False,
)
