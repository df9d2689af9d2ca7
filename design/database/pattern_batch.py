"""Checking many crease patterns: one JSON line per pattern file, resumable and parallel.

:func:`pattern_files` expands files and folders (searched recursively for the suffixes of
:data:`holofold.geometry.READERS`); :func:`check_pattern_file` reads and folds one file with
:func:`holofold.mechanics.simulate_pattern` under a time limit and returns its record (a plain
dict: a pattern that is refused, crashes or times out is a record with its reason);
:func:`run_pattern_batch` writes the records to a JSON-lines file as each finishes (one complete
line appended, flushed and fsynced), skipping files already recorded there (same resolved path
and SHA-256), on joblib worker processes when ``workers`` > 1.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import time
import warnings
from pathlib import Path

import numpy as np

from holofold.design.database.row_limits import RowTimeout, call_with_limit
from holofold.geometry import READERS, read_pattern, reader_for

__all__ = [
    "pattern_files",
    "file_sha256",
    "recorded_files",
    "check_pattern_file",
    "run_pattern_batch",
]

#: FoldResult fields too large (per state, per edge) or not plain data for a record line
_BULKY = {"pattern", "structure", "target", "fractions", "U", "coords", "fold_angles", "rest",
          "energy", "elapsed"}  # fmt: skip


def pattern_files(paths) -> list[Path]:
    """The pattern files of ``paths``: files as given, folders searched recursively for the
    suffixes the reader registry knows; sorted within a folder, duplicates dropped. Raises
    ``FileNotFoundError`` for a path that does not exist."""
    suffixes = {str(s).lower() for s in READERS.names()}
    out, seen = [], set()
    for given in paths:
        p = Path(given)
        if p.is_dir():
            found = sorted(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in suffixes)
        elif p.is_file():
            found = [p]
        else:
            raise FileNotFoundError(f"{given}: no such file or folder")
        for f in found:
            key = f.resolve()
            if key not in seen:
                seen.add(key)
                out.append(f)
    return out


def file_sha256(path) -> str:
    """SHA-256 of the file's bytes, hex."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def recorded_files(out) -> set[tuple[str, str]]:
    """(resolved path, sha256) of every complete record in the JSON-lines file ``out``; a last
    line without its newline or not valid JSON (a run killed mid-write) is cut off the file."""
    out = Path(out)
    if not out.exists():
        return set()
    data = out.read_bytes()
    keep = data.rfind(b"\n") + 1  # end of the last complete line
    lines = data[:keep].splitlines()
    done = set()
    for k, line in enumerate(lines):
        try:
            rec = json.loads(line)
        except ValueError:
            if k == len(lines) - 1:  # a torn final line: cut it too
                keep -= len(line) + 1
                break
            continue
        done.add((rec.get("path"), rec.get("sha256")))
    if keep != len(data):
        with open(out, "r+b") as fh:
            fh.truncate(keep)
            fh.flush()
            os.fsync(fh.fileno())
    return done


def _plain(value):
    """``value`` as JSON data: NaN and inf as None, arrays as lists, other objects as str."""
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    return str(value)


def _fold_fields(fold) -> dict:
    """The small fields of a FoldResult, read from the dataclass (``status`` as its text)."""
    return {
        f.name: _plain(getattr(fold, f.name))
        for f in dataclasses.fields(fold)
        if f.name not in _BULKY
    }


def _simulate(path, setting, options, size, scale, stage):
    import holofold.mechanics.pattern_simulation as simulation  # its simulate_pattern, as
    # looked up at the call (a test replaces it there)

    reader = reader_for(path)
    given = {k: v for k, v in options.items() if v is not None and k in reader.options}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pattern = read_pattern(path, **given)
    stage[0] = "fold"
    if size is not None:
        xy = pattern.flat if pattern.flat is not None else pattern.coords
        pattern = simulation.scaled_pattern(pattern, size / float(np.ptp(xy, axis=0).max()))
    elif scale is not None:
        pattern = simulation.scaled_pattern(pattern, scale)
    pattern = dataclasses.replace(pattern, meta={**pattern.meta, "source": Path(path).name})
    return pattern, simulation.simulate_pattern(pattern, setting)


def check_pattern_file(path, setting, options=None, size=None, scale=None, time_limit=None) -> dict:
    """The record of one pattern file folded with ``setting`` (a PatternSetting).

    Keys: ``file``, ``path`` (resolved), ``sha256``, ``imported`` (bool), ``reason`` (the one
    line why not imported, crashed or timed out; None when it folded), ``panels``,
    ``reached``, ``verdict``, ``note``, ``largest_strain`` (the panels' bars),
    ``largest_triangle_strain`` (in the plane of the panels' triangles), ``progress``,
    ``wrong_way_count``, ``collision`` (thick panels run into each other), ``thick``,
    ``clearance`` (m),
    ``status`` (the status line), ``seconds`` (wall time of this record), then ``fold``: the
    FoldResult's own small fields. ``options`` are reader options (``unit``, ``tol``, ``frame``,
    ``curves``, ``split``; each given only to the readers that take it); ``size`` m or
    ``scale`` rescale the pattern; ``time_limit`` s (None: none) covers reading and folding.
    """
    p = Path(path)
    rec = {"file": str(p), "path": str(p.resolve()), "sha256": file_sha256(p)}
    rec.update(imported=False, reason=None, panels=None, reached=None, verdict=None, note=None)
    rec.update(largest_strain=None, largest_triangle_strain=None, progress=None)
    rec.update(wrong_way_count=None, collision=None)
    rec.update(thick=None, clearance=None, status=None, fold=None)  # same keys on every line
    t0 = time.perf_counter()
    stage = ["import"]
    try:
        pattern, sim = call_with_limit(
            time_limit, _simulate, p, setting, dict(options or {}), size, scale, stage
        )
        stage[0] = "record"
    except RowTimeout:
        rec["reason"] = f"timeout after {time_limit:g} s (--time-limit)"
    except Exception as exc:  # a refused or crashing pattern is a line, never the batch's end
        text = " ".join(str(exc).split()) or type(exc).__name__
        rec["reason"] = f"{type(exc).__name__}: {text}"
        if type(exc).__module__.startswith("holofold") or isinstance(exc, (OSError, ValueError)):
            rec["reason"] = text
    if stage[0] == "record":
        f = sim.fold
        rec.update(
            imported=True, panels=int(pattern.n_faces), reached=float(f.reached),
            verdict=f.verdict, note=f.note,
            largest_strain=float(f.energy.panel_strain.max(initial=0.0)),
            largest_triangle_strain=float(f.energy.triangle_strain.max(initial=0.0)),
            progress=float(f.progress), wrong_way_count=int(len(f.wrong_way)),
            collision=bool(sim.collision), thick=sim.thick, clearance=_plain(sim.clearance),
            status=sim.status_line(),
        )  # fmt: skip
        rec["fold"] = _fold_fields(f)
    else:  # refused while reading, or crashed or timed out while folding
        rec["imported"] = stage[0] == "fold"
    rec["seconds"] = time.perf_counter() - t0
    return rec


def _append_line(fh, rec: dict) -> None:
    """One complete line, appended, flushed and fsynced."""
    fh.write(json.dumps(rec, allow_nan=False) + "\n")
    fh.flush()
    os.fsync(fh.fileno())


def _failed(path, reason: str) -> dict:
    """The record of a pattern whose worker process died (a crash below Python)."""
    p = Path(path)
    rec = {"file": str(p), "path": str(p.resolve()), "sha256": file_sha256(p)}
    for key in ("imported", "reason", "panels", "reached", "verdict", "note", "largest_strain",
                "largest_triangle_strain", "progress", "wrong_way_count", "collision", "thick",
                "clearance", "status", "fold"):  # fmt: skip
        rec[key] = None
    rec.update(imported=None, reason=reason, seconds=None)
    return rec


def _isolated(path, args, check):
    """``check(path, *args)`` in a process of its own: a record even if that process dies."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    ctx = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
    with ProcessPoolExecutor(1, mp_context=ctx) as pool:
        try:
            return pool.submit(check, path, *args).result()
        except BrokenProcessPool:
            return _failed(path, "crashed: its worker process died")


def _in_workers(todo, args, workers, check):
    """The records of ``todo`` from joblib processes, in order; if a worker process dies (a
    crash below Python), the files not yet recorded run each in a process of its own."""
    from joblib import Parallel, delayed

    par = Parallel(n_jobs=workers, return_as="generator", batch_size=1)
    k = 0
    try:
        for rec in par(delayed(check)(f, *args) for f in todo):
            k += 1
            yield rec
    except Exception:  # joblib's TerminatedWorkerError and kin: a worker process died
        for f in todo[k:]:
            yield _isolated(f, args, check)


def run_pattern_batch(
    files, out, setting, options=None, size=None, scale=None, time_limit=None, workers=1,
    progress=None, *, check=None,
) -> dict:  # fmt: skip
    """Check every file of ``files`` (see :func:`check_pattern_file`), appending its record
    to the JSON-lines file ``out`` as it finishes; files recorded there already (same resolved
    path and content) are skipped. ``workers`` > 1 (or -1: every core) runs them on joblib
    processes (a worker that dies takes no other pattern with it). ``progress(done, total,
    failed, record)`` is called after each line; ``check`` replaces :func:`check_pattern_file`
    (same arguments; tests).
    Returns counts: ``total``, ``skipped``, ``checked``, ``failed`` (not imported, crashed or
    timed out)."""
    out = Path(out)
    done = recorded_files(out)
    todo, skipped = [], 0
    for f in files:
        key = (str(Path(f).resolve()), file_sha256(f))
        if key in done:
            skipped += 1
        else:
            done.add(key)
            todo.append(f)
    args = (setting, dict(options or {}), size, scale, time_limit)
    check = check_pattern_file if check is None else check
    if workers == 1 or len(todo) <= 1:
        recs = (check(f, *args) for f in todo)
    else:
        recs = _in_workers(todo, args, workers, check)
    failed = checked = 0
    with open(out, "a", encoding="utf-8") as fh:
        for rec in recs:
            _append_line(fh, rec)
            checked += 1
            failed += rec["reason"] is not None
            if progress is not None:
                progress(skipped + checked, skipped + len(todo), failed, rec)
    return {"total": len(files), "skipped": skipped, "checked": checked, "failed": failed}
