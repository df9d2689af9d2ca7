"""holofold.fitting: planar target curves and the Miura-like strips fitted to them.

:mod:`~holofold.fitting.curves` (curves from functions, points and drawings),
:mod:`~holofold.fitting.strip` (the analytic strip and its named nodes),
:mod:`~holofold.fitting.strip_fit` (the fit with its errors and flat layout),
:mod:`~holofold.fitting.error` (index-matched and closest-point errors),
:mod:`~holofold.fitting.auto` (choosing m and offset for a tolerance) and
:mod:`~holofold.fitting.strip_files` (a fitted strip's fabrication files). See
docs/strip-fit.md. Imports only from holofold.geometry.
"""

from holofold.fitting.auto import DEFAULT_M_RANGE, AutoFit, FitNotFoundError, fit_auto
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
from holofold.fitting.strip_files import export_strip_files
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
    "DEFAULT_M_RANGE",
    "export_strip_files",
]
