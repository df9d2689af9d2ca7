"""The generalised Miura-ori surface fit: Jacobians, constraints, development, errors, folding."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from holofold.fitting import (
    CONSTRAINT_TOL,
    Placement,
    QuadGrid,
    builtin_surface,
    develop,
    fit_surface,
    sector_angles,
)
from holofold.fitting.quadmesh import (
    _develop_marching,
    constraints,
    planarity_scale,
    quad_warp,
)
from holofold.geometry import MAX_PANELS, ParameterError, miura_sheet
from holofold.mechanics import check_fold

CAP = builtin_surface("sphere-cap", radius=1.0, rim=0.45)
RNG = np.random.default_rng(3)


def _miura(m=4, n=6, ext=0.6):
    p = miura_sheet(m, n, a=0.03, b=0.04, gamma=math.radians(65), ext=ext)
    return p.coords.copy()


def test_a_miura_sheet_meets_every_condition_exactly():
    X = _miura()
    g = QuadGrid(4, 6)
    c = constraints(X, g, planarity_scale(X, g.quads), jacobian=False)
    assert np.abs(c).max() < 1e-13
    # sector angles are the flat ones (gamma and pi - gamma)
    th = sector_angles(X, g.quads)
    assert np.allclose(np.sort(np.unique(np.round(th, 9))), [math.radians(65), math.radians(115)])


def test_constraint_jacobian_matches_finite_differences():
    X = _miura() + 1e-3 * RNG.normal(size=(35, 3))
    g = QuadGrid(4, 6)
    scale = planarity_scale(X, g.quads)
    c, J = constraints(X, g, scale)
    J = J.toarray()
    eps = 1e-7
    for k in RNG.choice(X.size, 25, replace=False):
        Xp, Xm = X.copy().ravel(), X.copy().ravel()
        Xp[k] += eps
        Xm[k] -= eps
        fd = (
            constraints(Xp.reshape(-1, 3), g, scale, jacobian=False)
            - constraints(Xm.reshape(-1, 3), g, scale, jacobian=False)
        ) / (2 * eps)
        assert np.allclose(J[:, k], fd, rtol=1e-5, atol=1e-6 * np.abs(J).max())


def test_development_is_the_flat_miura():
    """The development of a folded Miura sheet is its flat pattern up to a rigid motion."""
    p = miura_sheet(6, 8, a=0.03, b=0.04, gamma=math.radians(60), ext=0.5)
    g = QuadGrid(6, 8)
    Y = develop(p.coords, g)
    e = p.edges
    assert np.allclose(np.linalg.norm(Y[e[:, 1]] - Y[e[:, 0]], axis=1), p.flat_edge_lengths,
                       rtol=1e-12)  # fmt: skip
    area = []
    for q in g.quads:
        x, y = Y[q, 0], Y[q, 1]
        area.append(0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    assert min(area) > 0  # every quad counter-clockwise
    Ym = _develop_marching(p.coords, g)  # the row-by-row unfolding agrees on a small sheet
    assert np.allclose(np.linalg.norm(Ym[e[:, 1]] - Ym[e[:, 0]], axis=1), p.flat_edge_lengths,
                       rtol=1e-10)  # fmt: skip


@pytest.mark.parametrize("cells", [(8, 8), (12, 10)])
def test_cap_fit_meets_constraints_and_beats_the_anchor(cells):
    """Constraints to CONSTRAINT_TOL, the flat pattern is the development, the fitted side is
    far closer to the sphere than the RFFQM anchor (0.0295 R at 64 panels)."""
    fit = fit_surface(CAP, cells, placement=Placement(size=(0.73, 0.78)))
    assert fit.ok, fit.message
    r = fit.residuals
    assert r["planarity_max"] < CONSTRAINT_TOL and r["kawasaki_max"] < CONSTRAINT_TOL
    assert r["angle_sum_max"] < CONSTRAINT_TOL and r["development_max"] < 1e-8
    assert fit.rms < 0.0295 / 10 and fit.max < 0.053 / 10  # R = 1
    # the distances are the sphere's: |x - c| - R of the side vertices
    side = fit.coords[fit.side]
    assert np.allclose(fit.distance, np.linalg.norm(side - [0, 0, -1], axis=1) - 1, atol=1e-14)
    # the crease pattern: every interior crease folded, Maekawa |M - V| = 2 at every vertex
    p = fit.pattern
    inner = p.interior
    assert set(p.assignment[inner]) <= {"M", "V"} and np.abs(p.fold_angle[inner]).min() > 1
    assert np.isfinite(list(fit.errors.values())).all()
    ids, _ = fit.grid.interior
    for v in ids[:: max(1, len(ids) // 15)]:
        at = (p.edges == v).any(axis=1) & inner
        mv = p.assignment[at]
        assert len(mv) == 4 and abs((mv == "M").sum() - (mv == "V").sum()) == 2


def test_fit_is_folded_by_the_simulator():
    """The honest fold: the flat pattern, folded from flat by rest-angle actuation, reaches
    the fitted state (here to 1e-9 of the size, far inside the 1e-3 tolerance)."""
    fit = fit_surface(CAP, (8, 8), placement=Placement(size=(0.73, 0.78)))
    fc = check_fold(fit)
    assert fc.reached, fc.reason
    assert fc.deviation_max < 1e-9 * CAP.size


def test_large_extrapolated_steps_reach_the_small_steps_state():
    """The check's 20-degree steps from the secant predictor end where 3-degree steps from the
    last state do (the same equilibrium, to 1e-9 of the size), in fewer steps."""
    fit = fit_surface(CAP, (8, 8), placement=Placement(size=(0.73, 0.78)))
    big = check_fold(fit)
    small = check_fold(fit, max_step_deg=3.0, extrapolate=False)
    assert big.reached and small.reached, (big.reason, small.reason)
    assert big.steps <= small.steps / 4
    assert np.abs(big.coords - small.coords).max() < 1e-9 * CAP.size


def test_a_fold_over_its_time_limit_is_not_verified():
    """A check that runs out of time says so (not verified, how far it got), neither folded
    nor failed for a reason of the fit."""
    fit = fit_surface(CAP, (8, 8), placement=Placement(size=(0.73, 0.78)))
    fc = check_fold(fit, time_limit=1e-9)
    assert fc.timed_out and not fc.reached
    assert fc.reason.startswith("not verified: the fold ran over its time limit of 1e-09 s at")
    assert fc.summary["fold_timed_out"] is True


def test_a_fit_that_does_not_fold_is_reported():
    """Warped quads are not a rigid fold: the check says the simulation ends away from it."""
    fit = fit_surface(CAP, (6, 6), placement=Placement(size=(0.6, 0.6)))
    bad = fit.coords.copy()
    bad[fit.grid.vid(3, 3)] += [0, 0, 0.02]  # one vertex out of its quads' planes
    broken = replace(fit, coords=bad)
    assert quad_warp(bad, fit.grid.quads).max() > 1e-3
    fc = check_fold(broken)
    assert not fc.reached and "from the fitted one" in fc.reason


def test_inputs_are_checked_before_work():
    with pytest.raises(ParameterError, match="MAX_PANELS"):
        fit_surface(CAP, (101, 100))
    assert MAX_PANELS == 10_000
    with pytest.raises(ParameterError, match="MxN"):
        fit_surface(CAP, "16by16")
    with pytest.raises(ParameterError, match="leaves the target's chart"):
        fit_surface(CAP, (8, 8), placement=Placement(size=(2.0, 2.0)))
    with pytest.raises(ParameterError, match="side"):
        fit_surface(CAP, (8, 8), side="left")


def test_too_curved_a_target_fails_with_the_reason():
    """A saddle curved as tightly as the cells (radius 0.4 m, cells 0.045 m) cannot be met:
    the fit says so, it does not return a broken pattern or raise from the linear algebra."""
    saddle = builtin_surface("saddle", radius=0.4, width=0.8, depth=0.8)
    fit = fit_surface(saddle, (10, 10), placement=Placement(size=(0.73, 0.73)))
    assert not fit.ok and fit.message
    assert any(w in fit.message for w in ("constraints", "linear systems", "degenerated", "flat"))


@pytest.mark.parametrize("sparse", [False, True])
def test_spd_factor_solves_the_preconditioner_block(sparse):
    """Both factorisations of J^T J + mu I (banded in the grid's band order; CHOLMOD where
    installed) solve it to rounding, and a singular matrix gets its damping raised."""
    from holofold.fitting.spd_factor import SPDFactor, cholmod_available

    if sparse and not cholmod_available():
        pytest.skip("cvxopt (holofold[cholmod]) is not installed")
    grid = QuadGrid(5, 7)
    X = _miura(5, 7) + RNG.normal(scale=1e-3, size=(grid.nv, 3))
    _, J = constraints(X, grid, planarity_scale(X, grid.quads))
    A = (J.T @ J).tocsr()  # singular: rigid motions and the mechanism
    f = SPDFactor(grid.band_order, grid.bandwidth, sparse=sparse)
    mu = f.factor(A, 1e-3)
    assert mu == 1e-3
    b = RNG.normal(size=A.shape[0])
    x = f.solve(b)
    scale = abs(A).sum(axis=1).max() * np.linalg.norm(x)  # backward error: rounding
    assert np.linalg.norm(A @ x + mu * x - b) < 1e-13 * scale
    raised = f.factor(A, 0.0)  # 1e-11 of the diagonal, raised where Cholesky breaks down
    assert 0 < raised < 1e-3 * float(A.diagonal().max())


def test_cholmod_and_banded_fits_agree():
    """The fit with CHOLMOD's factorisation is the banded one's (the same iterates: the
    factorisation is only the preconditioner)."""
    from holofold.fitting import spd_factor

    if not spd_factor.cholmod_available():
        pytest.skip("cvxopt (holofold[cholmod]) is not installed")
    place = Placement(size=(0.73, 0.78))
    sparse = fit_surface(CAP, (12, 12), placement=place)
    orig = spd_factor._cvxopt
    try:
        spd_factor._cvxopt = lambda: None
        banded = fit_surface(CAP, (12, 12), placement=place)
    finally:
        spd_factor._cvxopt = orig
    assert sparse.options["factorisation"] == "cholmod"
    assert banded.options["factorisation"] == "banded"
    assert sparse.rms == pytest.approx(banded.rms, rel=1e-6)
    assert np.abs(sparse.coords - banded.coords).max() < 1e-7  # m: MINRES stops at 1e-6-1e-9
