"""The gripper kind: the paper's electro-thermal grippers with the user's ranges and material.

docs/scenarios.md §8. The three patterns of :mod:`~holofold.design.scenarios.gripper` (1
Miura-based, 2 splitted Miura, 3 two-panel) and its four-step protocol (frequency, pre-bias,
heating to closure, prying), with the features ``Pattern L1 L2 t1 t2 tpanel rate W`` over the
user's ranges, the material and surroundings of a
:class:`~holofold.design.scenarios.gripper.GripperMaterial`, the heating rate and closure
distance, and the choice of the scripts' loose Newton tolerances (``converged = false``, the
published database) or tight ones (``converged = true``, scenario ``gripper-converged``).

Columns, SI units: ``freqFinal`` (rad/s), ``finalQ`` (W, the published formula at the file's
heating rate), ``Tmax`` (°C), ``stiff`` (N/m), as in the paper.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from holofold.design.scenarios.base import Column, Scenario
from holofold.design.scenarios.config import Section, read_features
from holofold.design.scenarios.gripper import (
    CLOSURE,
    FEATURES,
    PAPER_MATERIAL,
    PERFORMANCE,
    QLOAD,
    STEP_CAP,
    GripperMaterial,
    GripperOptions,
    check,
    closed_gripper,
    gripper_row_timeout,
    gripper_shape,
    gripper_view,
    simulate,
    write_closed_gripper_files,
    write_gripper_files,
)
from holofold.design.scenarios.plausible import (
    ENVIRONMENT,
    MATERIAL,
    check_lengths,
    check_plausible,
)

__all__ = [
    "GRIPPER_FEATURES",
    "gripper_scenario",
    "evaluate_gripper",
    "gripper_shape",
    "write_gripper_files",
    "write_closed_gripper_files",
    "closed_gripper",
    "gripper_view",
    "from_config",
]

#: the features with the paper's ranges (docs/scenarios.md §4.1)
GRIPPER_FEATURES = FEATURES
_PATTERN_NAMES = {1: "Miura-based", 2: "splitted Miura", 3: "two-panel"}
#: the scripts' options (the published database)
PAPER_OPTIONS = GripperOptions()


def evaluate_gripper(options: GripperOptions, row) -> dict:
    """freqFinal (rad/s), finalQ (W), Tmax (°C), stiff (N/m), mass (kg) and status of one
    design."""
    return {**simulate(row, options).as_row(), "mass": gripper_mass(options, row)}


#: the kind's columns: the paper's four and the gripper's mass
MASS = Column(
    "mass",
    "kg",
    "mass of the film: panels of tpanel, active creases of t1 + t2 over width W",
    display="g",
)


def gripper_mass(options: GripperOptions, row) -> float:
    """density x (panel area x tpanel + active-crease length x W x (t1 + t2 - tpanel)), kg:
    the flat film of panel thickness, with the bimorph (t1 + t2) instead of the panel over a
    strip of width W along every active crease (the compliant creases the model represents)."""
    from holofold.geometry.gripper import gripper_pattern

    g = gripper_pattern(int(round(row["Pattern"])), row["L1"], row["L2"], row["rate"])
    X = g.pattern.coords
    area = 0.0
    for f in g.pattern.faces:  # vector area of each planar polygon
        P = X[f]
        area += 0.5 * np.linalg.norm(np.cross(P, np.roll(P, -1, axis=0)).sum(axis=0))
    e = g.pattern.edges[np.asarray(g.active)]  # 0-based ids of the active creases
    length = float(np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1).sum())
    tp, t1, t2, W = (float(row[k]) for k in ("tpanel", "t1", "t2", "W"))
    return float(options.material.density * (area * tp + length * W * (t1 + t2 - tp)))


def gripper_scenario(
    name: str,
    description: str,
    options: GripperOptions = PAPER_OPTIONS,
    features: tuple[Column, ...] = GRIPPER_FEATURES,
    *,
    source: str = "",
) -> Scenario:
    """The :class:`Scenario` of gripper ``options`` (picklable for worker processes)."""
    mat = options.material
    cap = options.step_cap
    pats = next(c.choices for c in features if c.name == "Pattern")
    words = {
        "patterns": ", ".join(f"{int(p)} {_PATTERN_NAMES.get(int(p), '?')}" for p in pats),
        "E (Pa)": mat.E,
        "nu": mat.nu,
        "density (kg/m^3)": mat.density,
        "bimorph expansion mismatch (1/K)": mat.d_alpha,
        "conductivity panel / crease / air (W/(m K))": f"{mat.k_panel:g} / {mat.k_crease:g} / "
        f"{mat.k_air:g}",
        "room temperature (degC)": mat.room_temperature,
        "air layers": mat.env_layers,
        "dissipation angle (deg)": mat.dissipation_deg,
        "heating (W/m per step)": options.q_load,
        "closure distance (m)": options.closure,
        "heating-step cap": ", ".join(f"{k}: {v}" for k, v in STEP_CAP.items())
        if cap is None
        else cap,
        "Newton solves": "tightly converged" if options.converged else "the scripts' tolerances",
    }
    return Scenario(
        name=name,
        description=description,
        features=features,
        performance=(*PERFORMANCE, MASS),
        check=check,
        evaluate=partial(evaluate_gripper, options),
        categorical=("Pattern",),
        kind="gripper",
        setting=words,
        source=source,
        shape=gripper_shape,
        write_files=partial(write_closed_gripper_files, options),
        view=partial(gripper_view, options),
        row_timeout=gripper_row_timeout(options.step_cap),
    )


# ---------------------------------------------------------------------- scenario files
def _material(doc: Section) -> GripperMaterial:
    d = PAPER_MATERIAL
    pos = dict(low=0.0, low_open=True)
    mat = doc.sub("material")
    fields = dict(
        E=mat.number("E", d.E, **pos),
        nu=mat.number("nu", d.nu, low=-1.0, high=0.5, low_open=True),
        density=mat.number("density", d.density, **pos),
        d_alpha=mat.number("d_alpha", d.d_alpha, **pos),
        k_panel=mat.number("k_panel", d.k_panel, **pos),
        k_crease=mat.number("k_crease", d.k_crease, **pos),
    )
    if fields["nu"] == 0.5:
        raise mat.error("nu = 0.5 is outside (-1, 0.5)")
    for key in ("E", "density"):
        check_plausible(mat, key, fields[key], *MATERIAL[key])
    for key in ("d_alpha", "k_panel", "k_crease"):
        check_plausible(mat, key, fields[key], *ENVIRONMENT[key])
    mat.done()
    env = doc.sub("environment")
    fields |= dict(
        k_air=env.number("k_air", d.k_air, **pos),
        room_temperature=env.number("room_temperature", d.room_temperature, low=-273.15),
        env_layers=env.number("air_layers", d.env_layers, low=1, high=1000, integer=True),
        dissipation_deg=env.number(
            "dissipation_deg", d.dissipation_deg, low=0.0, high=89.0, low_open=True
        ),
    )
    for key, name in (("k_air", "k_air"), ("room_temperature", "room_temperature")):
        check_plausible(env, name, fields[key], *ENVIRONMENT[key])
    env.done()
    return GripperMaterial(**fields)


def _check_features(doc: Section, features: tuple[Column, ...]) -> None:
    by = {c.name: c for c in features}
    pats = by["Pattern"].choices
    if not set(pats) <= {1, 2, 3}:
        allowed = ", ".join(f"{k} ({v})" for k, v in _PATTERN_NAMES.items())
        raise doc.error(f"[features] Pattern = {list(pats)}: allowed: {allowed}")
    for k in ("L1", "L2", "t1", "t2", "tpanel", "rate", "W"):
        lo, hi = by[k].low, by[k].high
        if not lo > 0:
            raise doc.error(f"[features] {k} = [{lo:g}, {hi:g}] must be > 0 (SI units)")
    if not by["rate"].high < 1:
        raise doc.error(f"[features] rate = [{by['rate'].low:g}, {by['rate'].high:g}] must be < 1")


def from_config(doc: Section, name: str, description: str) -> Scenario:
    """The gripper scenario of a parsed scenario file (``kind = "gripper"``)."""
    material = _material(doc)
    heat = doc.sub("heating")
    q_load = heat.number("q_load", QLOAD, low=0.0, low_open=True)
    closure = heat.number("closure", CLOSURE, low=0.0, low_open=True)
    step_cap = heat.number("step_cap", None, low=1, high=100000, integer=True)
    check_lengths(heat, "gripper", {"closure": closure})
    heat.done()
    sol = doc.sub("solver")
    converged = sol.raw("converged", False)
    if not isinstance(converged, bool):
        raise sol.error(f"converged = {converged!r} must be true or false")
    sol.done()
    features = read_features(doc.sub("features"), GRIPPER_FEATURES, kind="gripper")
    _check_features(doc, features)
    options = GripperOptions(
        converged=converged,
        material=material,
        q_load=q_load,
        closure=closure,
        step_cap=step_cap,
    )
    return gripper_scenario(name, description, options, features)
