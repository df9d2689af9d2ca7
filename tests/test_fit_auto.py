"""Automatic choice of m and offset (fitting.auto)."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.fitting import fit_strip
from holofold.fitting.auto import PUBLISHED_MAX_WARP, FitNotFoundError, ThickCheck, fit_auto
from holofold.fitting.curves import parse_curve_spec
from holofold.geometry.errors import ParameterError

HALF = parse_curve_spec("half-circle:radius=2")


def test_half_circle_smallest_m_and_largest_offset():
    res = fit_auto(HALF, 0.1, m_range=[2, 4, 6, 8], offsets=[0.05, 0.1, 0.15, 0.2])
    fit, table = res
    # the circle's odd vertices lie at R + l_o, so the max closest-point error is >= offset,
    # and equal to it once the chords are short enough (m >= 4 here)
    assert (table["closest_max"] >= table["offset"] * (1 - 1e-9)).all()
    fine = table["m"] >= 4
    np.testing.assert_allclose(table["closest_max"][fine], table["offset"][fine], rtol=1e-9)
    # m = 2: the long chords cut inside the circle by more than 0.1 for small offsets
    np.testing.assert_allclose(table["closest_max"][:2], [0.129119485, 0.110257353], rtol=1e-8)
    assert fit.m == 4
    assert fit.offset == 0.1
    chosen = table[table["chosen"]]
    assert len(chosen) == 1 and int(chosen["m"].iloc[0]) == fit.m
    # every smaller m tried has no valid candidate meeting the tolerance
    smaller = table[table["m"] < fit.m]
    assert not (smaller["meets"] & smaller["valid"]).any()
    assert fit.closest.max <= 0.1 * (1 + 1e-9)
    # strip_width default: offset / 8; extrude default: length / 40
    np.testing.assert_allclose(fit.strip_width, 0.1 / 8)
    np.testing.assert_allclose(fit.extrude, np.pi * 2 / 40, rtol=1e-6)
    # the candidates' numbers are those of the full fit
    row = chosen.iloc[0]
    ref = fit_strip(HALF, int(row["m"]), row["offset"], row["strip_width"], row["extrude"])
    np.testing.assert_allclose(row["index_error"], ref.index_error, rtol=1e-14)


def test_mean_metric_and_smallest_error_preference():
    res = fit_auto(
        "parabola:span=4,height=1",
        0.02,
        m_range=range(2, 21, 2),
        metric="mean",
        prefer="smallest-error",
        strip_width=0.002,
        extrude=0.05,
    )
    t = res.candidates
    row = t[t["chosen"]].iloc[0]
    same_m = t[(t["m"] == row["m"]) & t["meets"]]
    assert row["closest_mean"] == same_m["closest_mean"].min()
    assert row["closest_mean"] <= 0.02
    assert res.strip.strip_width == 0.002 and res.strip.extrude == 0.05


def test_no_fit_found_reports_best():
    with pytest.raises(FitNotFoundError, match="best valid candidate reaches") as info:
        fit_auto(HALF, 0.01, m_range=[8], offsets=[0.1, 0.2])
    assert len(info.value.candidates) == 2


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"tolerance": 0.0}, "tolerance"),
        ({"tolerance": 0.1, "m_range": [1]}, "m must be an integer >= 2"),
        ({"tolerance": 0.1, "m_range": []}, "m_range is empty"),
        ({"tolerance": 0.1, "offsets": [-0.1]}, "offset"),
        ({"tolerance": 0.1, "metric": "rms"}, "metric"),
        ({"tolerance": 0.1, "strip_width": 0.0}, "strip_width"),
    ],
)
def test_bad_input(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        fit_auto(HALF, **kwargs)


def test_max_warp_keeps_the_choice_within_the_published_designs():
    kw = {"strip_width": 0.02, "extrude": 0.1}
    free = fit_auto("parabola:span=4,height=1", 0.05, max_warp=None, **kw)
    assert (free.strip.m, free.strip.offset) == (4, pytest.approx(0.04))
    assert free.strip.warp.max() == pytest.approx(0.0938, abs=5e-4)  # what the issue saw
    held = fit_auto("parabola:span=4,height=1", 0.05, **kw)  # default: PUBLISHED_MAX_WARP
    assert held.strip.warp.max() <= PUBLISHED_MAX_WARP
    assert (held.strip.m, held.strip.offset) == (8, pytest.approx(0.05))
    t = held.candidates
    assert t.loc[t["chosen"], "warp_max"].iloc[0] == pytest.approx(held.strip.warp.max())
    refused = t[(t["m"] == 4) & t["reason"].str.contains("max_warp")]
    assert len(refused) and (refused["warp_max"] > PUBLISHED_MAX_WARP).all()
    with pytest.raises(FitNotFoundError, match="refused because quads warp"):
        fit_auto("parabola:span=4,height=1", 0.05, m_range=[4], max_warp=0.01, **kw)


def test_no_overlap_of_the_folded_thick_panels():
    res = fit_auto(HALF, 0.1, m_range=[4, 6, 8], panel_thickness=6e-3, crease_width=1e-3,
                   require_no_overlap=True)  # fmt: skip
    t = res.candidates
    chosen = t[t["chosen"]].iloc[0]
    assert chosen["overlap"] == 0.0 and chosen["clearance"] > 0
    over = t[t["reason"].str.contains("thick panels overlap", na=False)]
    assert len(over) and (over["overlap"] > 0).all()  # deeper corrugations collide
    assert chosen["offset"] < over["offset"].max() or chosen["m"] > over["m"].min()
    with pytest.raises(ParameterError, match="needs a panel thickness"):
        fit_auto(HALF, 0.1, require_no_overlap=True)


def test_the_thick_panels_as_one_record_or_as_keywords():
    """``thick_check=ThickCheck(...)`` is the former keywords' fit: the same candidates (the
    same computation) and the same refusals."""
    import pandas as pd

    kw = dict(m_range=[4, 6], offsets=[0.05, 0.1, 0.2])
    old = fit_auto(HALF, 0.1, panel_thickness=6e-3, crease_width=1e-3, require_no_overlap=True,
                   thick="offset", **kw)  # fmt: skip
    check = ThickCheck(6e-3, 1e-3, require_no_overlap=True, thick="offset")
    new = fit_auto(HALF, 0.1, thick_check=check, **kw)
    pd.testing.assert_frame_equal(old.candidates, new.candidates, rtol=1e-12)
    chosen = new.candidates[new.candidates["chosen"]].iloc[0]
    assert chosen["overlap"] == 0.0 and new.strip.m == old.strip.m == chosen["m"]
    with pytest.raises(ParameterError, match="needs both a panel thickness and a crease width"):
        fit_auto(HALF, 0.1, thick_check=ThickCheck(panel_thickness=6e-3), **kw)
    with pytest.raises(ParameterError, match="unknown thickness technique 'thin'"):
        fit_auto(HALF, 0.1, thick_check=ThickCheck(thick="thin"), **kw)
    with pytest.raises(TypeError, match="unexpected keyword argument 'panel_thicknes'"):
        fit_auto(HALF, 0.1, panel_thicknes=6e-3)
    with pytest.raises(TypeError, match="give crease_width in the record"):
        fit_auto(HALF, 0.1, thick_check=check, crease_width=2e-3)


@pytest.mark.slow
def test_published_max_warp_is_what_the_published_arches_reach(reference_data):
    from holofold.fitting.strip import quad_warp, strip_geometry

    rows = reference_data.load("data3_ShapeFit")
    worst = max(
        quad_warp(g.nodes, g.faces).max()
        for g in (
            strip_geometry(HALF, int(r.m), r.offset, r.stripeWidth, r.extrude, "paper")
            for r in rows.itertuples()
        )
    )
    assert worst == pytest.approx(0.0347, abs=5e-5)
    assert worst <= PUBLISHED_MAX_WARP < worst + 1e-3
