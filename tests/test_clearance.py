"""Overlap volume and clearance of folded thick panels, against exact numbers and manifold3d."""

import math
import warnings

import numpy as np
import pytest

from holofold.fitting import fit_strip
from holofold.geometry import miura_sheet, panel_clearance, panel_overlap, printability
from holofold.geometry.clearance import _triangle_distance
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.solid import SolidWarning, thick_solid


def _two_squares(gap: float, shift: float = 0.0) -> CreasePattern:
    """Two separate 10 mm squares, parallel, ``gap`` apart in z (mid-surfaces)."""
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float) * 0.01
    lo = np.column_stack([sq, np.zeros(4)])
    hi = np.column_stack([sq + [shift, 0], np.full(4, gap)])
    return CreasePattern.from_faces(np.vstack([lo, hi]), [[0, 1, 2, 3], [4, 5, 6, 7]])


@pytest.mark.parametrize("gap", [0.3e-3, 0.8e-3, 2.5e-3])
def test_stacked_squares_exact_overlap_and_clearance(gap):
    t = 1e-3
    r = printability(_two_squares(gap), t)
    assert r.clearance == pytest.approx(gap - t, abs=1e-12)  # mid-surfaces gap, less t/2 + t/2
    assert r.overlap == pytest.approx(1e-4 * max(t - gap, 0.0), rel=1e-9, abs=1e-18)
    assert r.closest == (0, 1)


def test_shifted_squares_overlap_only_where_they_cover_each_other():
    r = printability(_two_squares(0.5e-3, shift=0.004), 1e-3)
    assert r.overlap == pytest.approx(0.006 * 0.01 * 0.5e-3, rel=1e-9)


def test_two_panels_at_a_crease_overlap_like_manifold_says():
    # two 10 mm squares folded 120 degrees about their common edge (dihedral 60 degrees)
    a = math.radians(120)
    xy = np.array([[0, 0, 0], [0, 0.01, 0], [0.01, 0, 0], [0.01, 0.01, 0]], float)
    back = np.array([[-0.01 * math.cos(math.pi - a), 0, 0.01 * math.sin(math.pi - a)]])
    coords = np.vstack([xy, xy[:2] + back * [-1, 1, 1]])
    p = CreasePattern.from_faces(coords, [[0, 2, 3, 1], [0, 1, 5, 4]])
    for t, w in ((1e-3, 0.0), (1e-3, 0.5e-3), (0.5e-3, 2e-3)):
        parts = thick_solid(p, t, w, union=False)
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            exact = sum(s.volume for s in parts) - thick_solid(p, t, w).volume
        assert panel_overlap(p, t, w) == pytest.approx(max(exact, 0.0), rel=1e-4, abs=1e-15)
        # the union says so exactly when the panels overlap
        warned = [x for x in said if issubclass(x.category, SolidWarning)]
        assert len(warned) == (1 if exact > 1e-15 else 0), (t, w, exact)
    assert panel_overlap(p, 0.5e-3, 2e-3) == 0.0
    assert panel_clearance(p, 1e-3) == math.inf  # the two share vertices: no pair to measure


@pytest.mark.parametrize("t, expect_overlap", [(0.5e-3, False), (1e-3, True)])
def test_folded_miura_overlap_is_the_union_loss(t, expect_overlap):
    p = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    r = printability(p, t, 2e-3)
    parts = thick_solid(p, t, 2e-3, union=False)
    with pytest.warns(UserWarning) if expect_overlap else _nothing():
        lost = sum(s.volume for s in parts) - thick_solid(p, t, 2e-3).volume
    if expect_overlap:
        assert r.overlap == pytest.approx(lost, rel=1e-3)  # no three panels meet in one point
        assert r.overlap > 1e-9
    else:
        assert r.overlap == 0.0 and len(r.candidates) == 0
    # the nearest panels sharing no vertex: across a valley of the folded sheet
    assert 0 < r.clearance < 0.02


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_clearance_shrinks_as_the_sheet_folds_up():
    c = [
        panel_clearance(miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=e), 0.5e-3)
        for e in (0.9, 0.6, 0.3, 0.1)
    ]
    assert all(a > b for a, b in zip(c, c[1:], strict=False))


def test_arch_strip_numbers():
    p = fit_strip("half-circle", 24, 0.2, 0.02, 0.1).pattern
    ok = printability(p, 1e-3, 4e-3)
    assert ok.overlap == 0.0
    bad = printability(p, 3e-3, 2e-3)
    assert bad.overlap > 0 and len(bad.candidates) > 0
    # clearance is set by the corrugation, not by the thickness difference only
    assert ok.clearance - bad.clearance == pytest.approx(2e-3, abs=3e-3)


def test_triangle_distance_against_dense_sampling():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(30, 3, 3))
    B = rng.normal(size=(30, 3, 3)) + rng.normal(size=(30, 1, 3))
    d = _triangle_distance(A, B)
    u = rng.random((3000, 2))
    u[u.sum(1) > 1] = 1 - u[u.sum(1) > 1]

    def sample(T):
        return T[0] + u[:, :1] * (T[1] - T[0]) + u[:, 1:] * (T[2] - T[0])

    for k in range(30):
        pa, pb = sample(A[k]), sample(B[k])
        brute = np.sqrt(((pa[:, None] - pb[None]) ** 2).sum(-1)).min()
        assert d[k] <= brute + 1e-12
        assert brute - d[k] < 0.1  # sampling spacing


def test_bad_thickness_is_refused():
    from holofold.geometry import ParameterError

    with pytest.raises(ParameterError, match="panel thickness"):
        printability(_two_squares(1e-3), 0.0)
    with pytest.raises(ParameterError, match="crease width"):
        printability(_two_squares(1e-3), 1e-3, -1.0)
