"""Issue 34 item 6: the details a designer trips on (one warning each, verdicts that name
panel bending, closed solids as surfaces, cutter previews and layers, interrupted runs in the
time total)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from holofold.cli import main
from holofold.geometry import read_pattern
from holofold.mechanics import fold_pattern, scaled_pattern

_OS = Path(__file__).parent / "data" / "origami-simulator"


def test_fit_surface_says_the_thick_panel_overlap_once(tmp_path, capsys):
    # 10 mm panels on a 4x4 sphere cap: the flat slabs and the folded printable part both
    # overlap (2.31 % of the volume); one warning line, not one per solid
    argv = ["fit", "--surface", "sphere-cap:radius=1,rim=0.4", "--cells", "4x4",
            "--panel-thickness", "0.01", "--crease-width", "0.002",
            "--crease-thickness", "0.001", "--printable", "-o", str(tmp_path / "s")]  # fmt: skip
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.startswith("holofold fit: warning: thick panels intersect"), err
    assert err.count("\n") == 1 and err.count("thick panels intersect") == 1, err
    assert "2.31 %" in err


def _square_twist():
    p = read_pattern(_OS / "singlesquaretwist.svg")
    return scaled_pattern(p, 0.2 / float(np.ptp(p.coords[:, :2], axis=0).max()))


def test_a_stalled_fold_names_its_panel_bending():
    # the square twist with one crease flipped against its assignment cannot fold rigidly: the
    # fold stalls near 78 % with a panel bent by about 84 deg, which the note must say
    p = _square_twist()
    tgt = p.fold_angle.copy()
    first = np.flatnonzero(p.interior & (tgt != 0))[0]
    tgt[first] = -tgt[first]
    kw = {"panel_thickness": 1e-3, "crease_thickness": 0.3e-3, "crease_width": 1e-3,
          "E": 1.5e9, "nu": 0.4}  # fmt: skip
    r = fold_pattern(p, 1.0, target=tgt, time_limit=60, **kw)
    assert r.verdict == "stalls"  # the verdict set is unchanged
    bend = float(np.degrees(r.energy.panel_bend.max()))
    assert bend > 45.0
    panel = int(np.argmax(r.energy.panel_bend))
    assert f"panels bend up to {bend:.0f} deg (panel {panel})" in r.note
    # a rigid fold of the same pattern says nothing of the kind
    ok = fold_pattern(p, 1.0, **kw)
    assert ok.verdict == "folds rigidly" and "bend up to" not in ok.note


def test_a_run_stopped_by_a_signal_counts_in_the_time_total(tmp_path, monkeypatch):
    import json

    import pytest

    from holofold.design.loop import design_loop as loop
    from holofold.design.loop.design_loop import DesignLoop, run_design

    def stopped(self):  # 1.25 s of simulation, then Ctrl-C (or SIGTERM as SystemExit)
        self.state.times["database"] += 1.25
        raise KeyboardInterrupt

    monkeypatch.setattr(DesignLoop, "database", stopped)
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_design("arch", "Zstiff > 150", out, samples=20, progress=False)
    runs = json.loads((out / "runs.json").read_text())
    assert len(runs) == 1 and runs[0]["interrupted"] is True
    assert runs[0]["stages"]["database"] == pytest.approx(1.25, abs=1e-3)
    # the next run's totals include the interrupted run's seconds and count it
    t = loop._Ledger(out).timings({"database": 0.5})
    assert t.all_runs["database"] == pytest.approx(1.75, abs=2e-3) and t.runs == 2


def test_laser_cutter_files_come_with_a_visible_preview(tmp_path, capsys):
    import matplotlib.image as mpimg

    out = tmp_path / "m"
    argv = ["pattern", "miura", "--m", "4", "--n", "4", "--gamma", "60", "--ext", "0.6",
            "--size", "0.2", "--profile", "laser", "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    capsys.readouterr()
    svg = next(out.glob("*.svg"))
    assert "0.01" in svg.read_text()  # the SVG keeps the laser's hairlines
    png = next(out.glob("*_preview.png"))
    img = mpimg.imread(png)[..., :3]
    inked = (img < 0.9).any(axis=2).mean()
    assert 0.005 < inked < 0.5  # lines a viewer sees, not a blank (or black) page
    red = (img[..., 0] > 0.8) & (img[..., 1] < 0.3) & (img[..., 2] < 0.3)
    blue = (img[..., 2] > 0.8) & (img[..., 0] < 0.3) & (img[..., 1] < 0.3)
    assert red.sum() > 100 and blue.sum() > 100  # red cut outline, blue mountain scores
