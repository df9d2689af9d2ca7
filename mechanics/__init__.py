"""holofold.mechanics: the bar-and-hinge simulator, electro-thermal actuation and modes.

Models (:mod:`~holofold.mechanics.structure`, :mod:`~holofold.mechanics.hinges`: concentrated
and compliant creases), element kernels (:mod:`~holofold.mechanics.bars`,
:mod:`~holofold.mechanics.springs`), the sparse assembly built once per topology
(:mod:`~holofold.mechanics.assembly`), solvers (:mod:`~holofold.mechanics.solvers`: Newton-
Raphson, displacement control, MGDCM, self-folding), analyses (secant stiffness, snapping),
:mod:`~holofold.mechanics.thermal`, :mod:`~holofold.mechanics.modal`, the :class:`Status` of
a computation, and every paper quirk in :mod:`~holofold.mechanics.compat`. See
docs/bar-and-hinge.md and docs/electro-thermal.md. Imports only geometry and fitting.
"""

from holofold.mechanics.analyses import (
    LoadGroup,
    SnapCheck,
    StiffnessResult,
    load_group,
    secant_stiffness,
    snap_check_mgdcm,
)
from holofold.mechanics.assembly import Assembler, SingularSystemError
from holofold.mechanics.bars import bar_forces, bar_strain
from holofold.mechanics.compat import PAPER, PHYSICAL, Profile
from holofold.mechanics.hinges import build_compliant, build_concentrated, crease_rest_targets
from holofold.mechanics.modal import eigenvalues, lumped_mass, natural_frequencies
from holofold.mechanics.solvers import (
    SolveResult,
    solve_displacement,
    solve_mgdcm,
    solve_newton,
    solve_selffold,
)
from holofold.mechanics.springs import dihedral_angle, dihedral_derivatives, spring_forces
from holofold.mechanics.status import CONVERGED, Outcome, Status, converged_mask, failed_mask
from holofold.mechanics.structure import (
    BarType,
    CreaseModel,
    SpringRole,
    Structure,
    support_mask,
)
from holofold.mechanics.thermal import (
    Bimorph,
    ThermalModel,
    ThermalState,
    crease_temperature_matrix,
    electrothermal_stage,
    heat_input_matrix,
    initial_thermal_state,
    steady_temperature,
    thermal_model,
    timoshenko_curvature,
)

__all__ = [
    # models
    "Structure",
    "CreaseModel",
    "BarType",
    "SpringRole",
    "support_mask",
    "build_concentrated",
    "build_compliant",
    "crease_rest_targets",
    "Profile",
    "PAPER",
    "PHYSICAL",
    # kernels and assembly
    "bar_forces",
    "bar_strain",
    "dihedral_angle",
    "dihedral_derivatives",
    "spring_forces",
    "Assembler",
    "SingularSystemError",
    # solvers and analyses
    "solve_newton",
    "solve_displacement",
    "solve_mgdcm",
    "solve_selffold",
    "SolveResult",
    "Status",
    "Outcome",
    "CONVERGED",
    "failed_mask",
    "converged_mask",
    "LoadGroup",
    "load_group",
    "secant_stiffness",
    "StiffnessResult",
    "snap_check_mgdcm",
    "SnapCheck",
    # electro-thermal and modal
    "ThermalModel",
    "thermal_model",
    "steady_temperature",
    "heat_input_matrix",
    "crease_temperature_matrix",
    "timoshenko_curvature",
    "Bimorph",
    "ThermalState",
    "initial_thermal_state",
    "electrothermal_stage",
    "lumped_mass",
    "natural_frequencies",
    "eigenvalues",
]
