"""Finished rows of a chunk still being simulated, kept on disk so that a killed run loses
seconds of simulation, not a chunk (issue 33).

While chunk ``k`` of a database is simulated, its finished rows are written at most every
:data:`CHECKPOINT_SECONDS` to ``chunks/rows-<k:05d>-<sha256:16>.parquet`` (atomically, named by
the checksum of its bytes; the newer file replaces the older). A resume takes them back and
simulates only the rest of the chunk; the file is removed once chunk ``k`` itself is written.
A checkpoint that is truncated, altered or holds rows outside its chunk is moved to
``chunks/damaged/`` with a warning (its rows are simulated again).

Each file holds one row per finished design: ``row`` (its position in the design table), the
performance columns and the typed status columns ``state`` and ``reason``; the outputs read
back are exactly the ones written (floats are stored as they are).
"""

from __future__ import annotations

import hashlib
import io
import os
import re
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.database.row_status import row_statuses, status_columns
from holofold.geometry.outputs import atomic_write

__all__ = ["CHECKPOINT_SECONDS", "RowCheckpoint", "move_damaged"]

#: seconds of finished rows a killed run may lose at most (plus the rows still running)
CHECKPOINT_SECONDS = 5.0

_NAME = re.compile(r"^rows-(\d{5})-([0-9a-f]{16})\.parquet$")


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


def move_damaged(path: Path, why: str) -> None:
    """Move a damaged chunk or checkpoint file to ``chunks/damaged/`` with a warning."""
    aside = path.parent / "damaged"
    aside.mkdir(exist_ok=True)
    dest = aside / f"{path.name}.{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}"
    os.replace(path, dest)
    warnings.warn(
        f"damaged chunk {path.name} ({why}) moved to {dest.relative_to(path.parent.parent)}; "
        "its rows will be simulated again",
        stacklevel=3,
    )


class RowCheckpoint:
    """The finished rows of chunk ``k`` (design-table positions ``lo`` to ``hi - 1``).

    Parameters
    ----------
    chunks : Path
        The database's ``chunks`` folder.
    k, lo, hi : int
        Chunk index and its row span.
    performance : sequence of str
        The scenario's performance column names.
    every : float
        Seconds between two writes at most (0: after every row).
    """

    def __init__(self, chunks: Path, k: int, lo: int, hi: int, performance, every: float):
        self.chunks, self.k, self.lo, self.hi = Path(chunks), int(k), int(lo), int(hi)
        self.performance = tuple(performance)
        self.every = float(every)
        self.saved: dict[int, dict] = {}  # position -> output (performance values, Status)
        self._last = self._now()
        self._unsaved = 0

    @staticmethod
    def _now() -> float:
        return time.monotonic()

    # ------------------------------------------------------------------ reading
    def _files(self) -> list[Path]:
        out = []
        for p in sorted(self.chunks.glob(f"rows-{self.k:05d}-*.parquet")):
            if _NAME.match(p.name):
                out.append(p)
            else:
                move_damaged(p, "not a checkpoint name")
        return out

    def load(self) -> dict[int, dict]:
        """The rows a killed run left for this chunk (position -> output); damaged files are
        moved aside. The file with the most rows wins (a newer file holds every row of an
        older one)."""
        best: dict[int, dict] = {}
        for p in self._files():
            rows, why = self._read(p)
            if why is not None:
                move_damaged(p, why)
            elif len(rows) >= len(best):
                best = rows
        self.saved = dict(best)
        return dict(best)

    def _read(self, path: Path) -> tuple[dict[int, dict], str | None]:
        data = path.read_bytes()
        if _digest(data) != _NAME.match(path.name)[2]:
            return {}, "checksum mismatch: truncated or altered"
        try:
            frame = pd.read_parquet(io.BytesIO(data))
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
            return {}, f"unreadable: {type(exc).__name__}"
        missing = {"row", "state", "reason", *self.performance} - set(frame.columns)
        if missing:
            return {}, "columns missing"
        pos = frame["row"].to_numpy()
        if not np.issubdtype(pos.dtype, np.integer) or len(set(pos.tolist())) != len(pos):
            return {}, "row positions are not distinct integers"
        if len(pos) and (pos.min() < self.lo or pos.max() >= self.hi):
            return {}, f"rows outside chunk {self.k}"
        try:
            statuses = row_statuses(frame)
        except ValueError as exc:
            return {}, str(exc)
        values = {c: frame[c].to_numpy(dtype=float) for c in self.performance}
        rows = {
            int(p): {**{c: float(values[c][j]) for c in self.performance}, "status": s}
            for j, (p, s) in enumerate(zip(pos.tolist(), statuses, strict=True))
        }
        return rows, None

    # ------------------------------------------------------------------ writing
    def add(self, pos: int, out: dict) -> None:
        """Record a finished row; write the file when ``every`` seconds have passed."""
        self.saved[int(pos)] = out
        self._unsaved += 1
        now = self._now()
        if now - self._last >= self.every:
            self.write(now)

    def write(self, now: float | None = None) -> None:
        """Write every recorded row (atomically), then remove the older files."""
        if not self._unsaved:
            return
        old = self._files()
        pos = sorted(self.saved)
        outs = [self.saved[p] for p in pos]
        frame = pd.DataFrame({"row": np.array(pos, dtype=np.int64)})
        for c in self.performance:
            frame[c] = np.array([o.get(c, np.nan) for o in outs], dtype=float)
        cols = status_columns(o["status"] for o in outs)
        frame["state"] = cols["state"]
        frame["reason"] = cols["reason"]
        buf = io.BytesIO()
        frame.to_parquet(buf, index=False)
        data = buf.getvalue()
        path = self.chunks / f"rows-{self.k:05d}-{_digest(data)}.parquet"
        atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))
        for p in old:
            if p != path:
                p.unlink(missing_ok=True)
        self._last = self._now() if now is None else now
        self._unsaved = 0

    def discard(self) -> None:
        """Remove this chunk's files (the chunk itself is written)."""
        for p in self.chunks.glob(f"rows-{self.k:05d}-*.parquet"):
            p.unlink(missing_ok=True)

    @staticmethod
    def discard_done(chunks: Path, done) -> None:
        """Remove the files of chunks already written (a run killed between writing a chunk
        and removing its checkpoint)."""
        for p in Path(chunks).glob("rows-*.parquet"):
            m = _NAME.match(p.name)
            if m is not None and int(m[1]) in done:
                p.unlink(missing_ok=True)
