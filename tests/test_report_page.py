"""The HTML report page of ``holofold design`` and its two plots; a real headless-browser check."""

from __future__ import annotations

import base64
import copy
import re
from html.parser import HTMLParser

import numpy as np
import pandas as pd
import pytest
from _browser import chromium as _chromium

from holofold.design.report.page import report_page_html, write_report_page
from holofold.design.rules import ForestRuleMiner
from holofold.design.rules.report import (
    plot_folded_design,
    plot_rule_boxes,
    plot_target_scatter,
    save_figure,
)
from holofold.design.rules.targets import parse_target
from holofold.design.scenarios import Column

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _rule(round_, rank, text, bounds, verified=None, **kw) -> dict:
    """A rule as the loop writes it: the Rule record's JSON with its round and verification."""
    n, failed, meeting = verified if verified else (None, None, None)
    out = {"round": round_, "rank": rank, "rule": text, "bounds": bounds,
           "train": {"precision": kw.get("train"), "recall": 0.5, "support": 60},
           "test": {"precision": kw.get("test"), "recall": 0.5, "support": 40},
           "verified_n": n, "verified_failed": failed, "verified_meeting": meeting}  # fmt: skip
    if kw.get("estimate") is not None:
        lo, hi = kw["estimate_95ci"]
        out["estimate"] = {"precision": kw["estimate"], "interval": [lo, hi], "rows": 60,
                           "out_of_bag_rows": 50, "held_out_rows": 10}  # fmt: skip
    return out


def make_summary() -> dict:
    """A complete summary in the shape the design loop writes (``DesignSummary.to_json``)."""
    rule0 = _rule(0, 1, "offset <= 200 mm and m in {12, 16}",
                  {"offset": {"gt": None, "le": 0.2}, "m": {"in": [12.0, 16.0]}},
                  (50, 0, 44), train=0.95, test=0.9, estimate=0.86,
                  estimate_95ci=[0.78, 0.92])  # fmt: skip
    rule0b = _rule(0, 2, "m = 8", {"m": {"in": [8.0]}}, None, train=0.9, test=0.8)
    rule1 = _rule(1, 1, "offset <= 180 mm and m in {12, 16}",
                  {"offset": {"gt": None, "le": 0.18}, "m": {"in": [12.0, 16.0]}},
                  (50, 0, 46), train=0.97, test=0.93)  # fmt: skip
    chosen = {
        "source": "best inside rule 1 of round 1",
        "features": {"m": 12.0, "offset": 0.1537},
        "performance": {"Zstiff": 140.2, "error": 0.031, "mass": 1.2},
        "status": "converged",
        "origin": "refine-1",
        "margins": {"Zstiff > 100": 0.402, "error < 0.05": -0.38, "m == 12": "inf"},
        "worst_margin": -0.38,
        "meets_target": False,
        "buildable": True,
        "objective": -0.38,
        "rule": {"round": 1, "rank": 1},
    }
    other = {**chosen, "source": "best of all simulated designs", "rule": None,
             "features": {"m": 16.0, "offset": 0.12},
             "performance": {"Zstiff": 310.0, "error": 0.02, "mass": 0.8},
             "margins": {"Zstiff > 100": 2.1, "error < 0.05": 0.6, "m == 12": "-inf"},
             "worst_margin": "-inf", "origin": "database"}  # fmt: skip
    return {
        "scenario": {
            "name": "my-arch",
            "kind": "strip",
            "description": "A strip arch fitted to a catenary <span> & loaded at its crown.",
            "source": "my_arch.toml",
            "setting": {"curve": "catenary from catenary.csv (mm), span 3 m", "E": 2e9, "nu": 0.3},
            "features": [
                {
                    "name": "m",
                    "unit": "-",
                    "display_unit": "-",
                    "description": "panels",
                    "low": None,
                    "high": None,
                    "choices": [8, 12, 16],
                },
                {
                    "name": "offset",
                    "unit": "m",
                    "display_unit": "mm",
                    "description": "crease offset",
                    "low": 0.1,
                    "high": 0.3,
                    "choices": [],
                },
            ],  # fmt: skip
            "performance": [
                {"name": "Zstiff", "unit": "N/m", "description": "vertical stiffness"},
                {"name": "error", "unit": "-", "description": "fit error"},
                {"name": "mass", "unit": "kg", "description": "mass"},
            ],
        },
        "target": "Zstiff > 100 & error < 0.05 & m == 12",
        "objective": "margin",
        "answer": "rule",
        "headline": "The design with the largest worst-case margin inside rule 1 of round 1.",
        "chosen": chosen,
        "alternatives": [other],
        "database": {
            "rows": 600,
            "failed": 2,
            "path": "database/",
            "by_origin": {"database": 500, "refine": 50, "verify": 50},
        },  # fmt: skip
        "rounds": [
            {"round": 0, "rows": 500, "failed": 2, "meeting": 80, "rules": [rule0, rule0b]},
            {"round": 1, "rows": 600, "failed": 2, "meeting": 95, "rules": [rule1]},
        ],
        "distributions": [
            {
                "name": "Zstiff",
                "unit": "N/m",
                "rows": 598,
                "failed": 2,
                "quantiles": {
                    "0%": 1.5,
                    "5%": 10.0,
                    "25%": 40.0,
                    "50%": 90.0,
                    "75%": 150.0,
                    "95%": 3600.0,
                    "100%": 12000.0,
                },
            }
        ],  # fmt: skip
        "files": {
            "fold": {"path": "files/design.fold", "label": "FOLD"},
            "printable": {"path": "files/printable.stl", "label": "printable STL"},
        },
        "images": {"design": "design.png", "rule": "rule.png", "scatter": "scatter.png"},
        "timings": {
            "this_run": {"database": 1.2, "mine": 3.1, "verify": 0.2, "refine": 0.1, "files": 1.2},
            "all_runs": {
                "database": 41.2,
                "mine": 3.1,
                "verify": 10.2,
                "refine": 30.0,
                "files": 1.2,
            },
            "runs": 3,
        },  # fmt: skip
    }


def _small_png(path, seed: int) -> bytes:
    import matplotlib.image

    rng = np.random.default_rng(seed)
    matplotlib.image.imsave(path, rng.random((8, 12, 3)))
    return path.read_bytes()


@pytest.fixture
def folder(tmp_path):
    tmp_path = tmp_path / "design"
    tmp_path.mkdir()
    for k, name in enumerate(("design.png", "rule.png", "scatter.png")):
        _small_png(tmp_path / name, k)
    (tmp_path / "files").mkdir()
    (tmp_path / "files" / "design.fold").write_text("{}")
    return tmp_path


class _Tables(HTMLParser):
    """Cell texts of every table, by class: ``{cls: [[cell, ...], ...]}``; also the hrefs."""

    def __init__(self):
        super().__init__()
        self.tables, self.hrefs, self.srcs = {}, [], []
        self._rows = self._cell = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table":
            self._rows = self.tables.setdefault(a.get("class") or "", [])
        elif tag == "tr" and self._rows is not None:
            self._rows.append([])
        elif tag in ("td", "th") and self._rows is not None:
            self._cell = []
        elif tag == "a":
            self.hrefs.append(a["href"])
        elif tag == "img":
            self.srcs.append(a["src"])

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._rows[-1].append("".join(self._cell).replace("\u00a0", " ").strip())
            self._cell = None
        elif tag == "table":
            self._rows = None


def _parse(page: str) -> _Tables:
    p = _Tables()
    p.feed(page)
    return p


def _visible(page: str) -> str:
    """The page without its embedded images (base64 may contain any letters), style and
    scripts (code, not text the reader sees)."""
    page = re.sub(r"<(style|script)[^>]*>.*?</\1>", "", page, flags=re.S)
    return re.sub(r"data:image/[a-z+]+;base64,[A-Za-z0-9+/=]*", "data:", page)


# ---- the page ------------------------------------------------------------------------------


def test_page_holds_the_design_table_and_target(folder):
    path = write_report_page(folder, make_summary())
    assert path == folder / "report.html"
    page = path.read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>")
    design = _parse(page).tables["design-table"]
    rows = {r[0]: r[1] for r in design if len(r) == 2}
    assert rows["m"] == "12"
    assert rows["offset"] == "153.7 mm"  # the display unit, labelled
    assert rows["Zstiff"] == "140.2 N/m"
    assert rows["error"] == "0.031"
    assert "Zstiff &gt; 100 &amp; error &lt; 0.05" in page
    # every condition: its value, margin and met / missed, the equality included
    for table in ("margins", "target-check"):
        m = {r[0]: r[1:] for r in _parse(page).tables[table][1:]}
        z = "Zstiff > 100 N/m"  # the threshold in the column's unit
        assert m[z][:2] == ["140.2 N/m", "+0.402 (+40.2 %)"]
        assert m[z][-1] == "met"
        assert m["error < 0.05"][1] == "-0.38 (-38.0 %)" and m["error < 0.05"][-1] == "missed"
        assert m["m == 12"] == ["12", "holds exactly", "", "met"]


def test_named_levels_read_with_their_names_in_the_design_table(folder):
    # issue 34 (validation/last_mile): the pattern and surface kinds' chosen design read
    # "thick 1", not which technique its panels use; the loop writes the levels' names into
    # design.json and the page reads them back
    from holofold.design.loop.design_loop import _scenario_summary
    from holofold.design.scenarios import Scenario
    from holofold.design.scenarios.pattern_loads import THICK_COLUMN

    sc = Scenario(name="t", description="t", check=lambda row: [], evaluate=lambda row: {},
                  features=(Column("pattern", "-", "", choices=(1.0, 2.0),
                                   names=("Miura-ori", "TMP")),
                            Column("tpanel", "m", "", 1e-3, 2e-3)),
                  performance=(Column("y", "N/m"), THICK_COLUMN))  # fmt: skip
    summary = make_summary()
    summary["scenario"] = {**summary["scenario"], **_scenario_summary(sc)}
    summary["chosen"] = {**summary["chosen"], "features": {"pattern": 2.0, "tpanel": 1.5e-3},
                         "performance": {"y": 140.2, "thick": 1.0}}  # fmt: skip
    page = write_report_page(folder, summary).read_text(encoding="utf-8")
    rows = {r[0]: r[1] for r in _parse(page).tables["design-table"] if len(r) == 2}
    assert rows["thick"] == "1 (offset)"
    assert rows["pattern"] == "2 (TMP)"
    assert rows["tpanel"] == "1.5 mm" and rows["y"] == "140.2 N/m"
    # a summary written before (no names) reads as it did
    page = write_report_page(folder, make_summary()).read_text(encoding="utf-8")
    assert {r[0]: r[1] for r in _parse(page).tables["design-table"] if len(r) == 2}["m"] == "12"


def test_the_answer_comes_first_and_says_how_it_was_found(folder):
    page = _visible(report_page_html(folder, make_summary()))
    sections = re.findall(r'<section id="([a-z]+)"', page)
    assert sections[:2] == ["answer", "alternatives"]
    assert "A verified design" in page and "inside rule 1 of round 1" in page
    s = make_summary()
    s["answer"], s["headline"] = "nearest", "No simulated design meets the target."
    s["chosen"]["rule"] = None
    nearest = _visible(report_page_html(folder, s))
    assert 'class="answer nearest"' in nearest and "No design meets the target" in nearest
    # the alternatives side by side: the chosen one first
    side = _parse(page).tables["side"]
    assert side[0][1].startswith("chosen: best inside rule 1 of round 1")
    assert side[0][2] == "best of all simulated designs"
    by = {r[0]: r[1:] for r in side[1:]}
    assert by["mass"] == ["1.2 kg", "0.8 kg"] and by["offset"] == ["153.7 mm", "120 mm"]
    assert by["rule verified precision"] == ["92.0 %", "\u2013"]


def test_page_problem_rules_and_timings(folder):
    page = report_page_html(folder, make_summary())
    t = _parse(page).tables
    features = {r[0]: r[1:] for r in t["features"][1:]}
    assert features["m"][1] == "one of 8, 12, 16"
    assert features["offset"] == ["mm", "100 mm to 300 mm", "crease offset"]
    setting = dict(r for r in t["setting-table"][1:])
    assert setting["E"] == "2×109"  # 2×10<sup>9</sup>, tags dropped
    assert setting["curve"] == "catenary from catenary.csv (mm), span 3 m"
    rules = [r for r in t["rules"] if r[0] != "round"]  # both rounds' rows, no headers
    assert rules[0] == [
        "0",
        "1",
        "offset <= 200 mm and m in {12, 16}",  # the rule in display units
        "86.0 % (78.0 % to 92.0 %)",
        "95.0 %",
        "90.0 %",
        "88.0 % (95 % interval 76.2 % to 94.4 %, n = 50)",
    ]
    assert rules[1][-1] == "not verified"
    assert rules[2][:4] == ["1", "1", "offset <= 180 mm and m in {12, 16}", "–"]  # no estimate
    assert "Round 1: best verified precision 92.0\u00a0% (rank 1), up 4.0 points from round 0" in (
        page
    )
    assert '<tr class="chosen"><td class="num">1</td>' in page  # the chosen rule highlighted
    for label in ("train precision", "held-out precision", "verified precision"):
        assert f"<th>{label}</th>" in page  # each precision labelled
    assert "Round 1: mined from 600 designs (2 failed simulations left out)" in page
    timings = {r[0]: r[1:] for r in t["timings"][1:]}
    assert t["timings"][0] == ["stage", "this run", "all 3 runs"]
    assert timings["rule mining"] == ["3.1 s", "3.1 s"]
    assert timings["total"] == ["5.8 s", "1 min 26 s"]  # 85.7 s over the three runs
    assert "600 designs simulated in this folder (base sample 500, refinement rounds 50, " in page
    dist = {r[0]: r[1:] for r in t["distributions"][1:]}
    assert dist["Zstiff"] == ["N/m", "598", "1.5", "10", "40", "90", "150", "3600", "12000"]


def test_text_is_escaped(folder):
    s = make_summary()
    s["scenario"]["name"] = "arch <b>&</b>"
    s["headline"] = "<script>alert(1)</script>"
    page = report_page_html(folder, s)
    assert "offset &lt;= 200 mm and m in {12, 16}" in page
    assert "offset <= 0.2" not in page
    assert "catenary &lt;span&gt; &amp; loaded" in page and "<span> &" not in page
    assert "<b>&</b>" not in page and "arch &lt;b&gt;&amp;&lt;/b&gt;" in page
    assert "<script>alert" not in page


def test_images_are_embedded_and_links_relative(folder):
    page = report_page_html(folder, make_summary())
    parsed = _parse(page)
    assert len(parsed.srcs) == 3
    for src, name in zip(parsed.srcs, ("design.png", "rule.png", "scatter.png"), strict=True):
        assert src.startswith("data:image/png;base64,")
        data = base64.b64decode(src.split(",", 1)[1])
        assert data.startswith(PNG_SIGNATURE) and data == (folder / name).read_bytes()
    assert 'data-images-total="3"' in page
    assert "files/design.fold" in parsed.hrefs and "files/printable.stl" in parsed.hrefs
    assert all(not h.startswith(("/", "http:", "https:", "file:")) for h in parsed.hrefs)
    # self-contained: nothing loaded from elsewhere
    assert "<link" not in page and "@import" not in page and 'src="http' not in page
    assert "(not found)" in page  # printable.stl was never written


def test_missing_parts_render_gracefully(folder):
    s = make_summary()
    for key in ("rounds", "database", "files", "images", "timings", "alternatives",
                "distributions"):  # fmt: skip
        s.pop(key)
    s["chosen"]["rule"] = None
    s["chosen"]["performance"]["error"] = None
    s["chosen"]["performance"]["mass"] = None
    s["scenario"]["description"] = None
    page = _visible(write_report_page(folder, s).read_text(encoding="utf-8"))
    assert re.search(r"\bnone\b", page, re.IGNORECASE) is None
    assert re.search(r"\bnan\b", page, re.IGNORECASE) is None
    assert "<img" not in page and 'data-images-total="0"' in page
    assert "No rules were mined" in page and "No timings were recorded." in page
    rows = {r[0]: r[1] for r in _parse(page).tables["design-table"] if len(r) == 2}
    assert rows["error"] == rows["mass"] == "\u2013"
    assert rows["Zstiff"] == "140.2 N/m"  # the unit from the scenario's columns


def test_only_round_zero_and_missing_image_files(tmp_path):
    s = make_summary()
    s["rounds"] = s["rounds"][:1]
    s["chosen"]["rule"] = {"round": 0, "rank": 1}
    for r in s["rounds"][0]["rules"]:
        r["verified_n"] = r["verified_failed"] = r["verified_meeting"] = None
    page = _visible(report_page_html(tmp_path, s))  # no image file exists in tmp_path
    assert "Round 0: best verified precision" not in page
    assert "Round 0: no rule verified." in page
    assert "<img" not in page and "picture design.png was not made" in page
    assert re.search(r"\b(none|nan)\b", page, re.IGNORECASE) is None


@pytest.mark.parametrize(
    "breakage",
    [
        lambda s: s.pop("target"),
        lambda s: s["chosen"].pop("features"),
        lambda s: s.__setitem__("scenario", "my-arch"),
        lambda s: s["chosen"].__setitem__("performance", [140.2]),
        lambda s: s["chosen"].__setitem__("rule", {"round": 7, "rank": 1}),
        lambda s: s.__setitem__("answer", "maybe"),
        lambda s: s.__setitem__("files", {"x": "../../etc/passwd"}),
        lambda s: s["rounds"][0]["rules"][0].__setitem__("verified_meeting", 51),
    ],
)
def test_a_malformed_summary_writes_nothing(folder, breakage):
    good = write_report_page(folder, make_summary()).read_bytes()
    bad = copy.deepcopy(make_summary())
    breakage(bad)
    with pytest.raises((ValueError, TypeError)):
        write_report_page(folder, bad)
    assert (folder / "report.html").read_bytes() == good  # the old page stays whole
    assert not list(folder.glob(".holofold-*"))  # and no temporary file is left


def test_a_malformed_summary_leaves_no_page(tmp_path):
    with pytest.raises(TypeError):
        write_report_page(tmp_path, ["not", "a", "summary"])
    with pytest.raises(OSError):
        write_report_page(tmp_path / "absent", make_summary())
    assert not list(tmp_path.iterdir())


def test_the_summary_round_trips_through_its_json():
    from holofold.design import DesignSummary

    s = make_summary()
    record = DesignSummary.from_json(s)
    again = DesignSummary.from_json(record.to_json())
    assert again == record
    assert record.chosen.rule.precision == pytest.approx(46 / 50)
    assert record.chosen.margins["m == 12"] == float("inf")
    assert record.alternatives[0].worst_margin == float("-inf")


# ---- the plots -----------------------------------------------------------------------------


def _database(n=400, seed=0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    return pd.DataFrame(
        {
            "offset": rng.uniform(0.1, 0.3, n),
            "m": rng.choice([8.0, 12.0, 16.0], n),
            "Zstiff": 10 ** rng.uniform(0, 4, n),
            "error": rng.uniform(0, 0.1, n),
        }
    )


def _by_label(ax, prefix):
    found = [c for c in ax.collections if c.get_label().startswith(prefix)]
    assert len(found) == 1, [c.get_label() for c in ax.collections]
    return found[0]


def test_target_scatter_colours_the_meeting_rows():
    import matplotlib.pyplot as plt

    table = _database()
    table.loc[:4, "Zstiff"] = np.nan  # failed rows: not plotted
    target = parse_target("Zstiff > 100 & offset < 0.2", table.columns)
    meets = target.evaluate(table)
    fig = plot_target_scatter(
        table,
        target,
        "offset",
        "Zstiff",
        chosen={"offset": 0.15, "Zstiff": 140.0},
        units={"offset": "m", "Zstiff": "N/m"},
    )
    ax = fig.axes[0]
    ok = np.isfinite(table["Zstiff"].to_numpy())
    hit = _by_label(ax, "meets the target")
    other = _by_label(ax, "other designs")
    star = _by_label(ax, "chosen design")
    assert 50 < meets.sum() < 250
    expected = table.loc[meets & ok, ["offset", "Zstiff"]].to_numpy()
    np.testing.assert_array_equal(hit.get_offsets(), expected)
    assert len(other.get_offsets()) == (ok & ~meets).sum() == len(table) - 5 - meets.sum()
    assert hit.get_label() == f"meets the target ({meets.sum()})"
    np.testing.assert_array_equal(star.get_offsets(), [[0.15, 140.0]])
    assert ax.get_yscale() == "log" and ax.get_xscale() == "linear"  # 4 decades vs 0.5
    assert ax.get_xlabel() == "offset [m]" and ax.get_ylabel() == "Zstiff [N/m]"
    # the thresholds: x = 0.2 vertical, y = 100 horizontal, both dashed
    lines = {(tuple(ln.get_xdata()), tuple(ln.get_ydata())) for ln in ax.lines}
    assert ((0.2, 0.2), (0, 1)) in lines and ((0, 1), (100.0, 100.0)) in lines
    assert all(ln.get_linestyle() == "--" for ln in ax.lines)
    plt.close(fig)


def test_target_scatter_without_simple_thresholds():
    import matplotlib.pyplot as plt

    table = _database()
    table.loc[0, "error"] = 0.0
    fig = plot_target_scatter(table, "Zstiff > 3000 | error < 0.01", "offset", "error")
    ax = fig.axes[0]
    expected = (table["Zstiff"] > 3000) | (table["error"] < 0.01)
    assert len(_by_label(ax, "meets the target").get_offsets()) == expected.sum()
    assert not ax.lines  # an or-target has no single threshold per axis
    assert ax.get_yscale() == "linear"  # an error of 0: no log
    assert ax.get_xlabel() == "offset"
    plt.close(fig)
    with pytest.raises(ValueError, match="width"):
        plot_target_scatter(table, "Zstiff > 1", "width", "error")


def _arch(n=25, radius=1.2, width=0.15):
    """A half-circle strip in the x-z plane, width along y: vertices (m), quads and creases."""
    s = np.linspace(0.0, np.pi, n)
    front = np.column_stack([radius * np.cos(s), np.zeros(n), 0.4 + radius * np.sin(s)])
    back = front + [0.0, width, 0.0]
    vertices = np.vstack([front, back])
    faces = [[i, i + 1, n + i + 1, n + i] for i in range(n - 1)]
    creases = np.array([[i, n + i] for i in range(1, n - 1)])
    return vertices, faces, creases


def test_folded_design_axes_cover_the_vertices_in_mm():
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    vertices, faces, creases = _arch()
    triangles = [[0, 1, 26]] + faces[1:]  # a triangle among the quads
    fig = plot_folded_design(vertices, triangles, creases=creases, title="arch m = 24")
    ax = fig.axes[0]
    mm = vertices * 1e3
    for k, lim in enumerate((ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d())):
        assert lim[0] <= mm[:, k].min() and lim[1] >= mm[:, k].max()
        assert lim[1] - lim[0] <= np.ptp(mm[:, k]) + 0.01 * np.ptp(mm, axis=0).max()  # tight
    assert (ax.get_xlim3d()[1]) > 1000  # in mm, not m
    fig.canvas.draw()  # projects the 3D collections
    panels = [c for c in ax.collections if isinstance(c, Poly3DCollection)]
    lines = [c for c in ax.collections if isinstance(c, Line3DCollection)]
    assert len(panels) == 1 and len(panels[0].get_paths()) == len(faces)
    assert len(lines) == 1 and len(lines[0].get_segments()) == len(creases)
    # equal aspect: the box's sides are in the ratio of the axis ranges (2405 : 155 : 1205 mm)
    aspect = np.asarray(ax.get_box_aspect())
    spans = np.ptp([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()], axis=1)
    np.testing.assert_allclose(aspect / aspect[0], spans / spans[0], rtol=1e-9)
    np.testing.assert_allclose(spans, np.ptp(mm, axis=0), atol=0.01 * np.ptp(mm))
    assert "mm" in ax.get_xlabel() and "mm" in ax.get_zlabel()
    assert ax.get_title() == "arch m = 24"
    # shading: the panels' colours vary with their orientation
    assert np.ptp(panels[0].get_facecolor()[:, :3].sum(axis=1)) > 0.1
    plt.close(fig)
    with pytest.raises(ValueError, match="shape"):
        plot_folded_design(vertices[:, :2], faces)


# ---- a real browser --------------------------------------------------------------------------


def _real_pictures(folder):
    """The three pictures of the page, drawn by the report's own plot functions."""
    vertices, faces, creases = _arch()
    save_figure(plot_folded_design(vertices, faces, creases=creases), folder / "design.png")
    table = _database()
    chosen = {"offset": 0.15, "Zstiff": 140.0}
    save_figure(
        plot_target_scatter(
            table,
            "Zstiff > 100 & error < 0.05",
            "offset",
            "Zstiff",
            chosen=chosen,
            units={"offset": "m", "Zstiff": "N/m"},
        ),
        folder / "scatter.png",
    )
    X = table[["offset", "m"]]
    y = parse_target("offset < 0.2 & m >= 12", X.columns).evaluate(X)
    miner = ForestRuleMiner(n_estimators=10, min_support=5, n_rules=1, random_state=0)
    miner.fit(X, y)
    offset = {"offset": Column("offset", "m", display="m")}
    save_figure(plot_rule_boxes(miner, X, 0, columns=offset), folder / "rule.png")


@pytest.mark.slow
def test_the_page_in_a_headless_browser(folder, tmp_path):
    import matplotlib.image

    _real_pictures(folder)
    page = write_report_page(folder, make_summary())
    url = page.resolve().as_uri()
    dom = _chromium(tmp_path, "--dump-dom", url).stdout
    body = re.search(r"<body([^>]*)>", dom)
    assert body, dom[:500]
    attrs = dict(re.findall(r'([\w-]+)="([^"]*)"', body.group(1)))
    assert attrs.get("data-images-total") == "3"
    assert attrs.get("data-images-loaded") == "3"  # every picture decoded
    assert '<table class="design-table">' in dom and "140.2" in dom

    shot = tmp_path / "shot.png"
    _chromium(tmp_path, f"--screenshot={shot}", "--window-size=1200,5200", url)
    pixels = matplotlib.image.imread(shot)[..., :3]
    assert pixels.shape[:2] == (5200, 1200)
    colours = np.unique((pixels * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 200  # text, tables and the three pictures
    assert pixels.std() > 0.08
    # the pictures are drawn: the scatter's red points and the arch's blue panels show
    red = (pixels[..., 0] > 0.7) & (pixels[..., 1] < 0.3) & (pixels[..., 2] < 0.3)
    blue = (pixels[..., 2] > 0.6) & (pixels[..., 0] < 0.5)
    assert red.sum() > 500 and blue.sum() > 2000


def test_no_alternatives_says_why_and_tiny_timings_read_as_such(folder):
    s = make_summary()
    s["alternatives"] = []
    s["timings"]["this_run"]["verify"] = 4.47e-05  # a resumed stage: its work was done
    page = _visible(report_page_html(folder, s))
    assert "the chosen one is the best of each verified rule and overall" in page
    timings = {r[0]: r[1:] for r in _parse(page).tables["timings"][1:]}
    assert timings["verification (new simulations inside the rule)"][0] == "< 0.01 s"
    s["answer"], s["chosen"]["rule"] = "designs", None
    page = _visible(report_page_html(folder, s))
    assert "no rule was verified, and the chosen one is the best simulated design" in page
    s["answer"] = "nearest"
    page = _visible(report_page_html(folder, s))
    assert "no simulated design meets the target; the chosen one is the nearest" in page


def test_the_grippers_picture_is_captioned_flat(folder):
    s = make_summary()
    assert "The chosen design, folded" in _visible(report_page_html(folder, s))
    s["scenario"]["kind"] = "gripper"
    page = _visible(report_page_html(folder, s))
    assert "The chosen design, flat as cut" in page and "The chosen design, folded" not in page
