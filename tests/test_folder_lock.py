"""One writer per output folder (issue 23 item 1): two processes, every combination."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pandas as pd
import pytest

from holofold.design import FolderBusyError, folder_lock

CLI = [sys.executable, "-m", "holofold.cli"]


def _held(folder) -> bool:
    try:
        with folder_lock(folder):
            return False
    except FolderBusyError:
        return True
    except OSError:
        return False


def _holder_pid(folder) -> int | None:
    """The pid the lock file names (written once the lock is held), without locking."""
    try:
        return json.loads((folder / ".holofold.lock").read_text())["pid"]
    except (OSError, ValueError, KeyError):
        return None


def _start(argv, folder, timeout=60.0):
    """Start ``argv``; return the process once it holds the lock of ``folder``."""
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + timeout
    while _holder_pid(folder) != p.pid:
        if p.poll() is not None or time.monotonic() > end:
            out, err = p.communicate()
            pytest.fail(f"{argv} never held {folder}: {p.returncode} {err[-2000:]}")
        time.sleep(0.05)
    return p


def _refused(argv, folder):
    t0 = time.monotonic()
    r = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    took = time.monotonic() - t0
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert f"{folder} is in use by another holofold run (pid " in r.stderr
    assert "wait for it to end or use another folder" in r.stderr
    assert r.stdout == ""
    return took


def _gen(folder, *extra):
    return [*CLI, "generate", "single-miura", "-o", str(folder), "--chunk-size", "500", *extra]


# the first run must outlast the second's start (a Python process importing holofold, 1-3 s):
# single-Miura rows take about 0.5 ms each, so it simulates 8000
@pytest.mark.parametrize(
    ("first", "second"),
    [pytest.param(["-n", "8000", "--seed", "0"], ["-n", "8000", "--seed", "1"],
                  marks=pytest.mark.slow),  # another --seed
     (["-n", "8000", "--seed", "0"], ["-n", "7900", "--seed", "0"])],  # another -n
    ids=["seed", "rows"],
)  # fmt: skip
def test_a_second_generate_into_a_busy_folder_is_refused_and_the_first_is_intact(
    tmp_path, first, second
):
    db = tmp_path / "db"
    a = _start(_gen(db, *first), db)
    took = _refused(_gen(db, *second), db)
    out, err = a.communicate(timeout=300)
    assert a.returncode == 0, err
    n = int(first[1])
    assert out.strip().endswith(f"{n} designs in {db / 'database.parquet'} (0 failed)")
    meta = json.loads((db / "meta.json").read_text())
    assert meta["rows"] == n and meta["seed"] == int(first[3])
    assert len(pd.read_parquet(db / "database.parquet")) == n
    assert not (db / "chunks" / "damaged").exists()  # nothing of the winner moved aside
    assert took < 30


@pytest.mark.slow
def test_two_design_runs_with_other_units_never_mix_files(tmp_path):
    out = tmp_path / "d"
    argv = [*CLI, "design", "single-miura", "--target", "axialstiff60 > 40000", "-n", "60",
            "--verify", "3", "--top", "1", "--rounds", "0", "--workers", "1", "--no-progress",
            "-o", str(out)]  # fmt: skip
    a = _start([*argv, "--units", "m"], out)
    _refused([*argv, "--units", "mm"], out)
    stdout, err = a.communicate(timeout=600)
    assert a.returncode == 0, err
    assert "chosen:" in stdout
    import trimesh

    summary = json.loads((out / "design.json").read_text())
    rels = [f["path"] for f in summary["files"].values()]
    stls = [out / rel for rel in rels if rel.endswith(".stl")]
    # the 0.04 m cell in the first run's unit (m), every file: 0.0x, never 4x mm
    extents = [max(trimesh.load(p).extents) for p in stls]
    assert stls and all(0.01 < e < 0.2 for e in extents), extents


def test_a_killed_holder_releases_the_folder_at_once(tmp_path):
    folder = tmp_path / "f"
    code = (
        "import sys, time; from holofold.design import folder_lock\n"
        "with folder_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(600)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code, str(folder)], stdout=subprocess.PIPE,
                         text=True)  # fmt: skip
    assert p.stdout.readline().strip() == "held"
    with pytest.raises(FolderBusyError, match=rf"pid {p.pid} on .*since"):
        with folder_lock(folder):
            pass
    os.kill(p.pid, signal.SIGKILL)
    p.wait()
    with folder_lock(folder):  # the OS released it with the process: never stale
        assert (folder / ".holofold.lock").is_file()


def test_a_waiting_run_says_so_once_and_goes_on_when_the_folder_is_free(tmp_path):
    folder = tmp_path / "f"
    code = (
        "import sys, time; from holofold.design import folder_lock\n"
        "with folder_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(1.5)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code, str(folder)], stdout=subprocess.PIPE,
                         text=True)  # fmt: skip
    assert p.stdout.readline().strip() == "held"
    said = []
    t0 = time.monotonic()
    with folder_lock(folder, wait=60, say=said.append):
        waited = time.monotonic() - t0
    p.wait()
    assert len(said) == 1 and said[0].startswith("waiting up to 60 s: ") and str(p.pid) in said[0]
    assert 0.3 < waited < 30
    with pytest.raises(FolderBusyError):  # and a short wait gives up with the same line
        q = subprocess.Popen([sys.executable, "-c", code, str(folder)], stdout=subprocess.PIPE,
                             text=True)  # fmt: skip
        assert q.stdout.readline().strip() == "held"
        with folder_lock(folder, wait=0.3, say=said.append):
            pass
    q.wait()


def test_the_lock_is_reentrant_in_one_process_and_a_refused_run_leaves_no_folder(tmp_path):
    folder = tmp_path / "new"
    with folder_lock(folder), folder_lock(folder):
        assert _held(folder) is False  # re-entered by this process
    with pytest.raises(ValueError, match="boom"), folder_lock(folder / "x"):
        raise ValueError("boom")
    assert not (folder / "x").exists()


def test_a_run_checks_the_folder_holds_its_own_table_and_settings(tmp_path, monkeypatch):
    from holofold.design import generate_database, store

    db = tmp_path / "db"
    generate_database("single-miura", 12, db, seed=4, chunk_size=6)
    real = store._build_locked

    def meddle(*args):  # another writer changes meta.json while the run holds the folder
        real(*args)
        meta = json.loads((db / "meta.json").read_text())
        (db / "meta.json").write_text(json.dumps({**meta, "seed": 5}))

    monkeypatch.setattr(store, "_build_locked", meddle)
    with pytest.raises(ValueError, match=r"meta.json records seed = 5, not this run's 4"):
        generate_database("single-miura", 12, db, seed=4, chunk_size=6)
