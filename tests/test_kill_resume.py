"""kill -9 at chosen points, then resume: no row lost, none doubled, the same results
(issue 15, section 6; issue 38: the points are events, not times). Each run is a real
``holofold`` process that kills itself and its workers with SIGKILL at the event that
``HOLOFOLD_TEST_FAULT`` names (holofold.geometry.fault_points): inside or just after its n-th
file write, or when its n-th row's result arrives, so every kill lands where it is meant on
any machine, fast or slow."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import pandas as pd
import pytest

pytestmark = [pytest.mark.slow, pytest.mark.processes]
HOLOFOLD = [sys.executable, "-m", "holofold.cli"]
LIMIT = 600.0  # a hang bound per run, not a speed check (a run takes seconds)


def _run(argv, fault=None):
    env = dict(os.environ)
    env.pop("HOLOFOLD_TEST_FAULT", None)
    if fault is not None:
        env["HOLOFOLD_TEST_FAULT"] = fault
    # its own session: the fault point kills the command and its workers, never pytest
    return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=LIMIT,
                          start_new_session=True)  # fmt: skip


def _kill_at(argv, points):
    """Run ``argv`` once per ``(event, n)`` in ``points``, killed at its ``n``-th ``event``;
    then once to the end. Returns the list of points at which a run was killed (a run that
    finishes first must exit 0)."""
    killed = []
    for event, n in points:
        r = _run(argv, f"kill:{event}:{n}")
        if r.returncode == -signal.SIGKILL:
            killed.append((event, n))
        else:
            assert r.returncode == 0, r.stderr
    r = _run(argv)
    assert r.returncode == 0, r.stderr
    return killed


def _temporaries(folder):
    return [p for p in folder.rglob(".holofold-*") if p.is_file()]


def test_the_fault_point_kills_at_its_event_and_refuses_a_bad_setting(tmp_path):
    argv = [*HOLOFOLD, "generate", "single-miura", "-n", "6", "--chunk-size", "2", "-o",
            str(tmp_path / "db")]  # fmt: skip
    assert _run(argv, "kill:written:1").returncode == -signal.SIGKILL
    stored = [p.name for p in (tmp_path / "db").rglob("*") if p.is_file()]
    assert sorted(stored) == [".holofold.lock", "designs.parquet"]  # one write, then the kill
    r = _run(argv, "kill:write:1")  # inside the next write: its temporary file is left
    assert r.returncode == -signal.SIGKILL and len(_temporaries(tmp_path / "db")) == 1
    r = _run(argv, "kill:chunk:1")
    assert r.returncode != 0 and "HOLOFOLD_TEST_FAULT = 'kill:chunk:1'" in r.stderr


def test_generate_killed_at_chosen_points_resumes_exactly(tmp_path):
    argv = [*HOLOFOLD, "generate", "arch", "-n", "120", "--chunk-size", "10",
            "--seed", "3", "--workers", "2"]  # fmt: skip
    r = _run([*argv, "-o", str(tmp_path / "ref")])
    assert r.returncode == 0, r.stderr
    ref = pd.read_parquet(tmp_path / "ref" / "database.parquet")
    # 12 chunks; each kill stores at most one file (at most 8 in all, fewer than the work), so
    # every run is killed: while starting, inside a write, after one, with rows in flight
    points = [("write", 1), ("row", 1), ("written", 1), ("row", 7), ("write", 2),
              ("row", 3), ("written", 1), ("row", 9), ("write", 2), ("written", 1)]  # fmt: skip
    killed = _kill_at([*argv, "-o", str(tmp_path / "db")], points)
    assert killed == points
    db = pd.read_parquet(tmp_path / "db" / "database.parquet")
    assert db["sample"].tolist() == list(range(120))  # none lost, none doubled
    pd.testing.assert_frame_equal(db, ref, check_exact=True)
    assert not (tmp_path / "db" / "chunks" / "damaged").exists()


def test_design_loop_killed_at_chosen_points_resumes_to_the_same_design(tmp_path):
    argv = [*HOLOFOLD, "design", "arch", "--target", "Zstiff > 60 & error < 0.08", "-n", "100",
            "--rounds", "1", "--refine", "20", "--verify", "8", "--top", "2", "--workers", "2",
            "--no-progress"]  # fmt: skip
    r = _run([*argv, "-o", str(tmp_path / "ref")])
    assert r.returncode == 0, r.stderr
    ref = json.loads((tmp_path / "ref" / "design.json").read_text())
    # every stage: the first database, the refinement, the verification, the report's files;
    # the n-th write of a resumed run is later and later in the loop as earlier runs store
    # their files, so runs killed after or inside their 1st-3rd write reach the last files
    points = [("row", 1), ("written", 2), ("write", 2), ("row", 40), ("written", 3), ("row", 15)]
    points += [("write", 3), ("written", 3), ("written", 3), ("written", 3)]
    killed = _kill_at([*argv, "-o", str(tmp_path / "out")], points)
    got = json.loads((tmp_path / "out" / "design.json").read_text())
    for key in ("features", "performance", "rule", "verified_precision", "margins", "rounds"):
        assert got[key] == ref[key], key
    assert got["database"]["rows"] == ref["database"]["rows"]
    assert len(killed) >= 5, killed


def test_a_kill_mid_chunk_keeps_the_rows_finished_before_it(tmp_path):
    # one chunk of 60 rows, checkpoints after every row (the default is every 5 s): a kill -9
    # when the 30th row arrives leaves the 29 before it, and the resume ends exactly
    script = (
        "import sys; from holofold.design.database.store import generate_database; "
        "generate_database('arch', 60, sys.argv[1], seed=5, chunk_size=60, workers=2, "
        "checkpoint=float(sys.argv[2]), progress=False)"
    )
    ref = _run([sys.executable, "-c", script, str(tmp_path / "ref"), "5"])
    assert ref.returncode == 0, ref.stderr
    argv = [sys.executable, "-c", script, str(tmp_path / "db"), "0"]
    assert _run(argv, "kill:row:30").returncode == -signal.SIGKILL
    (kept,) = (tmp_path / "db" / "chunks").glob("rows-00000-*.parquet")
    assert len(pd.read_parquet(kept)) == 29
    assert not list((tmp_path / "db" / "chunks").glob("part-*"))
    r = _run(argv)
    assert r.returncode == 0, r.stderr
    db = pd.read_parquet(tmp_path / "db" / "database.parquet")
    pd.testing.assert_frame_equal(db, pd.read_parquet(tmp_path / "ref" / "database.parquet"),
                                  check_exact=True)  # fmt: skip
    assert not list((tmp_path / "db" / "chunks").glob("rows-*"))
