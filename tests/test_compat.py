"""Profiles of reference quirks: field set, validation, and the effect the spec documents."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from holofold.design.scenarios.single_miura import EXTENSIONS, cell_models
from holofold.mechanics.analyses import secant_stiffness
from holofold.mechanics.compat import PAPER, PHYSICAL, Profile

FIELDS = {
    "edge_bar_area_last_panel",
    "panel_spring_width_is_crease_width",
    "approximate_corner_offset",
    "polarity_z_only",
    "mass_skip_first_triangles",
    "mass_centre_share",
    "reset_non_crease_rest_angles",
    "thermal_reinterpolate_from_stage_start",
}


def test_profiles_have_every_switch():
    names = {f.name for f in dataclasses.fields(Profile)}
    assert FIELDS <= names
    for f in FIELDS - {"mass_centre_share"}:
        assert getattr(PAPER, f) is True, f
        assert getattr(PHYSICAL, f) is False, f
    assert PAPER.mass_centre_share == PHYSICAL.mass_centre_share == pytest.approx(1 / 3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        PAPER.polarity_z_only = False  # type: ignore[misc]
    with pytest.raises(ValueError, match="mass_centre_share"):
        Profile(mass_centre_share=1.5)


def _stiffness(row, profile):
    models = cell_models(*row, profile=profile)
    return np.array([secant_stiffness(s, g, increments=3, tol=1e-7).stiffness for s, g in models])


def test_edge_area_quirk_moves_data0_row1_as_documented(reference_data):
    """specs/scenarios.md 1.3: accumulating the edge areas gives 5870.5 / 11683.2 / 70595.0
    for data0 row 1 instead of the published 6004.7 / 11762.5 / 71445.7."""
    d = reference_data.load("data0_SingleMiura")
    row = d.iloc[0][["tcrease", "tpanel", "W", "gama"]].to_numpy()
    published = d.iloc[0][["axialstiff30", "axialstiff60", "axialstiff90"]].to_numpy()
    paper = _stiffness(row, PAPER)
    assert np.allclose(paper, published, rtol=2e-5)
    summed = _stiffness(row, dataclasses.replace(PAPER, edge_bar_area_last_panel=False))
    assert np.allclose(summed, [5870.5, 11683.2, 70595.0], rtol=2e-5)
    assert len(EXTENSIONS) == 3
