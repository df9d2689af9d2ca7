"""Exceptions raised by holofold when input is wrong.

The input errors subclass :class:`ValueError`, so callers (and the CLI) can catch one type.
Messages name the offending value, where it is, and what is allowed. :class:`EnvironmentFault`
is the other kind: the machine, not the input, is wrong; it is never a design's result.
"""

from __future__ import annotations

__all__ = [
    "InvalidPatternError",
    "DegenerateGeometryError",
    "FormatError",
    "ParameterError",
    "EnvironmentFault",
    "check_range",
    "record_or_keywords",
]


class InvalidPatternError(ValueError):
    """A crease pattern's arrays are inconsistent (indices, assignments, angles, faces)."""


class DegenerateGeometryError(ValueError):
    """Geometry that cannot be used: zero lengths, zero areas, non-finite coordinates."""


class FormatError(ValueError):
    """A file (FOLD, SVG, CSV, ...) that cannot be read as the format it claims to be."""


class ParameterError(ValueError):
    """A design or model parameter outside its allowed range."""


class EnvironmentFault(RuntimeError):
    """The environment cannot run the computation: a missing or broken module, a shared library
    that fails to load, a compile failure, out of memory. It says the cause and the fix in one
    line; runs stop on it before more work, and it is never stored as a design's outcome."""


def check_range(
    name: str,
    value: float,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """Return ``float(value)`` or raise :class:`ParameterError` naming ``name`` and its range.

    ``low_open``/``high_open`` make the bound exclusive. Non-finite values are rejected.
    """
    import math

    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    lo = "(" if low_open else "["
    hi = ")" if high_open else "]"
    rng = f"{lo}{'-inf' if low is None else low}, {'inf' if high is None else high}{hi}"
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be finite, got {value!r} (allowed range {rng})")
    bad = (low is not None and (v < low or (low_open and v == low))) or (
        high is not None and (v > high or (high_open and v == high))
    )
    if bad:
        raise ParameterError(f"{name} = {value!r} is outside the allowed range {rng}")
    return v


def record_or_keywords(cls, given, keywords: dict, caller: str, param: str):
    """A settings record given whole (parameter ``param`` of function ``caller``), or made of
    its fields given as keywords, never both: ``given`` itself, or ``cls(**keywords)``. An
    unknown name raises ``TypeError`` as Python does for a function's parameter."""
    for name in keywords:
        if name not in cls.__dataclass_fields__:
            raise TypeError(f"{caller}() got an unexpected keyword argument {name!r}")
    if given is None:
        return cls(**keywords)
    if keywords:
        raise TypeError(f"{caller}({param}=...): give {next(iter(keywords))} in the record")
    return given
