"""Panels passing through each other (mechanics/intersection.py) and the fold stopping at the
last clean state (mechanics/folding.py, verdict 'folds until panels touch')."""

from __future__ import annotations

import math

import numpy as np
import pytest

from holofold.geometry import CreasePattern, miura_sheet
from holofold.mechanics import fold_pattern
from holofold.mechanics.intersection import has_intersections, intersecting_faces

SECTION = dict(panel_thickness=1e-3, crease_thickness=0.3e-3, crease_width=1e-3)
L = 0.05  # panel width, m


def _strip(angle: float = 179.0) -> CreasePattern:
    """Three panels in a row, both creases valleys to ``angle``: the end panels fold onto the
    middle one from the same side; their free edges meet above its middle at 120 degrees and
    pass through each other beyond."""
    flat = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [2, 1], [1, 1], [0, 1]]) * L
    faces = [[0, 1, 6, 7], [1, 2, 5, 6], [2, 3, 4, 5]]
    p = CreasePattern.from_faces(np.c_[flat, np.zeros(len(flat))], faces, flat=flat)
    asg = np.where(p.interior, "V", "B")
    ang = np.where(p.interior, angle, 0.0)
    return CreasePattern(p.coords, p.faces, p.edges, asg, ang, flat=flat)


def _strip_state(theta_deg: float) -> np.ndarray:
    """Vertex coordinates of :func:`_strip` with both creases folded by ``theta_deg``."""
    t = math.radians(theta_deg)
    x0 = L - L * math.cos(t)  # the end panels' free edges
    x3 = 2 * L + L * math.cos(t)
    z = L * math.sin(t)
    pts = [[x0, 0, z], [L, 0, 0], [2 * L, 0, 0], [x3, 0, z]]
    pts += [[x3, L, z], [2 * L, L, 0], [L, L, 0], [x0, L, z]]
    return np.array(pts)


def _crossing_triangles():
    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [2, 2, 0.1]])
    return X, [[0, 1, 2], [3, 4, 5]]


def _backends():
    try:
        import ipctk  # noqa: F401
    except ImportError:
        return ["numpy"]
    return ["numpy", "ipctk"]


@pytest.mark.parametrize("backend", _backends())
def test_two_crossing_triangles(backend):
    X, F = _crossing_triangles()
    assert has_intersections(X, F, backend=backend)
    assert intersecting_faces(X, F).tolist() == [[0, 1]]
    X2 = X.copy()
    X2[3:, 2] += 0.6  # lifted clear above the first
    assert not has_intersections(X2, F, backend=backend)


@pytest.mark.parametrize("backend", _backends())
@pytest.mark.parametrize(("theta", "crossing"), [(0.0, False), (90.0, False), (119.0, False),
                                                 (121.0, True), (179.0, True)])  # fmt: skip
def test_folded_strip_crosses_beyond_120_degrees(backend, theta, crossing):
    """Analytic: the end panels' free edges meet at 120 degrees; before, the state is clean;
    beyond, panels 0 and 2 pass through each other (panels sharing a crease never count)."""
    p, X = _strip(), _strip_state(theta)
    assert has_intersections(X, p.faces, backend=backend) is crossing
    pairs = intersecting_faces(X, p.faces).tolist()
    assert pairs == ([[0, 2]] if crossing else [])


@pytest.mark.parametrize("backend", _backends())
def test_a_folded_miura_sheet_is_clean(backend):
    m = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.3)
    assert not has_intersections(m.coords, m.faces, backend=backend)
    assert len(intersecting_faces(m.coords, m.faces)) == 0


def test_fold_stops_at_the_last_clean_state_when_panels_touch():
    """The strip driven to 179 degrees stops just before its end panels cross (120 deg, a
    fraction of 120/179), says where, and gives no success verdict."""
    p = _strip()
    r = fold_pattern(p, 1.0, **SECTION)
    first = 120.0 / 179.0
    step = 3.0 / 179.0
    assert r.verdict == "folds until panels touch"
    assert not r.status.converged and not r.complete
    assert first < r.touch_at <= first + step + 1e-9
    assert r.reached == pytest.approx(r.fractions[-1]) and r.reached < r.touch_at
    assert r.touch_where == (0, 2)
    assert not any(has_intersections(x, p.faces) for x in r.coords)
    a = r.fold_angles[-1][p.interior]
    assert np.all(a <= 120.0 + 1e-6) and np.all(a > 120.0 - 3.0 - 1e-6)
    assert "pass through each other" in r.summary()


def test_fold_below_the_touch_is_not_stopped():
    p = _strip(100.0)  # free edges still 0.65 L apart
    r = fold_pattern(p, 1.0, **SECTION)
    assert r.verdict == "folds rigidly" and r.complete and math.isnan(r.touch_at)
    off = fold_pattern(_strip(), 1.0, check_intersections=False, **SECTION)
    assert off.complete and has_intersections(off.coords[-1], p.faces)


def test_simulation_files_of_a_touching_fold_are_clean(tmp_path):
    """holofold simulate's files for the strip: every FOLD frame is checked independently (the
    numpy test) and is clean; the summary says where the fold stopped and which panels."""
    import json

    from holofold.mechanics import PatternSetting, simulate_pattern, write_simulation

    sim = simulate_pattern(_strip(), PatternSetting(contact=False))  # the check alone
    assert sim.fold.verdict == "folds until panels touch"
    write_simulation(sim, tmp_path / "out")
    frames = json.loads((tmp_path / "out" / "folded.fold").read_text())["file_frames"]
    faces = _strip().faces
    for fr in frames:
        X = np.array(fr["vertices_coords"], float)
        assert len(intersecting_faces(X, faces)) == 0
    summary = json.loads((tmp_path / "out" / "simulation.json").read_text())
    assert summary["fold"]["touch_faces"] == [0, 2]
    assert 120 / 179 < summary["fold"]["touch_at"] <= 123 / 179 + 1e-9
    assert summary["status_line"].startswith("folds until panels touch")


def test_coincident_cut_edges_in_a_flat_sheet_do_not_cross():
    """A cut (two vertex copies on one line, as in kirigami) in a flat sheet: coplanar, touching,
    not crossing (IPC Toolkit's has_intersections flags such flat states; the fold confirms
    with this test before it stops)."""
    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0], [1, 0, 0], [0, -1, 0]], float)
    F = [[0, 1, 2], [3, 5, 4]]
    assert len(intersecting_faces(X, F)) == 0
    assert not has_intersections(X, F, backend="numpy")
