"""A resumable, chunked Parquet database of simulated designs that guards itself.

Layout of a database folder::

    designs.parquet        the design table to simulate (written first, never changed)
    meta.json              scenario, column roles and units, the chunk layout, sampling, version
    chunks/part-00000-<sha256:16>.parquet ...   results, ``chunk_size`` rows each
    chunks/damaged/        chunks found damaged, moved aside (their rows are simulated again)
    database.parquet       all chunks concatenated, written when every chunk exists

Running :func:`build_database` again on the same folder skips the chunks already on disk, so an
interrupted run (Ctrl-C, a killed job) resumes without losing or duplicating rows:

* the chunk layout (rows per chunk) is fixed when the database is created and stored in
  ``meta.json``; a resume asking for another ``chunk_size`` uses the stored one (with a
  warning), so rows are never lost or counted twice;
* every chunk is written atomically and named by the SHA-256 of its bytes; each open checks the
  checksum and that the chunk holds exactly its rows of the design table (sample ids and
  features). A truncated, empty or altered chunk is moved to ``chunks/damaged/`` with a warning
  and its rows are simulated again;
* ``meta.json`` is written atomically and rebuilt from the design table and the scenario when
  it is missing.

A folder that holds a *different* design table is refused rather than mixed. On a Dask cluster
every missing row is submitted at once and a chunk is written as soon as its rows are done, in
any order.
"""

from __future__ import annotations

import hashlib
import io
import logging
import os
import re
import warnings
from contextlib import closing
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.database.folder_lock import folder_lock
from holofold.design.database.row_checkpoints import CHECKPOINT_SECONDS, RowCheckpoint, move_damaged
from holofold.design.database.row_limits import resolve_row_timeout
from holofold.design.database.row_status import STATE_COLUMNS, stale_rows, with_state
from holofold.design.database.runner import (
    check_scheduler,
    check_workers,
    dask_scheduler,
    evaluate_designs,
    iter_results,
    plan_tasks,
    progress_bar,
    results_table,
    validate_designs,
)
from holofold.design.database.sampling import sample_designs
from holofold.design.database.tables import write_table
from holofold.design.scenarios import Scenario, load_scenario
from holofold.geometry.outputs import atomic_write, write_json

__all__ = ["build_database", "generate_database", "load_database", "scan_chunks", "write_chunk"]

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
    on_invalid: str = "fail",
    row_timeout: float | str | None = None,
    retry_failed: bool = False,
    checkpoint: float = CHECKPOINT_SECONDS,
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
        Rows per result chunk. With joblib each chunk is finished before the next starts; on
        Dask every missing row is submitted at once (see ``scheduler``).
    checkpoint : float
        Seconds between two writes of the finished rows of the chunk in flight
        (:mod:`holofold.design.database.row_checkpoints`): a killed run loses at most this much
        finished work plus the rows still running. 0 writes after every row.
    workers : int
        Worker processes per chunk (joblib), or of the local Dask cluster with
        ``scheduler="local"``.
    progress : bool, optional
        Progress bar on stderr (default: only on a terminal).
    meta : dict, optional
        Extra metadata stored in ``meta.json`` (seed, sampling method, ...).
    scheduler : str, optional
        Simulate on a Dask cluster: a scheduler address (``tcp://host:8786``) or ``"local"``
        (one local cluster for the whole run); see
        :func:`holofold.design.database.runner.evaluate_designs`.
        Every row of the missing chunks is submitted at once and each chunk is written as
        soon as its last row is done (chunks may be written out of order), so no worker
        waits for the slowest row of a chunk. The results are the same as without it.
    on_invalid, row_timeout
        Per-row isolation, as in :func:`holofold.design.database.runner.evaluate_designs`: with
        ``"skip"`` invalid rows are stored as failed rows with their reason; a row past its
        time limit is stored as ``failed: timeout after ... s`` (a resume keeps it: chunks on
        disk are never simulated again).
    retry_failed : bool
        Simulate the stored failed rows again (their chunks are rewritten). Without it a
        resume simulates again only the stored rows whose failure was not the design's own
        (an environment fault an older version stored as a row, ``failed:
        ModuleNotFoundError: ...``). An environment fault while simulating stops the run
        (:class:`~holofold.geometry.errors.EnvironmentFault`) and is never stored.

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
    timeout = resolve_row_timeout(scenario.row_timeout, row_timeout)
    # every row checked before anything runs
    checked = validate_designs(scenario, designs, on_invalid)
    folder = Path(folder)
    designs = designs.reset_index(drop=True)
    if folder.is_dir() and not _writable(folder):
        return _read_only(folder, designs)
    with folder_lock(folder):  # one writer per folder, for the whole run
        _build_locked(
            scenario, designs, folder, checked, chunk_size, workers, progress, meta, scheduler,
            on_invalid, timeout, retry_failed, float(checkpoint),
        )  # fmt: skip
        _check_own(folder, designs, meta)
        return load_database(folder, _write=True)


#: what :func:`generate_database` passes on to :func:`build_database` (how the rows run)
_RUN_OPTIONS = frozenset(
    ("chunk_size", "workers", "progress", "scheduler", "row_timeout", "retry_failed", "checkpoint")
)


def _build_locked(
    scenario, designs, folder, checked, chunk_size, workers, progress, meta, scheduler,
    on_invalid, timeout, retry_failed=False, every=CHECKPOINT_SECONDS,
) -> None:  # fmt: skip
    """The body of :func:`build_database`, run holding the folder's lock."""
    chunks = folder / "chunks"
    chunks.mkdir(parents=True, exist_ok=True)
    dpath = folder / "designs.parquet"
    meta_path = folder / "meta.json"
    if dpath.exists():
        _check_designs(folder, designs)
        stored = _stored_layout(meta_path, chunks, len(designs))
        if stored is not None and stored != chunk_size:
            warnings.warn(
                f"{folder} was created with {stored} rows per chunk: resuming with that "
                f"layout, not chunk_size = {chunk_size}",
                stacklevel=2,
            )
            chunk_size = stored
    else:
        write_table(designs, dpath)
    if not meta_path.is_file():  # new, or lost: (re)built from the scenario and the designs
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
        write_json(meta_path, info)
    n_chunks = (len(designs) + chunk_size - 1) // chunk_size
    done = scan_chunks(folder, designs, chunk_size, needs=scenario.performance_names)
    _redo_stale(scenario, designs, done, chunk_size, workers, scheduler, on_invalid, timeout,
                retry_failed)  # fmt: skip
    RowCheckpoint.discard_done(chunks, done)
    todo = [k for k in range(n_chunks) if k not in done]
    if len(todo) < n_chunks:
        log.info("resuming: %d of %d chunks already done", n_chunks - len(todo), n_chunks)
    bar = None
    if todo and checked.invalid:
        warnings.warn(checked.skipped_line(), stacklevel=2)
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
                    scenario, designs, checked, todo, chunk_size, chunks, address, bar, timeout,
                    every,
                )  # fmt: skip
        else:
            invalid = checked.invalid_outputs(scenario)
            for k in todo:
                _build_chunk(
                    scenario, designs, checked, invalid, k, chunk_size, chunks, workers, bar,
                    timeout, every,
                )  # fmt: skip
    finally:
        if bar is not None:
            bar.close()


def _build_chunk(
    scenario, designs, checked, invalid, k, chunk_size, chunks, workers, bar, timeout, every
) -> None:  # fmt: skip
    """Simulate chunk ``k`` with joblib and write it: the table
    :func:`~holofold.design.database.runner.evaluate_designs` gives for its rows. The rows a killed
    run
    checkpointed are taken back, the others simulated in the same tasks (batches of one
    ``batch_key``) as an uninterrupted run, so a resume gives the same outputs."""
    n = len(designs)
    lo, hi = k * chunk_size, min(n, (k + 1) * chunk_size)
    outs = [invalid.get(i) for i in range(lo, hi)]
    where = [i for i in checked.positions if lo <= i < hi]
    mine = dict(zip(checked.positions, checked.rows, strict=True))
    rows = [mine[i] for i in where]
    keep = RowCheckpoint(chunks, k, lo, hi, scenario.performance_names, every)
    saved = keep.load()
    tasks = []
    for task in plan_tasks(scenario, rows):
        if all(where[j] in saved for j in task):  # a task all of whose rows were kept
            for j in task:
                outs[where[j] - lo] = saved[where[j]]
        else:
            tasks.append(task)
    if bar is not None:
        bar.update(sum(o is not None for o in outs))  # invalid rows and rows taken back
    if tasks:
        results = iter_results(
            scenario, rows, workers=workers, row_timeout=timeout, tasks=tasks
        )  # fmt: skip
        with closing(results):
            for j, out in results:
                outs[where[j] - lo] = out
                keep.add(where[j], out)
                if bar is not None:
                    bar.update(1)
    write_chunk(results_table(scenario, designs.iloc[lo:hi], outs), chunks, k)
    keep.discard()


def _check_designs(folder: Path, designs: pd.DataFrame) -> None:
    """Refuse ``folder`` unless its ``designs.parquet`` holds exactly ``designs``."""
    old = _read_parquet(folder / "designs.parquet", "the design table")
    same = list(old.columns) == list(designs.columns) and len(old) == len(designs)
    if same and _content_problem(_parquet_bytes(designs), old, outcome=False) is not None:
        same = False
    if not same:
        raise ValueError(
            f"{folder} already holds a different design table; use another folder "
            "(or delete it) instead of mixing two databases"
        )


def _check_own(folder: Path, designs: pd.DataFrame, meta: dict | None) -> None:
    """Before a run reports success: the folder holds its design table and its settings
    (``meta.json``'s rows and every key of ``meta``), else one line saying so."""
    import json

    _check_designs(folder, designs)
    try:
        stored = json.loads((folder / "meta.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ValueError(f"{folder}/meta.json cannot be read back ({exc})") from None
    mine = {"rows": len(designs), **json.loads(json.dumps(meta or {}))}
    for k, v in mine.items():
        if stored.get(k) != v:
            raise ValueError(
                f"{folder}/meta.json records {k} = {stored.get(k)!r}, not this run's {v!r}: "
                "another run wrote this folder; use another folder"
            )


def _writable(folder: Path) -> bool:
    """Whether a file can be created in ``folder`` (tried: permissions, a read-only file
    system or an immutable folder, whoever runs)."""
    import tempfile

    try:
        fd, tmp = tempfile.mkstemp(prefix=".holofold-", dir=folder)
    except OSError:
        return False
    os.close(fd)
    os.unlink(tmp)
    return True


def _read_only(folder: Path, designs: pd.DataFrame) -> pd.DataFrame:
    """A complete database in a folder this process cannot write: its rows, nothing written;
    an incomplete one is refused in one line."""
    _check_designs(folder, designs)
    chunk_size = _stored_layout(folder / "meta.json", folder / "chunks", len(designs))
    chunk_size = chunk_size or max(len(designs), 1)
    n_chunks = (len(designs) + chunk_size - 1) // chunk_size
    good = scan_chunks(folder, designs, chunk_size, move=False)
    if len(good) < n_chunks:
        raise PermissionError(
            f"{folder} is not writable and holds {len(good)} of {n_chunks} chunks: the "
            "missing rows cannot be simulated there; make it writable or use another folder"
        )
    log.info("%s is read-only and complete: read without writing", folder)
    frames = [pd.read_parquet(good[k]) for k in range(n_chunks)]
    return with_state(pd.concat(frames, ignore_index=True))


def _redo_stale(
    scenario, designs, done, chunk_size, workers, scheduler, on_invalid, timeout, retry_failed
) -> None:
    """Simulate again the stored rows of the sound chunks ``done`` that
    :func:`~holofold.design.database.row_status.stale_rows` names; each such chunk is rewritten (new
    checksum name) and ``done`` updated."""
    found = {}
    for k, p in done.items():
        cols = [c for c in pq_names(p) if c in STATE_COLUMNS]
        stale = np.flatnonzero(stale_rows(pd.read_parquet(p, columns=cols), retry_failed))
        if len(stale):
            found[k] = stale
    if not found:
        return
    n = sum(len(v) for v in found.values())
    what = "failed rows" if retry_failed else "rows whose stored failure was not the design's own"
    warnings.warn(f"simulating again {n} stored {what}", stacklevel=4)
    for k, stale in found.items():
        old = with_state(pd.read_parquet(done[k]))
        part = designs.iloc[k * chunk_size : (k + 1) * chunk_size]
        res = evaluate_designs(
            scenario, part.iloc[stale], workers=workers, progress=False, log_warnings=False,
            scheduler=scheduler, on_invalid=on_invalid, row_timeout=timeout or 0,
        )  # fmt: skip
        new = old.copy()
        for c in res.columns:
            if c in new.columns and c not in part.columns:
                new.loc[new.index[stale], c] = res[c].to_numpy()
        path = write_chunk(new, done[k].parent, k)
        if path != done[k]:
            done[k].unlink()
        done[k] = path


def pq_names(path) -> list[str]:
    """Column names of a Parquet file, from its schema only."""
    import pyarrow.parquet as pq

    return list(pq.read_schema(path).names)


_CHUNK = re.compile(r"part-(\d{5})(?:-([0-9a-f]{16}))?\.parquet$")


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


def write_chunk(frame: pd.DataFrame, chunks: Path, k: int) -> Path:
    """Write chunk ``k`` atomically as ``part-<k>-<sha256 of its bytes>.parquet``."""
    buf = io.BytesIO()
    frame.to_parquet(buf, index=False)
    data = buf.getvalue()
    path = Path(chunks) / f"part-{k:05d}-{_digest(data)}.parquet"
    return atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))


def _parquet_bytes(frame: pd.DataFrame) -> bytes:
    buf = io.BytesIO()
    frame.to_parquet(buf, index=False)
    return buf.getvalue()


def _read_parquet(path: Path, what: str) -> pd.DataFrame:
    try:
        return pd.read_parquet(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
        raise ValueError(f"{path}: {what} is not a readable Parquet file ({exc})") from None


def _stored_layout(meta_path: Path, chunks: Path, n_rows: int) -> int | None:
    """Rows per chunk the database was created with (meta.json, else its chunks), or None."""
    if meta_path.is_file():
        import json

        try:
            return int(json.loads(meta_path.read_text(encoding="utf-8"))["chunk_size"])
        except (OSError, ValueError, KeyError, TypeError):
            pass
    # meta.json lost or unreadable: a sound first chunk tells (unless it is the only one)
    for p in sorted(chunks.glob("part-00000*.parquet")):
        if not _CHUNK.match(p.name):
            continue
        try:
            rows = len(pd.read_parquet(p, columns=["sample"]))
        except Exception:  # noqa: BLE001 - a damaged chunk says nothing
            continue
        if 0 < rows < n_rows:
            return rows
    return None


def scan_chunks(
    folder, designs: pd.DataFrame, chunk_size: int, *, move: bool = True, needs=()
) -> dict[int, Path]:
    """The sound chunks of a database folder: chunk index -> path.

    A chunk is sound when its name's checksum matches its bytes and it holds exactly rows
    ``k * chunk_size ...`` of ``designs`` (same sample ids and feature values). Every other
    chunk file (truncated, empty, altered, a duplicate or outside the layout) is moved to
    ``chunks/damaged/`` with a warning. A chunk of an older holofold (no checksum in its
    name) that holds the right rows is renamed with its checksum. ``move=False`` (a
    read-only folder): nothing is moved or renamed; damaged chunks are left out. ``needs``:
    output columns a sound chunk must hold (the scenario's performance columns: a chunk an
    older holofold wrote without a column the scenario now has is simulated again).
    """
    chunks = Path(folder) / "chunks"
    n = len(designs)
    n_chunks = (n + chunk_size - 1) // chunk_size
    good: dict[int, Path] = {}
    for p in sorted(chunks.glob("part-*.parquet")):
        m = _CHUNK.match(p.name)
        if m is None:
            if move:
                move_damaged(p, "not a chunk name")
            continue
        k = int(m[1])
        data = p.read_bytes()
        why = None
        if k >= n_chunks:
            why = f"chunk {k} is outside the layout of {n_chunks} chunks"
        elif k in good:
            why = f"a second copy of chunk {k}"
        elif m[2] is not None and _digest(data) != m[2]:
            why = "checksum mismatch: truncated or altered"
        else:
            why = _content_problem(
                data, designs.iloc[k * chunk_size : (k + 1) * chunk_size], needs=needs
            )
        if why:
            if move:
                move_damaged(p, why)
            continue
        if m[2] is None and move:  # older layout: add the checksum to the name
            named = p.with_name(f"part-{k:05d}-{_digest(data)}.parquet")
            os.replace(p, named)
            p = named
        good[k] = p
    return good


def _content_problem(data: bytes, part: pd.DataFrame, outcome: bool = True, needs=()) -> str | None:
    """Why a chunk's bytes do not hold exactly the design rows ``part`` and the output
    columns ``needs`` (None if they do)."""
    try:
        res = pd.read_parquet(io.BytesIO(data))
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
        return f"unreadable: {type(exc).__name__}"
    lacking = [c for c in needs if c not in res.columns]
    if lacking:
        return (
            f"written without the column(s) {', '.join(lacking)} that the scenario now has "
            "(an older holofold)"
        )
    if len(res) != len(part):
        return f"{len(res)} rows instead of {len(part)}"
    cols = [c for c in part.columns if c in res.columns]
    if len(cols) != len(part.columns) or (outcome and "status" not in res.columns):
        return "columns missing"
    for c in cols:
        a, b = res[c], part[c]
        if pd.api.types.is_numeric_dtype(b) and pd.api.types.is_numeric_dtype(a):
            same = np.array_equal(
                a.to_numpy(dtype=float, na_value=np.nan),
                b.to_numpy(dtype=float, na_value=np.nan),
                equal_nan=True,
            )
        else:
            same = a.astype(str).tolist() == b.astype(str).tolist()
        if not same:
            return f"its {c} column differs from the design table"
    return None


def _build_on_dask(
    scenario: Scenario,
    designs: pd.DataFrame,
    checked,
    todo: list,
    chunk_size: int,
    chunks: Path,
    address: str,
    bar,
    timeout: float | None,
    every: float = CHECKPOINT_SECONDS,
) -> None:
    """Simulate the chunks ``todo`` on the Dask scheduler at ``address``.

    All their rows are submitted at once; a chunk is written (atomically) as soon as its last
    row is done, whatever the order, and its results are then dropped. On an exception or
    Ctrl-C the chunks already complete are on disk and the remaining tasks are cancelled.

    Parameters
    ----------
    designs : DataFrame
        The whole design table (index 0..n-1).
    checked : ValidatedTable
        Its validated rows (and the invalid ones, stored as failed rows).
    todo : list of int
        Indices of the missing chunks.
    bar : tqdm.tqdm or None
        Progress bar, advanced by one per finished row.
    timeout : float or None
        Time limit per row, seconds.
    every : float
        Seconds between two checkpoints of a chunk's finished rows (rows run one by one on
        Dask, so a resume gives the same outputs).
    """
    n = len(designs)
    spans = {k: (k * chunk_size, min(n, (k + 1) * chunk_size)) for k in todo}
    outs = {k: [None] * (hi - lo) for k, (lo, hi) in spans.items()}
    left = {k: hi - lo for k, (lo, hi) in spans.items()}
    rows = dict(zip(checked.positions, checked.rows, strict=True))
    owner, pending = [], []
    invalid = checked.invalid_outputs(scenario)
    keep = {
        k: RowCheckpoint(chunks, k, lo, hi, scenario.performance_names, every)
        for k, (lo, hi) in spans.items()
    }

    def done(k: int, pos: int, out: dict, *, new: bool = True) -> None:
        outs[k][pos] = out
        left[k] -= 1
        if bar is not None:
            bar.update(1)
        if new:
            keep[k].add(spans[k][0] + pos, out)
        if not left[k]:
            lo, hi = spans[k]
            # the same table as evaluate_designs(scenario, part) would give
            write_chunk(results_table(scenario, designs.iloc[lo:hi], outs.pop(k)), chunks, k)
            keep.pop(k).discard()

    for k, (lo, hi) in spans.items():
        saved = keep[k].load()
        for i in range(lo, hi):
            if i in invalid:
                done(k, i - lo, invalid[i], new=False)
            elif i in saved:
                done(k, i - lo, saved[i], new=False)
            else:
                owner.append((k, i - lo))
                pending.append(rows[i])
    if not pending:
        return
    with closing(iter_results(scenario, pending, address=address, row_timeout=timeout)) as results:
        for j, out in results:
            done(*owner[j], out)


def generate_database(
    scenario: Scenario | str,
    n: int,
    folder: str | os.PathLike,
    *,
    seed: int = 0,
    method: str = "random",
    ranges: dict | None = None,
    csv: bool = False,
    on_invalid: str = "skip",
    **run,
) -> pd.DataFrame:
    """Sample ``n`` designs of ``scenario`` and simulate them into ``folder`` (resumable).

    ``seed``, ``method`` and ``ranges`` go to
    :func:`holofold.design.database.sampling.sample_designs`
    and are recorded in ``meta.json``; ``run`` (``chunk_size``, ``workers``, ``progress``,
    ``scheduler``, ``row_timeout``, ``retry_failed``, ``checkpoint``) to
    :func:`build_database`, whose defaults and meanings they keep. ``csv`` also writes
    ``database.csv``. Returns the database.

    Sampled designs lie inside the features' ranges, but a scenario's check can still refuse
    some (an odd arch ``m`` from ``ranges``, a gripper whose ``W`` is not below ``L2/2``: 49
    of 2000 in the paper's ranges): ``"skip"`` (default) stores them as failed rows with
    their reason, ``on_invalid="fail"`` refuses the database before anything is simulated.
    Designs refused while simulating (a self-overlapping strip) are failed rows either way.
    """
    unknown = sorted(set(run) - _RUN_OPTIONS)
    if unknown:  # before any work, as Python itself would for a named parameter
        raise TypeError(f"generate_database() got an unexpected keyword argument {unknown[0]!r}")
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if int(n) < 1:
        raise ValueError(f"n = {n} designs must be >= 1")
    designs = sample_designs(scenario, int(n), seed=seed, method=method, ranges=ranges)
    recorded = {k: list(v) for k, v in (ranges or {}).items()}
    meta = {"seed": seed, "method": method, "ranges": recorded}
    db = build_database(scenario, designs, folder, meta=meta, on_invalid=on_invalid, **run)
    if csv:
        write_table(db, Path(folder) / "database.csv")
    return db


def load_database(folder: str | os.PathLike, *, _write: bool = False) -> pd.DataFrame:
    """All sound chunks of a database folder, in row order (damaged ones are moved aside)."""
    folder = Path(folder)
    dpath = folder / "designs.parquet"
    if dpath.is_file():
        designs = _read_parquet(dpath, "the design table")
        stored = _stored_layout(folder / "meta.json", folder / "chunks", len(designs))
        chunk_size = stored or max(len(designs), 1)
        parts = [p for _, p in sorted(scan_chunks(folder, designs, chunk_size).items())]
    else:
        parts = sorted((folder / "chunks").glob("part-*.parquet"))
    if not parts:
        raise FileNotFoundError(f"{folder} holds no finished chunks")
    df = with_state(pd.concat([pd.read_parquet(p) for p in parts], ignore_index=True))
    if _write:
        write_table(df, folder / "database.parquet")
    return df
