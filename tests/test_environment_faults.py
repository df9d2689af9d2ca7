"""Environment faults stop the run and never become rows (issue 23 item 2); typed row status
(state, reason) with old databases migrated on read (issue 24 item 6)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from holofold.cli import main
from holofold.design import (
    Column,
    Scenario,
    as_environment_fault,
    build_database,
    evaluate_designs,
    generate_database,
    load_database,
    with_state,
)
from holofold.design.database.store import write_chunk
from holofold.geometry import EnvironmentFault
from holofold.mechanics import CONVERGED, Status

NUMBA = "failed: ModuleNotFoundError: No module named 'numba'"


def _broken(row):
    if row["a"] > 0.5:
        raise ModuleNotFoundError("No module named 'numba'", name="numba")
    return {"y": row["a"], "status": CONVERGED}


def _singular(row):
    if row["a"] > 0.5:
        raise RuntimeError("singular tangent")  # the design's own failure: a row
    return {"y": row["a"], "status": CONVERGED}


def _scenario(fn):
    return Scenario(name="toy", description="", check=lambda row: [], evaluate=fn,
                    features=(Column("a", "-", "", 0.0, 1.0),),
                    performance=(Column("y", "-"),))  # fmt: skip


@pytest.mark.parametrize(
    ("exc", "words"),
    [(ModuleNotFoundError("No module named 'numba'", name="numba"), "pip install numba"),
     (ImportError("libfoo.so: cannot open shared object file"), "install or repair"),
     (OSError("libllvmlite.so: cannot open shared object file"), "reinstall the package"),
     (MemoryError(), "out of memory"),
     (EnvironmentFault("numba is broken: reinstall it"), "reinstall it")],
)  # fmt: skip
def test_environment_faults_are_told_apart_from_a_designs_own_failure(exc, words):
    fault = as_environment_fault(exc, "row 3 of arch")
    assert isinstance(fault, EnvironmentFault) and words in str(fault)
    assert "\n" not in str(fault)
    for own in (
        RuntimeError("singular tangent"),
        ValueError("invalid design"),
        ZeroDivisionError(),
    ):
        assert as_environment_fault(own) is None


def test_an_environment_fault_stops_the_run_before_more_rows_and_is_never_stored(tmp_path):
    designs = pd.DataFrame({"a": [0.1, 0.2, 0.9, 0.3, 0.4, 0.6]})
    with pytest.raises(EnvironmentFault, match=r"No module named 'numba'; install or repair numba"):
        evaluate_designs(_scenario(_broken), designs)
    with pytest.raises(EnvironmentFault):
        build_database(_scenario(_broken), designs, tmp_path / "db", chunk_size=2)
    chunks = sorted((tmp_path / "db" / "chunks").glob("part-*.parquet"))
    assert len(chunks) == 1  # rows 0-1 done; the chunk of the fault never written
    assert (pd.read_parquet(chunks[0])["state"] == "converged").all()
    # the design's own failure is a row, and the run goes on
    db = build_database(_scenario(_singular), designs, tmp_path / "own", chunk_size=2)
    assert db["state"].tolist() == ["converged"] * 2 + ["failed", "converged"] * 1 + [
        "converged",
        "failed",
    ]
    assert db.loc[2, "reason"] == "RuntimeError: singular tangent"
    assert db.loc[2, "status"] == "failed: RuntimeError: singular tangent"


def test_the_command_line_stops_in_one_line_with_cause_and_fix(tmp_path, capsys, monkeypatch):
    import holofold.design.scenarios.strip as strip

    def no_numba(*args, **kwargs):
        raise ModuleNotFoundError("No module named 'numba'", name="numba")

    monkeypatch.setattr(strip, "secant_stiffness_batch", no_numba)
    out = tmp_path / "db"
    code = main(["generate", "arch", "-n", "5", "-o", str(out), "--chunk-size", "5"])
    err = capsys.readouterr().err
    assert code == 3 and err.count("\n") == 1, err
    assert "environment fault while simulating a design of arch" in err
    assert "pip install numba" in err and "run the same command again to resume" in err
    assert not list((out / "chunks").glob("part-*"))  # nothing stored


def _old_format(db, rows, status):
    """Rewrite the chunks of ``db`` as an older version stored them: ``status`` text only,
    ``rows`` failed with ``status``."""
    for p in sorted((db / "chunks").glob("part-*.parquet")):
        k = int(p.name[5:10])
        frame = pd.read_parquet(p).drop(columns=["state", "reason"])
        for i in range(len(frame)):
            if k * 3 + i in rows:
                frame.loc[i, ["axialstiff30", "axialstiff60", "axialstiff90"]] = np.nan
                frame.loc[i, "status"] = status
        p.unlink()
        write_chunk(frame, db / "chunks", k)
    (db / "database.parquet").unlink()


def test_resume_simulates_again_the_rows_an_environment_fault_left_and_migrates(tmp_path):
    fresh = generate_database("single-miura", 6, tmp_path / "ref", seed=2, chunk_size=3)
    db = tmp_path / "db"
    generate_database("single-miura", 6, db, seed=2, chunk_size=3)
    _old_format(db, {1, 3, 4}, NUMBA)
    old = load_database(db)  # migrated on read: typed columns from the text
    assert old["state"].tolist() == ["converged", "failed", "converged", "failed", "failed",
                                     "converged"]  # fmt: skip
    assert old.loc[1, "reason"] == "ModuleNotFoundError: No module named 'numba'"
    with pytest.warns(UserWarning, match="simulating again 3 stored rows whose stored failure"):
        again = generate_database("single-miura", 6, db, seed=2, chunk_size=3)
    assert (again["state"] == "converged").all()
    cols = ["axialstiff30", "axialstiff60", "axialstiff90"]
    np.testing.assert_allclose(again[cols], fresh[cols], rtol=1e-12)
    assert list(again.columns) == list(fresh.columns)


def test_retry_failed_runs_the_designs_own_failures_again_on_request(tmp_path, capsys):
    db = tmp_path / "db"
    generate_database("single-miura", 6, db, seed=2, chunk_size=3)
    _old_format(db, {0, 5}, "failed: RuntimeError: singular tangent")
    kept = generate_database("single-miura", 6, db, seed=2, chunk_size=3)
    assert kept["state"].tolist().count("failed") == 2  # the design's own: kept
    argv = ["generate", "single-miura", "-n", "6", "--seed", "2", "--chunk-size", "3",
            "-o", str(db), "--retry-failed"]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr()
    assert "6 designs in" in out.out and "(0 failed)" in out.out
    assert "simulating again 2 stored failed rows" in out.err
    assert (load_database(db)["state"] == "converged").all()


def test_typed_status_columns_round_trip_and_old_text_migrates():
    statuses = [CONVERGED, Status.not_converged("Z case: 1 of 5 increments above tol"),
                Status.failed("timeout after 60 s (row_timeout)")]  # fmt: skip
    old = pd.DataFrame({"x": [1, 2, 3], "status": [str(s) for s in statuses]})
    new = with_state(old)
    assert new["state"].tolist() == ["converged", "not converged", "failed"]
    assert new["reason"].tolist() == ["", "Z case: 1 of 5 increments above tol",
                                      "timeout after 60 s (row_timeout)"]  # fmt: skip
    assert with_state(new) is new  # typed already: read as is, never parsed again
