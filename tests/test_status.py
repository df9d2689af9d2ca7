"""The Status type: text round trip, gathering labelled parts, table masks."""

import numpy as np
import pytest

from holofold.mechanics.status import (
    CONVERGED,
    Outcome,
    Status,
    converged_mask,
    failed_mask,
)


def test_text_round_trip():
    for s in (
        CONVERGED,
        Status.not_converged("2 of 5 increments above tol: increment 3", "X case"),
        Status.failed("RuntimeError: singular tangent"),
    ):
        back = Status.parse(str(s))
        assert str(back) == str(s) and back.outcome is s.outcome
    assert str(CONVERGED) == "converged"
    assert str(Status.failed("no closure")) == "failed: no closure"
    assert Status.parse(CONVERGED) is CONVERGED


def test_invalid_statuses_are_refused():
    with pytest.raises(ValueError, match="needs a reason"):
        Status(Outcome.FAILED)
    with pytest.raises(ValueError, match="no reasons"):
        Status(Outcome.CONVERGED, ("why",))
    with pytest.raises(ValueError, match="not 'converged'"):
        Status.parse("ok")
    with pytest.raises(ValueError, match="not 'converged'"):
        Status.parse("converged: but")


def test_from_exception_keeps_the_first_line():
    s = Status.from_exception(ValueError("bad value\nsecond line"))
    assert str(s) == "failed: ValueError: bad value" and s.is_failed
    assert str(Status.from_exception(KeyError())) == "failed: KeyError"


def test_gather_takes_the_worst_outcome_and_labels_the_parts():
    nc = Status.not_converged("1 of 3 increments above tol")
    fl = Status.failed("increment 2, iteration 4: singular")
    assert Status.gather({"a": CONVERGED, "b": CONVERGED}) is CONVERGED
    g = Status.gather({"Z case": nc, "X case": CONVERGED})
    assert str(g) == "not converged: Z case: 1 of 3 increments above tol"
    g = Status.gather({"Z case": nc, "X case": fl})
    assert g.is_failed and g.reasons == (
        "Z case: not converged: 1 of 3 increments above tol",
        "X case: increment 2, iteration 4: singular",
    )
    capped = Status.gather({"Z case": nc, "X case": fl}, worst=Outcome.NOT_CONVERGED)
    assert capped.outcome is Outcome.NOT_CONVERGED
    assert capped.reasons[1] == "X case: failed: increment 2, iteration 4: singular"


def test_masks_read_text_and_objects():
    col = ["converged", "not converged: x", "failed: y", CONVERGED, Status.failed("z")]
    np.testing.assert_array_equal(failed_mask(col), [False, False, True, False, True])
    np.testing.assert_array_equal(converged_mask(col), [True, False, False, True, False])
    assert failed_mask([]).shape == (0,)
