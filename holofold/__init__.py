"""holofold: holistic inverse design of origami, shape and function.

From a target (a curve to follow, a stiffness, a snap-through or not) to a design that can be
fabricated. Four layers, each with its own public face, import one way only::

    holofold.geometry   crease patterns, generators, meshes, fabrication files
    holofold.fitting    curves and the Miura strip fitted to them
    holofold.mechanics  bar-and-hinge simulation, electro-thermal actuation, modes
    holofold.design     scenarios, databases, design rules, verification

The layers are attributes (``hf.design``, ``hf.geometry``, ...) and the names a user needs
first are here too, all imported on first use, so ``import holofold`` is cheap. SI units
throughout.

Quickstart: fit the paper's arch to a half circle, simulate one design, build a small
database and mine a rule from it.

>>> import holofold as hf
>>> fit = hf.fit_strip(hf.builtin_curve("half-circle", radius=2.0), m=12, offset=0.2,
...                    strip_width=0.02, extrude=0.1)
>>> fit.pattern.n_vertices, fit.pattern.n_faces, round(fit.index_error, 4)  # m
(75, 48, 0.0972)
>>> arch = hf.get_scenario("arch")
>>> out = arch.evaluate({"m": 12, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3,
...                      "offset": 0.2, "stripeWidth": 0.02, "extrude": 0.1})
>>> str(out["status"]), round(out["Zstiff"], 1), round(out["Xstiff"], 1)  # N/m
('converged', 92.3, 79.9)
>>> sheet = hf.miura_sheet(4, 4, a=0.02, b=0.02, gamma=1.0, ext=0.6)  # m, rad
>>> sheet.n_vertices, sheet.n_faces
(25, 16)

The design loop is asked with three records, each checked when made: what you want
(:class:`DesignProblem`), how it searches (:class:`LoopSettings`) and how it runs
(:class:`Execution`); ``hf.run_design(problem, folder=..., settings=..., execution=...)`` then
writes the chosen design, its files and ``report.html`` (docs/scenarios.md §9).

>>> problem = hf.DesignProblem("arch", "Zstiff > 100 & error < 0.1", objective="min tpanel")
>>> problem.target.columns, problem.objective.column
(('Zstiff', 'error'), 'tpanel')
>>> hf.LoopSettings(samples=200, budget=1000, strategy="mixed").budget
1000
>>> hf.LoopSettings(samples=10)
Traceback (most recent call last):
ValueError: samples = 10 must be an integer >= 20

Everything else is on the layer faces (``hf.geometry``, ``hf.fitting``, ``hf.mechanics``,
``hf.design``); extending holofold (a reader, a format, a pattern family, a scenario kind, a
cutter profile, a refinement strategy) is described in CONTRIBUTING.md.
"""

import lazy_loader

#: the four layers, and the names a user needs first by the layer whose face offers them
#: (each imported on first use; at most about 40: the layer faces keep the rest)
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submodules=["geometry", "fitting", "mechanics", "design"],
    submod_attrs={
        "geometry": [
            "CreasePattern",
            "miura_sheet",
            "tmp_sheet",
            "read_pattern",
            "export",
            "CutterOptions",
        ],
        "fitting": [
            "builtin_curve",
            "load_curve",
            "fit_strip",
            "fit_auto",
            "builtin_surface",
            "load_surface",
            "fit_surface",
        ],
        "mechanics": ["build_concentrated", "secant_stiffness", "PAPER", "check_fold"],
        "design": [
            "get_scenario",
            "evaluate_designs",
            "generate_database",
            "read_table",
            "ForestRuleMiner",
            "mine_rules",
            "verify_rules",
            "run_design",
            "DesignProblem",
            "LoopSettings",
            "Execution",
            "load_scenario",
            "read_scenario",
            "parse_target",
        ],
    },
)
