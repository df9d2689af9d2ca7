"""``holofold simulate`` over many files: one JSON line per pattern, resume, time limit,
workers (design/database/pattern_batch.py, holofold/cli/simulate.py)."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

from holofold.cli import main
from holofold.design import pattern_files, recorded_files
from holofold.geometry import READERS

OS = Path(__file__).parent / "data" / "origami-simulator"
NAMES = ("simpleVertex.svg", "waterbombBase.svg", "popupSimple.svg")
FIELDS = (
    "file", "path", "sha256", "imported", "reason", "panels", "reached", "verdict", "note",
    "largest_strain", "largest_triangle_strain", "progress", "wrong_way_count", "collision",
    "seconds", "fold",
)  # fmt: skip


def _lines(path):
    return [json.loads(s) for s in Path(path).read_text().splitlines()]


@pytest.fixture(scope="module")
def patterns(tmp_path_factory):
    """A folder with the three vendored files in a subfolder and a broken SVG."""
    root = tmp_path_factory.mktemp("patterns")
    (root / "os").mkdir()
    for n in NAMES:
        shutil.copy(OS / n, root / "os" / n)
    (root / "broken.svg").write_text("<svg this is not xml")
    (root / "notes.txt").write_text("not a pattern")
    return root


@pytest.fixture(scope="module")
def batch(patterns, tmp_path_factory):
    out = tmp_path_factory.mktemp("batch") / "checks.jsonl"
    code = main(["simulate", str(patterns), "-o", str(out)])
    assert code == 0
    return out


def test_folder_searched_by_the_reader_suffixes(tmp_path):
    for k, suffix in enumerate(READERS.names()):
        (tmp_path / "a" / str(k)).mkdir(parents=True)
        (tmp_path / "a" / str(k) / f"p{suffix.upper()}").write_text("")
    (tmp_path / "a" / "x.txt").write_text("")
    found = pattern_files([tmp_path, tmp_path / "a" / "0" / f"p{READERS.names()[0].upper()}"])
    assert sorted(f.suffix.lower() for f in found) == sorted(READERS.names())  # no duplicate


def test_one_line_per_pattern_with_the_single_file_numbers(patterns, batch, tmp_path):
    recs = _lines(batch)
    assert len(recs) == 4
    by_name = {Path(r["file"]).name: r for r in recs}
    assert set(by_name) == {*NAMES, "broken.svg"}
    for r in recs:
        assert set(FIELDS) <= set(r)
        assert r["seconds"] >= 0
    bad = by_name["broken.svg"]
    assert bad["imported"] is False and "broken.svg" in bad["reason"]
    assert "\n" not in bad["reason"] and bad["verdict"] is None
    for name in NAMES:
        r = by_name[name]
        assert r["imported"] is True and r["reason"] is None
        out = tmp_path / name
        main(["simulate", str(OS / name), "-o", str(out)])
        single = json.loads((out / "simulation.json").read_text())["fold"]
        assert r["verdict"] == single["verdict"] == r["fold"]["verdict"]
        assert r["note"] == single["note"]
        assert r["reached"] == pytest.approx(single["reached"], rel=1e-9, abs=1e-12)
        assert r["progress"] == pytest.approx(single["progress"], rel=1e-9, abs=1e-12)
        assert r["largest_strain"] == pytest.approx(
            single["largest_panel_strain"], rel=1e-9, abs=1e-15
        )
        assert r["largest_triangle_strain"] == pytest.approx(
            single["largest_triangle_strain"], rel=1e-9, abs=1e-15
        )
        assert r["largest_triangle_strain"] >= r["largest_strain"] * (1 - 1e-9)
        assert r["fold"]["requested"] == 1.0
        assert r["wrong_way_count"] == len(r["fold"]["wrong_way"])
    assert by_name["simpleVertex.svg"]["panels"] == 4
    assert by_name["waterbombBase.svg"]["panels"] == 8


def test_resume_redoes_a_removed_and_a_torn_line_only(patterns, batch, tmp_path, capsys):
    out = tmp_path / "checks.jsonl"
    lines = batch.read_text().splitlines(keepends=True)
    # drop line 1, keep line 0 and 2, tear line 3 in half (a run killed mid-write)
    out.write_text(lines[0] + lines[2] + lines[3][: len(lines[3]) // 2])
    kept = {json.loads(lines[0])["path"], json.loads(lines[2])["path"]}
    assert {p for p, _ in recorded_files(out)} == kept
    assert out.read_text() == lines[0] + lines[2]  # the torn line cut off
    out.write_text(lines[0] + lines[2] + lines[3][: len(lines[3]) // 2])
    capsys.readouterr()
    assert main(["simulate", str(patterns), "-o", str(out)]) == 0
    assert "2 checked" in capsys.readouterr().out
    recs = _lines(out)
    assert len(recs) == 4 and len({r["path"] for r in recs}) == 4
    assert out.read_text().startswith(lines[0] + lines[2])
    again = {json.loads(s)["path"]: json.loads(s) for s in lines}
    for r in recs:
        assert r["verdict"] == again[r["path"]]["verdict"]
    # everything recorded: nothing run, nothing written
    before = out.read_bytes()
    assert main(["simulate", str(patterns), "-o", str(out)]) == 0
    assert out.read_bytes() == before
    assert "0 checked" in capsys.readouterr().out


def test_changed_file_is_checked_again(tmp_path):
    src = tmp_path / "p" / "waterbombBase.svg"
    src.parent.mkdir()
    shutil.copy(OS / "waterbombBase.svg", src)
    out = tmp_path / "c.jsonl"
    assert main(["simulate", str(src), "-o", str(out)]) == 0  # one file, .jsonl: batch
    src.write_text(src.read_text() + "\n")
    assert main(["simulate", str(src.parent), "-o", str(out)]) == 0
    recs = _lines(out)
    assert len(recs) == 2 and recs[0]["sha256"] != recs[1]["sha256"]


def test_time_limit_makes_failed_lines_and_the_batch_goes_on(patterns, tmp_path, capsys):
    out = tmp_path / "t.jsonl"
    # a limit no read-and-fold can meet (a record past its deadline is a timeout too)
    code = main(["simulate", str(patterns / "os"), "-o", str(out), "--time-limit", "1e-6"])
    assert code == 0
    recs = _lines(out)
    assert len(recs) == 3
    for r in recs:
        assert r["reason"] == "timeout after 1e-06 s (--time-limit)"
        assert r["verdict"] is None
    err = capsys.readouterr().err
    assert "[3/3, 3 failed]" in err


def test_usage_errors_are_one_line(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert main(["simulate", str(tmp_path / "empty"), "-o", str(tmp_path / "c.jsonl")]) == 2
    assert "no crease-pattern files" in capsys.readouterr().err
    code = main(["simulate", str(OS / NAMES[0]), str(OS / NAMES[1]), "-o",
                 str(tmp_path / "nowhere" / "c.jsonl")])  # fmt: skip
    assert code == 2
    err = capsys.readouterr().err
    assert "nowhere" in err and len(err.strip().splitlines()) == 1
    code = main(["simulate", str(OS / NAMES[0]), "-o", str(tmp_path / "out"), "--workers", "2"])
    assert code == 2
    assert not (tmp_path / "c.jsonl").exists()


@pytest.mark.processes
def test_two_workers_give_the_same_lines(patterns, batch, tmp_path):
    out = tmp_path / "w2.jsonl"
    assert main(["simulate", str(patterns), "-o", str(out), "--workers", "2"]) == 0
    one = {r["path"]: r for r in _lines(batch)}
    two = {r["path"]: r for r in _lines(out)}
    assert set(one) == set(two)
    for path, a in one.items():
        b = two[path]
        for key in ("imported", "reason", "panels", "verdict", "note", "wrong_way_count",
                    "collision", "sha256"):  # fmt: skip
            assert a[key] == b[key], (path, key)
        for key in ("reached", "progress", "largest_strain"):
            if a[key] is None:
                assert b[key] is None
            else:
                assert math.isclose(a[key], b[key], rel_tol=1e-9, abs_tol=1e-15), (path, key)


def test_a_crash_while_folding_is_a_line(monkeypatch, tmp_path):
    import holofold.mechanics.pattern_simulation as simulate

    def boom(pattern, setting):
        raise RuntimeError("solver blew up")

    monkeypatch.setattr(simulate, "simulate_pattern", boom)
    out = tmp_path / "c.jsonl"
    args = [str(OS / NAMES[0]), str(OS / NAMES[1])]
    assert main(["simulate", *args, "-o", str(out)]) == 0
    recs = _lines(out)
    assert [Path(r["file"]).name for r in recs] == list(NAMES[:2])
    for r in recs:
        assert r["imported"] is True  # read, then crashed
        assert r["reason"] == "RuntimeError: solver blew up" and r["verdict"] is None


def _dies_on_popup(path, *args):
    """check_pattern_file, except that the process dies (as a segfault would) on popupSimple."""
    import os

    from holofold.design import check_pattern_file

    if Path(path).name == "popupSimple.svg":
        os._exit(70)
    return check_pattern_file(path, *args)


@pytest.mark.processes
def test_a_worker_that_dies_takes_only_its_pattern(patterns, batch, tmp_path):
    from holofold.design import run_pattern_batch
    from holofold.mechanics import PatternSetting

    out = tmp_path / "d.jsonl"
    files = pattern_files([patterns])
    counts = run_pattern_batch(
        files, out, PatternSetting(), {"split": "as-needed"}, workers=2, check=_dies_on_popup
    )
    assert counts == {"total": 4, "skipped": 0, "checked": 4, "failed": 2}
    recs = {Path(r["file"]).name: r for r in _lines(out)}
    assert set(recs) == {*NAMES, "broken.svg"}
    assert recs["popupSimple.svg"]["reason"] == "crashed: its worker process died"
    ref = {Path(r["file"]).name: r for r in _lines(batch)}
    for name in ("simpleVertex.svg", "waterbombBase.svg"):
        assert recs[name]["verdict"] == ref[name]["verdict"]
        assert math.isclose(recs[name]["reached"], ref[name]["reached"], rel_tol=1e-9)
