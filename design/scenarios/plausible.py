"""Physical plausibility of a scenario file's values, per kind, checked when the file is read.

A value can be a valid number and still not mean what its key says: ``room_temperature = 294``
(kelvin given for a Celsius key), gripper arm lengths ``L1 = [4, 8]`` (millimetres given for
metres: a 4 m gripper ran 400 s for 20 designs), ``E = 1e25`` (no solid is that stiff: every
stiffness came out at round-off). Each key of each kind has a plausible range here (SI; the
table is docs/limits.md §"Physical ranges"); a value outside is refused in one line naming the
file, table and key, the range, and the unit it probably was in::

    grip.toml: [features] L1 = [4, 8] m is outside the physical range [1e-05, 0.5] m of this
    key; it looks like mm: give [0.004, 0.008]
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

__all__ = ["MATERIAL", "FORCE", "LENGTHS", "ENVIRONMENT", "check_plausible"]

#: (low, high, unit) of material constants shared by every kind
MATERIAL = {
    "E": (1e3, 1.2e12, "Pa"),  # soft gels to diamond (1.05e12 Pa)
    "density": (1.0, 25_000.0, "kg/m^3"),  # aerogels to osmium (22,600)
}
#: (low, high, unit) of a load case's total force: below 1e-9 N a displacement is at the
#: model's round-off, above 1e7 N (a thousand tonnes) no origami part is loaded
FORCE = (1e-9, 1e7, "N")
#: per kind: (low, high) of each length key, m (features, setting sizes)
LENGTHS = {
    "strip": {"tcrease": (1e-6, 0.1), "tpanel": (1e-6, 0.1), "W": (1e-6, 0.1),
              "offset": (1e-4, 10.0), "stripeWidth": (1e-5, 10.0), "extrude": (1e-4, 10.0)},
    "sheet": {"tcrease": (1e-6, 0.1), "tpanel": (1e-6, 0.1), "W": (1e-6, 0.1),
              "size_x": (1e-3, 100.0), "size_y": (1e-3, 100.0)},
    "gripper": {"L1": (1e-5, 0.5), "L2": (1e-5, 0.5), "t1": (1e-9, 1e-3), "t2": (1e-9, 1e-3),
                "tpanel": (1e-7, 1e-2), "W": (1e-7, 0.1), "closure": (1e-6, 0.5)},
}  # fmt: skip
#: (low, high, unit) of the gripper's material and surroundings
ENVIRONMENT = {
    "room_temperature": (-100.0, 150.0, "degC"),
    "d_alpha": (1e-7, 1e-3, "1/K"),
    "k_panel": (1e-3, 500.0, "W/(m K)"),
    "k_crease": (1e-3, 500.0, "W/(m K)"),
    "k_air": (1e-3, 1.0, "W/(m K)"),
}

_SCALES = (("mm", 1e-3), ("um", 1e-6), ("cm", 1e-2))


def _fmt(values: Sequence[float]) -> str:
    shown = ", ".join(f"{v:.6g}" for v in values)
    return f"[{shown}]" if len(values) > 1 else shown


def check_plausible(where, key: str, values, low: float, high: float, unit: str) -> None:
    """Raise ``where.error(...)`` (a Section) if any of ``values`` is outside [low, high],
    with the unit the numbers probably are in (mm, um or cm for metres; kelvin for
    degrees Celsius)."""
    vals = [float(v) for v in (values if isinstance(values, Sequence) else [values])]
    if all(low <= v <= high for v in vals):
        return
    hint = ""
    if unit == "degC" and all(173.15 <= v <= 473.15 for v in vals):
        hint = f"; it looks like kelvin: give {_fmt([v - 273.15 for v in vals])} (degC)"
    elif unit == "m":
        for name, k in _SCALES:
            if all(low <= v * k <= high for v in vals):
                hint = f"; it looks like {name}: give {_fmt([v * k for v in vals])}"
                break
    raise where.error(
        f"{key} = {_fmt(vals)} {unit} is outside the physical range [{low:g}, {high:g}] {unit} "
        f"of this key{hint} (docs/limits.md)"
    )


def check_lengths(where, kind: str, values: Mapping[str, Sequence[float]]) -> None:
    """:func:`check_plausible` of every length key of ``kind`` in ``values`` (key -> numbers)."""
    for key, (low, high) in LENGTHS.get(kind, {}).items():
        if key in values:
            check_plausible(where, key, values[key], low, high, "m")
