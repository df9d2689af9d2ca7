"""The end-to-end demo: ``holofold design`` on the paper's arch, small enough for a minute.

:func:`run_demo` is what ``holofold demo`` runs: the design loop of
:mod:`~holofold.design.loop.design_loop`
on the shipped ``arch.toml`` scenario file (a Miura strip over a half circle of radius 2 m):
a database of arch designs, rules for :data:`DEMO_TARGET`, their verification by fresh
simulations, one refinement round, the chosen design with its margins, its fabrication files
(FOLD, SVG, STL, OBJ, thick solid), pictures and ``report.html``, all in one folder.
"""

from __future__ import annotations

import os
from collections.abc import Callable

from holofold.design.loop.design_loop import run_design
from holofold.design.loop.settings import DesignProblem, Execution, LoopSettings
from holofold.design.scenarios import shipped_scenarios

__all__ = ["DEMO_TARGET", "run_demo"]

DEMO_TARGET = "Zstiff > 100 & error < 0.1"


def run_demo(
    folder: str | os.PathLike,
    *,
    samples: int = 200,
    verify: int = 30,
    rounds: int = 1,
    refine: int = 60,
    target: str = DEMO_TARGET,
    seed: int = 0,
    workers: int = 2,
    say: Callable[[str], None] = lambda text: None,
) -> dict:
    """Run the design loop on the arch into ``folder``; returns the summary (``design.json``).

    Every argument is checked before the folder is created.
    """
    problem = DesignProblem(shipped_scenarios()["arch"], target)
    settings = LoopSettings(samples=samples, rounds=rounds, refine=refine, verify=verify,
                            seed=seed, until_verified=False)  # fmt: skip
    execution = Execution(workers=workers, say=say)
    out = run_design(problem, folder=folder, settings=settings, execution=execution)
    return out.summary
