"""Finished rows of the chunk in flight are kept: an interrupted run loses seconds of
simulation, not a chunk, and the resume still gives the same database (issue 33, item 6)."""

from __future__ import annotations

import warnings

import pandas as pd
import pytest

import holofold.design.database.store as store
from holofold.design import Column, Scenario
from holofold.design.database.runner import BATCH_ROWS
from holofold.design.database.sampling import sample_designs
from holofold.mechanics import CONVERGED, Status

CALLS: list = []


def _one(row):
    CALLS.append(row["a"])
    if row["a"] > 0.9:
        return {"double": float("nan"), "status": Status.failed("too long", "and too wide")}
    return {"double": 2.0 * row["a"] + 1e-17 * row["a"] ** 3, "status": CONVERGED}


def _batch(rows):
    return [_one(r) for r in rows]


ONE_BY_ONE = Scenario(
    name="rows",
    description="a cheap scenario, one row per task",
    features=(Column("a", "m", "a length", 0.0, 1.0),),
    performance=(Column("double", "m"),),
    check=lambda row: [],
    evaluate=_one,
)
BATCHED = Scenario(
    name="batched",
    description="a cheap scenario whose rows run in batches",
    features=ONE_BY_ONE.features,
    performance=ONE_BY_ONE.performance,
    check=lambda row: [],
    evaluate=_one,
    evaluate_batch=_batch,
    batch_key=lambda row: 0,
)


def _interrupted_after(monkeypatch, rows_done):
    """Make the next build stop (Ctrl-C) once ``rows_done`` rows have arrived."""
    real = store.iter_results

    def stopping(scenario, rows, **kw):
        for j, (pos, out) in enumerate(real(scenario, rows, **kw)):
            if j == rows_done:
                raise KeyboardInterrupt
            yield pos, out

    monkeypatch.setattr(store, "iter_results", stopping)
    return real


def _checkpoints(folder):
    return sorted((folder / "chunks").glob("rows-*.parquet"))


@pytest.mark.parametrize("scenario, done, resimulated", [
    (ONE_BY_ONE, 13, 30 - 13),  # rows 0-12 kept: the resume runs the other 17
    (BATCHED, BATCH_ROWS + 3, 30 - BATCH_ROWS),  # the first task kept, the second run again
])  # fmt: skip
def test_a_resume_takes_back_the_finished_rows_and_gives_the_same_database(
    scenario, done, resimulated, tmp_path, monkeypatch
):
    designs = sample_designs(scenario, 30, seed=4)
    reference = store.build_database(scenario, designs, tmp_path / "ref", chunk_size=30)
    real = _interrupted_after(monkeypatch, done)
    with pytest.raises(KeyboardInterrupt):
        store.build_database(scenario, designs, tmp_path / "db", chunk_size=30, checkpoint=0)
    (kept,) = _checkpoints(tmp_path / "db")
    assert len(pd.read_parquet(kept)) == done  # every finished row, none lost
    monkeypatch.setattr(store, "iter_results", real)
    CALLS.clear()
    db = store.build_database(scenario, designs, tmp_path / "db", chunk_size=30)
    assert len(CALLS) == resimulated
    pd.testing.assert_frame_equal(db, reference, check_exact=True)
    assert (db["state"] == "failed").sum() == (designs["a"] > 0.9).sum() > 0  # reasons kept
    assert not _checkpoints(tmp_path / "db")  # removed once the chunk is written


def test_checkpoints_are_written_no_more_often_than_asked(tmp_path, monkeypatch):
    designs = sample_designs(ONE_BY_ONE, 20, seed=1)
    _interrupted_after(monkeypatch, 12)
    with pytest.raises(KeyboardInterrupt):  # a long interval: nothing written yet
        store.build_database(ONE_BY_ONE, designs, tmp_path / "db", chunk_size=20, checkpoint=1e9)
    assert not _checkpoints(tmp_path / "db")
    clock = iter(range(0, 1000, 2))  # a fake clock: 2 s per reading
    monkeypatch.setattr(store.RowCheckpoint, "_now", staticmethod(lambda: next(clock)))
    with pytest.raises(KeyboardInterrupt):
        store.build_database(ONE_BY_ONE, designs, tmp_path / "db", chunk_size=20, checkpoint=5)
    (kept,) = _checkpoints(tmp_path / "db")
    # one reading at the start (0 s) and one per row: written at rows 3, 6, 9 and 12
    assert len(pd.read_parquet(kept)) == 12


def test_a_damaged_checkpoint_is_moved_aside_and_its_rows_simulated_again(tmp_path, monkeypatch):
    designs = sample_designs(ONE_BY_ONE, 20, seed=2)
    reference = store.build_database(ONE_BY_ONE, designs, tmp_path / "ref", chunk_size=10)
    real = _interrupted_after(monkeypatch, 5)
    with pytest.raises(KeyboardInterrupt):
        store.build_database(ONE_BY_ONE, designs, tmp_path / "db", chunk_size=10, checkpoint=0)
    (kept,) = _checkpoints(tmp_path / "db")
    kept.write_bytes(kept.read_bytes()[:-20])  # truncated
    monkeypatch.setattr(store, "iter_results", real)
    CALLS.clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        db = store.build_database(ONE_BY_ONE, designs, tmp_path / "db", chunk_size=10)
    said = [str(w.message) for w in caught]
    assert any(kept.name in s and "checksum mismatch" in s for s in said), said
    assert len(CALLS) == 20  # chunk 0's five kept rows again, and chunk 1
    assert len(list((tmp_path / "db" / "chunks" / "damaged").iterdir())) == 1
    pd.testing.assert_frame_equal(db, reference, check_exact=True)


def test_a_checkpoint_of_a_chunk_already_written_is_removed(tmp_path, monkeypatch):
    designs = sample_designs(ONE_BY_ONE, 10, seed=3)
    store.build_database(ONE_BY_ONE, designs, tmp_path / "db", chunk_size=10)
    stale = tmp_path / "db" / "chunks" / "rows-00000-0123456789abcdef.parquet"
    stale.write_bytes(b"left by a run killed after writing its chunk")
    CALLS.clear()
    store.build_database(ONE_BY_ONE, designs, tmp_path / "db", chunk_size=10)
    assert not stale.exists() and CALLS == []
