"""One writer per output folder (issue 23 item 1): two processes, every combination.

Driven by events, not clocks (issue 38): a holder is stopped with SIGSTOP once it holds the
lock (so it still holds it whatever the speed of the machine) and continued with SIGCONT
after the second run was refused; a waiting run's holder lets go when the waiter says it
waits."""

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

pytestmark = pytest.mark.processes
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


def _start(argv, folder, timeout=600.0):
    """Start ``argv``; return the process once it holds the lock of ``folder``, stopped
    (SIGSTOP) so that it holds it until :func:`_go` (``timeout``: a hang bound)."""
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + timeout
    while _holder_pid(folder) != p.pid:
        if p.poll() is not None or time.monotonic() > end:
            out, err = p.communicate()
            pytest.fail(f"{argv} never held {folder}: {p.returncode} {err[-2000:]}")
        time.sleep(0.05)
    os.kill(p.pid, signal.SIGSTOP)
    return p


def _go(p):
    os.kill(p.pid, signal.SIGCONT)


def _refused(argv, folder):
    r = subprocess.run(argv, capture_output=True, text=True, timeout=600)  # a hang bound
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert f"{folder} is in use by another holofold run (pid " in r.stderr
    assert "wait for it to end or use another folder" in r.stderr
    assert r.stdout == ""


def _gen(folder, *extra):
    return [*CLI, "generate", "single-miura", "-o", str(folder), "--chunk-size", "500", *extra]


# the first run holds the folder (stopped) while the second starts and is refused
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
    try:
        _refused(_gen(db, *second), db)
    finally:
        _go(a)
    out, err = a.communicate(timeout=300)
    assert a.returncode == 0, err
    n = int(first[1])
    assert out.strip().endswith(f"{n} designs in {db / 'database.parquet'} (0 failed)")
    meta = json.loads((db / "meta.json").read_text())
    assert meta["rows"] == n and meta["seed"] == int(first[3])
    assert len(pd.read_parquet(db / "database.parquet")) == n
    assert not (db / "chunks" / "damaged").exists()  # nothing of the winner moved aside


@pytest.mark.slow
def test_two_design_runs_with_other_units_never_mix_files(tmp_path):
    out = tmp_path / "d"
    argv = [*CLI, "design", "single-miura", "--target", "axialstiff60 > 40000", "-n", "60",
            "--verify", "3", "--top", "1", "--rounds", "0", "--workers", "1", "--no-progress",
            "-o", str(out)]  # fmt: skip
    a = _start([*argv, "--units", "m"], out)
    try:
        _refused([*argv, "--units", "mm"], out)
    finally:
        _go(a)
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
    # the holder lets go when it reads a line: sent when the waiter says it waits (an event)
    code = (
        "import sys; from holofold.design import folder_lock\n"
        "with folder_lock(sys.argv[1]):\n    print('held', flush=True); sys.stdin.readline()\n"
        "print('released', flush=True)\n"
    )

    def holder():
        p = subprocess.Popen([sys.executable, "-c", code, str(folder)], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)  # fmt: skip
        assert p.stdout.readline().strip() == "held"
        return p

    def release(p):
        p.stdin.write("go\n")
        p.stdin.close()

    p = holder()
    said = []

    def say(text):
        said.append(text)
        release(p)

    with folder_lock(folder, wait=600, say=say):  # 600 s: a hang bound
        assert p.stdout.readline().strip() == "released"  # got it after the holder let go
    p.wait(timeout=600)
    assert len(said) == 1 and said[0].startswith("waiting up to 600 s: ") and str(p.pid) in said[0]
    q = holder()  # and a short wait on a holder that never lets go gives up with the same line
    try:
        with pytest.raises(FolderBusyError, match=rf"pid {q.pid}"):
            with folder_lock(folder, wait=0.3, say=said.append):
                pass
        assert len(said) == 2 and said[1].startswith("waiting up to 0.3 s: ")
    finally:
        release(q)
        q.wait(timeout=600)


def test_the_lock_is_reentrant_in_one_process_and_a_refused_run_leaves_no_folder(tmp_path):
    folder = tmp_path / "new"
    with folder_lock(folder), folder_lock(folder):
        assert _held(folder) is False  # re-entered by this process
    with pytest.raises(ValueError, match="boom"), folder_lock(folder / "x"):
        raise ValueError("boom")
    assert not (folder / "x").exists()


def test_a_run_checks_the_folder_holds_its_own_table_and_settings(tmp_path, monkeypatch):
    from holofold.design import generate_database
    from holofold.design.database import store

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
