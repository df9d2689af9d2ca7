"""Physical sanity of a sheet before a model is built (issue 33 item 2)."""

import math

import numpy as np
import pytest

import holofold.geometry as g
from holofold.geometry.errors import ParameterError
from holofold.geometry.physical import SheetWarning, check_sheet, sheet_mass
from holofold.mechanics import PatternSetting, scaled_pattern, simulate_pattern


def _miura():
    return g.miura_sheet(4, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=1.0)


def test_scaled_down_pattern_refused_before_folding():
    small = scaled_pattern(_miura(), 0.03)  # panels ~0.6 mm, default 1 mm crease width
    # 2.6 mm across: warned as an unlikely size, then refused (1 mm creases on 0.6 mm panels)
    with pytest.raises(ParameterError, match="mm"), pytest.warns(SheetWarning, match="2.598 mm"):
        simulate_pattern(small, PatternSetting())


def test_crease_wider_than_panels_refused_with_pattern_size():
    with pytest.raises(ParameterError, match="wider than panel"):
        check_sheet(_miura(), crease_width=0.05)


def test_extent_refused_and_warned():
    p = _miura()
    with pytest.raises(ParameterError, match="outside"):
        check_sheet(scaled_pattern(p, 1e-4))
    with pytest.warns(SheetWarning, match="read in in"):
        check_sheet(scaled_pattern(p, 0.0254), unit="in")


def test_sheet_mass_of_a_square_is_analytic():
    # two triangles of a 0.1 m square, one 0.1*sqrt(2) m diagonal crease
    xy = np.array([[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]], float)
    edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]])
    sq = g.CreasePattern(xy, (np.array([0, 1, 2]), np.array([0, 2, 3])), edges,
                         np.array(["B", "B", "B", "B", "M"]), np.zeros(5))  # fmt: skip
    m = sheet_mass(sq, 1e-3, 5e-4, 1e-3, 1000.0)
    want = 1000.0 * (0.01 * 1e-3 + 0.1 * math.sqrt(2) * 1e-3 * (5e-4 - 1e-3))
    assert m == pytest.approx(want, rel=1e-12)


def test_good_sheet_passes():
    check_sheet(_miura(), panel_thickness=1e-3, crease_thickness=5e-4, crease_width=1e-3)
