"""Design your own arch end to end through the Python API: curve, function, files.

Usage::

    python examples/design_my_arch.py [output-folder] [samples]    # default: my-arch/, 400

The problem: a Miura strip over a catenary of span 3 m (rise 1.5 m) given as a CSV of points in
millimetres (``examples/data/catenary_span3m_mm.csv``), pinned at its feet, with 5 N down at
mid-span. The target: stiffer than 300 N/m under that load while the strip's centre line stays
within 4 cm of the curve (:data:`TARGET`). The steps, each one library call:

1. the scenario object (curve, material, supports, load, feature ranges);
2. a database of simulated designs (resumable: run the script again and it continues);
3. design rules mined for the target;
4. each rule verified by simulating fresh designs inside it;
5. the simulated design with the largest margin inside the best verified rule;
6. its fabrication files (FOLD, SVG, STL, OBJ, thick solid) and ``design.json``.

``examples/my_arch.toml`` is the same problem as a file for ``holofold design``, which also
refines the database around the rules and writes a report page. ``RESULT`` holds the numbers
of the last run.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

from holofold.design import (
    STRIP_FEATURES,
    StripLoad,
    StripSetting,
    choose_design,
    column_roles,
    generate_database,
    mine_rules,
    mined_rules,
    parse_target,
    strip_scenario,
    verify_rules,
)
from holofold.fitting import read_points_csv
from holofold.geometry import write_json

HERE = Path(__file__).resolve().parent
TARGET = "Vstiff > 300 & error < 0.04"
#: filled by :func:`main`
RESULT: dict = {}


def my_arch():
    """The scenario object: the same problem as ``examples/my_arch.toml``."""
    curve = read_points_csv(HERE / "data" / "catenary_span3m_mm.csv", units="mm")  # in m
    setting = StripSetting(
        curve=curve,
        loads=(
            StripLoad(
                "V", at=0.5, direction=(0, 0, -1), force=5.0, increments=5, snap_displacement=0.5
            ),
        ),  # fmt: skip
        E=2.0e9,
        nu=0.3,
        density=1250.0,
        curve_label="catenary, span 3 m, rise 1.5 m (CSV in mm)",
    )
    ranges = {"m": (8, 10, 12, 16), "tpanel": (2e-3, 5e-3), "W": (2e-3, 4e-3),
              "offset": (0.05, 0.20), "stripeWidth": (0.01, 0.03),
              "extrude": (0.05, 0.15)}  # fmt: skip
    features = tuple(
        replace(c, choices=tuple(map(float, ranges[c.name])))
        if c.name == "m"
        else replace(c, low=ranges[c.name][0], high=ranges[c.name][1])
        if c.name in ranges
        else c
        for c in STRIP_FEATURES
    )
    return strip_scenario("my-arch", "Miura strip over a 3 m catenary", setting, features)


def main(folder="my-arch", samples=400, verify=30, workers=2) -> dict:
    out = Path(folder)
    scenario = my_arch()
    target = parse_target(TARGET, scenario.performance_names)

    db = generate_database(scenario, samples, out / "database", seed=0, workers=workers)
    print(f"database: {len(db)} designs, {int(target.evaluate(db).sum())} meet {TARGET}")

    roles = column_roles(db.columns, out / "database" / "database.parquet")
    mined = mine_rules(db, target, roles=roles, seed=0, max_overlap=0.5)
    rules = mined_rules(mined.miner, mined.test_scores)  # Rule records, best first
    if not rules:
        raise SystemExit(f"no rule found for {TARGET}; try more samples")

    checks = verify_rules(scenario, rules, TARGET, verify, seed=1, workers=workers)
    cols = scenario.columns  # units, and the units people read (mm, deg)
    for r, v in zip(rules, checks, strict=True):
        print(f"rule {r.rank}: {r.text(cols)}\n  test precision {r.test.precision:.2f}, "
              f"{v.describe()}")  # fmt: skip
    best = max(range(len(rules)), key=lambda i: (checks[i].precision, checks[i].interval[0]))

    # every simulated design (database and verification) is a candidate
    import pandas as pd

    table = pd.concat([db, *(v.designs for v in checks)], ignore_index=True)
    label, margins, how = choose_design(table, target, rules[best])
    design = {c: float(table.loc[label, c]) for c in scenario.feature_names}
    performance = {c: float(table.loc[label, c]) for c in scenario.performance_names}
    print(f"chosen {how}: " + ", ".join(f"{k} = {cols[k].format(v)}" for k, v in design.items()))
    print("  " + ", ".join(f"{k} = {cols[k].format(v)}" for k, v in performance.items()))
    print("  margins: " + ", ".join(f"{k}: {v:+.2f}" for k, v in margins.items()))

    files = scenario.write_files(design, out / "files")
    summary = {"features": design, "performance": performance,
               "rule": rules[best].to_json(cols),
               "verified_precision": checks[best].precision, "margins": margins,
               "scenario": scenario.name, "files": files.record(out)}  # fmt: skip
    write_json(out / "design.json", summary)
    print(f"files: {', '.join(f.path.name for f in files)} in {out / 'files'}/")
    RESULT.clear()
    RESULT.update(summary, table=table)
    return summary


if __name__ == "__main__":
    main(*(sys.argv[1:2] or ["my-arch"]), *(int(a) for a in sys.argv[2:3]))
