"""holofold.fitting: planar target curves and the Miura-like strips fitted to them.

:mod:`~holofold.fitting.curves` (curves from functions, points and path data),
:mod:`~holofold.fitting.curve_files` (curves from CSV and SVG files, in their units),
:mod:`~holofold.fitting.strip` (the analytic strip and its named nodes),
:mod:`~holofold.fitting.strip_fit` (the fit with its errors and flat layout),
:mod:`~holofold.fitting.error` (index-matched and closest-point errors),
:mod:`~holofold.fitting.auto` (choosing m and offset for a tolerance) and
:mod:`~holofold.fitting.strip_files` (a fitted strip's fabrication files). See
docs/strip-fit.md. Surfaces (docs/surface-fit.md): :mod:`~holofold.fitting.surfaces` (target
surfaces: built-ins, height functions, mesh files), :mod:`~holofold.fitting.quadmesh` (the
generalised Miura-ori's conditions and flat layout), :mod:`~holofold.fitting.surface_fit` (the
fit) and :mod:`~holofold.fitting.surface_files` (its files). Imports only from
holofold.geometry.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "auto": [
            "AutoFit",
            "FitNotFoundError",
            "fit_auto",
            "ThickCheck",
            "DEFAULT_M_RANGE",
            "PUBLISHED_MAX_WARP",
        ],
        "curves": [
            "BUILTIN_CURVES",
            "CurveError",
            "PlanarCurve",
            "builtin_curve",
            "parse_curve_spec",
        ],
        "curve_files": [
            "CurveUnitWarning",
            "CurveSelectionWarning",
            "CurveColumnsWarning",
            "CurveClosedWarning",
            "MAX_SVG_BYTES",
            "MAX_SVG_NESTING",
            "MAX_SVG_ELEMENTS",
            "MAX_SVG_POINTS",
            "MAX_CSV_POINTS",
            "PLAUSIBLE_SIZE",
            "check_curve_size",
            "read_points_csv",
            "read_svg_curve",
            "load_curve",
        ],
        "error": ["ClosestPointError", "closest_point_error", "index_matched_error", "paper_error"],
        "strip": ["SAMPLINGS", "MAX_M", "StripGeometry", "strip_geometry"],
        "strip_files": ["export_strip_files", "write_strip_set"],
        "strip_fit": ["StripFit", "fit_strip"],
        "surfaces": [
            "BUILTIN_SURFACES",
            "MESH_SURFACE_TYPES",
            "SurfaceError",
            "SurfaceUnitWarning",
            "TargetSurface",
            "builtin_surface",
            "height_surface",
            "load_surface",
            "mesh_surface",
            "read_surface",
        ],
        "quadmesh": ["QuadGrid", "develop", "sector_angles", "quad_warp"],
        "surface_files": ["export_surface_files"],
        "surface_fit": [
            "CONSTRAINT_TOL",
            "Placement",
            "SurfaceFit",
            "SurfaceFitError",
            "fit_surface",
            "starting_tiling",
        ],
    },
)
