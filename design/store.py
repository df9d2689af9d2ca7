"""A resumable, chunked Parquet database of simulated designs.

Layout of a database folder::

    designs.parquet        the design table to simulate (written first, never changed)
    meta.json              scenario, column units, sampling, holofold version
    chunks/part-00000.parquet ...   results, ``chunk_size`` rows each, written atomically
    database.parquet       all chunks concatenated, written when every chunk exists

Running :func:`build_database` again on the same folder skips the chunks already on disk, so an
interrupted run (Ctrl-C, a killed job) resumes without losing or duplicating rows. A folder that
holds a *different* design table is refused rather than mixed. On a Dask cluster every missing
row is submitted at once and a chunk is written as soon as its rows are done, in any order.
"""

from __future__ import annotations

import logging
import os
from contextlib import closing
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.runner import (
    check_scheduler,
    check_workers,
    dask_scheduler,
    evaluate_designs,
    iter_results,
    progress_bar,
    results_table,
    validate_designs,
)
from holofold.design.sampling import sample_designs
from holofold.design.scenarios import Scenario, load_scenario
from holofold.design.tables import write_table
from holofold.geometry.outputs import write_json

__all__ = ["build_database", "generate_database", "load_database"]

log = logging.getLogger(__name__)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("holofold")
    except PackageNotFoundError:  # not installed: running from a checkout
        return "unknown"


def build_database(
    scenario: Scenario | str,
    designs: pd.DataFrame,
    folder: str | os.PathLike,
    *,
    chunk_size: int = 100,
    workers: int = 1,
    progress: bool | None = None,
    meta: dict | None = None,
    scheduler: str | None = None,
) -> pd.DataFrame:
    """Simulate ``designs`` into ``folder``, resuming whatever an earlier run left there.

    Parameters
    ----------
    scenario : Scenario or str
    designs : DataFrame
        Feature columns in SI units (plus any bookkeeping columns such as ``sample``).
    folder : path
        Database folder (created if needed).
    chunk_size : int
        Rows per result chunk: the unit of work lost at most when a run is interrupted.
        With joblib each chunk is finished before the next starts; on Dask it only sets how
        often results are written (see ``scheduler``).
    workers : int
        Worker processes per chunk (joblib), or of the local Dask cluster with
        ``scheduler="local"``.
    progress : bool, optional
        Progress bar on stderr (default: only on a terminal).
    meta : dict, optional
        Extra metadata stored in ``meta.json`` (seed, sampling method, ...).
    scheduler : str, optional
        Simulate on a Dask cluster: a scheduler address (``tcp://host:8786``) or ``"local"``
        (one local cluster for the whole run); see :func:`holofold.design.runner.evaluate_designs`.
        Every row of the missing chunks is submitted at once and each chunk is written as
        soon as its last row is done (chunks may be written out of order), so no worker
        waits for the slowest row of a chunk. The results are the same as without it.

    Returns
    -------
    DataFrame
        All rows in order with performance columns and ``status``; also written to
        ``database.parquet``.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    chunk_size = int(chunk_size)
    if chunk_size < 1:
        raise ValueError(f"chunk_size = {chunk_size} must be >= 1")
    workers = check_workers(workers)
    if scheduler is not None:
        scheduler = check_scheduler(scheduler)
    checked = validate_designs(scenario, designs)  # every row checked before anything runs
    folder = Path(folder)
    chunks = folder / "chunks"
    chunks.mkdir(parents=True, exist_ok=True)
    designs = designs.reset_index(drop=True)
    dpath = folder / "designs.parquet"
    if dpath.exists():
        old = pd.read_parquet(dpath)
        same = list(old.columns) == list(designs.columns) and len(old) == len(designs)
        if same:
            a = old.to_numpy(dtype=float, na_value=np.nan)
            b = designs.to_numpy(dtype=float, na_value=np.nan)
            same = np.array_equal(a, b, equal_nan=True)
        if not same:
            raise ValueError(
                f"{folder} already holds a different design table; use another folder "
                "(or delete it) instead of mixing two databases"
            )
    else:
        write_table(designs, dpath)
        info = {
            "scenario": scenario.name,
            "scenario_file": scenario.source or None,
            "features": {c.name: c.unit for c in scenario.features},
            "performance": {c.name: c.unit for c in scenario.performance},
            "categorical": list(scenario.categorical),
            "rows": len(designs),
            "chunk_size": chunk_size,
            "holofold_version": _version(),
            **(meta or {}),
        }
        write_json(folder / "meta.json", info)
    n_chunks = (len(designs) + chunk_size - 1) // chunk_size
    todo = [k for k in range(n_chunks) if not (chunks / f"part-{k:05d}.parquet").exists()]
    if len(todo) < n_chunks:
        log.info("resuming: %d of %d chunks already done", n_chunks - len(todo), n_chunks)
    bar = None
    if todo:
        left = sum(min(chunk_size, len(designs) - k * chunk_size) for k in todo)
        bar = progress_bar(len(designs), scenario.name, progress, initial=len(designs) - left)
    try:
        if scheduler is not None and todo:
            for w in checked.warnings:
                log.warning("outside the paper's sampling ranges: %s", w)
            # one cluster for the whole run; every missing row is submitted at once
            with dask_scheduler(scheduler, workers) as address:
                _build_on_dask(
                    scenario, designs, checked.rows, todo, chunk_size, chunks, address, bar
                )
        else:
            for k in todo:
                part = designs.iloc[k * chunk_size : (k + 1) * chunk_size]
                res = evaluate_designs(scenario, part, workers=workers, progress=False)
                write_table(res, chunks / f"part-{k:05d}.parquet")
                if bar is not None:
                    bar.update(len(part))
    finally:
        if bar is not None:
            bar.close()
    return load_database(folder, _write=True)


def _build_on_dask(
    scenario: Scenario,
    designs: pd.DataFrame,
    rows: list,
    todo: list,
    chunk_size: int,
    chunks: Path,
    address: str,
    bar,
) -> None:
    """Simulate the chunks ``todo`` on the Dask scheduler at ``address``.

    All their rows are submitted at once; a chunk is written (atomically) as soon as its last
    row is done, whatever the order, and its results are then dropped. On an exception or
    Ctrl-C the chunks already complete are on disk and the remaining tasks are cancelled.

    Parameters
    ----------
    designs : DataFrame
        The whole design table (index 0..n-1); ``rows`` its validated rows, same order.
    todo : list of int
        Indices of the missing chunks.
    bar : tqdm.tqdm or None
        Progress bar, advanced by one per finished row.
    """
    n = len(designs)
    spans = {k: (k * chunk_size, min(n, (k + 1) * chunk_size)) for k in todo}
    owner = [(k, i - lo) for k, (lo, hi) in spans.items() for i in range(lo, hi)]
    outs = {k: [None] * (hi - lo) for k, (lo, hi) in spans.items()}
    left = {k: hi - lo for k, (lo, hi) in spans.items()}
    pending = [rows[i] for lo, hi in spans.values() for i in range(lo, hi)]
    with closing(iter_results(scenario, pending, address=address)) as results:
        for j, out in results:
            k, pos = owner[j]
            outs[k][pos] = out
            left[k] -= 1
            if bar is not None:
                bar.update(1)
            if not left[k]:
                lo, hi = spans[k]
                # the same table as evaluate_designs(scenario, part) would give
                res = results_table(scenario, designs.iloc[lo:hi], outs.pop(k))
                write_table(res, chunks / f"part-{k:05d}.parquet")


def generate_database(
    scenario: Scenario | str,
    n: int,
    folder: str | os.PathLike,
    *,
    seed: int = 0,
    method: str = "random",
    ranges: dict | None = None,
    chunk_size: int = 100,
    workers: int = 1,
    progress: bool | None = None,
    scheduler: str | None = None,
    csv: bool = False,
) -> pd.DataFrame:
    """Sample ``n`` designs of ``scenario`` and simulate them into ``folder`` (resumable).

    ``seed``, ``method`` and ``ranges`` go to :func:`holofold.design.sampling.sample_designs`
    and are recorded in ``meta.json``; the rest to :func:`build_database`. ``csv`` also
    writes ``database.csv``. Returns the database.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if int(n) < 1:
        raise ValueError(f"n = {n} designs must be >= 1")
    designs = sample_designs(scenario, int(n), seed=seed, method=method, ranges=ranges)
    recorded = {k: list(v) for k, v in (ranges or {}).items()}
    db = build_database(
        scenario, designs, folder, chunk_size=chunk_size, workers=workers, progress=progress,
        meta={"seed": seed, "method": method, "ranges": recorded}, scheduler=scheduler,
    )  # fmt: skip
    if csv:
        write_table(db, Path(folder) / "database.csv")
    return db


def load_database(folder: str | os.PathLike, *, _write: bool = False) -> pd.DataFrame:
    """All finished chunks of a database folder, in row order."""
    folder = Path(folder)
    parts = sorted((folder / "chunks").glob("part-*.parquet"))
    if not parts:
        raise FileNotFoundError(f"{folder} holds no finished chunks")
    df = pd.concat([pd.read_parquet(p) for p in parts], ignore_index=True)
    if _write:
        write_table(df, folder / "database.parquet")
    return df
