"""Scenario 3 of the paper: electro-thermally actuated grippers, three patterns (data2).

Each design (``Pattern L1 L2 t1 t2 tpanel rate W``, SI units) is meshed with compliant creases
(width W, bimorph layers t1/t2 with an expansion mismatch of +-50e-6 1/K) and simulated in four
steps, each a function of plain data that returns its outputs and a
:class:`~holofold.mechanics.status.Status` (protocol: docs/scenarios.md §4):

A. :func:`run_frequency`: ``freqFinal``, the lowest angular natural frequency of the flat
   gripper, rad/s (the paper's scripts say Hz);
B. :func:`run_prebias`: patterns 1 and 2 get tiny out-of-plane forces that stay applied;
C. :func:`run_heating`: heating steps until the arm tips are closer than 1 mm; ``Tmax`` (°C)
   and ``finalQ`` (W, the published formula) at closure;
D. :func:`run_prying`: ``stiff``, the prying stiffness of the closed gripper, N/m.

Material and surroundings (moduli, density, bimorph mismatch, conductivities, room temperature)
are a :class:`GripperMaterial`, and the heating rate and closure distance fields of
:class:`GripperOptions`; their defaults are the scripts' constants below.

Supports and loads are the named node sets of :func:`gripper_nodes`. The reference's quirks are
switches of ``GripperOptions.profile`` and the ``gripper_*`` formulas of
:mod:`holofold.mechanics.compat`. A design that does not close within the step cap fails
(``no closure``, NaN outputs); a Miura-based design closing before heating step 18 (published
finalQ <= 0) keeps its outputs but fails (``early closure``): the paper dropped both kinds of
rows. With the defaults the closing step, hence finalQ and Tmax, of 98.5 % (two-panel), 95.5 %
(splitted) and 92.5 % (Miura-based) of the published sample rows is reproduced; the rest, and
much of the two-panel stiffness, is the round-off sensitivity of the reference's loosely
converged Newton solves (docs/scenarios.md §6.2). ``GripperOptions(converged=True)`` (scenario
``gripper-converged``) converges every solve tightly: repeatable outputs for new databases.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache, partial

import numpy as np

from holofold.design.scenarios.base import Column, Scenario, positive, single_thread
from holofold.geometry.errors import ParameterError
from holofold.geometry.gripper import DEFAULT_RANGE, GripperPattern, gripper_pattern
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.compat import (
    PAPER,
    Profile,
    gripper_air_gap,
    gripper_closing_step,
    gripper_final_q,
    gripper_prying_stiffness,
)
from holofold.mechanics.hinges import build_compliant
from holofold.mechanics.modal import lumped_mass, natural_frequencies
from holofold.mechanics.solvers import solve_newton
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.status import CONVERGED, Outcome, Status
from holofold.mechanics.structure import Structure
from holofold.mechanics.thermal import (
    Bimorph,
    HeatMatrices,
    ThermalState,
    electrothermal_stage,
    initial_thermal_state,
    thermal_model,
)

__all__ = [
    "SCENARIO",
    "SCENARIO_CONVERGED",
    "GripperMaterial",
    "PAPER_MATERIAL",
    "GripperOptions",
    "GripperResult",
    "GripperModel",
    "GripperNodes",
    "FrequencyResult",
    "PrebiasResult",
    "HeatingResult",
    "PryingResult",
    "simulate",
    "evaluate",
    "check",
    "gripper_model",
    "gripper_nodes",
    "run_frequency",
    "run_prebias",
    "run_heating",
    "run_prying",
    "build_model",
    "natural_frequency",
    "published_q",
    "decode_closing_step",
    "STATUS_NO_CLOSURE",
    "gripper_shape",
    "write_gripper_files",
    "gripper_row_timeout",
]

# constants of every gripper script (the defaults of GripperMaterial and GripperOptions)
E = 2e9
NU = 0.3
DENSITY = 1200.0
QLOAD = 0.1  #: W per metre of crease per heating step
D_ALPHA = 50e-6  #: 1/K
CLOSURE = 1e-3  #: m
K_PANEL = K_CREASE = 0.3  #: W/(m K)
K_AIR = 0.026
ROOM_T = 21.0
ENV_LAYERS = 10
DISSIPATION_DEG = 20.0
STEP_CAP = {1: 400, 2: 400, 3: 300}


def gripper_row_timeout(step_cap: int | None = None) -> float:
    """Seconds a gripper row may take, from the size of its work: 60 s (a process's first row
    compiles the kernels in 9-13 s) plus 0.15 s per heating step of the cap (``step_cap``, or
    the largest pattern's). Measured: about 6 ms per heating step, 2.3 s for the slowest of six
    warm rows (cap 400), so 120 s by default is 50 times that; a row past it (a design far
    outside the paper's sizes: arms of metres took 20 s per row) is cut short and recorded as
    a timeout."""
    cap = step_cap or max(STEP_CAP.values())
    return 60.0 + 0.15 * cap


PREBIAS_FORCE = 1e-10  #: N per node and increment (step B)
PREBIAS_INCREMENTS = 10
PREBIAS_TOL = 5e-6  #: m
STATUS_NO_CLOSURE = Status.failed("no closure")
#: tolerances of ``GripperOptions(converged=True)``: self-folding residual (N), load-control
#: displacement step (m), and the iteration cap of every Newton solve
CONVERGED_TOL = {"force": 1e-10, "displacement": 1e-12, "max_iter": 200}


@dataclass(frozen=True)
class GripperMaterial:
    """Material of panels, creases and bimorph, and the surroundings; the defaults are the
    scripts' constants (:data:`E`, :data:`NU`, ...), which reproduce the published database.

    Attributes
    ----------
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio of panels, creases and both bimorph layers.
    density : float
        kg/m^3 (lumped masses of step A).
    d_alpha : float
        Thermal expansion mismatch of the bimorph layers, 1/K.
    k_panel, k_crease, k_air : float
        Thermal conductivities of panels, creases and the surrounding air, W/(m K).
    room_temperature : float
        Ambient and initial temperature, °C.
    env_layers : int
        Air layers of the thermal model of the surroundings.
    dissipation_deg : float
        Angle of the heat-dissipation cone into the air, degrees.
    """

    E: float = E
    nu: float = NU
    density: float = DENSITY
    d_alpha: float = D_ALPHA
    k_panel: float = K_PANEL
    k_crease: float = K_CREASE
    k_air: float = K_AIR
    room_temperature: float = ROOM_T
    env_layers: int = ENV_LAYERS
    dissipation_deg: float = DISSIPATION_DEG


#: the scripts' material and surroundings
PAPER_MATERIAL = GripperMaterial()


def _ramp(pattern: int, step: int) -> tuple[float, float]:
    """(heating factor, self-folding tolerance in N) of heating step ``step`` (1-based)."""
    if pattern == 1:
        return (0.1, 1e-7) if step <= 10 else (0.2, 1e-6) if step <= 20 else (1.0, 2e-6)
    if pattern == 2:
        if step <= 10:
            return 0.05, 1e-7
        if step <= 20:
            return 0.1, 1e-6
        return (0.2, 2e-6) if step <= 30 else (1.0, 2e-6)
    return 1.0, 5e-7


def published_q(pattern: int, L1, L2, step, range_: float | None = None, q_load: float = QLOAD):
    """finalQ (W) for closure at heating step ``step``: :func:`~holofold.mechanics.compat.
    gripper_final_q` at the heating rate ``q_load`` (W/m per step; default this scenario's) and,
    by default, the pattern's range."""
    r = DEFAULT_RANGE[pattern] if range_ is None else range_
    return gripper_final_q(pattern, L1, L2, step, r, rate=q_load)


def decode_closing_step(
    pattern: int, L1, L2, finalQ, range_: float | None = None, q_load: float = QLOAD
):
    """The (real-valued) heating step of a published finalQ (inverse of :func:`published_q`)."""
    r = DEFAULT_RANGE[pattern] if range_ is None else range_
    return gripper_closing_step(pattern, L1, L2, finalQ, r, rate=q_load)


@dataclass(frozen=True)
class GripperOptions:
    """Simulation options; the defaults reproduce the published database.

    Attributes
    ----------
    profile : Profile
        Paper-compatibility switches (:data:`~holofold.mechanics.compat.PAPER`); those of the
        gripper are ``raw_crease_polarity``, ``dissipation_pi_314``,
        ``published_gripper_stiffness`` and ``arccos_dihedral``.
    step_cap : int or None
        Heating-step cap (default 400 / 400 / 300 per pattern).
    prebias_7cd7abc : bool
        Miura-based pre-bias supports of script version 7cd7abc (x of the base-triangle
        centres free) instead of 2ede7cc (which version made the published data is not known).
    stiffness_tol : float
        Newton tolerance (m) of the 1e-8 N prying runs of patterns 1 and 2 (the scripts'
        first 1e-10 N runs use 1e-7).
    keep_history : bool
        Keep per-step tip distance and Tmax, the prying runs and the last shape in the result.
    converged : bool
        Run every Newton solve to a tight tolerance (:data:`CONVERGED_TOL`) instead of the
        scripts' loose ones: the outputs are then repeatable functions of the design (a 1e-15
        change of the input moves them by < 1e-11). Use it for new databases; the default
        reproduces the published one.
    material : GripperMaterial
        Material and surroundings the model is built with (:func:`simulate`).
    q_load : float
        Heating power per metre of crease and heating step before the ramp factor, W/m
        (:data:`QLOAD`; also the rate of the finalQ formula).
    closure : float
        Tip distance below which the gripper counts as closed, m (:data:`CLOSURE`).
    """

    profile: Profile = PAPER
    step_cap: int | None = None
    prebias_7cd7abc: bool = False
    stiffness_tol: float = 1e-7
    keep_history: bool = False
    converged: bool = False
    material: GripperMaterial = PAPER_MATERIAL
    q_load: float = QLOAD
    closure: float = CLOSURE

    def tolerance(self, tol: float, kind: str) -> dict:
        """Keyword arguments ``tol``/``max_iter`` of one solve: the script's ``tol`` or, with
        ``converged``, the tight tolerance of ``kind`` ("force", N, or "displacement", m)."""
        if not self.converged:
            return {"tol": tol}
        return {"tol": CONVERGED_TOL[kind], "max_iter": CONVERGED_TOL["max_iter"]}


@dataclass(frozen=True, eq=False)
class GripperResult:
    """Outputs of one gripper simulation (units: rad/s, W, °C, N/m).

    Kept only with ``GripperOptions(keep_history=True)``: ``tip_distance`` (m) and
    ``Tmax_history`` (°C) per heating step, ``stiffness_runs`` (the prying Newton
    :class:`~mechanics.solvers.SolveResult` s), and the meshed shape at the last heating step
    (the closing one, or the cap): flat ``nodes`` (nn, 3) m, ``triangles`` (nt, 3) node ids,
    ``displacement`` (nn, 3) m and nodal ``temperature`` (nn,) °C.
    """

    freqFinal: float
    finalQ: float
    Tmax: float
    stiff: float
    closing_step: int | None
    status: Status
    tip_distance: np.ndarray = field(default_factory=lambda: np.zeros(0))
    Tmax_history: np.ndarray = field(default_factory=lambda: np.zeros(0))
    unconverged_steps: int = 0
    stiffness_runs: tuple = ()
    nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.intp))
    displacement: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    temperature: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def as_row(self) -> dict:
        return {
            "freqFinal": self.freqFinal,
            "finalQ": self.finalQ,
            "Tmax": self.Tmax,
            "stiff": self.stiff,
            "status": self.status,
        }


# --------------------------------------------------------------------------- named node sets
#: ``((nodes, dofs), ...)``: support groups for :meth:`Structure.fixed`
Supports = tuple[tuple[np.ndarray, str], ...]
_NONE = np.zeros(0, np.intp)


@dataclass(frozen=True, eq=False)
class GripperNodes:
    """Named node sets of one meshed gripper: 0-based node ids of its :class:`Structure`.

    Loads put the same force on every node of a set. Node sets are (k,) int arrays.

    Attributes
    ----------
    base, base_centres : (k,) int
        The held part of the base: pattern 1 the copies of vertices 1 and 2 in the two base
        triangles and the triangles' centres; patterns 2, 3 the corners of base panel 1 (no
        centres).
    tips : (2,) int
        The arm-tip pair whose distance decides closure (step C).
    prebias_down, prebias_up : (k,) int
        Pushed in -z / +z in step B (empty for pattern 3).
    pry_plus, pry_minus : (k,) int
        Pulled along +``arm_axis`` / -``arm_axis`` in step D, opening the tips.
    probe : int
        Node whose displacement along ``arm_axis`` gives the prying stiffness.
    arm_axis : int
        0 (x: pattern 1) or 1 (y: patterns 2, 3).
    clamp, hold, hold_7cd7abc, hold_heating : Supports
        Supports of step A (the base in every DOF), of steps B and D, of step B with
        ``GripperOptions(prebias_7cd7abc=True)`` and of step C.
    """

    base: np.ndarray
    base_centres: np.ndarray
    tips: np.ndarray
    prebias_down: np.ndarray
    prebias_up: np.ndarray
    pry_plus: np.ndarray
    pry_minus: np.ndarray
    probe: int
    arm_axis: int
    clamp: Supports
    hold: Supports
    hold_7cd7abc: Supports
    hold_heating: Supports


def _copies(s: Structure, pairs) -> np.ndarray:
    """Node of each ``(vertex, panel)`` of ``pairs`` (reference numbers, 1-based): the copy of
    that pattern vertex in that panel of the compliant mesh, in the order given."""
    out = []
    for v, p in pairs:
        node = s.vertex_nodes(v - 1, panel=p - 1)
        if len(node) != 1:
            raise ValueError(f"vertex {v} has {len(node)} copies in panel {p}, not one")
        out.append(node[0])
    return np.array(out, np.intp)


def _crease_end(s: Structure, creases) -> np.ndarray:
    """First centre-line end node (p1) of each crease (reference numbers, 1-based)."""
    ids = np.asarray(creases) - 1
    rows = np.searchsorted(s.creases.ids, ids)
    if not np.array_equal(s.creases.ids[np.minimum(rows, len(s.creases) - 1)], ids):
        raise ValueError(f"creases {list(creases)} are not all modelled creases")
    return s.creases.nodes[rows, 4]


def _miura_based_nodes(s: Structure) -> GripperNodes:
    # reference node ids (1-based) in the comments, as the scripts list them
    tri1 = _copies(s, [(1, 1), (2, 1)])  # vertices 1, 2 in base triangle 1: 1, 3
    tri2 = _copies(s, [(1, 2), (2, 2)])  # ... in base triangle 2: 4, 5
    centres = s.panel_centres[[0, 1]]  # of the base triangles: 74, 75
    return GripperNodes(
        base=np.concatenate([tri1, tri2]),
        base_centres=centres,
        tips=_crease_end(s, (12, 19)),  # tip end of each arm's axial crease: 59, 71
        # every copy of vertex 3 and the base-triangle-2 copy of vertex 4 down: 2, 6, 8, 24;
        # the other two copies of vertex 4 up: 14, 27 (as the script lists them)
        prebias_down=_copies(s, [(3, 1), (4, 2), (3, 3), (3, 7)]),
        prebias_up=_copies(s, [(4, 4), (4, 8)]),
        pry_plus=s.vertex_nodes(7),  # both copies of the +x arm tip, vertex 8: 16, 19
        pry_minus=s.vertex_nodes(11),  # of the -x arm tip, vertex 12: 29, 32
        probe=int(_copies(s, [(8, 5)])[0]),  # 16
        arm_axis=0,
        clamp=((np.concatenate([tri1, tri2, centres]), "xyz"),),
        hold=((tri1, "xy"), (tri2, "x"), (centres, "xz")),
        hold_7cd7abc=((tri1, "xy"), (tri2, "x"), (centres, "z")),
        # the script's thermal list has node 4 (vertex 1, triangle 2) where the others have
        # node 3 (vertex 2, triangle 1): 1 xy, 4 xy, 4 x, 5 x, 74 xz, 75 xz; node 3 is free.
        # Kept: the published temperatures and closing steps were computed with it.
        hold_heating=((_copies(s, [(1, 1), (1, 2)]), "xy"), (tri2, "x"), (centres, "xz")),
    )


def _splitted_nodes(s: Structure) -> GripperNodes:
    base = _copies(s, [(1, 1), (2, 1), (3, 1), (4, 1)])  # the base square: 1-4
    plus = _copies(s, [(15, 8), (14, 8)])  # tip edge of the +y arm's middle panel: 31, 32
    minus = _copies(s, [(22, 14), (23, 14)])  # ... of the -y arm's: 53, 54
    fixed = ((base, "xyz"),)
    return GripperNodes(
        base=base,
        base_centres=_NONE,
        tips=_copies(s, [(14, 8), (22, 14)]),  # the tip corners at x = -L2/4: 32, 53
        # outer corners at the arm split line, in their root-side panels: 15, 24, 38, 46
        prebias_down=_copies(s, [(12, 4), (9, 6), (17, 10), (20, 12)]),
        prebias_up=np.concatenate([plus, minus]),
        pry_plus=plus,
        pry_minus=minus,
        probe=int(plus[0]),  # 31
        arm_axis=1,
        clamp=fixed,
        hold=fixed,
        hold_7cd7abc=fixed,
        hold_heating=fixed,
    )


def _two_panel_nodes(s: Structure) -> GripperNodes:
    base = _copies(s, [(1, 1), (2, 1), (4, 1), (3, 1)])  # base panel 1 in its vertex order: 1-4
    plus = _copies(s, [(8, 3), (7, 3)])  # tip edge of the +y arm: 11, 12
    fixed = ((base, "xyz"),)
    return GripperNodes(
        base=base,
        base_centres=_NONE,
        tips=_copies(s, [(7, 3), (11, 5)]),  # the tip corners at x = 0: 12, 17
        prebias_down=_NONE,
        prebias_up=_NONE,
        pry_plus=plus,
        pry_minus=_copies(s, [(11, 5), (12, 5)]),  # tip edge of the -y arm: 17, 18
        probe=int(plus[0]),  # 11
        arm_axis=1,
        clamp=fixed,
        hold=fixed,
        hold_7cd7abc=fixed,
        hold_heating=fixed,
    )


def gripper_nodes(grip: GripperPattern, structure: Structure) -> GripperNodes:
    """The named node sets of ``structure``, the compliant-crease model of ``grip``
    (:func:`build_model`); they are the node ids of the reference scripts minus one."""
    build = {1: _miura_based_nodes, 2: _splitted_nodes, 3: _two_panel_nodes}[grip.kind]
    return build(structure)


# --------------------------------------------------------------------------- the model
def build_model(
    pattern: int,
    L1,
    L2,
    t1,
    t2,
    tpanel,
    rate,
    W,
    *,
    profile: Profile = PAPER,
    material: GripperMaterial = PAPER_MATERIAL,
):
    """Pattern and compliant-crease structure (no supports) of one gripper design.

    Returns ``(GripperPattern, Structure)``, E and nu from ``material``. With
    ``profile.raw_crease_polarity`` the crease springs keep the reference's raw orientation, to
    which the pattern's ``alpha_sign`` refers; without it use ``fold_sign`` (both give the same
    physical folding).
    """
    grip = gripper_pattern(pattern, L1, L2, rate)
    s = build_compliant(
        grip.pattern,
        crease_width=W,
        crease_thickness=t1 + t2,
        panel_thickness=tpanel,
        E_panel=material.E,
        E_crease=material.E,
        nu_panel=material.nu,
        nu_crease=material.nu,
        diagonal_rate=100.0 if pattern == 3 else 4.0,
        profile=profile,
    )
    return grip, s


@dataclass(frozen=True, eq=False)
class GripperModel:
    """One meshed gripper design, ready for steps A-D.

    Attributes
    ----------
    grip : GripperPattern
    structure : Structure
        Compliant-crease model without supports; ``structure.profile`` is the run's profile.
    nodes : GripperNodes
    bimorph : Bimorph
        Bimorph coating of the creases, in ``structure.creases`` order.
    heat_length : (nci,) float
        Heated length of each crease, m, in ``structure.creases`` order.
    material : GripperMaterial
        What the model is made of; steps A-C take density, conductivities and room temperature
        from it.
    """

    grip: GripperPattern
    structure: Structure
    nodes: GripperNodes
    bimorph: Bimorph
    heat_length: np.ndarray
    material: GripperMaterial = PAPER_MATERIAL

    @property
    def kind(self) -> int:
        return self.grip.kind


def gripper_model(
    row, profile: Profile = PAPER, material: GripperMaterial = PAPER_MATERIAL
) -> GripperModel:
    """The model of one design (``row``: mapping with the 8 feature columns, SI units)."""
    P = int(round(row["Pattern"]))
    L1, L2, t1, t2, tp, rate, W = (
        float(row[k]) for k in ("L1", "L2", "t1", "t2", "tpanel", "rate", "W")
    )
    grip, s = build_model(P, L1, L2, t1, t2, tp, rate, W, profile=profile, material=material)
    if not np.array_equal(s.creases.ids, grip.active):
        raise ValueError("every interior crease of a gripper pattern must be active")
    sign = grip.alpha_sign if profile.raw_crease_polarity else grip.fold_sign
    n = len(grip.active)
    E, d_alpha = material.E, material.d_alpha
    bimorph = Bimorph(d_alpha=d_alpha * sign, t1=t1, t2=t2, E1=E, E2=E, width=np.full(n, W))
    return GripperModel(grip, s, gripper_nodes(grip, s), bimorph, grip.heat_length, material)


# --------------------------------------------------------------------------- step A
@dataclass(frozen=True, eq=False)
class FrequencyResult:
    """Step A: ``freqFinal``, rad/s, and its status."""

    freqFinal: float
    status: Status


def _flat_frequency(
    s: Structure, n_panels: int, profile: Profile, density: float = DENSITY
) -> float:
    """Lowest angular natural frequency (rad/s) of the supported structure ``s``, unloaded
    (``density`` in kg/m^3)."""
    _, _, K = Assembler(s).evaluate(np.zeros((s.n_nodes, 3)))
    m = lumped_mass(
        s,
        density,
        centre_share=profile.mass_centre_share,
        skip_first=n_panels if profile.mass_skip_first_triangles else 0,
    )
    return float(natural_frequencies(K, np.repeat(m, 3), s.free_dofs, n=1)[0])


def run_frequency(model: GripperModel) -> FrequencyResult:
    """Step A: the flat, unloaded gripper with its base clamped (``nodes.clamp``)."""
    s = model.structure
    clamped = s.fixed(model.nodes.clamp)
    w = _flat_frequency(clamped, model.grip.pattern.n_faces, s.profile, model.material.density)
    status = CONVERGED if math.isfinite(w) else Status.failed(f"not finite ({w!r})")
    return FrequencyResult(w, status)


def natural_frequency(
    pattern_id: int,
    grip: GripperPattern,
    structure: Structure,
    profile: Profile | None = None,
    density: float = DENSITY,
) -> float:
    """freqFinal (rad/s) of a model from :func:`build_model` (step A alone, one BLAS thread).

    ``profile`` sets the mass switches (default: the structure's); ``density`` in kg/m^3."""
    if grip.kind != pattern_id:
        raise ValueError(f"pattern_id = {pattern_id!r} but the pattern is of kind {grip.kind}")
    s = structure.fixed(gripper_nodes(grip, structure).clamp)
    with single_thread():
        return _flat_frequency(s, grip.pattern.n_faces, profile or structure.profile, density)


# --------------------------------------------------------------------------- step B
@dataclass(frozen=True, eq=False)
class PrebiasResult:
    """Step B: the state to heat from (U, applied force), the Newton run (None for pattern 3,
    which has no pre-bias) and its status."""

    state: ThermalState
    run: SolveResult | None
    status: Status


def _nodal_load(n_nodes: int, groups, force: float) -> np.ndarray:
    """(nn, 3) load, N: ``force`` on every node of each ``(nodes, axis, sign)`` group."""
    F = np.zeros((n_nodes, 3))
    for nodes, axis, sign in groups:
        F[nodes, axis] = sign * force
    return F


def run_prebias(model: GripperModel, options: GripperOptions) -> PrebiasResult:
    """Step B: ``PREBIAS_FORCE`` per node and increment, -z on ``prebias_down`` and +z on
    ``prebias_up``, ``PREBIAS_INCREMENTS`` Newton increments (these forces stay applied)."""
    s, n = model.structure, model.nodes
    state = initial_thermal_state(s, model.material.room_temperature)
    if not len(n.prebias_down) + len(n.prebias_up):
        return PrebiasResult(state, None, CONVERGED)
    sb = s.fixed(n.hold_7cd7abc if options.prebias_7cd7abc else n.hold)
    load = _nodal_load(
        s.n_nodes, ((n.prebias_down, 2, -1.0), (n.prebias_up, 2, 1.0)), PREBIAS_FORCE
    )
    run = solve_newton(
        sb, load, increments=PREBIAS_INCREMENTS, assembler=Assembler(sb),
        **options.tolerance(PREBIAS_TOL, "displacement"),
    )  # fmt: skip
    state = state.replace(U=run.U.copy(), force=run.applied_force.copy())
    return PrebiasResult(state, run, run.status)


# --------------------------------------------------------------------------- step C
@dataclass(frozen=True, eq=False)
class HeatingResult:
    """Step C: the state at the last heating step, the closing step (None if the tips did not
    close), per-step ``tip_distance`` (m) and ``Tmax_history`` (°C), the number of heating
    steps whose self-folding solve missed its tolerance, and the status."""

    state: ThermalState
    closing_step: int | None
    tip_distance: np.ndarray
    Tmax_history: np.ndarray
    unconverged_steps: int
    status: Status

    @property
    def Tmax(self) -> float:
        """Highest nodal temperature at closure, °C (NaN without closure)."""
        return float(self.state.T.max()) if self.closing_step is not None else math.nan


def run_heating(model: GripperModel, start: ThermalState, options: GripperOptions) -> HeatingResult:
    """Step C: each heating step adds ``ramp * options.q_load * heat_length`` (W) to the creases
    and re-equilibrates, until the tips are closer than ``options.closure`` or the step cap.
    Conductivities and room temperature are the model's (``model.material``)."""
    g, n, mat = model.grip, model.nodes, model.material
    s = model.structure.fixed(n.hold_heating)
    asm = Assembler(s)
    thermal = thermal_model(
        s,
        panel_conductivity=mat.k_panel,
        crease_conductivity=mat.k_crease,
        air_thickness=gripper_air_gap(g.kind, g.L1, g.L2, g.range),
        env_conductivity=mat.k_air,
        env_layers=mat.env_layers,
        dissipation_deg=mat.dissipation_deg,
        room_temperature=mat.room_temperature,
    )
    matrices = HeatMatrices.of(s)
    a, b = n.tips
    state, dist, tmax, unconverged = start, [], [], 0
    closing, status = None, STATUS_NO_CLOSURE
    for step in range(1, (options.step_cap or STEP_CAP[g.kind]) + 1):
        factor, tol = _ramp(g.kind, step)
        state, results = electrothermal_stage(
            s, thermal, model.bimorph, state, factor * options.q_load * model.heat_length,
            **options.tolerance(tol, "force"), assembler=asm, matrices=matrices,
        )  # fmt: skip
        unconverged += sum(int(not r.ok) for r in results)
        d = (s.nodes[a] + state.U[a]) - (s.nodes[b] + state.U[b])
        dist.append(math.sqrt(d.dot(d)))  # = np.linalg.norm(d): sqrt of the same dot
        tmax.append(float(state.T.max()))
        if results[-1].failed:
            status = Status.failed(f"heating step {step}: {results[-1].status}")
            break
        if dist[-1] < options.closure:
            closing = step
            why = f"{unconverged} of {step} heating steps did not meet the tolerance"
            status = Status.not_converged(why) if unconverged else CONVERGED
            break
    return HeatingResult(state, closing, np.array(dist), np.array(tmax), unconverged, status)


# --------------------------------------------------------------------------- step D
@dataclass(frozen=True, eq=False)
class PryingResult:
    """Step D: ``stiff`` (N/m; NaN if a run failed), the Newton runs and the status."""

    stiff: float
    runs: tuple[SolveResult, ...]

    @property
    def parts(self) -> dict[str, Status]:
        """Status of each run, labelled as in the row status."""
        return {f"prying-stiffness run {k}": r.status for k, r in enumerate(self.runs, 1)}

    @property
    def status(self) -> Status:
        return Status.gather(self.parts)


def run_prying(model: GripperModel, state: ThermalState, options: GripperOptions) -> PryingResult:
    """Step D, from the closed ``state`` (its forces and rest angles kept): ``pry_plus`` and
    ``pry_minus`` pulled apart along the arms, stiffness by the compat formula.

    Pattern 3: 50 increments of 1e-10 N per node, ``du`` of ``probe`` between increments 1 and
    50. Patterns 1, 2: 3 increments of 1e-10 N, then 5 (pattern 1) or 3 of 1e-8 N, ``du`` over
    the first 3 of the second run.
    """
    n, kind = model.nodes, model.kind
    s = model.structure.fixed(n.hold).with_rest_angles(state.spring_rest)
    asm = Assembler(s)
    opening = ((n.pry_minus, n.arm_axis, -1.0), (n.pry_plus, n.arm_axis, 1.0))

    def pry(force, increments, tol, U0, F0):
        return solve_newton(
            s, _nodal_load(s.n_nodes, opening, force), increments=increments, U0=U0, F0=F0,
            assembler=asm, **options.tolerance(tol, "displacement"),
        )  # fmt: skip

    if kind == 3:
        runs = (pry(1e-10, 50, 5e-6, state.U, state.force),)
        counted = dict(force=1e-10, increments=49, run_increments=50)
    else:
        r1 = pry(1e-10, 3, 1e-7, state.U, state.force)
        n2 = 5 if kind == 1 else 3
        runs = (r1, pry(1e-8, n2, options.stiffness_tol, r1.U, r1.applied_force))
        counted = dict(force=1e-8, increments=3, run_increments=n2)
    if any(r.failed for r in runs):
        return PryingResult(math.nan, runs)
    u = runs[-1].U_history[:, n.probe, n.arm_axis]
    du = abs(u[49] - u[0]) if kind == 3 else abs(u[2] - runs[0].U[n.probe, n.arm_axis])
    stiff = gripper_prying_stiffness(kind, du, **counted, profile=s.profile)
    return PryingResult(float(stiff), runs)


# --------------------------------------------------------------------------- steps A-D
def simulate(row, options: GripperOptions = GripperOptions()) -> GripperResult:
    """Steps A-D for one design (``row``: mapping with the 8 feature columns, SI units), with
    BLAS limited to one thread (the many small dense solves are slower when threads contend)."""
    errs = check(row)
    if errs:
        raise ParameterError("; ".join(errs))
    with single_thread():
        model = gripper_model(row, options.profile, options.material)
        freq = run_frequency(model)
        prebias = run_prebias(model, options)
        heating = run_heating(model, prebias.state, options)
        closed = heating.closing_step is not None
        prying = run_prying(model, heating.state, options) if closed else None
    g, keep = model.grip, options.keep_history
    history = _history(model, heating, prying) if keep else {}
    if prying is None:
        nan = math.nan
        return GripperResult(
            freq.freqFinal, nan, nan, nan, None, heating.status,
            unconverged_steps=heating.unconverged_steps, **history,
        )  # fmt: skip
    finalQ = float(published_q(g.kind, g.L1, g.L2, heating.closing_step, g.range, options.q_load))
    if g.kind == 1 and finalQ <= 0:  # the script discarded these rows
        step = heating.closing_step
        status = Status.failed(f"early closure at heating step {step} (published finalQ <= 0)")
    else:
        parts = {"natural frequency": freq.status, "pre-bias": prebias.status}
        parts |= {"heating": heating.status, **prying.parts}
        finite = np.isfinite([freq.freqFinal, finalQ, heating.Tmax, prying.stiff]).all()
        status = Status.gather(parts, worst=Outcome.NOT_CONVERGED if finite else None)
    return GripperResult(
        freq.freqFinal, finalQ, heating.Tmax, prying.stiff, heating.closing_step, status,
        unconverged_steps=heating.unconverged_steps, **history,
    )  # fmt: skip


def _history(model: GripperModel, heating: HeatingResult, prying: PryingResult | None) -> dict:
    """The ``keep_history`` fields of :class:`GripperResult`."""
    s = model.structure
    return dict(
        tip_distance=heating.tip_distance,
        Tmax_history=heating.Tmax_history,
        stiffness_runs=prying.runs if prying is not None else (),
        nodes=s.nodes.copy(),
        triangles=np.asarray(s.triangles, np.intp).copy(),
        displacement=heating.state.U.copy(),
        temperature=np.asarray(heating.state.T, float).copy(),
    )


FEATURES = (
    Column("Pattern", "-", "1 Miura-based, 2 splitted Miura, 3 two-panel", choices=(1, 2, 3)),
    Column("L1", "m", "arm length", 3e-3, 7e-3, display="mm"),
    Column("L2", "m", "arm width", 2e-3, 4e-3, display="mm"),
    Column("t1", "m", "bimorph layer 1 thickness", 0.15e-6, 0.25e-6, display="um"),
    Column("t2", "m", "bimorph layer 2 thickness", 0.6e-6, 1.0e-6, display="um"),
    Column("tpanel", "m", "panel thickness", 10e-6, 30e-6, display="um"),
    Column("rate", "-", "tip-segment fraction of L1", 0.2, 0.6),
    Column("W", "m", "crease width", 100e-6, 300e-6, display="um"),
)
PERFORMANCE = (
    Column("freqFinal", "rad/s", "lowest angular natural frequency of the flat gripper"),
    Column("finalQ", "W", "heating power at closure (published formula)"),
    Column("Tmax", "degC", "maximum temperature at closure"),
    Column("stiff", "N/m", "prying stiffness of the closed gripper (published formula)"),
)


def check(row) -> list[str]:
    """Physical validity of one design (empty if valid)."""
    errs = positive(row, ("L1", "L2", "t1", "t2", "tpanel", "rate", "W"))
    p = row.get("Pattern")
    if p not in (1, 2, 3) and p not in (1.0, 2.0, 3.0):
        errs.append(f"Pattern = {p!r} must be 1, 2 or 3")
        return errs
    if errs:
        return errs
    P, L1, L2, rate, W = int(p), row["L1"], row["L2"], row["rate"], row["W"]
    if rate >= 1:
        errs.append(f"rate = {rate!r} must be < 1")
    elif P in (1, 2) and (1 - rate) * L1 <= L2 / 2:
        errs.append(
            f"(1 - rate) L1 = {(1 - rate) * L1:.4g} m must exceed L2/2 = {L2 / 2:.4g} m "
            f"for pattern {P}"
        )
    if P == 3 and W >= (1 - rate) * L1:
        errs.append(f"W = {W!r} m must be smaller than the root-panel length (1 - rate) L1")
    if W >= L2 / 2:
        errs.append(f"W = {W!r} m must be smaller than L2/2 = {L2 / 2:.4g} m")
    return errs


def evaluate(row) -> dict:
    """freqFinal (rad/s), finalQ (W), Tmax (°C), stiff (N/m) and status for one design."""
    return simulate(row).as_row()


def evaluate_converged(row) -> dict:
    """As :func:`evaluate`, every Newton solve converged tightly (``converged=True``)."""
    return simulate(row, CONVERGED_OPTIONS).as_row()


def gripper_shape(row) -> CreasePattern:
    """The design's stress-free (flat) gripper pattern, m."""
    return gripper_pattern(int(round(row["Pattern"])), row["L1"], row["L2"], row["rate"]).pattern


def write_gripper_files(row, folder, units: str = "mm", cutter=None):
    """The flat gripper's fabrication set (:func:`~holofold.geometry.write_fabrication_set`):
    FOLD, SVG and DXF for ``cutter``, STL/OBJ and the thick solid (meshes in ``units``)."""
    from holofold.geometry import write_fabrication_set  # trimesh: only for files

    return write_fabrication_set(
        gripper_shape(row), folder, panel_thickness=float(row["tpanel"]),
        crease_width=float(row["W"]), units=units, cutter=cutter,
    )  # fmt: skip


# ------------------------------------------------------ the closed state: files and view
@lru_cache(maxsize=8)
def _closed(options: GripperOptions, items: tuple):
    row = dict(items)
    result = simulate(row, replace(options, keep_history=True))
    model = gripper_model(row, options.profile, options.material)
    return result, model


def closed_gripper(options: GripperOptions, row):
    """(GripperResult with its history, GripperModel) of one design: the shape and the
    temperatures at the closing heating step (or at the step cap if it never closes)."""
    return _closed(options, tuple(sorted((k, float(v)) for k, v in dict(row).items())))


def _closed_mesh(options: GripperOptions, row):
    import trimesh

    res, _ = closed_gripper(options, row)
    return trimesh.Trimesh(res.nodes + res.displacement, res.triangles, process=False), res


def write_closed_gripper_files(
    options: GripperOptions, row, folder, units: str = "mm", cutter=None
):
    """The flat gripper's fabrication set (:func:`write_gripper_files`) and its closed (heated)
    state: ``closed.stl`` (key ``closed``: the mid-surface at the closing heating step, in
    ``units``) and ``closed_temperature.ply`` (``closed_temperature``: the same, each vertex
    coloured by its temperature, blue at room temperature to red at Tmax)."""
    from pathlib import Path

    from holofold.geometry import export

    fab = write_gripper_files(row, folder, units=units, cutter=cutter)
    mesh, res = _closed_mesh(options, row)
    T = np.asarray(res.temperature, float)
    s = (T - T.min()) / max(float(np.ptp(T)), 1e-12)
    colours = np.column_stack(
        [
            255 * np.minimum(1, 2 * s),
            40 + 200 * (1 - np.abs(2 * s - 1)),
            255 * np.maximum(0, 1 - 2 * s),
            np.full(len(s), 255),
        ]
    )
    hot = mesh.copy()
    hot.visual.vertex_colors = colours.astype(np.uint8)
    state = "closed" if res.closing_step is not None else "at the step cap (not closed)"
    stl = export(mesh, Path(folder) / "closed.stl", units=units)
    ply = export(hot, Path(folder) / "closed_temperature.ply", units=units)
    fab = fab.plus("closed", stl, f"STL of the gripper {state} by heating ({units})")
    return fab.plus(
        "closed_temperature", ply, f"PLY of the gripper {state}, coloured by temperature ({units})"
    )


def gripper_view(options: GripperOptions, row):
    """From flat (room temperature) to closed by heating, coloured by temperature, with the
    held base nodes (:class:`~holofold.design.report.view.DesignView`)."""
    from holofold.design.report.view import DesignView

    res, model = closed_gripper(options, row)
    room = options.material.room_temperature
    held = np.unique(np.concatenate([np.asarray(n, int) for n, _ in model.nodes.hold_heating]))
    closed = res.closing_step is not None
    last = (f"closed at heating step {res.closing_step}" if closed
            else f"not closed after {len(res.tip_distance)} heating steps")  # fmt: skip
    T = np.asarray(res.temperature, float)
    facts = [("state", last),
             ("room temperature", f"{room:.4g} degC"),
             ("hottest point when closed", f"{T.max():.4g} degC (Tmax)"),
             ("tip distance", f"{1e3 * res.tip_distance[-1]:.3g} mm (closure below "
                              f"{1e3 * options.closure:.3g} mm)")]  # fmt: skip
    if closed and np.isfinite(res.finalQ):
        facts.append(("heating power at closure", f"{res.finalQ:.4g} W (finalQ)"))
    return DesignView(
        frames=np.stack([res.nodes, res.nodes + res.displacement]),
        labels=("flat, at room temperature", last),
        faces=[list(t) for t in res.triangles], supports=held,
        scalar=np.stack([np.full(len(T), room), T]), scalar_name="temperature",
        scalar_unit="degC", facts=tuple(facts),
    )  # fmt: skip


def _closed_files(converged: bool, row, folder, units: str = "mm", cutter=None):
    """The built-in gripper's files with its closed (heated) state, as its scenario file's
    (:func:`write_closed_gripper_files`)."""
    options = GripperOptions(converged=converged)
    return write_closed_gripper_files(options, row, folder, units=units, cutter=cutter)


def _closed_view(converged: bool, row):
    """The built-in gripper's 3D view, flat to closed by heating
    (:func:`gripper_view`)."""
    return gripper_view(GripperOptions(converged=converged), row)


SCENARIO = Scenario(
    name="gripper",
    description=(
        "Electro-thermal gripper, three patterns (1 Miura-based, 2 splitted Miura, 3 two-panel):"
        " angular natural frequency (rad/s), heating power and maximum temperature at closure,"
        " prying stiffness (Zhu & Filipov 2022, data2)."
    ),
    features=FEATURES,
    performance=PERFORMANCE,
    check=check,
    evaluate=evaluate,
    categorical=("Pattern",),
    row_timeout=gripper_row_timeout(),
    shape=gripper_shape,
    write_files=partial(_closed_files, False),
    view=partial(_closed_view, False),
)
CONVERGED_OPTIONS = GripperOptions(converged=True)
#: the gripper with tightly converged Newton solves: repeatable outputs for new databases
SCENARIO_CONVERGED = replace(
    SCENARIO,
    name="gripper-converged",
    description=(
        "Electro-thermal gripper, three patterns (1 Miura-based, 2 splitted Miura, 3 two-panel):"
        " angular natural frequency (rad/s), heating power and maximum temperature at closure,"
        " prying stiffness; every Newton solve converged to a tight tolerance, so the outputs"
        " are repeatable (the published data2 stiffness is not: it comes from loosely"
        " converged solves)."
    ),
    evaluate=evaluate_converged,
    write_files=partial(_closed_files, True),
    view=partial(_closed_view, True),
)
