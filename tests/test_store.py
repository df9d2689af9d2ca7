"""Sampling and the resumable chunked database."""

import numpy as np
import pandas as pd
import pytest

import holofold.design.database.store as store
from holofold.cli import main
from holofold.design.database.sampling import sample_designs
from holofold.design.scenarios import get_scenario


@pytest.fixture(scope="module")
def scen():
    return get_scenario("single-miura")


def test_random_rows_are_independent_of_n_and_start(scen):
    a = sample_designs(scen, 10, seed=3)
    b = sample_designs(scen, 4, seed=3, start=6)
    pd.testing.assert_frame_equal(a.iloc[6:].reset_index(drop=True), b)
    c = sample_designs(scen, 10, seed=4)
    assert not np.allclose(a["tpanel"], c["tpanel"])


@pytest.mark.parametrize("method", ["random", "lhs", "sobol"])
def test_samples_stay_in_the_papers_ranges(scen, method):
    d = sample_designs(scen, 64, seed=0, method=method)
    for col in scen.features:
        if col.required:
            assert d[col.name].between(col.low, col.high).all(), col.name
    if method == "lhs":  # one sample in each of the 64 strata of every feature
        strata = np.floor((d["W"] - 1e-3) / 3e-3 * 64).astype(int)
        assert sorted(strata) == list(range(64))


def test_ranges_override_and_errors(scen):
    d = sample_designs(scen, 20, seed=0, ranges={"W": (2e-3, 2.5e-3)}, fixed={"gama": 1.0})
    assert d["W"].between(2e-3, 2.5e-3).all() and (d["gama"] == 1.0).all()
    with pytest.raises(ValueError, match="unknown feature 'Wx'"):
        sample_designs(scen, 5, ranges={"Wx": (0, 1)})
    with pytest.raises(ValueError, match="method"):
        sample_designs(scen, 5, method="grid")


def test_a_range_must_match_the_kind_of_feature(capsys, tmp_path):
    arch = get_scenario("arch")  # m: categorical, choices 8, 12, 16, 24
    d = sample_designs(arch, 200, seed=0, ranges={"m": (10, 20)})  # the choices in [10, 20]
    assert set(d["m"]) == {12.0, 16.0}
    assert set(sample_designs(arch, 50, seed=0, ranges={"m": [8, 24]})["m"]) == {8.0, 24.0}
    with pytest.raises(ValueError, match=r"no choice .* lies in \[30, 40\]"):
        sample_designs(arch, 5, ranges={"m": (30, 40)})
    with pytest.raises(ValueError, match="offset is continuous; give \\(low, high\\)"):
        sample_designs(arch, 5, ranges={"offset": [0.1, 0.2]})  # used to be taken as a range
    out = tmp_path / "db"
    argv = ["generate", "arch", "-n", "2", "-o", str(out), "--range"]
    assert main([*argv, "offset=0.1,0.2"]) == 2
    assert "NAME=LOW:HIGH" in capsys.readouterr().err and not out.exists()
    assert main([*argv, "m=10:20"]) == 0  # 8:24 used to sample only 8 and 24
    assert set(pd.read_parquet(out / "database.parquet")["m"]) <= {12.0, 16.0}


def test_interrupted_build_resumes_without_duplicates(scen, tmp_path, monkeypatch):
    designs = sample_designs(scen, 7, seed=1)
    calls = []
    real = store.iter_results

    def counting(scenario, rows, **kw):
        calls.append(sum(len(t) for t in kw["tasks"]))
        if len(calls) == 2 and not hasattr(counting, "interrupted"):
            counting.interrupted = True
            raise KeyboardInterrupt
        return real(scenario, rows, **kw)

    monkeypatch.setattr(store, "iter_results", counting)
    with pytest.raises(KeyboardInterrupt):
        store.build_database(scen, designs, tmp_path / "db", chunk_size=3)
    assert len(list((tmp_path / "db" / "chunks").glob("*.parquet"))) == 1
    calls.clear()
    db = store.build_database(scen, designs, tmp_path / "db", chunk_size=3)
    assert calls == [3, 1]  # only the rows of the missing chunks (3-5, 6) were simulated
    assert list(db["sample"]) == list(range(7))
    assert (db["status"] == "converged").all()
    again = pd.read_parquet(tmp_path / "db" / "database.parquet")
    pd.testing.assert_frame_equal(db, again)
    other = sample_designs(scen, 7, seed=2)
    with pytest.raises(ValueError, match="different design table"):
        store.build_database(scen, other, tmp_path / "db", chunk_size=3)


def test_generate_command(tmp_path, capsys):
    out = tmp_path / "db"
    assert main(["generate", "single-miura", "-n", "3", "-o", str(out), "--csv"]) == 0
    db = pd.read_csv(out / "database.csv")
    assert len(db) == 3 and (db["axialstiff60"] > 0).all()
    assert "3 designs" in capsys.readouterr().out
    assert main(["generate", "single-miura", "-n", "0", "-o", str(tmp_path / "x")]) == 2
    assert not (tmp_path / "x").exists()
    assert main(["generate", "nosuch", "-n", "3", "-o", str(tmp_path / "y")]) == 2


def test_a_huge_sample_is_refused_before_any_work(scen):
    with pytest.raises(ValueError, match="core-days; at most 5,000,000"):
        sample_designs(scen, 10**9)  # refused before drawing: 10**9 rows would not fit
    with pytest.raises(ValueError, match="whole number"):
        sample_designs(scen, 2.5)


def test_generate_database_passes_exactly_build_databases_run_options_on(tmp_path):
    import inspect

    own = {"scenario", "designs", "folder", "meta", "on_invalid"}
    build = set(inspect.signature(store.build_database).parameters) - own
    assert build == store._RUN_OPTIONS
    with pytest.raises(TypeError, match="'chunksize'"):
        store.generate_database("single-miura", 4, tmp_path / "db", chunksize=2)
    assert not (tmp_path / "db").exists()  # refused before any work
