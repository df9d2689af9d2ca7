"""Folding a crease pattern by rest-angle actuation (mechanics/folding.py, measures.py)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from holofold.geometry import CreasePattern, miura_sheet
from holofold.mechanics import FoldSettings, fold_pattern, fold_targets, model_energy

SECTION = dict(panel_thickness=1e-3, crease_thickness=0.3e-3, crease_width=1e-3)


def _pattern(flat, faces, assignment, angle):
    """A flat pattern whose interior edges get ``assignment`` and ``angle`` (degrees)."""
    flat = np.asarray(flat, float)
    p = CreasePattern.from_faces(np.c_[flat, np.zeros(len(flat))], faces, flat=flat)
    asg = np.where(p.interior, assignment, "B")
    ang = np.where(p.interior, angle, 0.0)
    return CreasePattern(p.coords, p.faces, p.edges, asg, ang, flat=flat)


def _distances(X):
    return np.linalg.norm(X[:, None] - X[None], axis=-1)


@pytest.mark.parametrize("model", ["concentrated", "compliant"])
def test_one_crease_reaches_its_target_stress_free(model):
    flat = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]]) * 0.05
    p = _pattern(flat, [[0, 1, 2, 3], [1, 4, 5, 2]], "V", 90.0)
    r = fold_pattern(p, 1.0, model=model, **SECTION)
    assert r.verdict == "folds rigidly" and r.complete and r.status.converged
    assert r.fold_angles[-1][p.interior] == pytest.approx([90.0], abs=1e-6)
    assert r.progress == pytest.approx(1.0, abs=1e-8)
    assert r.fractions[0] == 0.0 and r.fractions[-1] == 1.0


def test_miura_folds_to_its_rigid_state():
    """A Miura sheet driven to the fold angles of its rigid state at Ext = 0.6 reaches exactly
    that state (distances between all vertices as in miura_sheet(ext=0.6), 1e-9 relative)."""
    folded = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    r = fold_pattern(folded, 1.0, **SECTION)
    assert r.verdict == "folds rigidly" and "stress free" in r.note
    D, D0 = _distances(r.coords[-1]), _distances(folded.coords)
    assert np.abs(D - D0).max() <= 1e-9 * D0.max()
    assert r.fold_angles[-1] == pytest.approx(folded.fold_angle, abs=1e-6)
    half = fold_pattern(folded, 0.5, **SECTION)
    assert half.reached == 0.5 and 0.4 < half.progress < 0.6


def test_flat_miura_folds_towards_180():
    """A flat sheet whose M/V creases have no angle stays flat; driven to -+180 degrees
    (capped at 179) it folds."""
    flat = miura_sheet(3, 3, a=0.02, b=0.02, gamma=math.radians(60), ext=1.0)
    assert not flat.fold_angle.any() and not fold_targets(flat).any()
    full = np.where(flat.assignment == "M", -180.0, np.where(flat.assignment == "V", 180.0, 0))
    t = fold_targets(flat, full)
    assert set(np.unique(t[flat.assignment == "M"])) == {-179.0}
    assert set(np.unique(t[flat.assignment == "V"])) == {179.0}
    r = fold_pattern(flat, 0.5, target=full, **{**SECTION, "panel_thickness": 3e-3})
    assert r.verdict == "folds rigidly" and r.complete
    assert r.wrong_way.size == 0
    assert 0.45 < r.progress < 0.55


def test_a_degree_three_vertex_does_not_fold_rigidly():
    """Three valleys meeting inside a square (none collinear): no rigid motion folds them."""
    flat = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.0], [0.45, 0.55]]) * 0.05
    p = _pattern(flat, [[0, 4, 5, 3], [4, 1, 2, 5], [5, 2, 3]], "V", 60.0)
    r = fold_pattern(p, 1.0, **SECTION)
    assert r.verdict == "does not fold rigidly" and "panels bend up to" in r.note
    assert np.degrees(r.energy.panel_bend.max()) > 3.0
    assert r.energy.panel_strain.max() > 1e-4


def test_collinear_creases_fold_and_the_third_is_stuck():
    """Two collinear valleys fold as one line; the third crease of the vertex cannot follow."""
    flat = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]]) * 0.05
    p = _pattern(flat, [[0, 1, 4], [1, 2, 4], [2, 3, 0, 4]], "V", 60.0)
    r = fold_pattern(p, 1.0, **{**SECTION, "panel_thickness": 3e-3})  # stiff panels stay flat
    assert r.verdict == "folds off target" and "1 of 3 driven creases turn less" in r.note
    assert r.fold_angles[-1][p.interior] == pytest.approx([60, 0, 60], abs=2.0)


def test_a_limit_point_is_passed_by_a_snap():
    """With one Newton iteration per step no step converges; each is then completed by
    minimising the energy (the snap path), which reaches the rigid state all the same."""
    p = miura_sheet(2, 2, a=0.02, b=0.02, gamma=1.0, ext=0.6)
    r = fold_pattern(p, 1.0, max_iter=2, **SECTION)
    assert r.complete and r.verdict == "folds rigidly" and r.snaps.size > 0
    assert r.fold_angles[-1] == pytest.approx(p.fold_angle, abs=1e-4)


def test_a_step_that_cannot_converge_stops_the_fold(monkeypatch):
    import holofold.mechanics.folding as folding
    import holofold.mechanics.leave_flat as leave_flat

    monkeypatch.setattr(folding, "_relax", lambda *a, **k: None)  # no snap either
    # nor the pseudo-transient fallback (tests/test_leave_flat.py: it carries this fold on)
    monkeypatch.setattr(
        leave_flat, "flow_to_equilibrium",
        lambda asm, U, *a, **k: leave_flat.FlowResult(U, False, float("inf"), 0),
    )  # fmt: skip
    p = miura_sheet(2, 2, a=0.02, b=0.02, gamma=1.0, ext=0.6)
    r = fold_pattern(p, 1.0, max_iter=2, **SECTION)  # one Newton iteration per step
    assert r.verdict == "stalls" and not r.complete and not r.status.converged
    assert r.reached < 1.0 and r.halvings == 4
    assert "does not converge" in r.summary()


def test_energy_split_adds_up():
    p = miura_sheet(3, 3, a=0.02, b=0.02, gamma=1.0, ext=0.5)
    r = fold_pattern(p, 0.5, **SECTION)
    e = model_energy(r.structure, r.U[-1], r.rest, n_edges=p.n_edges)
    assert e.total > 0
    assert e.panel_energy.sum() + e.crease_energy.sum() == pytest.approx(e.total, rel=1e-10)
    assert (e.crease_energy[~p.interior] == 0).all()


def test_fold_settings_as_one_record_or_as_keywords():
    """``settings=FoldSettings(...)`` is the former keywords' fold: the same path (the same
    computation, to 1e-12), and the same refusals."""
    p = miura_sheet(3, 3, a=0.02, b=0.02, gamma=1.0, ext=0.5)
    old = fold_pattern(p, 0.5, model="compliant", max_step_deg=5.0, max_iter=20, **SECTION)
    st = FoldSettings(model="compliant", max_step_deg=5.0, max_iter=20)
    new = fold_pattern(p, 0.5, settings=st, **SECTION)
    assert len(new.U) == len(old.U) >= 2 and new.verdict == old.verdict
    scale = np.abs(old.U[-1]).max()
    assert scale > 1e-4  # m: it folded
    np.testing.assert_allclose(new.U[-1], old.U[-1], rtol=0, atol=1e-12 * scale)
    with pytest.raises(ValueError, match="model = 'thin'; allowed"):
        fold_pattern(p, 0.5, settings=FoldSettings(model="thin"), **SECTION)
    with pytest.raises(TypeError, match="unexpected keyword argument 'max_steps_deg'"):
        fold_pattern(p, 0.5, max_steps_deg=5.0, **SECTION)
    with pytest.raises(TypeError, match="give max_iter in the record"):
        fold_pattern(p, 0.5, settings=st, max_iter=5, **SECTION)


def test_folded_pattern_keeps_layout_and_assignment():
    p = miura_sheet(2, 2, a=0.02, b=0.02, gamma=1.0, ext=0.7)
    r = fold_pattern(p, 1.0, **SECTION)
    q = r.folded()
    assert np.array_equal(q.flat, p.flat)
    assert np.array_equal(q.assignment, p.assignment)
    assert q.fold_angle == pytest.approx(p.fold_angle, abs=1e-6)


_OS = Path(__file__).parent / "data" / "origami-simulator"
_PP = dict(panel_thickness=1e-3, crease_thickness=0.2e-3, crease_width=1e-3, E=1.5e9, nu=0.42)


@pytest.mark.parametrize("name", ["pinwheelBase.svg", "russianTriangle.svg"])
def test_fold_angles_are_tracked_through_180_degrees(name):
    """Origami Simulator's pinwheel base and Russian triangle at 100 %: valleys pass 180 deg
    (a dihedral angle known modulo 360 would read them as mountains near -180, which called
    these folds 'bifurcation at flat'); unwrapped along the path they keep their side."""
    from holofold.geometry import read_pattern
    from holofold.mechanics import scaled_pattern

    p = scaled_pattern(read_pattern(_OS / name), 0.2)
    # the path as actuated, not stopped where panels pass through each other (checked below)
    r = fold_pattern(p, 1.0, check_intersections=False, **_PP)
    assert r.complete and r.verdict == "folds rigidly", r.summary()
    assert r.wrong_way.size == 0 and math.isnan(r.wrong_at)
    # with the intersection check (the default), both stop before 100 %: the pinwheel's snap
    # at 98.8 % passes panels 4 and 7 through each other, and at 45 % the Russian triangle's
    # panels around vertex 7 cross (IPC Toolkit and the numpy test agree)
    t = fold_pattern(p, 1.0, **_PP)
    lo, hi = {"pinwheelBase.svg": (0.98, 0.99), "russianTriangle.svg": (0.44, 0.46)}[name]
    assert t.verdict == "folds until panels touch" and lo < t.touch_at < hi, t.summary()
    assert t.touch_where[0] >= 0
    assert t.wrong_way.size == 0 and math.isnan(t.wrong_at)
    a = r.fold_angles
    assert np.abs(a[-1]).max() > 180.0  # a crease past 180: the case this is about
    # the folded pattern keeps each crease's side, at most 180 deg (the FOLD convention)
    f = r.folded()
    assert np.abs(f.fold_angle).max() == 180.0
    past = np.abs(a[-1]) > 180.0
    assert (np.sign(f.fold_angle[past]) == np.sign(r.target[past])).all()


def test_a_crease_turning_against_its_assignment_is_reported_with_where_it_started():
    """Origami Simulator's flapping bird leaves flat on another branch: two driven creases end
    folded against their assignment; the verdict says so and from which fraction."""
    from holofold.geometry import read_pattern
    from holofold.mechanics import scaled_pattern

    r = fold_pattern(scaled_pattern(read_pattern(_OS / "flappingBird.svg"), 0.2), 1.0, **_PP)
    assert r.verdict == "turns against its assignment" and r.wrong_way.size >= 1
    assert 0.0 < r.wrong_at <= 0.2 and r.wrong_at in r.fractions
    assert f"the first at {100 * r.wrong_at:.1f} %" in r.note
    t, a = r.target[r.wrong_way], r.fold_angles[-1, r.wrong_way]
    assert (np.sign(a) != np.sign(t)).all() and (np.abs(a) > 10.0).all()
