"""Every output path checked writable before any work (issue 23 item 3); a complete database
resumes in a read-only folder without writing."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest

from holofold.cli import main


def _frozen(paths):
    """Make folders unwritable for whoever runs (root too): chattr +i, else chmod 0o555 for
    a user the permissions bind; returns an undo function, or skips."""
    paths = [str(p) for p in paths]
    if shutil.which("chattr"):
        r = subprocess.run(["chattr", "+i", *paths], capture_output=True)
        if r.returncode == 0:
            return lambda: subprocess.run(["chattr", "-i", *paths], check=True)
    if os.geteuid() != 0:
        for p in paths:
            os.chmod(p, 0o555)
        return lambda: [os.chmod(p, 0o755) for p in paths]
    pytest.skip("cannot make a folder read-only here (no chattr, running as root)")


@pytest.fixture
def frozen():
    undo = []
    yield lambda *paths: undo.append(_frozen(paths))
    for u in undo:
        u()


def _one_line(capsys, *words):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert ".holofold-" not in err  # never a temporary file's name
    for w in words:
        assert w in err, err
    return err


def test_evaluate_refuses_an_unwritable_output_before_simulating(tmp_path, capsys, frozen,
                                                                 monkeypatch):  # fmt: skip
    import holofold.design.database.runner as runner

    src = tmp_path / "designs.csv"
    src.write_text("tcrease,tpanel,W,gama\n8e-4,3e-3,2e-3,1.1\n")
    ro = tmp_path / "ro"
    ro.mkdir()
    frozen(ro)
    monkeypatch.setattr(runner, "iter_results", lambda *a, **k: pytest.fail("simulated"))
    assert main(["evaluate", "single-miura", str(src), "-o", str(ro / "res.csv")]) == 2
    _one_line(capsys, f"output {ro / 'res.csv'}: cannot write in {ro}")


def test_mine_refuses_unwritable_json_and_plot_before_training(tmp_path, capsys, frozen,
                                                               monkeypatch):  # fmt: skip
    import holofold.design.rules.mining as mining

    monkeypatch.setattr(mining, "mine_rules", lambda *a, **k: pytest.fail("trained"))
    ro = tmp_path / "ro"
    ro.mkdir()
    frozen(ro)
    db = os.path.join(os.environ.get("HOLOFOLD_REFERENCE_DATA", "../shared/reference-data"),
                      "data3_ShapeFit.txt")  # fmt: skip
    for opt, name in (("--json", "rules.json"), ("--plot", "rules.png")):
        assert main(["mine", db, "--target", "Zstiff > 800", opt, str(ro / name)]) == 2
        _one_line(capsys, f"{opt} {ro / name}: cannot write in {ro}")


def test_verify_and_generate_refuse_unwritable_folders_before_simulating(tmp_path, capsys,
                                                                         frozen):  # fmt: skip
    ro = tmp_path / "ro"
    ro.mkdir()
    frozen(ro)
    rules = tmp_path / "rules.json"
    rules.write_text('[{"rule": "m > 8", "bounds": {"m": {"gt": 8, "le": null}}}]')
    argv = ["verify", "arch", "--rules", str(rules), "--target", "Zstiff > 1", "-n", "2"]
    assert main([*argv, "-o", str(ro / "v")]) == 2
    _one_line(capsys, f"--output {ro / 'v'}: cannot write in {ro}")
    assert main(["generate", "arch", "-n", "2", "-o", str(ro / "db")]) == 2
    _one_line(capsys, f"{ro / 'db'}: cannot write in {ro}")
    assert main(["design", "arch", "--target", "Zstiff > 1", "-o", str(ro / "d")]) == 2
    _one_line(capsys, f"{ro / 'd'}: cannot write in {ro}")


def test_a_complete_database_resumes_in_a_read_only_folder_without_writing(tmp_path, capsys,
                                                                           frozen):  # fmt: skip
    db = tmp_path / "db"
    argv = ["generate", "single-miura", "-n", "6", "--chunk-size", "3", "-o", str(db)]
    assert main(argv) == 0
    first = capsys.readouterr().out
    before = {p: p.stat().st_mtime_ns for p in db.rglob("*")}
    frozen(db, db / "chunks")
    assert main(argv) == 0
    assert capsys.readouterr().out == first  # the same line: 6 designs, 0 failed
    assert {p: p.stat().st_mtime_ns for p in db.rglob("*")} == before  # nothing written
    # an incomplete one is refused in one line before anything is simulated
    part = tmp_path / "part"
    assert main([*argv[:-1], str(part)]) == 0
    capsys.readouterr()
    next(part.glob("chunks/part-00001-*.parquet")).unlink()
    frozen(part, part / "chunks")
    assert main([*argv[:-1], str(part)]) == 2
    _one_line(capsys, f"{part} is not writable and holds 1 of 2 chunks")
