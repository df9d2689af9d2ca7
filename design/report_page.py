"""The self-contained HTML report of ``holofold design``: one page, read top to bottom.

:func:`write_report_page` turns the design summary (what ``design.json`` holds) into
``report.html``: the problem (scenario, fixed setting, design features), the target, the rules
of each round with their verified precision, the chosen design with its margins, the pictures
(embedded as base64 PNG), links to the design's files and the time of each stage. The page
loads nothing from anywhere (inline CSS, no JS library); a tiny inline script records, after
load, how many of its images decoded (``data-images-loaded`` on ``<body>``).
"""

from __future__ import annotations

import base64
import html
import math
import numbers
from collections.abc import Mapping
from pathlib import Path
from urllib.parse import quote

from holofold.design.targets import TargetError, parse_target
from holofold.geometry.outputs import check_output_path, write_text

__all__ = ["write_report_page", "report_page_html"]

_REQUIRED = ("scenario", "target", "features", "performance")

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


def _estimate(rule: Mapping) -> str:
    """'91.0 % (95 % interval 85.0 % to 95.0 %)' or the missing mark."""
    p = _percent(rule.get("estimate"))
    if p is None:
        return _MISSING
    ci = rule.get("estimate_95ci")
    if isinstance(ci, list | tuple) and len(ci) == 2:
        lo, hi = (_percent(c) for c in ci)
        if lo is not None and hi is not None:
            return f"{p} ({lo} to {hi})"
    return p


def _verified(rule: Mapping, fallback=None) -> str:
    """'88.0 % (95 % interval 76.0 % to 94.0 %, n = 50)' or 'not verified'."""
    p = _percent(rule.get("verified_precision", fallback))
    if p is None:
        return "not verified"
    extra = []
    ci = rule.get("verified_95ci")
    if isinstance(ci, list | tuple) and len(ci) == 2:
        lo, hi = (_percent(c) for c in ci)
        if lo is not None and hi is not None:
            extra.append(f"95\u00a0% interval {lo} to {hi}")
    n = rule.get("verified_n")
    if _is_number(n) and math.isfinite(float(n)):
        extra.append(f"n\u00a0=\u00a0{int(n)}")
    return f"{p} ({', '.join(extra)})" if extra else p


def _seconds(t) -> str:
    if not _is_number(t) or not math.isfinite(float(t)):
        return _MISSING
    t = float(t)
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


# ---- the sections ----------------------------------------------------------------------------


def _units(summary: Mapping) -> dict:
    scenario = summary["scenario"]
    units = {}
    for key in ("features", "performance"):
        for col in scenario.get(key) or []:
            if isinstance(col, Mapping) and "name" in col:
                units[col["name"]] = col.get("unit")
    units.update(summary.get("units") or {})
    return units


def _problem(summary: Mapping, units: Mapping) -> str:
    sc = summary["scenario"]
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
        rows = [[_esc(k), _value(v, units.get(k))] for k, v in setting.items()]
        out.append(_table(["quantity", "value"], rows, "setting-table"))
    feats = [f for f in sc.get("features") or [] if isinstance(f, Mapping)]
    if feats:
        out.append("<h3>Design features (what the designer chooses)</h3>")
        rows = []
        for f in feats:
            unit = _unit(f.get("unit"))
            if f.get("choices"):
                span = "one of " + _value(list(f["choices"]))
            elif f.get("low") is not None or f.get("high") is not None:
                span = f"{_num(f.get('low'))} to {_num(f.get('high'))}"
            else:
                span = _MISSING
            if unit and span != _MISSING:
                span += f"\u00a0{_esc(unit)}"
            rows.append(
                [
                    _esc(f.get("name", "")),
                    _esc(unit) or _MISSING,
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
                _esc(_unit(p.get("unit"))) or _MISSING,
                _value(p.get("description")),
            ]
            for p in perf
        ]
        out.append(_table(["quantity", "unit", "meaning"], rows, "performance"))
    out.append("</section>")
    return "".join(out)


def _target(summary: Mapping) -> str:
    out = ['<section id="target"><h2>2. The target</h2>']
    out.append(f'<p><span class="expr">{_esc(summary["target"])}</span></p>')
    db = summary.get("database") or {}
    if db:
        parts = []
        if _is_number(db.get("rows")):
            parts.append(f"{_num(db['rows'])} simulated designs")
        if _is_number(db.get("failed")) and db["failed"]:
            parts.append(f"{_num(db['failed'])} failed simulation(s) left out")
        if db.get("path"):
            href = _esc(quote(str(db["path"]).replace("\\", "/"), safe="/"))
            parts.append(f'stored in <a href="{href}">{_esc(db["path"])}</a>')
        if parts:
            out.append(f"<p>Database: {'; '.join(parts)}.</p>")
    out.append("</section>")
    return "".join(out)


def _best(rules) -> tuple[float, Mapping] | None:
    scored = [
        (float(r["verified_precision"]), r)
        for r in rules
        if _percent(r.get("verified_precision")) is not None
    ]
    return max(scored, key=lambda s: s[0]) if scored else None


def _rounds(summary: Mapping) -> str:
    out = ['<section id="rules"><h2>3. The rules</h2>']
    rounds = [r for r in summary.get("rounds") or [] if isinstance(r, Mapping)]
    if not rounds:
        out.append("<p>No rules were mined.</p></section>")
        return "".join(out)
    out.append(
        '<p class="note">Estimate: the precision the miner expects on new designs inside the '
        "rule, with its 95&nbsp;% interval, from database rows its trees did not train on. "
        "Train and test precision: the share of database designs inside the "
        "rule that meet the target. Verified precision: the share of new designs sampled inside "
        "the rule and simulated that meet it, with its 95&nbsp;% interval and the number of "
        "new designs n.</p>"
    )
    chosen_text = (summary.get("rule") or {}).get("rule")
    changes = []
    previous, previous_round = None, None
    for k, rd in enumerate(rounds):
        number = rd.get("round", k)
        rules = [r for r in rd.get("rules") or [] if isinstance(r, Mapping)]
        head = f"Round {_num(number)}"
        if _is_number(rd.get("rows")):
            head += f" ({_num(rd['rows'])} designs in the database)"
        out.append(f"<h3>{head}</h3>")
        if rules:
            rows, classes = [], []
            for r in rules:
                rows.append(
                    [
                        (_num(number), "num"),
                        (_num(r.get("rank")), "num"),
                        f"<code>{_esc(r.get('rule', ''))}</code>",
                        (_estimate(r), "num"),
                        (_precision(r.get("train_precision")), "num"),
                        (_precision(r.get("test_precision")), "num"),
                        _verified(r),
                    ]
                )
                is_chosen = chosen_text is not None and r.get("rule") == chosen_text
                classes.append("chosen" if is_chosen else "")
            header = ["round", "rank", "rule", "estimate", "train precision", "test precision"]
            out.append(_table(header + ["verified precision"], rows, "rules", classes))
        else:
            out.append("<p>No rule reached the miner's precision and support thresholds.</p>")
        best = _best(rules)
        if best is None:
            line = "no rule verified"
        else:
            p, r = best
            line = f"best verified precision {_percent(p)} (rank {_num(r.get('rank'))})"
            if previous is not None:
                delta = 100 * (p - previous)
                if abs(delta) < 0.05:
                    line += f", unchanged from round {_num(previous_round)}"
                else:
                    word = "up" if delta > 0 else "down"
                    line += f", {word} {abs(delta):.1f} points from round {_num(previous_round)}"
            previous, previous_round = p, number
        changes.append(f"<li>Round {_num(number)}: {line}.</li>")
    if chosen_text is not None:
        out.append('<p class="note">Highlighted: the chosen rule.</p>')
    out.append("<h3>How the verified precision changed</h3><ul>" + "".join(changes) + "</ul>")
    out.append("</section>")
    return "".join(out)


def _margin_bar(m: float) -> str:
    width = min(abs(m), 1.0) * 120
    cls = "pos" if m >= 0 else "neg"
    return f'<span class="bar {cls}" style="width:{width:.0f}px"></span>'


def _design(summary: Mapping, units: Mapping) -> str:
    out = ['<section id="design"><h2>4. The chosen design</h2>']
    rule = summary.get("rule") or {}
    verified = _verified(rule, summary.get("verified_precision"))
    if rule.get("rule"):
        out.append(
            f'<p class="headline">Chosen rule: <code>{_esc(rule["rule"])}</code><br>'
            f"verified precision: {verified}</p>"
        )
    try:
        in_target = set(parse_target(str(summary["target"])).columns)
    except TargetError:
        in_target = set()
    rows, classes = [], []
    for group, key in (("design features", "features"), ("performance", "performance")):
        values = summary[key] or {}
        rows.append(None)
        classes.append(group)
        for name, v in values.items():
            u = _unit(units.get(name))
            rows.append([_esc(name), (_value(v), "num"), _esc(u)])
            classes.append("in-target" if name in in_target else "")
    body = [
        '<table class="design-table"><thead><tr><th>quantity</th><th>value</th>'
        "<th>unit</th></tr></thead><tbody>"
    ]
    for row, cls in zip(rows, classes, strict=True):
        if row is None:
            body.append(f'<tr class="group"><th colspan="3">{_esc(cls)}</th></tr>')
            continue
        cells = "".join(
            f'<td class="{c[1]}">{c[0]}</td>' if isinstance(c, tuple) else f"<td>{c}</td>"
            for c in row
        )
        body.append(f'<tr class="{cls}">{cells}</tr>' if cls else f"<tr>{cells}</tr>")
    body.append("</tbody></table>")
    out.append("".join(body))
    if in_target:
        out.append('<p class="note">Quantities in bold appear in the target.</p>')
    margins = summary.get("margins") or {}
    if margins:
        out.append("<h3>Margins to the target</h3>")
        rows = []
        for cond, m in margins.items():
            m = float(m) if _is_number(m) else math.nan
            if math.isnan(m):
                state = _MISSING
            else:  # == and != conditions have an infinite margin: met or missed, no size
                state = (
                    '<span class="met">met</span>'
                    if m >= 0
                    else ('<span class="missed">missed</span>')
                )
            finite = math.isfinite(m)
            rows.append(
                [
                    f"<code>{_esc(cond)}</code>",
                    (f"{m:+.3g}" if finite else _MISSING, "num"),
                    _margin_bar(m) if finite else "",
                    state,
                ]
            )
        out.append(_table(["condition", "margin", "", "status"], rows, "margins"))
        out.append(
            '<p class="note">Margin: (value &minus; threshold) / |threshold| for a lower bound '
            "(the other way round for an upper bound): 0 on the threshold, 0.1 = 10&nbsp;% to "
            "spare, negative when the condition is missed.</p>"
        )
    out.append("</section>")
    return "".join(out)


def _pictures(folder: Path, summary: Mapping) -> tuple[str, int]:
    images = summary.get("images") or {}
    out = ['<section id="pictures"><h2>5. Pictures</h2>']
    order = [k for k in _CAPTIONS if k in images] + [k for k in images if k not in _CAPTIONS]
    n = 0
    for key in order:
        rel = images[key]
        if not rel:
            continue
        path = folder / str(rel)
        caption = _CAPTIONS.get(key, str(key))
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


def _files(folder: Path, summary: Mapping) -> str:
    files = summary.get("files") or {}
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
    notes = [str(w) for w in summary.get("warnings") or () if w]
    if notes:
        out.append('<p><strong>Notes on the files:</strong></p><ul class="files">')
        out.extend(f"<li>{_esc(w)}</li>" for w in notes)
        out.append("</ul>")
    out.append("</section>")
    return "".join(out)


def _timings(summary: Mapping) -> str:
    timings = summary.get("timings") or {}
    out = ['<section id="timings"><h2>7. Time per stage</h2>']
    if not timings:
        out.append("<p>No timings were recorded.</p></section>")
        return "".join(out)
    rows = [[_esc(_STAGES.get(k, k)), (_seconds(t), "num")] for k, t in timings.items()]
    finite = [float(t) for t in timings.values() if _is_number(t) and math.isfinite(float(t))]
    rows.append(["<b>total</b>", (f"<b>{_seconds(sum(finite))}</b>", "num")])
    out.append(_table(["stage", "wall time"], rows, "timings"))
    out.append("</section>")
    return "".join(out)


def _check(summary) -> None:
    if not isinstance(summary, Mapping):
        raise TypeError(f"the summary must be a mapping, got {type(summary).__name__}")
    missing = [k for k in _REQUIRED if k not in summary]
    if missing:
        raise ValueError(f"the summary lacks {', '.join(missing)}")
    if not isinstance(summary["scenario"], Mapping):
        raise ValueError("summary['scenario'] must be a mapping")
    for key in ("features", "performance"):
        if not isinstance(summary[key], Mapping):
            raise ValueError(f"summary[{key!r}] must map names to values")


def report_page_html(folder, summary: Mapping) -> str:
    """The report page as one HTML string (images read from files relative to ``folder``).

    Parameters
    ----------
    folder : path
        The design folder; the summary's ``images`` and ``files`` are relative to it.
    summary : mapping
        The design summary: ``scenario``, ``target``, ``features`` and ``performance`` are
        required; ``database``, ``rounds``, ``rule``, ``verified_precision``, ``units``,
        ``margins``, ``files``, ``images`` and ``timings`` are optional.

    Returns
    -------
    str
    """
    _check(summary)
    folder = Path(folder)
    units = _units(summary)
    name = summary["scenario"].get("name") or "design"
    pictures, n_images = _pictures(folder, summary)
    sections = [
        _problem(summary, units),
        _target(summary),
        _rounds(summary),
        _design(summary, units),
        pictures,
        _files(folder, summary),
        _timings(summary),
    ]
    nav = " ".join(
        f'<a href="#{a}">{t}</a>'
        for a, t in (
            ("problem", "problem"),
            ("target", "target"),
            ("rules", "rules"),
            ("design", "chosen design"),
            ("pictures", "pictures"),
            ("files", "files"),
            ("timings", "timings"),
        )
    )
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>holofold design: {_esc(name)}</title><style>{_CSS}</style></head>\n"
        f'<body data-images-total="{n_images}">\n'
        f"<header><h1>Design report: {_esc(name)}</h1>"
        f'<p class="sub">made by <code>holofold design</code></p><nav>{nav}</nav></header>\n'
        + "\n".join(sections)
        + f"\n<script>{_SCRIPT}</script>\n</body></html>\n"
    )


def write_report_page(folder, summary: Mapping) -> Path:
    """Write ``folder/report.html`` atomically: the whole page is built before anything is written.

    Parameters
    ----------
    folder : path
        An existing design folder (images and files named in the summary are relative to it).
    summary : mapping
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
    path = check_output_path(Path(folder) / "report.html", "report page")
    return write_text(path, report_page_html(folder, summary))
