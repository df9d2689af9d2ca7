"""The paper's scenarios reproduce fixed subsets of the published rows.

The full-row check is ``validation/reproduce.py``; these subsets keep the test time small.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from holofold.design.scenarios import SCENARIO_NAMES, get_scenario
from holofold.design.scenarios.arch import arch_model

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")


def _rel(ours, ref):
    return np.abs(np.asarray(ours, float) - ref) / np.abs(ref)


def _evaluate(name, df):
    sc = get_scenario(name)
    feats = [c for c in sc.feature_names if c in df.columns]
    rows = [sc.complete(r) for r in df[feats].to_dict("records")]
    out = [sc.evaluate(r) for r in rows]
    return (
        sc,
        {c: np.array([o[c] for o in out]) for c in sc.performance_names},
        [str(o["status"]) for o in out],
    )


def test_registry():
    assert SCENARIO_NAMES == ("single-miura", "canopy", "arch", "gripper", "gripper-converged")
    for n in SCENARIO_NAMES:
        sc = get_scenario(n)
        assert sc.name == n and sc.performance_names and sc.feature_names
    with pytest.raises(ValueError, match="allowed"):
        get_scenario("tube")


def test_single_miura_data0_subset(reference_data):
    d = reference_data.load("data0_SingleMiura")
    sub = d.iloc[::20]  # 50 rows
    sc, out, status = _evaluate("single-miura", sub)
    assert all(s == "converged" for s in status)
    for c in sc.performance_names:
        e = _rel(out[c], sub[c].to_numpy())
        assert np.median(e) <= 1e-5, c
        assert e.max() <= 1e-3, c


@pytest.mark.slow
@pytest.mark.parametrize(
    "stem",
    [
        "data1_MiuraSheet_sample",
        "data1_TMPSheet_sample",
        "data4_MiuraSheetMat_sample",
        "data4_TMPSheetMat_sample",
    ],
)
def test_canopy_subset(reference_data, stem):
    d = reference_data.load(stem)
    sub = pd.concat([d[(d["m"] == 24) & (d["n"] == 6)].iloc[:2], d[d["m"] == 36].iloc[:1]])
    assert len(sub)
    sc, out, status = _evaluate("canopy", sub)
    assert all(s == "converged" for s in status)
    # pooled over rows and columns: these models are ill-conditioned at the 1e-5 level
    e = np.concatenate([_rel(out[c], sub[c].to_numpy()) for c in sc.performance_names])
    assert np.median(e) <= 1e-5 and e.max() <= 1e-3, e


def test_canopy_material_columns_matter():
    sc = get_scenario("canopy")
    base = dict(pattern=2, m=24, n=6, tcrease=7e-4, tpanel=3e-3, W=2e-3)
    from holofold.design.scenarios.canopy import sheet_models

    s0 = sheet_models(sc.complete(base), extensions=(0.6,))[0][0]
    s1 = sheet_models(sc.complete({**base, "creaseE": 4e9, "panelE": 1e9}), extensions=(0.6,))[0][0]
    hinge = s0.spring_role == 0
    assert np.allclose(s1.spring_k[hinge], 2 * s0.spring_k[hinge])
    assert np.allclose(s1.spring_k[~hinge], 0.5 * s0.spring_k[~hinge])
    assert np.allclose(s1.bar_E, 1e9)


@pytest.mark.slow
def test_arch_data3_subset(reference_data):
    d = reference_data.load("data3_ShapeFit")
    sub = d.iloc[:50]  # every m, two snapping rows
    assert sub["Zsnap"].sum() >= 1 and set(sub["m"]) == {8.0, 12.0, 16.0, 24.0}
    sc, out, status = _evaluate("arch", sub)
    snap = sub["Zsnap"].to_numpy() == 1
    assert np.array_equal(out["Zsnap"], sub["Zsnap"].to_numpy())
    for c in ("Zstiff", "Xstiff"):
        assert _rel(out[c][~snap], sub[c].to_numpy()[~snap]).max() <= 1e-6, c
    assert _rel(out["error"], sub["error"].to_numpy()).max() <= 1e-12
    # snapping rows: unconverged iterate as in the reference (~1e-3), status names it
    assert _rel(out["Zstiff"][snap], sub["Zstiff"].to_numpy()[snap]).max() <= 2e-2
    for s, sn in zip(status, snap, strict=True):
        assert ("snap-through" in s) == sn
        assert (s == "converged") == (not sn)


def test_arch_model_supports_and_error():
    row = dict(m=8, tcrease=7e-4, tpanel=3e-3, W=2e-3, offset=0.2, stripeWidth=0.02, extrude=0.1)
    s, apex, err = arch_model(row)
    m = 8
    assert s.n_nodes == 6 * m + 3 + 4 * m
    assert np.flatnonzero(s.supports.all(1)).tolist() == [0, 16, 17, 33, 34, 50]
    assert apex == 8 and np.allclose(s.nodes[apex], [2, 0, 2])
    assert err == pytest.approx(0.093679, abs=1e-6)  # docs/strip-fit.md §5.1 test vector


@pytest.mark.parametrize(
    "name,row,msg",
    [
        ("single-miura", dict(tcrease=-1e-3, tpanel=1e-3, W=1e-3, gama=1.0), "tcrease"),
        ("single-miura", dict(tcrease=1e-3, tpanel=1e-3, W=1e-3, gama=2.0), "gama"),
        ("canopy", dict(pattern=2, m=25, n=6, tcrease=1e-3, tpanel=1e-3, W=1e-3), "even"),
        ("canopy", dict(pattern=2, m=24, n=7, tcrease=1e-3, tpanel=1e-3, W=1e-3), "multiple of 3"),
        ("canopy", dict(pattern=3, m=24, n=6, tcrease=1e-3, tpanel=1e-3, W=1e-3), "pattern"),
        (
            "arch",
            dict(m=9, tcrease=1e-3, tpanel=1e-3, W=1e-3, offset=0.2, stripeWidth=0.02, extrude=0.1),
            "even",
        ),  # fmt: skip
        (
            "arch",
            dict(m=8, tcrease=1e-3, tpanel=0, W=1e-3, offset=0.2, stripeWidth=0.02, extrude=0.1),
            "tpanel",
        ),  # fmt: skip
    ],
)
def test_checks_reject_invalid_rows(name, row, msg):
    errs = get_scenario(name).check(row)
    assert errs and any(msg in e for e in errs)


def test_checks_accept_paper_rows():
    assert (
        get_scenario("single-miura").check(dict(tcrease=7e-4, tpanel=3e-3, W=2e-3, gama=1.1)) == []
    )
    assert (
        get_scenario("arch").check(
            dict(m=8, tcrease=7e-4, tpanel=3e-3, W=2e-3, offset=0.2, stripeWidth=0.02, extrude=0.1)
        )
        == []
    )
    sc = get_scenario("single-miura")
    assert sc.features[3].out_of_range(math.radians(85))
    assert sc.features[3].out_of_range(math.radians(60)) is None


# ----------------------------------------------------------------------------- analyses
def _shallow_truss(h=0.1, EA=1e4):
    from holofold.mechanics.structure import Structure

    nodes = np.array([[-1.0, 0, 0], [0, 0, h], [1.0, 0, 0]])
    sup = np.ones((3, 3), bool)
    sup[1, 2] = False
    s = Structure(nodes=nodes, bars=[[0, 1], [1, 2]], bar_area=1.0, bar_E=EA,
                  springs=np.zeros((0, 4)), spring_k=[], spring_rest=[], supports=sup)  # fmt: skip
    L0 = math.hypot(1.0, h)
    return s, 2 * EA * h**3 / (3 * math.sqrt(3) * L0**3)


def test_secant_stiffness_of_shallow_truss():
    from holofold.mechanics.analyses import load_group, secant_stiffness

    s, pmax = _shallow_truss()
    P = 0.1 * pmax
    r = secant_stiffness(
        s, load_group([1], "-z"), force_per_increment=P / 4, increments=4, tol=1e-12
    )
    w = 0.1 + r.result.U[1, 2]
    L0 = math.hypot(1.0, 0.1)
    assert P == pytest.approx(1e4 * w * (0.1**2 - w**2) / L0**3, rel=1e-8)  # equilibrium
    assert r.stiffness == pytest.approx(P / abs(r.result.U[1, 2]), rel=1e-12)
    assert r.converged


def test_snap_check_mgdcm_finds_the_analytic_limit_load():
    from holofold.mechanics.analyses import load_group, snap_check_mgdcm

    s, pmax = _shallow_truss()
    snap = snap_check_mgdcm(s, load_group([1], "-z"), 1.25 * pmax, initial_step=0.02)
    assert snap.snaps
    assert snap.limit_load == pytest.approx(pmax, rel=0.01)
    safe = snap_check_mgdcm(s, load_group([1], "-z"), 0.8 * pmax, initial_step=0.05)
    assert not safe.snaps and safe.reached_load >= 0.8 * pmax
