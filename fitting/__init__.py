"""Fitting layer of holofold: planar target curves and Miura-like strips fitted to them.

Modules: :mod:`fitting.curves` (curve types, parsing, lengths, distances),
:mod:`fitting.strip` (the analytic strip of specs/scenarios.md 5.3-5.4),
:mod:`fitting.error` (published index-matched error and closest-point error) and
:mod:`fitting.auto` (choosing m and offset for a tolerance).
"""

from holofold.fitting.auto import AutoFit, FitNotFoundError, fit_auto
from holofold.fitting.curves import (
    BUILTIN_CURVES,
    CurveError,
    PlanarCurve,
    builtin_curve,
    load_curve,
    parse_curve_spec,
    read_points_csv,
    read_svg_curve,
)
from holofold.fitting.error import (
    ClosestPointError,
    closest_point_error,
    index_matched_error,
    paper_error,
)
from holofold.fitting.strip import SAMPLINGS, StripGeometry, strip_geometry
from holofold.fitting.strip_fit import StripFit, fit_strip

__all__ = [
    "BUILTIN_CURVES",
    "CurveError",
    "PlanarCurve",
    "builtin_curve",
    "load_curve",
    "parse_curve_spec",
    "read_points_csv",
    "read_svg_curve",
    "ClosestPointError",
    "closest_point_error",
    "index_matched_error",
    "paper_error",
    "SAMPLINGS",
    "StripGeometry",
    "strip_geometry",
    "StripFit",
    "fit_strip",
    "AutoFit",
    "FitNotFoundError",
    "fit_auto",
]
