"""Target surfaces: closest points against closed forms and trimesh, charts, files and units."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import trimesh

from holofold.fitting import (
    SurfaceError,
    SurfaceUnitWarning,
    builtin_surface,
    height_surface,
    load_surface,
    read_surface,
)
from holofold.geometry import FormatError

RNG = np.random.default_rng(7)


def _near(surface, k=200, spread=0.05):
    """Points near the charted surface: chart points moved along random directions."""
    u0, u1, v0, v1 = surface.domain
    u = RNG.uniform(u0, u1, k) * 0.9
    v = RNG.uniform(v0, v1, k) * 0.9
    p, _ = surface.chart(u, v)
    return p + spread * surface.size * RNG.normal(size=p.shape)


def test_sphere_distance_is_radial():
    s = builtin_surface("sphere-cap", radius=1.5, rim=0.6)
    p = _near(s)
    centre = np.array([0.0, 0.0, -1.5])
    assert np.allclose(s.distance(p), np.linalg.norm(p - centre, axis=1) - 1.5, atol=1e-14)
    foot, nrm = s.closest(p)
    assert np.allclose(np.linalg.norm(foot - centre, axis=1), 1.5, atol=1e-14)
    assert np.allclose(np.linalg.norm(nrm, axis=1), 1.0)


def test_cylinder_distance_is_radial_in_xz():
    s = builtin_surface("cylinder", radius=0.8, length=1.0, angle=120)
    p = _near(s)
    r = np.hypot(p[:, 0], p[:, 2] + 0.8)
    assert np.allclose(s.distance(p), r - 0.8, atol=1e-14)
    # the chart is isometric: arc length along u
    q, _ = s.chart(np.array([0.0, 0.8 * math.pi / 6]), np.zeros(2))
    assert math.isclose(
        np.linalg.norm(q[1] - q[0]), 2 * 0.8 * math.sin(math.pi / 12), rel_tol=1e-12
    )


@pytest.mark.parametrize(
    "spec",
    [
        "saddle:radius=1,width=1,depth=0.8",
        "paraboloid:radius=0.7",
        "wave:amplitude=0.05,wavelength=0.5",
    ],
)
def test_height_surface_foot_points_are_orthogonal_and_agree_with_trimesh(spec):
    """Newton's foot point: on the surface, the offset along the normal; its distance agrees
    with trimesh's closest point on a fine tessellation to the tessellation's error."""
    s = load_surface(spec)
    p = _near(s, spread=0.02)
    foot, nrm = s.closest(p)
    d = p - foot
    resid = d - np.einsum("kd,kd->k", d, nrm)[:, None] * nrm  # tangential part
    assert np.abs(resid).max() < 1e-10 * s.size
    fine = s.mesh  # 96 x 96 grid
    _, dist, _ = trimesh.proximity.closest_point(fine, p)
    h = s.size / 96
    assert np.allclose(np.abs(s.distance(p)), dist, atol=0.05 * h)


def test_user_height_function_matches_builtin():
    R = 1.2
    user = height_surface(lambda x, y: -(x * x + y * y) / (2 * R), (-0.5, 0.5), (-0.4, 0.4))
    ref = builtin_surface("paraboloid", radius=R, width=1.0, depth=0.8)
    p = _near(ref, spread=0.01)
    assert np.allclose(user.distance(p), ref.distance(p), atol=1e-7 * ref.size)


def _dome_in_mm(path):
    """The built-in spherical cap (radius 1 m, rim 0.4) and its mesh written to ``path`` in mm."""
    s = builtin_surface("sphere-cap", radius=1.0, rim=0.4)
    mesh = s.mesh.copy()
    mesh.apply_scale(1000.0)
    mesh.export(path)
    return s, path


def test_mesh_file_in_mm_matches_the_sphere(tmp_path):
    """A fine spherical cap written in mm and read with units='mm' is the sphere in metres."""
    s, path = _dome_in_mm(tmp_path / "dome.stl")
    m = read_surface(path, units="mm")
    assert m.kind == "mesh" and m.units == "mm"
    assert math.isclose(m.size, s.size, rel_tol=1e-6)
    p = _near(s, spread=0.01)
    h = s.size / 96
    assert np.allclose(m.distance(p), s.distance(p), atol=0.02 * h)
    # the chart of a height field lands on the mesh
    u0, u1, v0, v1 = m.domain
    q, n = m.chart(np.linspace(u0, u1, 9) * 0.8, np.linspace(v0, v1, 9) * 0.8)
    assert np.abs(s.distance(q)).max() < 0.02 * h
    _, ns = s.closest(q)
    assert np.einsum("kd,kd->k", n, ns).min() > 0.999


def test_mesh_units_warning_and_refusals(tmp_path):
    s, path = _dome_in_mm(tmp_path / "dome_mm.stl")
    with pytest.warns(SurfaceUnitWarning, match="units='mm'"):
        read_surface(path)  # metres: 800 m across
    closed = tmp_path / "ball.stl"
    trimesh.creation.icosphere(2).export(closed)
    with pytest.warns(UserWarning, match="closed solid: its .* upward faces"):
        cap = read_surface(closed, units="m")  # a closed solid: its upper skin
    assert cap.params["faces"] == "upward faces of a closed solid"
    ball = trimesh.creation.icosphere(2)
    opened = tmp_path / "opened.stl"  # open (one face off) and folding back over its plane
    trimesh.Trimesh(ball.vertices, ball.faces[1:]).export(opened)
    with pytest.raises(SurfaceError, match="not a height field"):
        read_surface(opened, units="m")
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"solid x\nnonsense\n")
    with pytest.raises((FormatError, SurfaceError)):
        read_surface(bad)
    with pytest.raises(SurfaceError, match="does not exist"):
        read_surface(tmp_path / "none.obj")
    with pytest.raises(SurfaceError, match=r"\.stl"):
        read_surface(tmp_path / "x.step")


def test_builtin_errors_name_the_problem():
    with pytest.raises(SurfaceError, match="built-ins: sphere-cap"):
        builtin_surface("torus", radius=1)
    with pytest.raises(SurfaceError, match="missing radius"):
        builtin_surface("sphere-cap")
    with pytest.raises(SurfaceError, match="unknown height"):
        builtin_surface("saddle", radius=1, height=2)
    with pytest.raises(SurfaceError, match="not a number"):
        load_surface("saddle:radius=one")
    with pytest.raises(ValueError, match="rim"):
        builtin_surface("sphere-cap", radius=1, rim=0.9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert load_surface("cylinder:radius=1").params["angle"] == 90.0
