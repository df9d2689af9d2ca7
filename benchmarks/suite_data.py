"""The databases and targets of the rule-miner target suite (issue 13, section 1).

Databases: the published data0 (single Miura, 1000 rows) and data3 (arch, 3000 rows) whole, the
published canopy (data1: Miura + TMP sheets, 2 x 200 rows) and gripper
(data2: three patterns, 3 x 200 rows) samples, and four databases that holofold generates with
:func:`holofold.design.generate_database`, reproducibly by seed (random sampling in the
scenario's ranges), cached outside the repository (``~/.cache/holofold-suite`` unless a folder
is given) and resumed when a build was interrupted:

=================  ==================  =====  ====  ===============================
name               scenario            rows   seed  cost (2 idle cores)
=================  ==================  =====  ====  ===============================
gen-arch           arch                3000   13    ~4 min (0.13 s a row)
gen-canopy         canopy              1200   14    ~5 min (0.5 s a row)
gen-gripper        gripper-converged   600    15    ~9 min (1.7 s a row)
gen-miura          single-miura        4000   16    ~1.5 min (0.04 s a row)
=================  ==================  =====  ====  ===============================

The gripper's designs are those of ``generate_database`` with the rows the scenario refuses
skipped (``(1 - rate) L1 > L2 / 2`` for patterns 1 and 2, which every published row meets).
The canopy is simulated with the scenario's default moduli, as the published data1 (data4's
sampled moduli are not sampled by the scenario, so data4 is not in the suite).

``gen-miura`` carries no target: like ``gen-arch`` for data3's rules (and data3 for
``gen-arch``'s) and ``gen-canopy`` for data1's, it holds fresh rows of the same simulator and
ranges on which a rule's precision is measured on thousands of rows (``EXTERNAL``).

Targets: single thresholds at positive rates of 3-20 % (the threshold is the quantile of the
column, rounded to 3 significant digits, so the rate is close to the stated one), ranges,
two- and three-objective targets and targets that depend on a categorical feature. Each is a
:class:`SuiteTarget`; :func:`suite_targets` lists them all.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design import (
    build_database,
    column_roles,
    generate_database,
    load_database,
    load_scenario,
    read_table,
    sample_designs,
)
from holofold.mechanics.status import failed_mask

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(
    os.environ.get("HOLOFOLD_REFERENCE_DATA", ROOT.parent / "shared" / "reference-data")
)
CACHE = Path(os.environ.get("HOLOFOLD_SUITE_CACHE", Path.home() / ".cache" / "holofold-suite"))

#: name -> (scenario, rows, seed) of the databases holofold generates
GENERATED = {
    "gen-arch": ("arch", 3000, 13),
    "gen-canopy": ("canopy", 1200, 14),
    "gen-gripper": ("gripper-converged", 600, 15),
    "gen-miura": ("single-miura", 4000, 16),  # no targets: fresh rows to test data0's rules on
}
#: database -> another database of the same simulator and ranges, to test its rules on many
#: fresh rows (a cheap, low-noise stand-in for verification by simulation)
EXTERNAL = {"data0": "gen-miura", "data3": "gen-arch", "gen-arch": "data3", "data1": "gen-canopy"}
#: the scenario whose simulator reproduces each database (None: no simulator here)
SIMULATOR = {
    "data0": "single-miura",
    "data3": "arch",
    "data1": "canopy",
    "data2": "gripper",
    "gen-arch": "arch",
    "gen-canopy": "canopy",
    "gen-gripper": "gripper-converged",
    "gen-miura": "single-miura",
}


@dataclass(frozen=True)
class Database:
    """A table with its design features (``categorical`` among them)."""

    name: str
    table: pd.DataFrame
    features: tuple
    categorical: tuple

    @property
    def scenario(self) -> str | None:
        return SIMULATOR.get(self.name)


def _published(stems, name) -> Database:
    parts = []
    for stem in stems:
        path = REFERENCE / f"{stem}.txt"
        if not path.is_file():
            raise FileNotFoundError(f"{path} is missing (set HOLOFOLD_REFERENCE_DATA)")
        parts.append(read_table(path))
    table = pd.concat(parts, ignore_index=True)
    roles = column_roles(table.columns)
    return Database(name, table, roles.features, roles.categorical)


def build_generated(name: str, cache: Path = CACHE, workers: int = 2) -> Path:
    """Build (or resume) one generated database; returns its folder.

    The designs are drawn as :func:`holofold.design.generate_database` draws them (random
    sampling in the scenario's ranges, row ``i`` from ``default_rng([seed, i])``); rows the
    scenario refuses (the gripper's ``(1 - rate) L1 > L2 / 2`` for patterns 1 and 2, as in the
    published data) are skipped and the first ``rows`` valid ones kept.
    """
    scenario, rows, seed = GENERATED[name]
    folder = Path(cache) / "databases" / name
    done = folder / "database.parquet"
    if done.is_file() and len(pd.read_parquet(done, columns=["status"])) == rows:
        return folder
    sc = load_scenario(scenario)
    names = [c.name for c in sc.features]
    if scenario == "gripper-converged" or scenario == "gripper":
        designs = sample_designs(sc, 2 * rows, seed=seed)
        ok = [not sc.check(r) for r in designs[names].to_dict("records")]
        designs = designs.loc[ok].iloc[:rows].reset_index(drop=True)
        meta = {"seed": seed, "method": "random", "ranges": {}, "rejected_invalid": True}
        build_database(sc, designs, folder, workers=workers, chunk_size=50, meta=meta)
    else:
        generate_database(sc, rows, folder, seed=seed, workers=workers, chunk_size=50)
    return folder


def load_databases(cache: Path = CACHE, *, build: bool = True, workers: int = 2) -> dict:
    """All suite databases by name (failed simulations left out of the generated ones)."""
    dbs = {
        "data0": _published(["data0_SingleMiura"], "data0"),
        "data3": _published(["data3_ShapeFit"], "data3"),
        "data1": _published(["data1_MiuraSheet_sample", "data1_TMPSheet_sample"], "data1"),
        "data2": _published(
            ["data2_MiuraBased_sample", "data2_SplittedMiura_sample", "data2_TwoPanel_sample"],
            "data2",
        ),
    }
    for name in GENERATED:
        folder = Path(cache) / "databases" / name
        if build:
            build_generated(name, cache, workers)
        elif not (folder / "database.parquet").is_file():
            continue
        table = load_database(folder)
        table = table.loc[~failed_mask(table["status"])].reset_index(drop=True)
        roles = column_roles(table.columns, folder / "database.parquet")
        dbs[name] = Database(name, table, roles.features, roles.categorical)
    return dbs


# ---------------------------------------------------------------------------------------------
# targets
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SuiteTarget:
    """One target of the suite: a database, an expression over its columns and its kind."""

    key: str
    database: str
    expression: str
    kind: str  # "single", "range", "two", "three", "categorical"

    def labels(self, db: Database) -> np.ndarray:
        from holofold.design import parse_target

        return np.asarray(parse_target(self.expression, db.table.columns).evaluate(db.table))


def _round(v: float) -> float:
    if v == 0 or not math.isfinite(v):
        return float(v)
    return float(f"{v:.3g}")


def _q(db: Database, col: str, q: float) -> str:
    return f"{_round(float(np.quantile(db.table[col].to_numpy(dtype=float), q))):g}"


def _specs(dbs: dict) -> list[tuple[str, str, str]]:
    """(database, expression, kind) of every target; thresholds from the data's quantiles."""
    out = []

    def add(db, kind, expr):
        if db in dbs:
            d = dbs[db]
            out.append((db, expr(lambda col, q: _q(d, col, q)), kind))

    # single Miura, data0 (1000 rows, no categorical feature)
    add("data0", "single", lambda q: f"axialstiff60 < {q('axialstiff60', 0.10)}")
    add("data0", "single", lambda q: f"axialstiff90 > {q('axialstiff90', 0.95)}")
    add("data0", "single", lambda q: f"axialstiff30 < {q('axialstiff30', 0.03)}")
    add("data0", "single", lambda q: f"axialstiff30 > {q('axialstiff30', 0.85)}")
    add(
        "data0",
        "range",
        lambda q: f"{q('axialstiff60', 0.4)} < axialstiff60 < {q('axialstiff60', 0.55)}",
    )
    add(
        "data0",
        "two",
        lambda q: (
            f"axialstiff30 < {q('axialstiff30', 0.5)} & axialstiff90 > {q('axialstiff90', 0.6)}"
        ),
    )
    # arch, data3 (3000 rows); the paper's two targets first
    add("data3", "three", lambda q: "Zstiff > 800 & Xstiff > 600 & error < 0.1")
    add("data3", "single", lambda q: "Zsnap == 1")
    add("data3", "single", lambda q: f"error < {q('error', 0.05)}")
    add("data3", "single", lambda q: f"Xstiff > {q('Xstiff', 0.97)}")
    add("data3", "range", lambda q: f"{q('Zstiff', 0.30)} < Zstiff < {q('Zstiff', 0.45)}")
    add("data3", "two", lambda q: f"Zsnap == 0 & error < {q('error', 0.15)}")
    add("data3", "categorical", lambda q: f"Zstiff > {q('Zstiff', 0.90)}")
    add(
        "data3",
        "categorical",
        lambda q: f"{q('Xstiff', 0.6)} < Xstiff < {q('Xstiff', 0.8)} & error > {q('error', 0.5)}",
    )
    # canopy sample, data1 (400 rows: Miura and TMP sheets)
    add("data1", "categorical", lambda q: f"bendstiff90 > {q('bendstiff90', 0.85)}")
    add("data1", "single", lambda q: f"axialstiff30 < {q('axialstiff30', 0.10)}")
    add(
        "data1",
        "range",
        lambda q: f"{q('bendstiff60', 0.3)} < bendstiff60 < {q('bendstiff60', 0.5)}",
    )
    add(
        "data1",
        "two",
        lambda q: (
            f"bendstiff30 > {q('bendstiff30', 0.5)} & axialstiff90 < {q('axialstiff90', 0.5)}"
        ),
    )
    add("data1", "categorical", lambda q: f"bendstiff90 < {q('bendstiff90', 0.15)}")
    # gripper sample, data2 (600 rows, three patterns)
    add("data2", "single", lambda q: f"stiff > {q('stiff', 0.85)}")
    add("data2", "single", lambda q: f"freqFinal > {q('freqFinal', 0.90)}")
    add("data2", "two", lambda q: f"finalQ > {q('finalQ', 0.5)} & Tmax < {q('Tmax', 0.5)}")
    add("data2", "range", lambda q: f"{q('Tmax', 0.40)} < Tmax < {q('Tmax', 0.55)}")
    add("data2", "categorical", lambda q: f"finalQ < {q('finalQ', 0.10)}")
    # arch, generated (3000 rows)
    add("gen-arch", "single", lambda q: f"Zstiff > {q('Zstiff', 0.95)}")
    add("gen-arch", "single", lambda q: f"Xstiff < {q('Xstiff', 0.08)}")
    add("gen-arch", "single", lambda q: f"error < {q('error', 0.12)}")
    add("gen-arch", "range", lambda q: f"{q('Xstiff', 0.50)} < Xstiff < {q('Xstiff', 0.65)}")
    add("gen-arch", "two", lambda q: f"Zstiff > {q('Zstiff', 0.5)} & error < {q('error', 0.2)}")
    add(
        "gen-arch",
        "three",
        lambda q: (
            f"Zstiff > {q('Zstiff', 0.5)} & Xstiff > {q('Xstiff', 0.5)} & error < {q('error', 0.3)}"
        ),
    )
    add("gen-arch", "categorical", lambda q: f"{q('Zstiff', 0.8)} < Zstiff < {q('Zstiff', 0.92)}")
    # canopy, generated (1200 rows)
    add("gen-canopy", "single", lambda q: f"bendstiff30 > {q('bendstiff30', 0.90)}")
    add("gen-canopy", "single", lambda q: f"axialstiff60 < {q('axialstiff60', 0.05)}")
    add("gen-canopy", "single", lambda q: f"axialstiff30 > {q('axialstiff30', 0.85)}")
    add(
        "gen-canopy",
        "range",
        lambda q: f"{q('axialstiff90', 0.45)} < axialstiff90 < {q('axialstiff90', 0.6)}",
    )
    add(
        "gen-canopy",
        "two",
        lambda q: (
            f"bendstiff60 > {q('bendstiff60', 0.6)} & axialstiff60 < {q('axialstiff60', 0.5)}"
        ),
    )
    add(
        "gen-canopy",
        "three",
        lambda q: (
            f"bendstiff30 > {q('bendstiff30', 0.6)} & bendstiff90 > {q('bendstiff90', 0.6)} "
            f"& axialstiff30 < {q('axialstiff30', 0.5)}"
        ),
    )
    add("gen-canopy", "categorical", lambda q: f"bendstiff90 < {q('bendstiff90', 0.15)}")
    add("gen-canopy", "categorical", lambda q: f"axialstiff90 > {q('axialstiff90', 0.85)}")
    # gripper, generated in converged mode (600 rows)
    add("gen-gripper", "single", lambda q: f"stiff > {q('stiff', 0.85)}")
    add("gen-gripper", "single", lambda q: f"finalQ > {q('finalQ', 0.90)}")
    add(
        "gen-gripper",
        "range",
        lambda q: f"{q('freqFinal', 0.40)} < freqFinal < {q('freqFinal', 0.55)}",
    )
    add("gen-gripper", "two", lambda q: f"stiff > {q('stiff', 0.5)} & Tmax < {q('Tmax', 0.5)}")
    add(
        "gen-gripper",
        "three",
        lambda q: (
            f"finalQ > {q('finalQ', 0.4)} & stiff > {q('stiff', 0.4)} & Tmax < {q('Tmax', 0.6)}"
        ),
    )
    add("gen-gripper", "categorical", lambda q: f"stiff < {q('stiff', 0.10)}")
    return out


def suite_targets(dbs: dict) -> list[SuiteTarget]:
    """Every target of the suite over the databases present, each with its key."""
    out = []
    for k, (db, expr, kind) in enumerate(_specs(dbs)):
        out.append(SuiteTarget(f"T{k + 1:02d}", db, expr, kind))
    return out


if __name__ == "__main__":  # build the generated databases only
    import argparse

    ap = argparse.ArgumentParser(description="build the suite's generated databases")
    ap.add_argument("--cache", type=Path, default=CACHE)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("names", nargs="*", default=list(GENERATED))
    a = ap.parse_args()
    for n in a.names:
        print(n, build_generated(n, a.cache, a.workers), flush=True)
