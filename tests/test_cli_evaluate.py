"""``holofold evaluate``: file formats, validation before output, exit status."""

from __future__ import annotations

import logging
import shutil

import numpy as np
import pandas as pd
import pytest

from holofold.cli import main

FEATS = ["tcrease", "tpanel", "W", "gama"]
PERF = ["axialstiff30", "axialstiff60", "axialstiff90"]


@pytest.fixture()
def data0(reference_data):
    return reference_data.load("data0_SingleMiura").iloc[:3]


def test_csv_in_csv_out(tmp_path, data0, capsys):
    src = tmp_path / "designs.csv"
    data0[FEATS].assign(label=["a", "b", "c"]).to_csv(src, index=False)
    out = tmp_path / "results.csv"
    assert main(["evaluate", "single-miura", str(src), "-o", str(out)]) == 0
    res = pd.read_csv(out)
    assert res.columns.tolist() == FEATS + ["label"] + PERF + ["status", "state", "reason"]
    assert res["label"].tolist() == ["a", "b", "c"]
    assert np.allclose(res[PERF].to_numpy(), data0[PERF].to_numpy(), rtol=1e-4)
    assert (res["status"] == "converged").all()
    assert "3 design(s) evaluated" in capsys.readouterr().out
    # the command leaves the library's logging alone (in-process callers still get warnings)
    assert logging.getLogger("holofold.design.database.runner").level == logging.NOTSET


def test_parquet_in_parquet_out(tmp_path, data0):
    src = tmp_path / "designs.parquet"
    data0[FEATS].to_parquet(src)
    out = tmp_path / "results.parquet"
    assert main(["evaluate", "single-miura", str(src), "-o", str(out), "--workers", "2"]) == 0
    res = pd.read_parquet(out)
    assert np.allclose(res[PERF].to_numpy(), data0[PERF].to_numpy(), rtol=1e-4)


def test_published_txt_with_feature_names(tmp_path, reference_data):
    src = reference_data.path("data0_SingleMiura")
    lines = src.read_text().splitlines()[:2]
    txt = tmp_path / "data0_mine.txt"
    txt.write_text("\n".join(lines) + "\n")
    shutil.copy(src.with_name("data0_FeatureName.txt"), tmp_path / "data0_FeatureName.txt")
    out = tmp_path / "r.csv"
    assert main(["evaluate", "single-miura", str(txt), "-o", str(out)]) == 0
    res = pd.read_csv(out)
    ref = np.array([[float(v) for v in ln.split(",")] for ln in lines])
    assert np.allclose(res[PERF].to_numpy(), ref[:, 4:], rtol=1e-4)
    # without the names file: a clear error and no output
    (tmp_path / "data0_FeatureName.txt").unlink()
    out2 = tmp_path / "r2.csv"
    assert main(["evaluate", "single-miura", str(txt), "-o", str(out2)]) == 2
    assert not out2.exists()


def test_invalid_rows_write_nothing(tmp_path, capsys):
    src = tmp_path / "bad.csv"
    pd.DataFrame(
        {
            "tcrease": [7e-4, 7e-4, -1e-3],
            "tpanel": [3e-3] * 3,
            "W": [2e-3] * 3,
            "gama": [1.1, 3.0, 1.1],
        }  # fmt: skip
    ).to_csv(src, index=False)
    out = tmp_path / "out.csv"
    assert main(["evaluate", "single-miura", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "row 2: gama" in err and "row 3: tcrease" in err
    assert not out.exists()


def test_missing_column_and_bad_paths(tmp_path, capsys):
    src = tmp_path / "d.csv"
    pd.DataFrame({"tcrease": [7e-4]}).to_csv(src, index=False)
    out = tmp_path / "o.csv"
    assert main(["evaluate", "single-miura", str(src), "-o", str(out)]) == 2
    assert "missing column" in capsys.readouterr().err
    assert main(["evaluate", "single-miura", str(src), "-o", str(tmp_path / "o.xlsx")]) == 2
    assert "unknown extension" in capsys.readouterr().err
    assert main(["evaluate", "arch", str(tmp_path / "none.csv"), "-o", str(out)]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not out.exists()


def test_out_of_range_warns_but_runs(tmp_path, capsys):
    src = tmp_path / "d.csv"
    pd.DataFrame({"tcrease": [1.2e-3], "tpanel": [3e-3], "W": [2e-3], "gama": [1.1]}).to_csv(
        src, index=False
    )
    out = tmp_path / "o.csv"
    assert main(["evaluate", "single-miura", str(src), "-o", str(out)]) == 0
    assert "outside the paper's sampling range" in capsys.readouterr().err
    assert pd.read_csv(out)["status"].tolist() == ["converged"]
