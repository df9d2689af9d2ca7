"""Per-row isolation (issue 15, section 5): invalid rows skipped as failed rows, a time limit
per row, on the Python API and the evaluate / generate / verify commands."""

from __future__ import annotations

import functools
import json
import math
import threading
import time

import numpy as np
import pandas as pd
import pytest

from holofold.cli import main
from holofold.design import (
    DesignTableError,
    RowTimeout,
    evaluate_designs,
    generate_database,
    get_scenario,
    load_scenario,
    resolve_row_timeout,
    sample_designs,
    verify_rule,
)
from holofold.design.database.row_limits import call_with_limit
from holofold.design.database.store import build_database
from holofold.design.scenarios import Column, Scenario
from holofold.design.scenarios.base import ROW_TIMEOUTS
from holofold.mechanics.status import failed_mask

pytestmark = pytest.mark.processes  # worker processes and row time limits
TIMEOUT = "failed: timeout"


def _spin(seconds: float) -> None:
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:  # Python bytecodes: interruptible
        pass


def _toy_evaluate(row):
    if row["a"] == 7:
        _spin(30.0)  # a hanging row
    return {"double": 2 * row["a"], "status": "converged"}


def _toy_check(row):
    return [] if row["a"] <= 8 else [f"a = {row['a']:g} must be <= 8"]


#: a toy scenario: doubles a, refuses a > 8, hangs at a = 7
TOY = Scenario("toy", "doubles a; refuses a > 8", (Column("a", "m", "a length", 1.0, 10.0),),
               (Column("double", "m", "2 a"),), _toy_check, _toy_evaluate)  # fmt: skip


@pytest.fixture(scope="module")
def miura():
    sc = get_scenario("single-miura")
    return sc, sample_designs(sc, 6, seed=11).drop(columns="sample")


def _with_invalid_rows(designs: pd.DataFrame) -> pd.DataFrame:
    bad = designs.astype(object)
    bad.loc[1, "gama"] = "abc"  # non-numeric
    bad.loc[3, "tcrease"] = -1e-3  # out of the physical range
    bad.loc[4, "tpanel"] = np.inf  # non-finite
    return bad


def _same(a: pd.DataFrame, b: pd.DataFrame) -> None:
    for c in ("status", "state", "reason"):
        assert a[c].tolist() == b[c].tolist()
    for c in a.columns.drop(["status", "state", "reason"]):
        x, y = a[c].to_numpy(dtype=float), b[c].to_numpy(dtype=float)
        assert np.array_equal(x, y, equal_nan=True), c


# ---------------------------------------------------------------------------- invalid rows
def test_skip_records_invalid_rows_in_place_and_simulates_the_rest(miura):
    sc, designs = miura
    table = _with_invalid_rows(designs)
    with pytest.warns(UserWarning, match=r"3 of 6 row\(s\) invalid.*first: row 2: gama"):
        res = evaluate_designs(sc, table, on_invalid="skip")
    assert len(res) == 6 and list(res.index) == list(table.index)
    status = res["status"].tolist()
    assert status[1] == "failed: invalid design: gama = 'abc' is not a number"
    assert status[3] == "failed: invalid design: tcrease = -0.001 must be a finite value > 0"
    assert status[4] == "failed: invalid design: tpanel is infinite"
    assert res.loc[[1, 3, 4], sc.performance_names].isna().all().all()
    valid = [0, 2, 5]
    alone = evaluate_designs(sc, designs.iloc[valid])  # the valid rows on their own
    cols = [*sc.performance_names, "status", "state", "reason"]
    _same(res.loc[valid, cols], alone[cols])


def test_fail_keeps_refusing_the_table():
    calls = []
    sc = Scenario(**{**TOY.__dict__, "evaluate": lambda r: calls.append(r) or {}})
    df = pd.DataFrame({"a": [1.0, 9.0, "x", 2.0]})
    with pytest.raises(DesignTableError, match="2 invalid row") as exc:
        evaluate_designs(sc, df)
    assert "row 2: a = 9 must be <= 8" in str(exc.value)
    assert "--on-invalid skip" in str(exc.value)
    assert calls == []
    with pytest.raises(ValueError, match="on_invalid"):
        evaluate_designs(TOY, df, on_invalid="ignore")
    with pytest.raises(DesignTableError, match="missing column"):  # never skipped
        evaluate_designs(TOY, pd.DataFrame({"b": [1.0]}), on_invalid="skip")


def test_verify_rule_skips_refused_fresh_designs():
    bounds = {"a": {"gt": 4.0, "le": None}}  # half of (4, 10] is refused (a > 8)
    with pytest.raises(DesignTableError):
        verify_rule(TOY, bounds, "double > 12", 20, seed=1, on_invalid="fail", row_timeout=0)
    with pytest.warns(UserWarning, match="invalid"):  # skip: the default for sampled designs
        v = verify_rule(TOY, bounds, "double > 12", 20, seed=1, row_timeout=0)
    refused = (v.designs["a"] > 8).to_numpy()
    assert refused.any() and v.n_failed == refused.sum() and v.n_ok == 20 - refused.sum()
    assert v.designs["status"][refused].str.startswith("failed: invalid design: a = ").all()
    assert v.n_meeting == ((v.designs["a"] > 6) & ~refused).sum()


# ---------------------------------------------------------------------------- time limit
def test_row_timeout_settings():
    assert get_scenario("single-miura").row_timeout == 60
    assert get_scenario("arch").row_timeout == 60
    assert get_scenario("canopy").row_timeout == ROW_TIMEOUTS["sheet"] == 300
    assert get_scenario("gripper").row_timeout == get_scenario("gripper-converged").row_timeout
    assert get_scenario("gripper").row_timeout == 120
    assert TOY.row_timeout == ROW_TIMEOUTS[""]
    assert resolve_row_timeout(60.0) == 60.0
    assert resolve_row_timeout(60.0, 2) == 2.0
    for off in (0, "none", "inf", math.inf):
        assert resolve_row_timeout(60.0, off) is None
    for bad in (-1, "soon", math.nan, True):
        with pytest.raises(ValueError, match="row_timeout"):
            resolve_row_timeout(60.0, bad)


def test_limit_interrupts_python_code_in_any_thread(monkeypatch):
    import holofold.design.database.row_limits as row_limits

    # a 60 s spin (a hang bound): only the watchdog's exception ends it with RowTimeout
    with pytest.raises(RowTimeout):
        call_with_limit(0.05, _spin, 60.0)
    assert call_with_limit(60.0, sum, [1, 2]) == 3
    # one C call the watchdog cannot cut short (acquiring a lock): it blocks until the watchdog
    # has fired (an event, not a clock; 60 s a hang bound), runs to its end, and still counts
    # as late
    fired, gate, real = threading.Event(), threading.Lock(), row_limits._raise_in
    gate.acquire()

    def raise_in(thread_id, exc_type):
        real(thread_id, exc_type)
        if exc_type is not None:
            fired.set()
            gate.release()

    monkeypatch.setattr(row_limits, "_raise_in", raise_in)
    with pytest.raises(RowTimeout):
        call_with_limit(0.02, functools.partial(gate.acquire, True, 60.0))
    assert fired.is_set() and gate.locked()  # the acquire got the gate the watchdog released
    monkeypatch.setattr(row_limits, "_raise_in", real)
    _spin(0.05)  # and nothing arrives afterwards
    caught = []

    def in_thread():
        try:
            call_with_limit(0.05, _spin, 60.0)
        except RowTimeout:
            caught.append(True)

    threads = [threading.Thread(target=in_thread) for _ in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(120.0)  # a hang bound
    assert caught == [True, True]
    _spin(0.1)  # nothing arrives after the call has returned


def test_a_hanging_row_times_out_and_the_run_goes_on():
    res = evaluate_designs(TOY, pd.DataFrame({"a": [1.0, 7.0, 2.0]}), row_timeout=0.2)
    assert res["status"].tolist() == ["converged", "failed: timeout after 0.2 s (row_timeout)",
                                      "converged"]  # fmt: skip
    assert res["double"].tolist()[::2] == [2.0, 4.0] and np.isnan(res["double"][1])


@pytest.mark.parametrize("workers", [1, 2])
def test_tiny_limit_times_out_every_row_and_leaves_results_unchanged(miura, workers):
    sc, designs = miura
    res = evaluate_designs(sc, designs, workers=workers, row_timeout=1e-7)
    assert len(res) == len(designs)
    assert res["status"].str.startswith(TIMEOUT).all()
    assert res[sc.performance_names].isna().all().all()
    # an interrupted row leaves nothing behind: the same rows again, with and without limit
    _same(evaluate_designs(sc, designs, workers=workers),
          evaluate_designs(sc, designs, workers=workers, row_timeout=0))  # fmt: skip


def test_batched_rows_time_out_one_by_one():
    sc = load_scenario("arch")
    designs = sample_designs(sc, 3, seed=2, fixed={"m": 8})
    res = evaluate_designs(sc, designs, row_timeout=1e-7)
    assert res["status"].str.startswith(TIMEOUT).all()
    ok = evaluate_designs(sc, designs, on_invalid="skip")  # the default limit: no timeout
    assert (ok["status"] == "converged").all()


# ---------------------------------------------------------------------------- databases
def test_resume_of_a_generate_with_timeouts_duplicates_nothing(tmp_path):
    folder = tmp_path / "db"
    first = generate_database("single-miura", 6, folder, chunk_size=2, row_timeout=1e-7)
    assert first["status"].str.startswith(TIMEOUT).all()
    chunks = sorted((folder / "chunks").glob("part-*.parquet"))
    assert len(chunks) == 3
    chunks[1].unlink()  # as if the run had stopped before writing chunk 1
    (folder / "database.parquet").unlink()
    again = generate_database("single-miura", 6, folder, chunk_size=2, workers=2)
    assert again["sample"].tolist() == list(range(6))
    assert again["status"].tolist()[2:4] == ["converged"] * 2  # simulated again
    timed_out = again["status"].str.startswith(TIMEOUT)
    assert timed_out.tolist() == [True, True, False, False, True, True]  # kept from the disk


def test_generate_skips_designs_the_check_refuses(tmp_path, capsys):
    out = tmp_path / "db"
    argv = ["generate", "arch", "-n", "4", "--range", "m=4,5", "--seed", "2", "-o", str(out),
            "--chunk-size", "2"]  # fmt: skip
    assert main([*argv, "--on-invalid", "fail"]) == 2
    assert "must be even" in capsys.readouterr().err
    assert main(argv) == 0  # skip: the default of a command that samples its own designs
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "row(s) invalid, recorded as failed" in err
    db = pd.read_parquet(out / "database.parquet")
    odd = db["m"] == 5
    assert 0 < odd.sum() < 4 and len(db) == 4
    assert db["status"][odd].str.startswith("failed: invalid design: m = 5 must be even").all()
    assert (db["status"][~odd] == "converged").all()


# ---------------------------------------------------------------------------- command line
def test_evaluate_command_flags(tmp_path, capsys, miura):
    sc, designs = miura
    src, out = tmp_path / "d.csv", tmp_path / "r.csv"
    _with_invalid_rows(designs).to_csv(src, index=False)
    assert main(["evaluate", "single-miura", str(src), "-o", str(out)]) == 2
    assert not out.exists()
    capsys.readouterr()
    assert main(["evaluate", "single-miura", str(src), "-o", str(out), "--on-invalid", "skip",
                 "--row-timeout", "none"]) == 0  # fmt: skip
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and "3 of 6 row(s) invalid" in captured.err
    assert "3 converged" in captured.out and "3 failed" in captured.out
    res = pd.read_csv(out)
    assert len(res) == 6 and failed_mask(res["status"]).tolist() == [0, 1, 0, 1, 1, 0]
    assert main(["evaluate", "single-miura", str(src), "-o", str(out), "--on-invalid", "skip",
                 "--row-timeout", "1e-7", "--workers", "2"]) == 0  # fmt: skip
    assert pd.read_csv(out)["status"].str.startswith("failed:").all()
    for bad in ("-3", "soon"):
        assert main(["evaluate", "single-miura", str(src), "-o", str(out),
                     "--row-timeout", bad]) == 2  # fmt: skip
        assert "--row-timeout" in capsys.readouterr().err


def test_verify_command_with_row_timeout(tmp_path, capsys):
    rules = tmp_path / "rules.json"
    rules.write_text(json.dumps([{"rule": "any", "bounds": {"gama": {"gt": 1.0, "le": None}}}]))
    argv = ["verify", "single-miura", "--rules", str(rules), "--target", "axialstiff60 < 6000",
            "-n", "3", "--row-timeout", "1e-7", "--on-invalid", "skip"]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr().out
    # a design past its time limit is not verified to meet the target: it counts against it
    assert "meeting the target: 0/3 = 0.000 (95 % CI 0.000-0.561; 3 failed, counted as not" in out
    assert json.loads(out.splitlines()[-1]) == [{"rank": 1, "precision": 0.0, "simulated": 0}]


@pytest.mark.slow
def test_timeout_and_skip_on_dask_worker_threads(tmp_path):
    distributed = pytest.importorskip("distributed")
    df = pd.DataFrame({"a": [7.0, 1.0, 9.0, 2.0, 9.0], "sample": range(5)})
    expected = ["failed: timeout after 0.2 s (row_timeout)", "converged",
                "failed: invalid design: a = 9 must be <= 8", "converged",
                "failed: invalid design: a = 9 must be <= 8"]  # fmt: skip
    threads = dict(processes=False, n_workers=1, threads_per_worker=2, protocol="tcp://")
    with distributed.LocalCluster(**threads, dashboard_address=":0") as cluster:
        address = cluster.scheduler_address
        res = evaluate_designs(TOY, df, scheduler=address, row_timeout=0.2, on_invalid="skip",
                               log_warnings=False)  # fmt: skip
        assert res["status"].tolist() == expected
        with pytest.warns(UserWarning, match=r"2 of 5 row\(s\) invalid"):
            db = build_database(TOY, df, tmp_path / "db", chunk_size=2, scheduler=address,
                                on_invalid="skip", row_timeout=0.2)  # fmt: skip
    assert db["status"].tolist() == expected and db["sample"].tolist() == list(range(5))
