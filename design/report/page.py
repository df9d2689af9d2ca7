"""The self-contained HTML report of ``holofold design``: one page, the answer first.

:func:`write_report_page` turns the design summary (a
:class:`~holofold.design.loop.summary.DesignSummary`, or what ``design.json`` holds, validated by
it) into ``report.html``. The first screen is the answer: how the design was found, stated
honestly (a verified rule, the best simulated design, or the nearest one and what it misses),
each target condition with the chosen design's value, margin and met/missed, the part to print
(its extent, whether it fits the printer's bed and what to do if not, a print-time class), the
kind's own facts (the gripper's closed state and temperatures) and a 3D view to turn, from flat
to folded, with supports, loads and the target curve. Then the alternatives side by side, the
problem, what the designs reach, the chosen design in full, the rules of each round with their
training, held-out and verified precision labelled, the pictures (embedded PNG), the files,
and the counts and times of this run and of all runs on the folder. Values are shown in the
columns' display units (mm, um, degrees). The page loads nothing from anywhere (inline CSS and
script, no library); an inline script records how many of its images decoded
(``data-images-loaded`` on ``<body>``).
"""

from __future__ import annotations

import base64
import html
import math
import numbers
import re
from collections.abc import Mapping
from pathlib import Path
from urllib.parse import quote

from holofold.design.loop.summary import DesignSummary, Pick
from holofold.design.report.view import view_css, view_html
from holofold.design.rules.targets import TargetError, parse_target
from holofold.design.scenarios import Column, format_value
from holofold.geometry.outputs import check_output_path, write_text

__all__ = ["write_report_page", "report_page_html"]

_MISSING = "\u2013"  # en dash: a value that is absent or not finite

_MIME = {
    ".png": "image/png",
    ".jpg": "image/jpeg",
    ".jpeg": "image/jpeg",
    ".gif": "image/gif",
    ".svg": "image/svg+xml",
}

_CAPTIONS = {
    "design": "The chosen design, folded (coordinates in mm; creases in red).",
    "rule": "The chosen rule as a box chart: each feature's full range in the database (grey) "
    "and the range the rule allows (blue).",
    "scatter": "The database against the target: designs meeting the target in red, the others "
    "in grey, the chosen design as a star; dashed lines are the target's thresholds.",
}

_STAGES = {
    "database": "database (simulations)",
    "choose": "choosing the design",
    "mine": "rule mining",
    "verify": "verification (new simulations inside the rule)",
    "refine": "refinement rounds",
    "files": "design files and pictures",
}

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
  color: #1d232a; background: #fff; max-width: 1040px; margin: 0 auto; padding: 24px 32px 64px;
  line-height: 1.45; font-size: 15px; }
h1 { font-size: 26px; margin: 0 0 4px; }
h2 { font-size: 20px; margin: 34px 0 10px; padding-bottom: 4px; border-bottom: 2px solid #d7dee6; }
h3 { font-size: 16px; margin: 20px 0 6px; }
.sub { color: #56616d; margin: 0 0 12px; }
nav { font-size: 13px; color: #56616d; margin: 8px 0 0; }
nav a { margin-right: 12px; }
a { color: #1f5fa8; }
table { border-collapse: collapse; margin: 6px 0 12px; font-size: 14px; }
th, td { border: 1px solid #d7dee6; padding: 4px 10px; text-align: left; vertical-align: top; }
th { background: #eef2f6; font-weight: 600; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.group th { background: #dfe7ef; }
tr.chosen td { background: #fff6d6; }
tr.in-target td:first-child { font-weight: 600; }
code, .expr { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace;
  font-size: 14px; background: #f3f5f7; padding: 1px 5px; border-radius: 3px; }
.expr { display: inline-block; font-size: 16px; padding: 6px 12px; }
.note { color: #56616d; font-size: 13px; }
.met { color: #19703a; font-weight: 600; }
.missed { color: #b3261e; font-weight: 600; }
.bar { display: inline-block; height: 10px; vertical-align: middle; border-radius: 2px; }
.bar.pos { background: #3c9a5f; }
.bar.neg { background: #c8463d; }
.headline { background: #f3f7fb; border-left: 4px solid #1f5fa8; padding: 8px 14px;
  margin: 10px 0; }
figure { margin: 16px 0 24px; }
figure img { max-width: 100%; height: auto; border: 1px solid #d7dee6; }
figcaption { color: #3d4650; font-size: 14px; margin-top: 4px; }
ul.files li { margin: 2px 0; }
.answer { border-left: 6px solid #3c9a5f; background: #f1f8f3; padding: 10px 16px;
  margin: 12px 0; font-size: 16px; }
.answer.nearest { border-color: #d08a1e; background: #fdf6e9; }
.answer.nothing { border-color: #b3261e; background: #fbeceb; }
.answer .kind { font-weight: 700; text-transform: uppercase; font-size: 12px;
  letter-spacing: 0.05em; color: #3d4650; display: block; margin-bottom: 2px; }
.cards { display: flex; gap: 14px; flex-wrap: wrap; margin: 8px 0; }
.card { flex: 1 1 300px; border: 1px solid #d7dee6; border-radius: 4px; padding: 8px 12px;
  background: #fbfcfd; }
.card h3 { margin: 0 0 6px; font-size: 15px; }
.card p { margin: 4px 0; }
.fits { color: #19703a; font-weight: 600; }
.nofit { color: #b3261e; font-weight: 600; }
table.side td { white-space: nowrap; }
table.side th { white-space: normal; max-width: 230px; font-weight: 500; }
table.side th b { font-weight: 700; }
"""

_SCRIPT = """
window.addEventListener("load", function () {
  var imgs = document.images, n = 0;
  for (var i = 0; i < imgs.length; i++) {
    if (imgs[i].complete && imgs[i].naturalWidth > 0) { n++; }
  }
  document.body.dataset.imagesLoaded = String(n);
  document.body.dataset.imagesTotal = String(imgs.length);
});
"""


# ---- formatting: every piece of text goes through _esc, every number through _num -------------


def _esc(text) -> str:
    return html.escape(str(text), quote=True)


def _is_number(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _num(v, digits: int = 4) -> str:
    """A number as HTML: ``digits`` significant digits, powers of ten as superscripts."""
    if v is None or isinstance(v, bool) or not _is_number(v):
        return _MISSING if v is None else _esc(v)
    if isinstance(v, numbers.Integral):
        return str(int(v))
    v = float(v)
    if not math.isfinite(v):
        return _MISSING
    text = f"{v:.{digits}g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        power = f"10<sup>{int(exponent)}</sup>"
        return power if mantissa == "1" else f"{mantissa}\u00d7{power}"
    return text


def _unit(unit) -> str:
    return "" if unit in (None, "", "-") else str(unit)


def _value(v, unit=None) -> str:
    """A value with its unit (numbers), or escaped text; lists joined, dicts as key: value."""
    if v is None:
        return _MISSING
    if isinstance(v, bool):
        return "yes" if v else "no"
    if _is_number(v):
        text = _num(v)
        u = _unit(unit)
        return f"{text}\u00a0{_esc(u)}" if u and text != _MISSING else text
    if isinstance(v, Mapping):
        return "; ".join(f"{_esc(k)}: {_value(x)}" for k, x in v.items()) or _MISSING
    if isinstance(v, list | tuple):
        return ", ".join(_value(x) for x in v) or _MISSING
    text = str(v)
    return _esc(text) if text.strip() else _MISSING


def _percent(p) -> str | None:
    if not _is_number(p) or not math.isfinite(float(p)):
        return None
    return f"{100 * float(p):.1f}\u00a0%"


def _precision(p) -> str:
    return _percent(p) or _MISSING


def _estimate(rule) -> str:
    """A VerifiedRule's estimate: '91.0 % (85.0 % to 95.0 %)' or the missing mark."""
    est = rule.rule.estimate
    p = None if est is None else _percent(est.precision)
    if p is None:
        return _MISSING
    lo, hi = _percent(est.low), _percent(est.high)
    return f"{p} ({lo} to {hi})" if lo is not None and hi is not None else p


def _verified(rule) -> str:
    """A VerifiedRule's verified precision: '88.0 % (95 % interval 76.0 % to 94.0 %, n = 50)'
    or 'not verified'."""
    p = _percent(rule.precision)
    if p is None:
        return "not verified"
    lo, hi = (_percent(c) for c in rule.interval)
    v = rule.verified
    failed = f", {v.failed} failed" if v.failed else ""
    return f"{p} (95\u00a0% interval {lo} to {hi}, n\u00a0=\u00a0{v.tried}{failed})"


def _seconds(t) -> str:
    if not _is_number(t) or not math.isfinite(float(t)):
        return _MISSING
    t = float(t)
    if t < 0.01:  # a stage that found its work done (a resumed verification): no 4.47e-05 s
        return "&lt;\u00a00.01\u00a0s" if t > 0 else "0\u00a0s"
    if t < 60:
        return f"{t:.3g}\u00a0s"
    minutes, seconds = divmod(round(t), 60)
    return f"{minutes}\u00a0min {seconds:02d}\u00a0s"


def _table(header, rows, cls: str | None = None, row_classes=None) -> str:
    """``rows`` of already-escaped HTML cells; a cell given as ``(html, "num")`` is a number."""
    out = [f'<table class="{_esc(cls)}">' if cls else "<table>", "<thead><tr>"]
    out += [f"<th>{_esc(h)}</th>" for h in header]
    out.append("</tr></thead><tbody>")
    for k, row in enumerate(rows):
        rc = row_classes[k] if row_classes else ""
        out.append(f'<tr class="{rc}">' if rc else "<tr>")
        for cell in row:
            if isinstance(cell, tuple):
                out.append(f'<td class="{cell[1]}">{cell[0]}</td>')
            else:
                out.append(f"<td>{cell}</td>")
        out.append("</tr>")
    out.append("</tbody></table>")
    return "".join(out)


# ---- units -----------------------------------------------------------------------------------


def _columns(summary: DesignSummary) -> dict[str, Column]:
    """Name -> Column (unit and display unit) of the summary's scenario."""
    out = {}
    for key in ("features", "performance"):
        for c in summary.scenario.get(key) or []:
            if not isinstance(c, Mapping) or "name" not in c:
                continue
            unit = str(c.get("unit") or "-")
            names = tuple(str(n) for n in c.get("names") or ())  # named levels: "1 (offset)"
            levels = tuple(float(v) for v in c.get("choices") or ()) if names else ()
            try:
                col = Column(str(c["name"]), unit, display=str(c.get("display_unit") or ""),
                             choices=levels, names=names)  # fmt: skip
            except ValueError:  # a display unit this holofold does not know: the SI unit
                col = Column(str(c["name"]), unit)
            out[col.name] = col
    return out


def _shown(v, col: Column | None, digits: int = 4) -> str:
    """A value in its column's display unit, labelled; the missing mark if absent."""
    if v is None or isinstance(v, bool) or not _is_number(v) or not math.isfinite(float(v)):
        return _MISSING
    if col is None:
        return _num(v, digits)
    return _esc(col.format(float(v), digits=digits).replace(" ", "\u00a0"))


def _plain(v: float, digits: int = 3) -> str:
    """A number without a unit and, below 1e6, without an exponent (the missing mark if NaN)."""
    return _esc(format_value(float(v), digits=digits)) if math.isfinite(v) else _MISSING


# ---- the sections ----------------------------------------------------------------------------

_KIND_TITLE = {
    "rule": "A verified design",
    "designs": "The best simulated design",
    "nearest": "No design meets the target: the nearest",
    "none": "No design",
}


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def _condition_text(cond: str, names, cols: Mapping) -> str:
    """A condition on one column with its numbers in the column's display unit
    (``rms_error < 5e-05`` on a length in m: ``rms_error < 0.05 mm``), escaped; as written
    otherwise."""
    col = cols.get(names[0]) if len(names) == 1 else None
    if col is None or not getattr(col, "unit", "") or col.unit == "-":
        return _esc(cond)
    out, last = [], 0
    for m in _NUMBER.finditer(cond):
        out += [_esc(cond[last : m.start()]), _shown(float(m.group(0)), col)]
        last = m.end()
    return "".join(out) + _esc(cond[last:])


def _condition_rows(pick: Pick, target: str, cols: Mapping) -> list:
    """Per target condition: the chosen design's value, its margin and met / missed."""
    rows = []
    for cond, m in pick.margins.items():
        try:
            names = parse_target(cond).columns
        except TargetError:
            names = ()
        values = [_shown(pick.performance.get(n, pick.features.get(n)), cols.get(n)) for n in names]
        value = ", ".join(values) or _MISSING
        if math.isnan(m):
            margin, state = _MISSING, _MISSING
        elif math.isinf(m):  # == and !=: met or missed, no size; say by how much it differs
            margin = "holds exactly" if m > 0 else "does not hold"
            state = (
                '<span class="met">met</span>' if m > 0 else '<span class="missed">missed</span>'
            )
        else:
            margin = f"{m:+.3g} ({100 * m:+.1f}\u00a0%)"
            state = (
                '<span class="met">met</span>' if m >= 0 else '<span class="missed">missed</span>'
            )
        rows.append(
            [
                f"<code>{_condition_text(cond, names, cols)}</code>",
                (value, "num"),
                (margin, "num"),
                _margin_bar(m) if math.isfinite(m) else "",
                state,
            ]
        )
    return rows


def _fabrication(summary: DesignSummary) -> str:
    f = summary.fabrication
    if f is None:
        return ""
    bed = _esc(f.bed_text)
    if f.film:
        return (
            '<div class="card" id="part"><h3>The part to make</h3>'
            f'<p><a href="{_esc(quote(f.file, safe="/"))}">{_esc(f.file)}</a>: '
            f"<b>{_esc(f.extent_text())}</b>.</p><p>{_esc(f.advice)}</p></div>"
        )
    if f.fits:
        verdict = f'<span class="fits">fits</span> the {bed} bed'
    elif f.pieces:
        verdict = f'<span class="nofit">does not fit</span> the {bed} bed whole: {f.pieces} pieces'
    else:
        verdict = f'<span class="nofit">does not fit</span> the {bed} bed'
    href = _esc(quote(f.file.replace("\\", "/"), safe="/"))
    pieces = ""
    if f.segments:
        sheet = _esc(quote(f"{f.segments}/assembly.svg", safe="/"))
        pieces = (
            f'<p>The pieces: <a href="{sheet}">assembly sheet</a> and '
            f"<code>{_esc(f.segments)}/segment_01.stl</code> ... "
            f"<code>segment_{f.pieces:02d}.stl</code>, each placed on the bed.</p>"
        )
    from holofold.geometry.bed import INFILL, PRINT_RATE, SOLID_SKIN, print_time_text

    return (
        '<div class="card" id="part"><h3>The part to print</h3>'
        f'<p><a href="{href}">{_esc(f.file)}</a>: <b>{_esc(f.extent_text())}</b>; {verdict}.</p>'
        f"<p>{_esc(f.advice)}</p>{pieces}"
        f"<p>Print time: <b>{_esc(print_time_text(f.hours))}</b> ({_esc(f.time_class)}: the volume "
        f"a slicer deposits, solid to {SOLID_SKIN * 1e3:g}&nbsp;mm and {INFILL:.0%} infill "
        f"above, at {PRINT_RATE * 1e9:g}&nbsp;mm<sup>3</sup>/s, calibrated with PrusaSlicer; "
        "the slicer gives the real time)."
        "</p></div>"
    )


def _facts(summary: DesignSummary) -> str:
    facts = summary.extras.get("facts") if isinstance(summary.extras, Mapping) else None
    if not facts:
        return ""
    title = "The design in use"
    if summary.scenario.get("kind") == "gripper":
        title = "Closed by heating"
    rows = "".join(f"<p>{_esc(k)}: <b>{_esc(v)}</b></p>" for k, v in facts.items())
    return f'<div class="card" id="facts"><h3>{_esc(title)}</h3>{rows}</div>'


def _meets_overlapping(summary: DesignSummary) -> bool:
    """No buildable design met the target, and the one shown meets it with overlapping panels."""
    pick = summary.chosen
    shown = pick is not None and pick.meets and pick.buildable is False
    return summary.answer == "nearest" and shown


def _answer(summary: DesignSummary, cols: Mapping) -> str:
    out = ['<section id="answer"><h2>The answer</h2>']
    kind = summary.answer
    css = {"rule": "", "designs": "", "nearest": " nearest", "none": " nothing"}[kind]
    title = _KIND_TITLE[kind]
    if _meets_overlapping(summary):
        title = "No buildable design meets the target: the best, overlapping"
    out.append(
        f'<div class="answer{css}"><span class="kind">{_esc(title)}</span>'
        f"{_esc(summary.headline)}</div>"
    )
    obj = summary.objective
    out.append(
        f'<p>Target <span class="expr">{_esc(summary.target)}</span> &middot; objective '
        f"<b>{_esc(obj)}</b>"
        + ("" if not summary.allow_overlap else " &middot; overlapping panels allowed")
        + "</p>"
    )
    if summary.mined_target and summary.mined_target != summary.target:
        out.append(
            '<p class="note">Buildable by default: rules were mined and verified for '
            f"<code>{_esc(summary.mined_target)}</code>, the target with thick panels "
            "that do not overlap (--allow-overlap drops the condition), and no design "
            "whose panels overlap is chosen.</p>"
        )
    pick = summary.chosen
    if pick is not None:
        rows = _condition_rows(pick, summary.target, cols)
        out.append(
            _table(["condition", "chosen design", "margin", "", "status"], rows, "target-check")
        )
        out.append(
            '<p class="note">Margin: (value &minus; threshold) / |threshold| for a lower '
            "bound, the other way round for an upper bound: 0 on the threshold, +0.1 = "
            "10&nbsp;% to spare, negative when missed. An equality holds exactly or not."
            "</p>"
        )
    cards = _fabrication(summary) + _facts(summary)
    if cards:
        out.append(f'<div class="cards">{cards}</div>')
    view = summary.extras.get("view") if isinstance(summary.extras, Mapping) else None
    if view:
        out.append("<h3>The chosen design in 3D</h3>")
        out.append(view_html(view, "design-view"))
    out.append("</section>")
    return "".join(out)


def _alternatives(summary: DesignSummary, cols: Mapping) -> str:
    picks = [p for p in ((summary.chosen,) + summary.alternatives) if p is not None]
    seen, unique = set(), []
    for p in picks:  # the chosen design first, each design once
        key = tuple(sorted(p.features.items()))
        if key not in seen:
            seen.add(key)
            unique.append(p)
    out = ['<section id="alternatives"><h2>Alternatives, side by side</h2>']
    if len(unique) < 2:
        why = (
            "the chosen one is the best of each verified rule and overall"
            if summary.answer == "rule"
            else "no rule was verified, and the chosen one is the best simulated design"
            if summary.answer == "designs"
            else "no buildable design meets the target; the chosen one meets it, overlapping"
            if _meets_overlapping(summary)
            else "no simulated design meets the target; the chosen one is the nearest"
        )
        out.append(f"<p>No other design was put forward: {why}.</p></section>")
        return "".join(out)
    try:
        target_cols = list(parse_target(summary.target).columns)
    except TargetError:
        target_cols = []
    obj = summary.objective.split()[-1] if summary.objective != "margin" else None
    perf = list(dict.fromkeys([*target_cols, *([obj] if obj else []), "mass", "overlap"]))
    perf = [n for n in perf if any(n in p.performance for p in unique)]
    feats = list(unique[0].features)
    header = [""] + [
        ("chosen: " if k == 0 else "") + p.source.replace("; ", ", ") for k, p in enumerate(unique)
    ]
    rows = [
        ["rule verified precision"]
        + [
            _MISSING
            if p.rule is None
            else _precision(p.rule.precision) + ("" if p.rule.meets_bar else " (below the bar)")
            for p in unique
        ]
    ]
    rows.append(["meets the target"] + ["yes" if p.meets else "no" for p in unique])
    rows.append(
        ["buildable (no overlap)"]
        + [_MISSING if p.buildable is None else ("yes" if p.buildable else "no") for p in unique]
    )
    rows.append(["worst margin"] + [(_num(p.worst_margin, 3), "num") for p in unique])
    if obj:
        rows.append(
            [f"objective: {_esc(summary.objective)}"]
            + [(_shown(p.objective, cols.get(obj)), "num") for p in unique]
        )
    for n in perf:
        rows.append(
            [f"<b>{_esc(n)}</b>"]
            + [(_shown(p.performance.get(n), cols.get(n)), "num") for p in unique]
        )
    for n in feats:
        rows.append([_esc(n)] + [(_shown(p.features.get(n), cols.get(n)), "num") for p in unique])
    out.append(_table(header, rows, "side"))
    out.append(
        '<p class="note">Each verified rule\'s best design under the objective, and the '
        "best of every simulated design; the first column is the chosen one.</p>"
    )
    out.append("</section>")
    return "".join(out)


def _problem(summary: DesignSummary, cols: Mapping) -> str:
    sc = summary.scenario
    out = ['<section id="problem"><h2>1. The problem</h2>']
    facts = [("scenario", sc.get("name")), ("kind", sc.get("kind")), ("source", sc.get("source"))]
    out.append(
        "<p>" + " &middot; ".join(f"{k}: <b>{_value(v)}</b>" for k, v in facts if v) + "</p>"
    )
    if sc.get("description"):
        out.append(f"<p>{_esc(sc['description'])}</p>")
    setting = sc.get("setting") or {}
    if setting:
        out.append("<h3>Fixed setting</h3>")
        rows = [[_esc(k), _value(v)] for k, v in setting.items()]
        out.append(_table(["quantity", "value"], rows, "setting-table"))
    feats = [f for f in sc.get("features") or [] if isinstance(f, Mapping)]
    if feats:
        out.append("<h3>Design features (what the designer chooses)</h3>")
        rows = []
        for f in feats:
            col = cols.get(f.get("name"))
            if f.get("choices"):
                span = "one of " + ", ".join(_shown(v, col) for v in f["choices"])
            elif f.get("low") is not None or f.get("high") is not None:
                span = f"{_shown(f.get('low'), col)} to {_shown(f.get('high'), col)}"
            else:
                span = _MISSING
            unit = col.display_unit if col is not None else ""
            rows.append(
                [
                    _esc(f.get("name", "")),
                    _esc(_unit(unit)) or _MISSING,
                    span,
                    _value(f.get("description")),
                ]
            )
        out.append(_table(["feature", "unit", "range or choices", "meaning"], rows, "features"))
    perf = [p for p in sc.get("performance") or [] if isinstance(p, Mapping)]
    if perf:
        out.append("<h3>Performance (what the simulation measures)</h3>")
        rows = [
            [
                _esc(p.get("name", "")),
                _esc(_unit(cols[p["name"]].display_unit if p.get("name") in cols else ""))
                or _MISSING,
                _value(p.get("description")),
            ]
            for p in perf
        ]
        out.append(_table(["quantity", "unit", "meaning"], rows, "performance"))
    out.append("</section>")
    return "".join(out)


def _reach(summary: DesignSummary, cols: Mapping) -> str:
    out = ['<section id="reach"><h2>2. What the designs reach</h2>']
    pilot = summary.pilot
    if pilot:
        line = (
            f"The pilot: {_num(pilot.get('rows'))} designs simulated first, "
            f"{_num(pilot.get('meeting'))} meeting the target."
        )
        if pilot.get("stopped"):
            line += (
                f" <b>The run stopped there</b>: {_esc(pilot.get('reason'))}. The "
                "distributions below say what the designs reach; change the target or the "
                "feature ranges and run again (the simulations are kept)."
            )
        out.append(f"<p>{line}</p>")
    if summary.distributions:
        from holofold.design.report.describe import QUANTILES

        head = ["column", "unit", "designs"] + [
            "min" if q == 0 else "max" if q == 1 else f"{round(100 * q)}\u00a0%" for q in QUANTILES
        ]
        rows = []
        for d in summary.distributions:
            col = cols.get(d.name)
            unit = col.display_unit if col is not None else d.unit
            factor = col.display_factor if col is not None else 1.0
            rows.append(
                [f"<b>{_esc(d.name)}</b>", _esc(_unit(unit)) or _MISSING, (_num(d.rows), "num")]
                + [(_plain(v * factor), "num") for v in d.quantiles]
            )
        out.append(_table(head, rows, "distributions"))
        out.append(
            "<p class=\"note\">Quantiles of the target's (and the objective's) columns over "
            "every successfully simulated design of this folder.</p>"
        )
    else:
        out.append("<p>No distribution was recorded.</p>")
    out.append("</section>")
    return "".join(out)


def _design(summary: DesignSummary, cols: Mapping) -> str:
    out = ['<section id="design"><h2>3. The chosen design</h2>']
    pick = summary.chosen
    if pick is None:
        out.append("<p>Every simulation failed: there is no design to show.</p></section>")
        return "".join(out)
    out.append(
        f"<p>{_esc(pick.source)}; simulated as <code>{_esc(pick.origin)}</code>, status "
        f"<code>{_esc(pick.status)}</code>.</p>"
    )
    if pick.rule is not None:
        out.append(
            f'<p class="headline">Its rule, {_esc(pick.rule.label)}: '
            f"<code>{_esc(pick.rule.text)}</code><br>verified precision "
            f"{_verified(pick.rule)}</p>"
        )
    try:
        in_target = set(parse_target(summary.target).columns)
    except TargetError:
        in_target = set()
    body = [
        '<table class="design-table"><thead><tr><th>quantity</th><th>value</th></tr></thead><tbody>'
    ]
    for group, values in (("design features", pick.features), ("performance", pick.performance)):
        body.append(f'<tr class="group"><th colspan="2">{_esc(group)}</th></tr>')
        for name, v in values.items():
            cls = ' class="in-target"' if name in in_target else ""
            body.append(
                f"<tr{cls}><td>{_esc(name)}</td>"
                f'<td class="num">{_shown(v, cols.get(name))}</td></tr>'
            )
    body.append("</tbody></table>")
    out.append("".join(body))
    if in_target:
        out.append('<p class="note">Quantities in bold appear in the target.</p>')
    out.append("<h3>Margins to the target</h3>")
    out.append(
        _table(
            ["condition", "value", "margin", "", "status"],
            _condition_rows(pick, summary.target, cols),
            "margins",
        )
    )
    out.append("</section>")
    return "".join(out)


def _rounds(summary: DesignSummary, cols: Mapping) -> str:
    out = ['<section id="rules"><h2>4. The rules</h2>']
    if not summary.rounds:
        out.append("<p>No rules were mined (the run stopped after its pilot).</p></section>")
        return "".join(out)
    out.append(
        '<p class="note">Four precisions, each the share of designs inside the rule that meet the '
        "target: <b>estimate</b>, what the miner expects on new designs (95&nbsp;% interval), "
        "from database rows its trees did not train on; <b>train</b>, on the database rows the "
        "rule was mined from; <b>held-out</b>, on the database rows kept out of mining (the "
        "test split); <b>verified</b>, on new designs sampled inside the rule and simulated, "
        "with its 95&nbsp;% interval and the number n of new designs. Only the verified "
        "precision decides.</p>"
    )
    chosen = summary.chosen.rule if summary.chosen is not None else None
    changes, previous, previous_round = [], None, None
    for rd in summary.rounds:
        head = (
            f"Round {rd.index}: mined from {rd.rows} designs"
            + (f" ({rd.failed} failed simulations left out)" if rd.failed else "")
            + f", {rd.meeting} meeting the target"
        )
        out.append(f"<h3>{_esc(head)}</h3>")
        if rd.rules:
            rows, classes = [], []
            for r in rd.rules:
                rows.append(
                    [
                        (_num(r.round), "num"),
                        (_num(r.rank), "num"),
                        f"<code>{_esc(r.text)}</code>",
                        (_estimate(r), "num"),
                        (_precision(r.train_precision), "num"),
                        (_precision(r.test_precision), "num"),
                        _verified(r),
                    ]
                )
                is_chosen = chosen is not None and (r.round, r.rank) == (chosen.round, chosen.rank)
                classes.append("chosen" if is_chosen else "")
            header = [
                "round",
                "rank",
                "rule",
                "estimate",
                "train precision",
                "held-out precision",
                "verified precision",
            ]
            out.append(_table(header, rows, "rules", classes))
        else:
            out.append(f"<p>{_esc(rd.note) or 'No rule reached the miner thresholds.'}</p>")
        best = rd.best
        if best is None or best.precision is None:
            line = "no rule verified"
        else:
            p = best.precision
            line = f"best verified precision {_percent(p)} (rank {best.rank})"
            if previous is not None:
                delta = 100 * (p - previous)
                if abs(delta) < 0.05:
                    line += f", unchanged from round {previous_round}"
                else:
                    word = "up" if delta > 0 else "down"
                    line += f", {word} {abs(delta):.1f} points from round {previous_round}"
            previous, previous_round = p, rd.index
        changes.append(f"<li>Round {rd.index}: {line}.</li>")
    if chosen is not None:
        out.append(
            f'<p class="note">Highlighted: the chosen design\'s rule, {_esc(chosen.label)}'
            ", the best verified rule of all rounds.</p>"
        )
    out.append("<h3>How the verified precision changed</h3><ul>" + "".join(changes) + "</ul>")
    out.append("</section>")
    return "".join(out)


def _margin_bar(m: float) -> str:
    width = min(abs(m), 1.0) * 120
    cls = "pos" if m >= 0 else "neg"
    return f'<span class="bar {cls}" style="width:{width:.0f}px"></span>'


def _pictures(folder: Path, summary: DesignSummary) -> tuple[str, int]:
    images = summary.images
    out = ['<section id="pictures"><h2>5. Pictures</h2>']
    order = [k for k in _CAPTIONS if k in images] + [k for k in images if k not in _CAPTIONS]
    n = 0
    for key in order:
        rel = images[key]
        if not rel:
            continue
        path = folder / str(rel)
        caption = _CAPTIONS.get(key, str(key))
        if key == "design" and (summary.scenario or {}).get("kind") == "gripper":
            # the gripper's shape is its flat film as cut; heating folds it
            caption = (
                "The chosen design, flat as cut (coordinates in mm; creases in red); its state "
                "closed by heating is the 3D view's and closed.stl's."
            )
        if not path.is_file():
            out.append(
                f'<figure><p class="note">picture {_esc(rel)} was not made.</p>'
                f"<figcaption>{_esc(caption)}</figcaption></figure>"
            )
            continue
        mime = _MIME.get(path.suffix.lower(), "image/png")
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        out.append(
            f'<figure id="picture-{_esc(key)}"><img src="data:{mime};base64,{data}" '
            f'alt="{_esc(caption)}"><figcaption>{_esc(caption)}</figcaption></figure>'
        )
        n += 1
    if not n and not images:
        out.append("<p>No pictures were made.</p>")
    out.append("</section>")
    return "".join(out), n


def _files(folder: Path, summary: DesignSummary) -> str:
    files = summary.files
    out = ['<section id="files"><h2>6. Files</h2>']
    if not files:
        out.append("<p>No files were written.</p></section>")
        return "".join(out)
    out.append('<ul class="files">')
    for key, entry in files.items():
        rel, label = entry.get("path"), entry.get("label") or key
        if not rel:
            continue
        rel = str(rel).replace("\\", "/")
        href = _esc(quote(rel, safe="/"))
        missing = "" if (folder / rel).exists() else ' <span class="note">(not found)</span>'
        out.append(
            f'<li><a href="{href}">{_esc(label)}</a> <span class="note">{_esc(rel)}</span>'
            f"{missing}</li>"
        )
    out.append("</ul>")
    notes = [str(w) for w in summary.warnings if w]
    if notes:
        out.append('<p><strong>Notes on the files:</strong></p><ul class="files">')
        out.extend(f"<li>{_esc(w)}</li>" for w in notes)
        out.append("</ul>")
    out.append("</section>")
    return "".join(out)


_ORIGINS = {
    "database": "base sample",
    "refine": "refinement rounds",
    "verify": "verification of rules",
    "earlier": "earlier runs (rules since changed)",
}


def _timings(summary: DesignSummary) -> str:
    out = ['<section id="timings"><h2>7. Designs simulated and time spent</h2>']
    db = summary.database
    if db:
        by = db.get("by_origin") or {}
        parts = ", ".join(f"{_ORIGINS.get(k, k)} {_num(v)}" for k, v in by.items())
        line = f"{_num(db.get('rows'))} designs simulated in this folder"
        if parts:
            line += f" ({parts})"
        if db.get("failed"):
            line += f"; {_num(db['failed'])} of them failed (left out of mining and choosing)"
        if db.get("path"):
            href = _esc(quote(str(db["path"]).replace("\\", "/"), safe="/"))
            line += f'; stored in <a href="{href}">{_esc(db["path"])}</a>'
        out.append(
            f"<p>{line}. Every one of them is a candidate; each round mined from the "
            "designs simulated before it.</p>"
        )
    t = summary.timings
    if t is None:
        out.append("<p>No timings were recorded.</p></section>")
        return "".join(out)
    keys = list(dict.fromkeys([*t.this_run, *t.all_runs]))
    rows = [
        [
            _esc(_STAGES.get(k, k)),
            (_seconds(t.this_run.get(k, 0.0)), "num"),
            (_seconds(t.all_runs.get(k, 0.0)), "num"),
        ]
        for k in keys
    ]
    rows.append(
        [
            "<b>total</b>",
            (f"<b>{_seconds(sum(t.this_run.values()))}</b>", "num"),
            (f"<b>{_seconds(sum(t.all_runs.values()))}</b>", "num"),
        ]
    )
    runs = "1 run" if t.runs == 1 else f"all {t.runs} runs"
    out.append(_table(["stage", "this run", runs], rows, "timings"))
    out.append(
        '<p class="note">Wall time per stage. A resumed run finds its simulations on '
        "disk: its own time is short, the total over all runs is the cost.</p>"
    )
    out.append("</section>")
    return "".join(out)


def report_page_html(folder, summary: DesignSummary | Mapping) -> str:
    """The report page as one HTML string (images read from files relative to ``folder``).

    Parameters
    ----------
    folder : path
        The design folder; the summary's ``images`` and ``files`` are relative to it.
    summary : DesignSummary or mapping
        The design summary, or its JSON (``design.json``), validated by
        :meth:`DesignSummary.from_json`.

    Returns
    -------
    str
    """
    if not isinstance(summary, DesignSummary):
        summary = DesignSummary.from_json(summary)
    folder = Path(folder)
    cols = _columns(summary)
    name = summary.scenario.get("name") or "design"
    pictures, n_images = _pictures(folder, summary)
    sections = [
        _answer(summary, cols),
        _alternatives(summary, cols),
        _problem(summary, cols),
        _reach(summary, cols),
        _design(summary, cols),
        _rounds(summary, cols),
        pictures,
        _files(folder, summary),
        _timings(summary),
    ]
    nav = " ".join(
        f'<a href="#{a}">{t}</a>'
        for a, t in (
            ("answer", "answer"),
            ("alternatives", "alternatives"),
            ("problem", "problem"),
            ("reach", "what designs reach"),
            ("design", "chosen design"),
            ("rules", "rules"),
            ("pictures", "pictures"),
            ("files", "files"),
            ("timings", "time"),
        )
    )
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>holofold design: {_esc(name)}</title><style>{_CSS}{view_css}</style></head>\n"
        f'<body data-images-total="{n_images}">\n'
        f"<header><h1>Design report: {_esc(name)}</h1>"
        f'<p class="sub">made by <code>holofold design</code></p><nav>{nav}</nav></header>\n'
        + "\n".join(sections)
        + f"\n<script>{_SCRIPT}</script>\n</body></html>\n"
    )


def write_report_page(folder, summary: DesignSummary | Mapping) -> Path:
    """Write ``folder/report.html`` atomically: the whole page is built before anything is written.

    Parameters
    ----------
    folder : path
        An existing design folder (images and files named in the summary are relative to it).
    summary : DesignSummary or mapping
        See :func:`report_page_html`.

    Returns
    -------
    pathlib.Path
        The page's path.

    Raises
    ------
    TypeError, ValueError
        The summary lacks a required part (nothing is written).
    OSError
        The folder does not exist.
    """
    page = report_page_html(folder, summary)
    path = check_output_path(Path(folder) / "report.html", "report page")
    return write_text(path, page)
