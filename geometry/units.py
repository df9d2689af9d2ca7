"""Length units at the edges: the factor from a named unit to metres.

holofold works in SI inside; files a user gives or opens carry their own unit (a CSV of points
in mm, an STL for a slicer in mm). :func:`length_factor` is the one table of those names.
"""

from __future__ import annotations

from holofold.geometry.errors import ParameterError

__all__ = ["LENGTH_UNITS", "length_factor"]

#: unit name -> metres per unit
LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "in": 0.0254, "ft": 0.3048}


def length_factor(unit: str) -> float:
    """Metres per ``unit`` (one of :data:`LENGTH_UNITS`)."""
    key = str(unit).strip()
    if key not in LENGTH_UNITS:
        raise ParameterError(f"unknown length unit {unit!r}; allowed: {', '.join(LENGTH_UNITS)}")
    return LENGTH_UNITS[key]
