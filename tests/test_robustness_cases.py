"""Issue 33 cases checked one by one (docs/robustness.md): the design command's verdict line."""

from types import SimpleNamespace

import pytest

from holofold.design.loop.buildability import PartFit
from holofold.design.loop.design_loop import _say_chosen


def _said(fab):
    chosen = SimpleNamespace(rule=None, features={}, performance={}, meets=True, worst_margin=0.5)
    summary = SimpleNamespace(chosen=chosen, answer="rule", fabrication=fab)
    lines = []
    _say_chosen(lines.append, summary, SimpleNamespace(columns=[]), "out", {})
    return lines[0]


def _fit(turn, pieces, problem=""):
    return PartFit("files/printable.stl", (6.6, 0.49, 4.85e-3), 1e-5, (0.01, 0.01), turn,
                   872.0, "days", pieces, problem=problem)  # fmt: skip


@pytest.mark.parametrize(
    ("fab", "cannot"),
    [(None, False), (_fit(0.0, 1), False), (_fit(None, 101), False),
     (_fit(None, 0, "panel 0 cannot be sliced to fit the 10 x 10 mm bed"), True)],
)  # fmt: skip
def test_meets_the_target_is_not_said_alone_for_a_part_that_cannot_be_printed(fab, cannot):
    """`design --bed 10x10` said 'meets the target' while the part line and the report said the
    part cannot be cut to fit that bed; the verdict now says both."""
    line = _said(fab)
    assert "meets the target" in line
    assert ("cannot be printed on the 10 x 10 mm bed" in line) is cannot
