"""The end-to-end demo on the paper's arch: fit, simulate, database, rules, verification.

:func:`run_demo` is what ``holofold demo`` runs, step by step through the library:

1. fit a Miura strip to a half circle of radius 2 m and write its fabrication files
   (FOLD, SVG, STL, OBJ and a printable thick solid);
2. simulate that strip (vertical and horizontal stiffness, snap-through, fitting error);
3. sample arch designs and simulate them into a resumable Parquet database;
4. mine design rules for a target from the database (random forest, held-out test);
5. verify the best rule by simulating fresh designs inside it.

Everything lands in one folder, with ``summary.json`` describing what was done.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from pathlib import Path

from holofold.design.mining import mine_rules
from holofold.design.report import mining_summary, plot_rules, save_figure
from holofold.design.rulefile import rules_to_records, write_rules
from holofold.design.rules import FewRulesWarning
from holofold.design.runner import check_workers
from holofold.design.scenarios import get_scenario
from holofold.design.store import generate_database
from holofold.design.tables import column_roles
from holofold.design.targets import parse_target
from holofold.design.verify import verify_rules, write_verification
from holofold.fitting import builtin_curve, export_strip_files, fit_strip
from holofold.geometry.outputs import write_json

__all__ = ["DEMO_TARGET", "DEMO_STRIP", "DEMO_MATERIAL", "run_demo"]

DEMO_TARGET = "Zstiff > 100 & error < 0.1"
#: the fitted strip of step 1 (arch feature names, SI units)
DEMO_STRIP = {"m": 12, "offset": 0.2, "stripeWidth": 0.02, "extrude": 0.1}
#: a printable strip: 2 mm panels, 3 mm hinge gaps (the thick panels do not overlap)
DEMO_MATERIAL = {"tcrease": 0.8e-3, "tpanel": 2e-3, "W": 3e-3}


def run_demo(
    folder: str | os.PathLike,
    *,
    samples: int = 200,
    verify: int = 30,
    target: str = DEMO_TARGET,
    seed: int = 0,
    workers: int = 2,
    say: Callable[[str], None] = lambda text: None,
) -> dict:
    """Run the five steps into ``folder``; returns the summary (also ``summary.json``).

    ``say`` receives a line of progress per step (the command line prints them). Every
    argument is checked before the folder is created.
    """
    arch = get_scenario("arch")
    parse_target(target, arch.performance_names)
    if samples < 20:
        raise ValueError(f"--samples = {samples} must be >= 20 for rules to be mined")
    if verify < 1:
        raise ValueError(f"--verify = {verify} must be >= 1")
    check_workers(workers)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    design = {**DEMO_STRIP, **DEMO_MATERIAL}
    summary: dict = {"target": target}

    say("[1/5] fit a Miura strip to a half circle (radius 2 m) and export it")
    fit = fit_strip(
        builtin_curve("half-circle", radius=2.0), DEMO_STRIP["m"], DEMO_STRIP["offset"],
        DEMO_STRIP["stripeWidth"], DEMO_STRIP["extrude"],
    )  # fmt: skip
    files = export_strip_files(
        fit, out / "1_fit", panel_thickness=DEMO_MATERIAL["tpanel"], crease_width=design["W"]
    )
    summary["fit"] = {**fit.parameters, **fit.errors, "files": [str(f) for f in files]}

    say("[2/5] simulate the fitted strip (pinned feet, 5 N at the apex)")
    perf = arch.evaluate(design)
    perf["status"] = str(perf["status"])
    summary["fitted_strip"] = {"design": design, "performance": perf}
    say(
        f"Zstiff = {perf['Zstiff']:.1f} N/m, Xstiff = {perf['Xstiff']:.1f} N/m, "
        f"snaps = {bool(perf['Zsnap'])}, fitting error = {perf['error']:.4f} m ({perf['status']})"
    )

    say(f"[3/5] sample {samples} arch designs and simulate them into a database")
    db_folder = out / "2_database"
    db = generate_database(arch, samples, db_folder, seed=seed, workers=workers, csv=True)

    say(f"[4/5] mine design rules for: {target}")
    with warnings.catch_warnings():  # the summary says when fewer rules survive
        warnings.simplefilter("ignore", FewRulesWarning)
        mined = mine_rules(
            db, target, roles=column_roles(db.columns, db_folder / "database.parquet"),
            seed=seed, max_overlap=0.5, source=str(db_folder / "database.parquet"),
        )  # fmt: skip
    say(mining_summary(mined, str(db_folder / "database.parquet")))
    records = rules_to_records(mined.miner, mined.test_scores)
    rules_dir = out / "3_rules"
    rules_dir.mkdir(exist_ok=True)
    write_rules(rules_dir / "rules.json", records)
    save_figure(plot_rules(mined.miner, mined.table[list(mined.features)]), rules_dir / "rules.png")
    summary["rules"] = records
    if not records:
        raise ValueError(f"no rule was found for {target!r}; try more --samples")

    say(f"[5/5] verify the best rule with {verify} fresh simulations")
    results = verify_rules(arch, records[:1], target, verify, seed=seed, workers=workers)
    summary["verification"] = write_verification(out / "4_verify", records[:1], results)
    write_json(out / "summary.json", summary)
    say(
        f"\ndone: best rule '{records[0]['rule']}' holds for {results[0].n_meeting}/"
        f"{results[0].n_ok} fresh designs; files in {out}/ (summary.json, 1_fit/, "
        "2_database/, 3_rules/, 4_verify/)"
    )
    return summary
