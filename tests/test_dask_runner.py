"""Design evaluation on a Dask cluster: same numbers and order as joblib, failures, addresses."""

from __future__ import annotations

import json
import os
import sys
import threading
import time
from contextlib import contextmanager

import numpy as np
import pandas as pd
import pytest
from _toy import toy_scenario

distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.processes

import dask  # noqa: E402

import holofold.design.database.runner as runner  # noqa: E402
import holofold.design.database.store as store  # noqa: E402
from holofold.cli import main  # noqa: E402
from holofold.design.database.runner import check_scheduler, evaluate_designs  # noqa: E402
from holofold.design.database.sampling import sample_designs  # noqa: E402
from holofold.design.scenarios import Scenario, get_scenario  # noqa: E402


def _toy_evaluate(row):
    if row["a"] == 1:
        time.sleep(0.2)  # the first row finishes last
    if row["a"] == 13:
        raise RuntimeError("unlucky design\nsecond line")
    if row["a"] == 7:
        os._exit(3)  # the worker process dies (never called on the in-process cluster)
    return {"double": 2 * row["a"], "status": "converged"}


TOY = toy_scenario(_toy_evaluate)


@pytest.fixture(scope="module")
def address():
    """An in-process cluster (threads, no processes) reached over TCP like a remote one."""
    with distributed.LocalCluster(
        processes=False,
        n_workers=1,
        threads_per_worker=2,
        protocol="tcp://",
        dashboard_address=":0",
    ) as cluster:
        yield cluster.scheduler_address


@pytest.fixture(scope="module")
def miura():
    sc = get_scenario("single-miura")
    d = sample_designs(sc, 6, seed=5).iloc[[3, 0, 5, 1, 4, 2]]
    d.index = [60, 10, 50, 20, 40, 30]
    return sc, d


def test_same_numbers_and_order_as_joblib(address, miura):
    sc, d = miura
    assert address.startswith("tcp://")
    ref = evaluate_designs(sc, d, workers=1)
    res = evaluate_designs(sc, d, scheduler=address, progress=True)
    assert list(res["sample"]) == [3, 0, 5, 1, 4, 2]
    assert list(res.index) == [60, 10, 50, 20, 40, 30]
    assert (res["status"] == "converged").all()
    pd.testing.assert_frame_equal(res, ref, check_exact=True)


def test_failed_row_on_dask(address):
    df = pd.DataFrame({"id": ["p", "q", "r", "s"], "a": [1.0, 13.0, 3.0, 4.0]})
    res = evaluate_designs(TOY, df, scheduler=address)
    assert res["id"].tolist() == ["p", "q", "r", "s"]
    assert res["double"].iloc[[0, 2, 3]].tolist() == [2.0, 6.0, 8.0]
    assert np.isnan(res["double"].iloc[1])
    failed = "failed: RuntimeError: unlucky design"
    assert res["status"].tolist() == ["converged", failed, "converged", "converged"]


def test_dead_worker_fails_its_row_only():
    """A local cluster of real processes; the worker running a=7 exits (os._exit)."""
    df = pd.DataFrame({"a": [1.0, 7.0, 3.0, 4.0, 5.0]})
    cfg = {
        "distributed.scheduler.allowed-failures": 0,  # KilledWorker at the first death
        "distributed.scheduler.worker-saturation": 1.0,  # one task per worker at a time
    }
    with dask.config.set(cfg):
        res = evaluate_designs(TOY, df, scheduler="local", workers=2)
    assert res["status"].iloc[1].startswith("failed: KilledWorker: ")
    assert np.isnan(res["double"].iloc[1])
    assert res["double"].iloc[[0, 2, 3, 4]].tolist() == [2.0, 6.0, 8.0, 10.0]
    assert (res["status"].iloc[[0, 2, 3, 4]] == "converged").all()


@pytest.mark.parametrize(
    "bad", ["10.0.0.5:8786", "tcp://host", "tcp//host:8786", "tcp://host:99999", "", "loc"]
)
def test_bad_address_is_refused_before_anything(bad):
    calls = []
    sc = Scenario(**{**TOY.__dict__, "evaluate": lambda r: calls.append(r) or {}})
    with pytest.raises(ValueError, match=f"Dask scheduler {bad!r} is not an address"):
        evaluate_designs(sc, pd.DataFrame({"a": [1.0, 2.0]}), scheduler=bad)
    assert calls == []


def test_bad_worker_count_with_local_cluster(tmp_path):
    designs = pd.DataFrame({"a": [1.0, 2.0]})
    with pytest.raises(ValueError, match="workers = 0 must be >= 1"):
        store.build_database(TOY, designs, tmp_path / "db", scheduler="local", workers=0)
    assert not (tmp_path / "db").exists()


def test_good_addresses_and_missing_package(monkeypatch):
    assert check_scheduler(" LOCAL ") == "local"
    assert check_scheduler("tcp://10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert check_scheduler("tls://[::1]:8786") == "tls://[::1]:8786"
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(ValueError, match=r'pip install "holofold\[cluster\]"'):
        check_scheduler("tcp://10.0.0.5:8786")


def test_workers_without_holofold_are_reported(address, monkeypatch):
    def cannot_import(scenario):
        raise ModuleNotFoundError("No module named 'design'")

    monkeypatch.setattr(runner, "_worker_ready", cannot_import)
    with pytest.raises(ValueError, match=f"workers of {address} cannot run holofold.*'design'"):
        evaluate_designs(TOY, pd.DataFrame({"a": [1.0]}), scheduler=address)


def test_unreachable_scheduler_names_it():
    df = pd.DataFrame({"a": [1.0]})
    with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}):
        with pytest.raises(OSError, match="tcp://127.0.0.1:1"):
            evaluate_designs(TOY, df, scheduler="tcp://127.0.0.1:1")


#: set when the other chunks are written: the first row waits for it (an event, not a clock;
#: 120 s is a hang bound), so the first chunk finishes after all the others on any machine
OTHERS_WRITTEN = threading.Event()


def _slow_first(row):
    if row["a"] == 1:
        OTHERS_WRITTEN.wait(120.0)
    if row["a"] == 5:
        raise RuntimeError("unlucky design")
    return {"double": 2 * row["a"], "status": "converged"}


SLOW_FIRST = Scenario(**{**TOY.__dict__, "name": "slow-first", "evaluate": _slow_first})
EVALUATED = []  # rows run by _recording_evaluate_one (the in-process workers share it)
_EVALUATE_ONE = runner._evaluate_one


def _recording_evaluate_one(scenario, row, limit_threads, timeout=None):
    EVALUATED.append(tuple(sorted(row.items())))
    return _EVALUATE_ONE(scenario, row, limit_threads, timeout)


def _chunk_files(folder):
    """Chunk name without its checksum ("part-00003") -> table."""
    return {p.name[:10]: pd.read_parquet(p) for p in sorted((folder / "chunks").glob("*.parquet"))}


def _record_writes(monkeypatch, fail_at=None, then=None):
    """Record the chunks ``store.write_chunk`` writes; Ctrl-C instead of writing fail_at;
    ``then``: ``(n, event)``, set ``event`` once ``n`` chunks are written."""
    written, real = [], store.write_chunk

    def recording(df, chunks, k):
        if len(written) + 1 == fail_at:
            raise KeyboardInterrupt
        written.append(f"part-{k:05d}")
        out = real(df, chunks, k)
        if then is not None and len(written) == then[0]:
            then[1].set()
        return out

    monkeypatch.setattr(store, "write_chunk", recording)
    return written


def test_dask_build_writes_each_chunk_when_its_rows_are_done(
    address, tmp_path, monkeypatch, capsys
):
    designs = pd.DataFrame({"id": list("pqrstuv"), "a": np.arange(1.0, 8.0)}, index=range(10, 17))
    OTHERS_WRITTEN.set()  # serial: the first row first
    serial = store.build_database(SLOW_FIRST, designs, tmp_path / "serial", chunk_size=2)
    OTHERS_WRITTEN.clear()
    written = _record_writes(monkeypatch, then=(3, OTHERS_WRITTEN))
    db = store.build_database(
        SLOW_FIRST, designs, tmp_path / "dask", chunk_size=2, scheduler=address, progress=True
    )
    # every row was submitted at once: the three later chunks were written while the first
    # chunk's slow row was still running
    assert sorted(written[:3]) == ["part-00001", "part-00002", "part-00003"]
    assert written[3:] == ["part-00000"]
    assert "7/7" in capsys.readouterr().err  # the bar counted every row
    assert db["status"].tolist()[4] == "failed: RuntimeError: unlucky design"
    assert db["double"].tolist()[:4] == [2.0, 4.0, 6.0, 8.0]
    pd.testing.assert_frame_equal(db, serial, check_exact=True)
    a, b = _chunk_files(tmp_path / "dask"), _chunk_files(tmp_path / "serial")
    assert list(a) == list(b) == [f"part-0000{k}" for k in range(4)]
    for name in a:
        pd.testing.assert_frame_equal(a[name], b[name], check_exact=True)


def test_interrupted_dask_build_resumes_without_duplicates(address, miura, tmp_path, monkeypatch):
    sc, _ = miura
    designs = sample_designs(sc, 7, seed=1)
    serial = store.build_database(sc, designs, tmp_path / "serial", chunk_size=2)
    started = []

    @contextmanager
    def fake_local(scheduler, workers):  # stands in for starting a LocalCluster
        started.append((scheduler, workers))
        yield address

    monkeypatch.setattr(store, "dask_scheduler", fake_local)
    monkeypatch.setattr(runner, "_evaluate_one", _recording_evaluate_one)
    EVALUATED.clear()
    db_dir = tmp_path / "db"
    written = _record_writes(monkeypatch, fail_at=3)  # Ctrl-C when a third chunk is complete
    with pytest.raises(KeyboardInterrupt):
        store.build_database(sc, designs, db_dir, chunk_size=2, scheduler="local", workers=3)
    assert len(written) == 2
    assert sorted(p.name[:10] for p in (db_dir / "chunks").iterdir()) == sorted(written)
    assert not (db_dir / "database.parquet").exists()
    assert len(EVALUATED) <= 7  # every row submitted once
    first_run = set(written)
    with distributed.Client(address, set_as_default=False) as client:  # nothing left running
        end = time.monotonic() + 120  # a hang bound: the tasks are cancelled at once
        while time.monotonic() < end:
            if not client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks)):
                break
            time.sleep(0.1)
        assert not client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks))
    EVALUATED.clear()
    written.clear()
    db = store.build_database(sc, designs, db_dir, chunk_size=2, scheduler="local", workers=3)
    assert started == [("local", 3), ("local", 3)]  # one cluster per run, not per chunk
    assert sorted(_chunk_files(db_dir)) == [f"part-0000{k}" for k in range(4)]
    rest = [k for k in range(4) if f"part-0000{k}" not in first_run]
    assert sorted(written) == [f"part-0000{k}" for k in rest]  # only the missing ones
    rows = runner.validate_designs(sc, designs).rows
    want = [tuple(sorted(rows[i].items())) for k in rest for i in range(2 * k, min(7, 2 * k + 2))]
    assert sorted(EVALUATED) == sorted(want)  # only the missing chunks' rows, each once
    assert list(db["sample"]) == list(range(7))
    pd.testing.assert_frame_equal(db, serial, check_exact=True)
    resumed = _chunk_files(db_dir)
    for name, part in _chunk_files(tmp_path / "serial").items():
        pd.testing.assert_frame_equal(resumed[name], part)


def test_cli_scheduler_flag(address, miura, tmp_path, capsys):
    sc, d = miura
    src, out = tmp_path / "designs.csv", tmp_path / "out.csv"
    d.to_csv(src, index=False)
    assert main(["evaluate", "single-miura", str(src), "-o", str(out), "--scheduler", address]) == 0
    res = pd.read_csv(out)
    ref = evaluate_designs(sc, d).reset_index(drop=True)
    assert list(res["sample"]) == [3, 0, 5, 1, 4, 2]
    assert np.allclose(res["axialstiff60"], ref["axialstiff60"], rtol=1e-11, atol=0)
    assert "6 converged" in capsys.readouterr().out
    gen = tmp_path / "gen"
    argv = ["generate", "single-miura", "-n", "4", "-o", str(gen), "--chunk-size", "3"]
    assert main([*argv, "--scheduler", address]) == 0
    db = pd.read_parquet(gen / "database.parquet")
    assert list(db["sample"]) == [0, 1, 2, 3] and (db["status"] == "converged").all()
    bad = tmp_path / "bad"
    assert main(["generate", "single-miura", "-n", "4", "-o", str(bad), "--scheduler", "x"]) == 2
    assert "Dask scheduler 'x' is not an address" in capsys.readouterr().err
    assert not bad.exists()
    rules = tmp_path / "rules.json"
    box = {"tcrease": {"gt": None, "le": 0.6e-3}, "tpanel": {"gt": None, "le": 1.2e-3}}
    rules.write_text(json.dumps([{"rule": "soft", "bounds": box}]))
    argv = ["verify", "single-miura", "--rules", str(rules), "--target", "axialstiff60 < 6000"]
    for extra, folder in (([], "v1"), (["--scheduler", address], "v2")):
        assert main([*argv, "-n", "4", "-o", str(tmp_path / folder), *extra]) == 0
    v1, v2 = (pd.read_csv(tmp_path / f / "verify_rule1.csv") for f in ("v1", "v2"))
    pd.testing.assert_frame_equal(v1, v2)
    assert (v2["status"] == "converged").all()


def test_worker_settings_of_the_commands(monkeypatch):
    from argparse import Namespace

    from holofold.cli._parallel import parallel_settings

    def ps(workers, scheduler):
        return parallel_settings(Namespace(workers=workers, scheduler=scheduler))

    assert ps(None, None) == (1, None)
    assert ps(3, None) == (3, None)
    assert ps(None, "local") == (-1, "local")  # a local cluster: one process per core
    assert ps(1, " LOCAL ") == (1, "local")  # exactly one when asked
    assert ps(None, "tcp://10.0.0.5:8786") == (1, "tcp://10.0.0.5:8786")
    with pytest.raises(ValueError, match="--workers 4: the Dask cluster at tcp://10.0.0.5:8786"):
        ps(4, "tcp://10.0.0.5:8786")
    with pytest.raises(ValueError, match="--workers 0: must be >= 1"):
        ps(0, None)
    # the local cluster gets that many processes
    seen = {}

    class FakeCluster:
        scheduler_address = "tcp://127.0.0.1:1"

        def __init__(self, n_workers, **kw):
            seen["n"] = n_workers
            seen["kw"] = kw

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

    import distributed
    import joblib

    monkeypatch.setattr(distributed, "LocalCluster", FakeCluster)
    for workers, n in ((1, 1), (3, 3), (-1, joblib.cpu_count())):
        with runner.dask_scheduler("local", workers) as address:
            assert address == "tcp://127.0.0.1:1" and seen["n"] == n
            # nothing listens beyond this machine: scheduler, workers and dashboard on loopback
            assert seen["kw"]["host"] == "127.0.0.1"
            assert seen["kw"]["dashboard_address"].startswith("127.0.0.1:")


def test_cli_refuses_workers_with_a_remote_scheduler(miura, tmp_path, capsys):
    designs = tmp_path / "d.csv"
    miura[1].to_csv(designs, index=False)
    argv = ["evaluate", "single-miura", str(designs), "-o", str(tmp_path / "r.csv")]
    assert main([*argv, "--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"]) == 2
    assert "has its own workers" in capsys.readouterr().err
    assert not (tmp_path / "r.csv").exists()
