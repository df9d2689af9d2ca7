"""Dask that fails in one line (issue 23 item 6): a lost scheduler, no workers, and the README's
cluster recipe listening only on the address the user chose."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time

import pandas as pd
import pytest

pytest.importorskip("distributed")
psutil = pytest.importorskip("psutil")
pytestmark = pytest.mark.processes

SCHEDULER = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
WORKER = [sys.executable, "-m", "distributed.cli.dask_worker"]
CLI = [sys.executable, "-m", "holofold.cli"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _spawn(argv):
    return subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)  # fmt: skip


def _stop(*procs):
    for p in procs:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


def _wait_for_port(port, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    pytest.fail(f"nothing listens on port {port}")


def _scheduler(port):
    p = _spawn([*SCHEDULER, "--host", "127.0.0.1", "--port", str(port),
                "--dashboard-address", "127.0.0.1:0"])  # fmt: skip
    _wait_for_port(port)
    return p


def _worker(port):
    return _spawn([*WORKER, f"tcp://127.0.0.1:{port}", "--host", "127.0.0.1", "--nthreads", "1",
                   "--dashboard-address", "127.0.0.1:0"])  # fmt: skip


def _one_line(r, *words):
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr, r.stderr
    for w in words:
        assert w in r.stderr, r.stderr


def test_no_workers_for_the_stated_time_is_one_line_and_an_exit(tmp_path):
    port = _free_port()
    sched = _scheduler(port)
    try:
        r = subprocess.run(
            [*CLI, "generate", "single-miura", "-n", "4", "-o", str(tmp_path / "db"),
             "--scheduler", f"tcp://127.0.0.1:{port}"],
            capture_output=True, text=True, timeout=120,
            env={**os.environ, "HOLOFOLD_WORKER_TIMEOUT": "3"},
        )  # fmt: skip
        # (timeout=120: a hang bound; the run gives up after its 3 s limit)
    finally:
        _stop(sched)
    _one_line(r, f"no Dask worker at tcp://127.0.0.1:{port} for 3 s", "run the same command")


@pytest.mark.slow
def test_a_lost_scheduler_is_one_line_with_the_resume_hint_and_the_resume_is_exact(tmp_path):
    port = _free_port()
    sched, work = _scheduler(port), None
    db = tmp_path / "db"
    argv = [*CLI, "generate", "single-miura", "-n", "1500", "--chunk-size", "50", "-o", str(db)]
    try:
        work = _worker(port)
        run = subprocess.Popen(
            [*argv, "--scheduler", f"tcp://127.0.0.1:{port}"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        end = time.monotonic() + 120
        while not list((db / "chunks").glob("part-*.parquet")):
            assert run.poll() is None and time.monotonic() < end, run.communicate()
            time.sleep(0.05)
        os.killpg(sched.pid, signal.SIGKILL)  # the scheduler crashes
        out, err = run.communicate(timeout=120)
    finally:
        _stop(sched, *([work] if work else []))
    r = subprocess.CompletedProcess(argv, run.returncode, out, err)
    _one_line(r, f"lost the Dask scheduler at tcp://127.0.0.1:{port}", "run the same command")
    kept = len(list((db / "chunks").glob("part-*.parquet")))
    assert 1 <= kept < 30
    done = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    ref = subprocess.run([*argv[:-1], str(tmp_path / "ref")], capture_output=True, timeout=600)
    assert ref.returncode == 0
    a, b = (
        pd.read_parquet(db / "database.parquet"),
        pd.read_parquet(tmp_path / "ref/database.parquet"),
    )
    pd.testing.assert_frame_equal(a, b, rtol=1e-12)


def _listening(procs) -> list[tuple[str, int]]:
    pids = set()
    for p in procs:
        root = psutil.Process(p.pid)
        pids |= {root.pid, *(c.pid for c in root.children(recursive=True))}
    out = []
    for pid in pids:
        try:
            conns = psutil.Process(pid).net_connections(kind="inet")
        except psutil.Error:
            continue
        out += [c.laddr for c in conns if c.status == psutil.CONN_LISTEN]
    return out


@pytest.mark.slow
def test_the_readme_recipe_listens_only_on_the_chosen_address(tmp_path):
    import re
    from pathlib import Path

    readme = (Path(__file__).parents[1] / "README.md").read_text()
    recipe = re.search(r"```bash\n(dask scheduler --host .*?)```", readme, re.S).group(1)
    assert "--dashboard-address" in recipe and "--host" in recipe
    port = _free_port()
    sched = _scheduler(port)  # the recipe's flags with HOST = 127.0.0.1
    work = _worker(port)
    try:
        from distributed import Client

        with Client(f"tcp://127.0.0.1:{port}", timeout=30) as c:
            c.wait_for_workers(1, timeout=60)
        time.sleep(1.0)  # the worker's dashboard and nanny are up
        addrs = _listening([sched, work])
    finally:
        _stop(sched, work)
    assert len(addrs) >= 4  # scheduler, its dashboard, nanny, worker (and its dashboard)
    assert {a.ip for a in addrs} == {"127.0.0.1"}, addrs
