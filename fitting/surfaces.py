"""Target surfaces for the surface fit: built-ins, height functions and mesh files.

A :class:`TargetSurface` answers the two questions the fit asks (docs/surface-fit.md §2):

* ``closest(points)``: the foot points on the surface and the unit normals there (the distance
  and its gradient). Built-ins answer exactly (a sphere and a cylinder in closed form, the height
  surfaces by Newton's method on the foot-point condition); a mesh file answers through trimesh's
  closest-point query (``trimesh.proximity.closest_point``) with the face normal of the
  triangle hit.
* ``chart(u, v)``: a parametrisation by two lengths (metres), from which the fit's starting
  tiling is laid: a height surface is charted by its plan coordinates (x, y), the cylinder by
  arc length and axial position, a mesh file by the coordinates in its best-fit plane (a mesh
  must be a height field over that plane; one that folds back over it is refused).

Normals point to +z for height surfaces and mesh files (towards the side the best-fit plane's
normal was chosen), outwards for the sphere and the cylinder. Lengths are metres inside; a mesh
file is read in its stated ``units`` (:data:`~holofold.geometry.units.LENGTH_UNITS`).

Built-ins (:data:`BUILTIN_SURFACES`; every length in metres)::

    sphere-cap   radius R, rim: half-width of the square plan charted (default 0.5 R)
    cylinder     radius R, length L (along y), angle: arc charted, degrees (default 90)
    saddle       z = (x^2 - y^2) / (2 R): radius R, width, depth
    paraboloid   z = -(x^2 + y^2) / (2 R): radius R, width, depth
    wave         z = amplitude sin(k x) cos(k y), k = 2 pi / wavelength: amplitude,
                 wavelength, width, depth
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from holofold.geometry.errors import FormatError, ParameterError, check_range
from holofold.geometry.mesh_reader import mesh_difference, read_mesh
from holofold.geometry.units import LENGTH_UNITS, length_factor

__all__ = [
    "BUILTIN_SURFACES",
    "MESH_SURFACE_TYPES",
    "MAX_SURFACE_FACES",
    "SurfaceError",
    "SurfaceUnitWarning",
    "TargetSurface",
    "builtin_surface",
    "height_surface",
    "read_surface",
    "mesh_surface",
    "load_surface",
    "parse_surface_spec",
]

#: mesh file types read (through trimesh)
MESH_SURFACE_TYPES = ("stl", "obj", "ply", "off")
#: the most triangles a target mesh may have (a 1000 x 1000 height grid is 2e6; docs/limits.md)
MAX_SURFACE_FACES = 2_000_000
#: (smallest, largest) plausible extent of a target surface, m (as for curves)
PLAUSIBLE_SIZE = (0.01, 100.0)
#: triangles per side of the tessellation of a built-in (for pictures and files)
_TESSELLATION = 96


class SurfaceError(ParameterError):
    """A surface that cannot be used: an unknown name, bad parameters, an unreadable file."""


class SurfaceUnitWarning(UserWarning):
    """A surface whose size is implausible in the unit it was read in."""


@dataclass(frozen=True, eq=False, repr=False)
class TargetSurface:
    """A surface to fit, with its closest-point query and a chart for the starting tiling.

    Attributes
    ----------
    name : str
    kind : {"builtin", "height", "mesh"}
    params : dict
        The built-in's parameters (m), or the file and its units.
    domain : (4,) float
        Chart rectangle (u0, u1, v0, v1), metres.
    units : str
        Unit of the source file (``"m"`` for built-ins and functions); distances are reported
        in it too.
    """

    name: str
    kind: str
    params: dict[str, Any]
    domain: tuple[float, float, float, float]
    units: str
    _closest: Callable = field(repr=False)
    _chart: Callable = field(repr=False)
    _mesh: Any = field(default=None, repr=False)

    def __repr__(self) -> str:
        return f"TargetSurface({self.name!r}, kind={self.kind!r}, params={self.params!r})"

    def closest(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Foot points (k, 3) m and unit normals (k, 3) of ``points`` (k, 3) m."""
        p = np.asarray(points, float).reshape(-1, 3)
        return self._closest(p)

    def distance(self, points) -> np.ndarray:
        """Signed distances (k,) m: positive on the side the normals point to."""
        p = np.asarray(points, float).reshape(-1, 3)
        foot, nrm = self._closest(p)
        return np.einsum("kd,kd->k", p - foot, nrm)

    def chart(self, u, v) -> tuple[np.ndarray, np.ndarray]:
        """Points (k, 3) and unit normals (k, 3) at chart coordinates ``u``, ``v`` (k,) m."""
        u = np.asarray(u, float).ravel()
        v = np.asarray(v, float).ravel()
        return self._chart(u, v)

    @property
    def mesh(self):
        """A ``trimesh.Trimesh`` of the surface over its chart domain, metres."""
        if self._mesh is None:
            object.__setattr__(self, "_mesh", _tessellate(self))
        return self._mesh

    @property
    def size(self) -> float:
        """Largest extent of the charted surface (bounding box), m: the errors' normaliser."""
        return float(np.ptp(self.mesh.vertices, axis=0).max())


# ---------------------------------------------------------------------------- built-ins
def _sphere(radius: float, rim: float | None = None) -> TargetSurface:
    R = check_range("radius", radius, 0.0, None, low_open=True)
    rim = 0.5 * R if rim is None else check_range("rim", rim, 0.0, R / math.sqrt(2), low_open=True)
    sag = R - math.sqrt(R * R - 2 * rim * rim)  # at the plan square's corners
    centre = np.array([0.0, 0.0, -R])  # apex at z = 0

    def closest(p):
        d = p - centre
        r = np.linalg.norm(d, axis=1, keepdims=True)
        nrm = d / np.where(r > 0, r, 1.0)
        return centre + R * nrm, nrm

    def chart(u, v):
        z = np.sqrt(np.maximum(R * R - u * u - v * v, 0.0))
        p = np.stack([u, v, z - R], axis=1)
        return p, (p - centre) / R

    return TargetSurface("sphere-cap", "builtin", {"radius": R, "rim": rim, "sag": sag},
                         (-rim, rim, -rim, rim), "m", closest, chart)  # fmt: skip


def _cylinder(radius: float, length: float | None = None, angle: float = 90.0) -> TargetSurface:
    R = check_range("radius", radius, 0.0, None, low_open=True)
    L = 2.0 * R if length is None else check_range("length", length, 0.0, None, low_open=True)
    ang = check_range("angle", angle, 0.0, 300.0, low_open=True)
    half = 0.5 * math.radians(ang) * R
    axis_z = -R  # apex line at z = 0

    def closest(p):
        d = np.stack([p[:, 0], np.zeros(len(p)), p[:, 2] - axis_z], axis=1)
        r = np.linalg.norm(d, axis=1, keepdims=True)
        nrm = d / np.where(r > 0, r, 1.0)
        foot = np.stack([R * nrm[:, 0], p[:, 1], axis_z + R * nrm[:, 2]], axis=1)
        return foot, nrm

    def chart(u, v):
        phi = u / R
        nrm = np.stack([np.sin(phi), np.zeros_like(phi), np.cos(phi)], axis=1)
        return np.stack([R * nrm[:, 0], v, axis_z + R * nrm[:, 2]], axis=1), nrm

    return TargetSurface("cylinder", "builtin", {"radius": R, "length": L, "angle": ang},
                         (-half, half, -0.5 * L, 0.5 * L), "m", closest, chart)  # fmt: skip


def _height_builtin(name, f, grad, hess, params, width, depth) -> TargetSurface:
    w = check_range("width", width, 0.0, None, low_open=True)
    d = check_range("depth", depth, 0.0, None, low_open=True)
    params = {**params, "width": w, "depth": d}
    closest, chart = _height_queries(f, grad, hess)
    return TargetSurface(name, "builtin", params, (-w / 2, w / 2, -d / 2, d / 2), "m",
                         closest, chart)  # fmt: skip


def _quadric(name: str, sx: int, sy: int, radius, width, depth) -> TargetSurface:
    """The height field z = (sx x^2 + sy y^2) / (2 R), sx and sy +1 or -1 (curvatures +-1/R),
    over a ``width`` x ``depth`` rectangle centred on its apex (default R by R), m."""
    R = check_range("radius", radius, 0.0, None, low_open=True)
    w = R if width is None else width
    d = w if depth is None else depth
    return _height_builtin(
        name,
        lambda x, y: (sx * x * x + sy * y * y) / (2 * R),
        lambda x, y: (sx * x / R, sy * y / R),
        lambda x, y: (np.full_like(x, sx / R), np.zeros_like(x), np.full_like(x, sy / R)),
        {"radius": R}, w, d,
    )  # fmt: skip


def _saddle(radius: float, width: float | None = None, depth: float | None = None):
    return _quadric("saddle", 1, -1, radius, width, depth)


def _paraboloid(radius: float, width: float | None = None, depth: float | None = None):
    return _quadric("paraboloid", -1, -1, radius, width, depth)


def _wave(amplitude: float, wavelength: float, width: float | None = None,
          depth: float | None = None):  # fmt: skip
    a = check_range("amplitude", amplitude, 0.0, None, low_open=True)
    lam = check_range("wavelength", wavelength, 0.0, None, low_open=True)
    k = 2 * math.pi / lam
    w = lam if width is None else width
    d = w if depth is None else depth
    s, c = np.sin, np.cos
    return _height_builtin(
        "wave",
        lambda x, y: a * s(k * x) * c(k * y),
        lambda x, y: (a * k * c(k * x) * c(k * y), -a * k * s(k * x) * s(k * y)),
        lambda x, y: (-a * k * k * s(k * x) * c(k * y), -a * k * k * c(k * x) * s(k * y),
                      -a * k * k * s(k * x) * c(k * y)),  # fmt: skip
        {"amplitude": a, "wavelength": lam}, w, d,
    )  # fmt: skip


#: built-in surfaces: name -> (builder, required parameters, optional parameters)
BUILTIN_SURFACES: dict[str, tuple[Callable, tuple[str, ...], tuple[str, ...]]] = {
    "sphere-cap": (_sphere, ("radius",), ("rim",)),
    "cylinder": (_cylinder, ("radius",), ("length", "angle")),
    "saddle": (_saddle, ("radius",), ("width", "depth")),
    "paraboloid": (_paraboloid, ("radius",), ("width", "depth")),
    "wave": (_wave, ("amplitude", "wavelength"), ("width", "depth")),
}


def builtin_surface(name: str, **params) -> TargetSurface:
    """A built-in surface by name (:data:`BUILTIN_SURFACES`) with its parameters (m)."""
    key = str(name).strip().lower()
    if key not in BUILTIN_SURFACES:
        raise SurfaceError(
            f"unknown surface {name!r}; built-ins: {', '.join(BUILTIN_SURFACES)} "
            "(or a mesh file .stl/.obj/.ply/.off)"
        )
    build, required, optional = BUILTIN_SURFACES[key]
    missing = [p for p in required if p not in params]
    unknown = [p for p in params if p not in required + optional]
    if missing or unknown:
        what = "; ".join(
            ([f"missing {', '.join(missing)}"] if missing else [])
            + ([f"unknown {', '.join(unknown)}"] if unknown else [])
        )
        raise SurfaceError(
            f"surface {key!r}: {what}; parameters: {', '.join(required)}"
            + (f" (optional {', '.join(optional)})" if optional else "")
        )
    return build(**params)


def parse_surface_spec(spec: str) -> TargetSurface:
    """Parse ``"name:key=value,..."`` (``"sphere-cap:radius=1,rim=0.38"``)."""
    if not isinstance(spec, str) or not spec.strip():
        raise SurfaceError(f"empty surface specification {spec!r}")
    name, _, rest = spec.strip().partition(":")
    params: dict[str, float] = {}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, val = item.partition("=")
        if not eq or not key.strip():
            raise SurfaceError(f"surface parameter {item!r} in {spec!r} is not key=value")
        try:
            params[key.strip().lower()] = float(val)
        except ValueError:
            raise SurfaceError(
                f"surface parameter {key.strip()}={val!r} in {spec!r} is not a number"
            ) from None
    return builtin_surface(name, **params)


# ---------------------------------------------------------------------------- height surfaces
def _height_queries(f, grad, hess, iters: int = 12):
    """closest() and chart() of the graph z = f(x, y), given its derivatives (vectorised)."""

    def normal(x, y):
        fx, fy = grad(x, y)
        n = np.stack([-np.asarray(fx, float) + 0 * x, -np.asarray(fy, float) + 0 * x,
                      np.ones_like(x)], axis=1)  # fmt: skip
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def chart(u, v):
        return np.stack([u, v, f(u, v) + 0 * u], axis=1), normal(u, v)

    def closest(p):
        # Newton on g(x, y) = grad of 1/2 |(x, y, f) - p|^2 = 0, started from the plan point
        x, y = p[:, 0].copy(), p[:, 1].copy()
        for _ in range(iters):
            z = f(x, y) + 0 * x
            fx, fy = (np.asarray(a, float) + 0 * x for a in grad(x, y))
            fxx, fxy, fyy = (np.asarray(a, float) + 0 * x for a in hess(x, y))
            dz = z - p[:, 2]
            gx = (x - p[:, 0]) + dz * fx
            gy = (y - p[:, 1]) + dz * fy
            a11 = 1 + fx * fx + dz * fxx
            a12 = fx * fy + dz * fxy
            a22 = 1 + fy * fy + dz * fyy
            det = a11 * a22 - a12 * a12
            bad = ~(det > 1e-12)  # far from the surface: Gauss-Newton (drop the dz terms)
            a11 = np.where(bad, 1 + fx * fx, a11)
            a12 = np.where(bad, fx * fy, a12)
            a22 = np.where(bad, 1 + fy * fy, a22)
            det = a11 * a22 - a12 * a12
            sx = (a22 * gx - a12 * gy) / det
            sy = (a11 * gy - a12 * gx) / det
            x, y = x - sx, y - sy
            if max(np.abs(sx).max(initial=0), np.abs(sy).max(initial=0)) < 1e-15:
                break
        return chart(x, y)

    return closest, chart


def height_surface(
    f: Callable,
    x_range: tuple[float, float],
    y_range: tuple[float, float],
    *,
    name: str = "height",
    step: float | None = None,
) -> TargetSurface:
    """The graph z = f(x, y) over a plan rectangle, metres.

    ``f`` takes and returns numpy arrays (vectorised). Its derivatives are taken by central
    differences of step ``step`` (default 1e-4 of the rectangle's diagonal), so ``f`` must be
    smooth on the rectangle and a little beyond it.
    """
    if not callable(f):
        raise SurfaceError(f"a height surface needs a function f(x, y), got {type(f).__name__}")
    x0, x1 = (float(a) for a in x_range)
    y0, y1 = (float(a) for a in y_range)
    if not (math.isfinite(x0 + x1 + y0 + y1) and x1 > x0 and y1 > y0):
        raise SurfaceError(f"height surface ranges must be increasing, got {x_range}, {y_range}")
    h = 1e-4 * math.hypot(x1 - x0, y1 - y0) if step is None else float(step)

    def fv(x, y):
        z = np.asarray(f(x, y), float)
        return np.broadcast_to(z, np.shape(x)).astype(float)

    probe = fv(np.linspace(x0, x1, 7), np.linspace(y0, y1, 7))
    if not np.isfinite(probe).all():
        raise SurfaceError(f"height function {name!r} is not finite on its rectangle")

    def grad(x, y):
        return (fv(x + h, y) - fv(x - h, y)) / (2 * h), (fv(x, y + h) - fv(x, y - h)) / (2 * h)

    def hess(x, y):
        z = fv(x, y)
        fxx = (fv(x + h, y) - 2 * z + fv(x - h, y)) / (h * h)
        fyy = (fv(x, y + h) - 2 * z + fv(x, y - h)) / (h * h)
        fxy = (fv(x + h, y + h) - fv(x + h, y - h) - fv(x - h, y + h) + fv(x - h, y - h)) / (
            4 * h * h
        )
        return fxx, fxy, fyy

    closest, chart = _height_queries(fv, grad, hess)
    return TargetSurface(name, "height", {"x_range": (x0, x1), "y_range": (y0, y1)},
                         (x0, x1, y0, y1), "m", closest, chart)  # fmt: skip


# ---------------------------------------------------------------------------- mesh files
def read_surface(path, units: str = "m", *, check_size: bool = True) -> TargetSurface:
    """A target surface from an STL, OBJ, PLY or OFF file whose numbers are in ``units``.

    The mesh is charted by its best-fit plane (principal axes of its vertices) and must be a
    height field over it: a mesh with triangles facing away from that plane (a surface folding
    over itself) is refused. A closed solid (what CAD exports by default) gives its upper skin:
    the faces facing up over its best-fit plane (the plane's normal turned to +z), said in one
    warning; one without such a skin is refused with what to export. Closest points come from
    trimesh.
    """
    import trimesh

    k = length_factor(units)
    path = Path(path)
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in MESH_SURFACE_TYPES:
        raise SurfaceError(
            f"{path.name!r}: surface files must be {', '.join('.' + t for t in MESH_SURFACE_TYPES)}"
        )
    if not path.is_file():
        raise SurfaceError(f"surface file {str(path)!r} does not exist")
    # the file's own numbers, checked before trimesh may drop or repair anything
    V, F = read_mesh(path, max_faces=MAX_SURFACE_FACES)
    try:
        mesh = trimesh.Trimesh(V, F, process=True)
    except Exception as exc:  # trimesh raises many types for odd meshes
        raise FormatError(f"cannot build a mesh from {path.name!r}: {exc}") from None
    said = mesh_difference(path.name, V, F, mesh)
    if said:
        warnings.warn(said, UserWarning, stacklevel=2)
    mesh.remove_unreferenced_vertices()
    if len(mesh.faces) == 0:
        raise FormatError(f"{path.name!r} holds no triangle with an area")
    mesh.apply_scale(k)
    size = float(np.ptp(mesh.vertices, axis=0).max())
    if not size > 0:
        raise SurfaceError(f"{path.name!r} has zero extent")
    if check_size:
        lo, hi = PLAUSIBLE_SIZE
        if not lo <= size <= hi:
            raw = size / k
            better = sorted(
                (u for u in ("m", "cm", "mm", "in") if lo <= raw * LENGTH_UNITS[u] <= hi),
                key=lambda u: abs(math.log10(raw * LENGTH_UNITS[u])),
            )
            hint = (
                f"; if its numbers are in {better[0]}, give units={better[0]!r}" if better else ""
            )
            warnings.warn(
                f"surface {path.name!r} is {size:.4g} m across read in {units}, implausible for "
                f"an origami part ({lo:g}-{hi:g} m){hint}",
                SurfaceUnitWarning,
                stacklevel=2,
            )
    params = {"file": str(path), "units": units}
    if mesh.is_watertight:  # a closed solid (CAD's default export): its upper skin
        mesh, said = _upper_skin(mesh, path.name)
        warnings.warn(said, UserWarning, stacklevel=2)
        params["faces"] = "upward faces of a closed solid"
    return mesh_surface(mesh, name=path.stem, params=params, units=units)


def _reason(exc: Exception) -> str:
    """A library's error as one line (a missing optional module means damaged bytes here)."""
    if isinstance(exc, ModuleNotFoundError):
        return "the bytes are not a mesh of this format"
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def _upper_skin(mesh, name: str):
    """The faces of a closed solid ``mesh`` that face up over its best-fit plane (the plane's
    normal turned to the file's +z), as a mesh, and one line saying so; refused (with what to
    export) when none or too few do."""
    V = np.asarray(mesh.vertices, float)
    _, _, vt = np.linalg.svd(V - V.mean(axis=0), full_matrices=False)
    nz = vt[2] if vt[2][2] >= 0 else -vt[2]
    up = np.asarray(mesh.face_normals, float) @ nz > 0.2
    area = np.asarray(mesh.area_faces, float)
    share = float(area[up].sum() / area.sum()) if area.sum() > 0 else 0.0
    if up.sum() < 2 or share < 0.1:
        raise SurfaceError(
            f"{name!r} is a closed solid with no upper skin over its best-fit plane to fit: "
            "export the surface alone (an open STL/OBJ of the faces to fit)"
        )
    skin = mesh.submesh([np.flatnonzero(up)], append=True)
    said = (
        f"{name!r} is a closed solid: its {int(up.sum())} upward faces over the best-fit plane "
        f"({100 * share:.0f} % of its area) are taken as the surface; export the surface alone "
        "to fit another"
    )
    return skin, said


def mesh_surface(mesh, *, name: str = "mesh", params: dict | None = None,
                 units: str = "m") -> TargetSurface:  # fmt: skip
    """A target surface from a ``trimesh.Trimesh`` in metres (see :func:`read_surface`)."""
    import trimesh
    from scipy.interpolate import LinearNDInterpolator

    V = np.asarray(mesh.vertices, float)
    centre = V.mean(axis=0)
    _, _, vt = np.linalg.svd(V - centre, full_matrices=False)
    e1, e2, nz = vt[0], vt[1], vt[2]
    fn = np.asarray(mesh.face_normals, float)
    area = np.asarray(mesh.area_faces, float)
    if (fn @ nz * area).sum() < 0:
        nz = -nz
        e2 = -e2  # keep (e1, e2, nz) right-handed
    facing = fn @ nz
    back = area[facing < -1e-6].sum() / area.sum()
    if back > 1e-3:
        raise SurfaceError(
            f"mesh {name!r} is not a height field over its best-fit plane ({100 * back:.3g} % of "
            "its area faces away from it): give an open, dome-like or saddle-like surface patch"
        )
    frame = np.stack([e1, e2, nz])  # rows: chart axes
    local = (V - centre) @ frame.T
    interp = LinearNDInterpolator(local[:, :2], local[:, 2])
    # outward normals: smooth vertex normals of the mesh, facing +nz
    vn = np.asarray(mesh.vertex_normals, float)
    vn = np.where((vn @ nz)[:, None] < 0, -vn, vn)
    ninterp = LinearNDInterpolator(local[:, :2], vn)
    lo, hi = local[:, :2].min(axis=0), local[:, :2].max(axis=0)

    def chart(u, v):
        z = interp(u, v)
        nn = ninterp(u, v)
        miss = ~np.isfinite(z)
        if miss.any():  # outside the convex hull of the plan: the nearest plan point
            from scipy.spatial import cKDTree

            _, idx = cKDTree(local[:, :2]).query(np.stack([u[miss], v[miss]], axis=1))
            z = z.copy()
            z[miss] = local[idx, 2]
            nn = nn.copy()
            nn[miss] = vn[idx]
        p = centre + u[:, None] * e1 + v[:, None] * e2 + z[:, None] * nz
        return p, nn / np.linalg.norm(nn, axis=1, keepdims=True)

    fnz = np.where((fn @ nz)[:, None] < 0, -fn, fn)

    def closest(p):
        foot, _, tri = trimesh.proximity.closest_point(mesh, p)
        return np.asarray(foot, float), fnz[np.asarray(tri, int)]

    s = TargetSurface(name, "mesh", dict(params or {}), (lo[0], hi[0], lo[1], hi[1]), units,
                      closest, chart, mesh)  # fmt: skip
    return s


def load_surface(surface, units: str | None = None, *, check_size: bool = True) -> TargetSurface:
    """A :class:`TargetSurface` from a TargetSurface, a built-in spec string or a mesh file
    (whose numbers are in ``units``, default m)."""
    if isinstance(surface, TargetSurface):
        return surface
    if isinstance(surface, (str, Path)):
        s = str(surface)
        if Path(s).suffix.lower().lstrip(".") in MESH_SURFACE_TYPES or Path(s).is_file():
            return read_surface(s, units or "m", check_size=check_size)
        if units not in (None, "m"):
            raise SurfaceError(f"units={units!r} applies to surface files, not to {s!r}")
        return parse_surface_spec(s)
    raise SurfaceError(
        f"a surface must be a built-in spec, a mesh file or a TargetSurface, got "
        f"{type(surface).__name__}"
    )


# ---------------------------------------------------------------------------- tessellation
def _tessellate(surface: TargetSurface, n: int = _TESSELLATION):
    """The charted surface as a regular triangulated grid, metres."""
    import trimesh

    u0, u1, v0, v1 = surface.domain
    u, v = np.meshgrid(np.linspace(u0, u1, n + 1), np.linspace(v0, v1, n + 1), indexing="ij")
    p, _ = surface.chart(u.ravel(), v.ravel())
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    tris = np.concatenate(
        [np.stack([a, a + n + 1, a + n + 2], 1), np.stack([a, a + n + 2, a + 1], 1)]
    )
    return trimesh.Trimesh(vertices=p, faces=tris, process=False)
