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

from holofold.geometry.lazy_face import ALL, attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    __file__,
    submod_attrs={
        "auto": ALL,
        "curves": [
            "BUILTIN_CURVES",
            "CurveError",
            "PlanarCurve",
            "builtin_curve",
            "parse_curve_spec",
        ],
        "curve_files": ALL,
        "error": ["ClosestPointError", "closest_point_error", "index_matched_error", "paper_error"],
        "strip": ["SAMPLINGS", "MAX_M", "StripGeometry", "strip_geometry"],
        "strip_files": ALL,
        "strip_fit": ALL,
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
        "surface_files": ALL,
        "surface_fit": ALL,
    },
)
