"""The toy scenario of the batch-evaluation tests: one length a, one column double = 2 a."""

from __future__ import annotations

from holofold.design.scenarios import Column, Scenario


def toy_scenario(evaluate, check=lambda row: []) -> Scenario:
    """Scenario "toy": feature a (m, sampled in [1, 10]), performance double (m); ``evaluate``
    and ``check`` as :class:`Scenario` takes them (module-level functions pickle for workers)."""
    return Scenario(
        name="toy",
        description="doubles a",
        features=(Column("a", "m", "a length", 1.0, 10.0),),
        performance=(Column("double", "m", "2 a"),),
        check=check,
        evaluate=evaluate,
    )
