"""kill -9 at random points, then resume: no row lost, none doubled, the same results
(issue 15, section 6). Each run is a real ``holofold`` process killed with SIGKILL."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

pytestmark = pytest.mark.slow
HOLOFOLD = [sys.executable, "-m", "holofold.cli"]


def _chunks(folder):
    return len(list(folder.rglob("part-*.parquet"))) if folder.exists() else 0


def _kill_until_done(argv, folder, points, rng, limit=600.0, after=False):
    """Run ``argv`` and SIGKILL it (with its workers) once ``folder`` holds ``c`` more chunk
    files than at its start, plus a random 0-0.3 s, for each ``c`` in ``points`` (or, with
    ``after``, ``c`` seconds after it started); then let the last run finish. Returns the
    number of kills."""
    kills = 0
    start = time.monotonic()
    for c in [*points, None]:
        p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             start_new_session=True)  # fmt: skip
        if c is not None and after:
            try:
                p.wait(timeout=c)
            except subprocess.TimeoutExpired:
                pass
        elif c is not None:
            base = _chunks(folder)
            while p.poll() is None and _chunks(folder) < base + c:
                assert time.monotonic() - start < limit
                time.sleep(0.02)
            time.sleep(rng.uniform(0.0, 0.3))
        if c is not None:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)  # the command and its worker processes
                p.wait()
                kills += 1
                continue
        p.wait(timeout=limit)
        err = p.stderr.read().decode()
        if c is None or p.returncode == 0:
            assert p.returncode == 0, err
            return kills
    raise AssertionError("never finished")


def test_generate_killed_at_random_points_resumes_exactly(tmp_path):
    argv = [*HOLOFOLD, "generate", "arch", "-n", "300", "--chunk-size", "10",
            "--seed", "3", "--workers", "2"]  # fmt: skip
    subprocess.run([*argv, "-o", str(tmp_path / "ref")], check=True, capture_output=True)
    ref = pd.read_parquet(tmp_path / "ref" / "database.parquet")
    rng = np.random.default_rng(7)
    points = list(rng.integers(0, 3, 20))  # 0: killed while starting or within its first chunk
    kills = _kill_until_done([*argv, "-o", str(tmp_path / "db")], tmp_path / "db", points, rng)
    db = pd.read_parquet(tmp_path / "db" / "database.parquet")
    # Most runs are interrupted; on a fast machine the last chunks can finish within a wait.
    assert kills >= len(points) // 2
    assert db["sample"].tolist() == list(range(300))  # none lost, none doubled
    pd.testing.assert_frame_equal(db, ref, check_exact=True)
    assert not list((tmp_path / "db").rglob(".holofold-*"))  # no temporary file left behind


def test_design_loop_killed_at_random_points_resumes_to_the_same_design(tmp_path):
    argv = [*HOLOFOLD, "design", "arch", "--target", "Zstiff > 60 & error < 0.08", "-n", "100",
            "--rounds", "1", "--refine", "20", "--verify", "8", "--top", "2", "--workers", "2",
            "--no-progress"]  # fmt: skip
    subprocess.run([*argv, "-o", str(tmp_path / "ref")], check=True, capture_output=True)
    ref = json.loads((tmp_path / "ref" / "design.json").read_text())
    rng = np.random.default_rng(11)
    points = list(rng.uniform(0.5, 4.0, 20))  # seconds after each start: any stage, any file
    kills = _kill_until_done(
        [*argv, "-o", str(tmp_path / "out")], tmp_path / "out", points, rng, after=True
    )
    got = json.loads((tmp_path / "out" / "design.json").read_text())
    for key in ("features", "performance", "rule", "verified_precision", "margins", "rounds"):
        assert got[key] == ref[key], key
    assert got["database"]["rows"] == ref["database"]["rows"]
    assert kills >= 10  # 20 on 2 busy cores; a run that finishes before its kill time ends it
