"""holofold.mechanics: the bar-and-hinge simulator, electro-thermal actuation and modes.

Models (:mod:`~holofold.mechanics.structure`, :mod:`~holofold.mechanics.hinges`: concentrated
and compliant creases), element kernels (:mod:`~holofold.mechanics.bars`,
:mod:`~holofold.mechanics.springs`), the sparse assembly built once per topology
(:mod:`~holofold.mechanics.assembly`; the optional supernodal sparse Cholesky of large models,
:mod:`~holofold.mechanics.sparse_cholesky`), solvers (:mod:`~holofold.mechanics.solvers`: Newton-
Raphson, displacement control, MGDCM, self-folding), analyses (secant stiffness, snapping),
:mod:`~holofold.mechanics.thermal`, :mod:`~holofold.mechanics.modal`,
:mod:`~holofold.mechanics.fold_check` (a fitted surface folded from flat), the :class:`Status` of
a computation, and every paper quirk in :mod:`~holofold.mechanics.compat`. See
docs/bar-and-hinge.md and docs/electro-thermal.md. Imports only geometry and fitting.
"""

from holofold.geometry.lazy_face import ALL, attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    __file__,
    submodules=["kernels"],
    submod_attrs={
        "analyses": ALL,
        "assembly": ["Assembler", "BatchAssembler", "SingularSystemError"],
        "kernels": [
            "KERNEL_PATHS",
            "KernelPath",
            "KernelWarning",
            "check_environment",
            "small_model",
        ],
        "bars": ["bar_forces", "bar_strain"],
        "compat": ["Profile", "PAPER", "PHYSICAL"],
        "contact": ["PanelContact", "contact_model", "has_ipctk"],
        "fold_check": ALL,
        "folding": [
            "fold_pattern",
            "FoldSettings",
            "FoldResult",
            "fold_targets",
            "crease_classes",
            "default_supports",
            "MAX_FOLD_DEG",
        ],
        "pattern_simulation": [
            "PatternLoad",
            "PatternSetting",
            "PatternSimulation",
            "LoadOutcome",
            "simulate_pattern",
            "write_simulation",
            "plot_simulation",
            "scaled_pattern",
            "pattern_mass",
        ],
        "hinges": ["build_concentrated", "build_compliant", "crease_rest_targets"],
        "materials": ALL,
        "measures": ALL,
        "modal": ALL,
        "solvers": ALL,
        "springs": ["dihedral_angle", "dihedral_derivatives", "spring_forces"],
        "status": ["Status", "Outcome", "CONVERGED", "failed_mask", "converged_mask"],
        "structure": ["Structure", "CreaseModel", "BarType", "SpringRole", "support_mask"],
        "threads": ALL,
        "thermal": [
            "ThermalModel",
            "thermal_model",
            "steady_temperature",
            "heat_input_matrix",
            "crease_temperature_matrix",
            "HeatMatrices",
            "timoshenko_curvature",
            "Bimorph",
            "ThermalState",
            "initial_thermal_state",
            "electrothermal_stage",
        ],
    },
)
