"""Output of mined rules: text, DataFrame and figures (JSON: :mod:`holofold.design.rules.rulefile`).

Figures follow the paper: a box chart per rule (each feature's full range as a bar, the rule's
range shaded; Fig. 2F), a scatter of two features with the rows inside the rule marked against
the target (Fig. 3E), and the forest's feature importances. matplotlib is imported inside the
plotting functions (Agg backend when none is set), so importing this module costs nothing.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from holofold.design.rules import ForestRuleMiner, level_value
from holofold.design.rules.rulefile import mined_rules
from holofold.design.rules.targets import Target, parse_target
from holofold.design.scenarios.base import format_value
from holofold.geometry.outputs import atomic_write

__all__ = [
    "rules_frame",
    "rules_to_text",
    "mining_summary",
    "plot_rule_boxes",
    "plot_rules",
    "save_figure",
    "plot_rule_scatter",
    "plot_feature_importance",
    "plot_target_scatter",
    "plot_folded_design",
]


def rules_frame(miner: ForestRuleMiner, test: pd.DataFrame | None = None) -> pd.DataFrame:
    """``miner.rules_``, with test metrics (from ``evaluation.rule_scores``) as ``test_*``."""
    frame = miner.rules_.copy()
    if test is not None:
        if len(test) != len(frame):
            raise ValueError(f"test has {len(test)} rows for {len(frame)} rules")
        frame = pd.concat([frame, test.reset_index(drop=True).add_prefix("test_")], axis=1)
    return frame


def rules_to_text(
    miner: ForestRuleMiner,
    test: pd.DataFrame | None = None,
    *,
    columns: Mapping | None = None,
    digits: int = 3,
) -> str:
    """Human-readable list of the kept rules with their metrics, in display units.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    test : DataFrame, optional
        Held-out metrics per rule (``evaluation.rule_scores``: ``precision``, ``recall``,
        ``support``, ``true_positives``); its rows also join the estimate's evidence.
    columns : mapping, optional
        Name -> :class:`~holofold.design.scenarios.Column` (``tables.table_columns``): the
        thresholds are shown in each column's display unit (``tcrease <= 0.779 mm``); features
        without one read as bare SI numbers.
    digits : int, default=3
        Significant digits of the thresholds (the rules files keep them exactly).
    """
    if not len(miner.rules_):
        return (
            f"no rule reaches precision >= {miner.precision_min} with support >= "
            f"{miner.min_support} ({miner.n_candidates_} candidate boxes)"
        )
    lines = []
    for r in mined_rules(miner, test):
        e = r.estimate
        lines.append(f"rule {r.rank}: {r.text(columns, digits)}")
        rows = f"{e.out_of_bag_rows} out-of-bag" + (
            f" + {e.held_out_rows} held-out" if test is not None else ""
        )
        lines.append(
            f"    estimate: precision {e.precision:.3f} (95 % interval "
            f"{e.low:.3f}-{e.high:.3f}; from {rows} rows)"
        )
        t = r.train
        lines.append(
            f"    train:    precision {t.precision:.3f}  recall {t.recall:.3f}  support {t.support}"
        )
        if r.test is not None:
            t = r.test
            lines.append(
                f"    held-out: precision {t.precision:.3f}  recall {t.recall:.3f}  "
                f"support {t.support}"
            )
    if len(miner.rules_) < miner.n_rules:
        lines.append(f"(only {len(miner.rules_)} of the {miner.n_rules} requested rules survived)")
    return "\n".join(lines)


def mining_summary(mined, source: str, columns: Mapping | None = None) -> str:
    """What ``holofold mine`` prints: the table, target, features, split and the rules.

    ``mined``: a :class:`~holofold.design.rules.mining.MinedRules`; ``source``: the table's name;
    ``columns``: name -> Column for display units (:func:`rules_to_text`).
    """
    m, h = mined.miner, mined.holdout
    y = mined.meets
    n_hit = int(y.sum())
    cats = f" (categorical: {', '.join(mined.categorical)})" if mined.categorical else ""
    lines = []
    if mined.n_failed:
        lines.append(f"note: {mined.n_failed} failed simulation(s) left out")
    lines += [
        f"database: {source} ({len(mined.table)} rows)",
        f"target:   {mined.target} (met by {n_hit} rows, {100 * n_hit / y.size:.1f} %)",
        f"features: {', '.join(mined.features)}{cats}",
        f"split:    {len(h.train_index)} train / {len(h.test_index)} test rows "
        f"(seed {m.random_state}); {m.n_candidates_} candidate boxes, "
        f"{len(m.candidate_rules_)} pass the filters",
    ]
    if len(h.test_index) >= 2:
        free = mined.independent_features
        lines.append(
            "the target does not depend on: "
            + (", ".join(free) if free else "(it depends on every feature)")
            + " (held-out permutation test of the forest, 5 %)"
        )
    lines.append(rules_to_text(m, mined.test_scores, columns=columns))
    return "\n".join(lines)


def _pyplot():
    """pyplot, on the Agg backend unless the caller already imported pyplot themselves."""
    import sys

    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _frame(X, names) -> pd.DataFrame:
    return X if isinstance(X, pd.DataFrame) else pd.DataFrame(np.asarray(X), columns=names)


def _scale(columns: Mapping | None, name: str) -> tuple[float, str]:
    """(display factor, display unit) of a column, (1, "") without one."""
    c = (columns or {}).get(name)
    if c is None:
        return 1.0, ""
    unit = c.display_unit
    return c.display_factor, "" if unit in ("", "-") else unit


def plot_rule_boxes(
    miner: ForestRuleMiner,
    X,
    rule: int = 0,
    *,
    ax=None,
    columns: Mapping | None = None,
):
    """Box chart of one rule (Fig. 2F): per feature its full data range, the rule range shaded.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    X : DataFrame or array of shape (n_samples, n_features)
        Data giving each feature's full range (e.g. the whole database).
    rule : int, default=0
    ax : matplotlib Axes, optional
    columns : mapping, optional
        Name -> Column: ranges and thresholds are labelled in each column's display unit.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    names = miner.feature_names_
    df = _frame(X, names)
    bounds = miner.rule_bounds(rule)
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 0.5 + 0.45 * len(names)))
    else:
        fig = ax.figure
    for k, (name, b) in enumerate(zip(names, bounds, strict=True)):
        yk = len(names) - 1 - k
        ax.barh(yk, 1.0, left=0.0, height=0.5, color="0.88", edgecolor="0.5")
        if miner._encoding.categorical[k]:
            lv = miner._encoding.levels[k]
            allowed = set(lv.tolist()) if b is None else set(b)
            w = 1.0 / len(lv)
            for i, v in enumerate(lv.tolist()):
                if v in allowed:
                    ax.barh(yk, w, left=i * w, height=0.5, color="tab:blue", alpha=0.7)
                label = str(level_value(v))
                ax.text((i + 0.5) * w, yk, label, ha="center", va="center", fontsize=7)
            continue
        s, u = _scale(columns, name)
        col = df[name].to_numpy(dtype=float)
        lo, hi = float(np.min(col)), float(np.max(col))
        span = hi - lo if hi > lo else 1.0
        a = 0.0 if not math.isfinite(b[0]) else np.clip((b[0] - lo) / span, 0, 1)
        c = 1.0 if not math.isfinite(b[1]) else np.clip((b[1] - lo) / span, 0, 1)
        ax.barh(yk, c - a, left=a, height=0.5, color="tab:blue", alpha=0.7)
        # the rule's thresholds, in the feature's display unit, on the shaded bar
        if b is not None and math.isfinite(b[0]):
            ax.text(a, yk + 0.3, f"> {format_value(b[0] * s)}", ha="left", va="bottom",
                    fontsize=6.5, color="tab:blue")  # fmt: skip
        if b is not None and math.isfinite(b[1]):
            ax.text(c, yk + 0.3, f"<= {format_value(b[1] * s)}", ha="right", va="bottom",
                    fontsize=6.5, color="tab:blue")  # fmt: skip
        ax.text(-0.02, yk, format_value(lo * s), ha="right", va="center", fontsize=7)
        ax.text(1.02, yk, f"{format_value(hi * s)} {u}".rstrip(), ha="left", va="center",
                fontsize=7)  # fmt: skip
    ax.set_yticks(range(len(names)))
    ax.set_yticklabels(list(reversed(names)))
    ax.set_xlim(-0.25, 1.3)
    ax.set_xticks([])
    row = miner.rules_.iloc[rule]
    ax.set_title(
        f"rule {rule + 1}: training precision {row['precision']:.2f}, "
        f"support {int(row['support'])}",
        fontsize=9,
    )
    return fig


def save_figure(fig, path, dpi: int = 120):
    """Save a matplotlib figure atomically (the format from the suffix) and close it."""
    import matplotlib.pyplot as plt

    try:
        return atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=dpi))
    finally:
        plt.close(fig)


def plot_rules(miner: ForestRuleMiner, X, path=None, **kw):
    """Box charts of all kept rules side by side; saved to ``path`` when given.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    k = max(len(miner.rules_), 1)
    nf = len(miner.feature_names_)
    fig, axes = plt.subplots(1, k, figsize=(5.5 * k, 0.8 + 0.45 * nf), squeeze=False)
    if not len(miner.rules_):
        axes[0, 0].text(0.5, 0.5, "no rule", ha="center", va="center")
        axes[0, 0].set_axis_off()
    for i in range(len(miner.rules_)):
        plot_rule_boxes(miner, X, i, ax=axes[0, i], **kw)
    fig.tight_layout()
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_rule_scatter(
    miner: ForestRuleMiner, X, y, features, rule: int = 0, *, ax=None, columns=None
):
    """Scatter of two features (Fig. 3E): target rows vs others, rows inside the rule marked.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    X : DataFrame or array, y : array of labels
    features : (str, str)
    rule : int, default=0
    columns : mapping, optional
        Name -> Column: axes in each column's display unit.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    names = miner.feature_names_
    fx, fy = features
    for f in (fx, fy):
        if f not in names:
            raise ValueError(f"feature {f!r} is not one of {', '.join(names)}")
    df = _frame(X, names)
    (sx, ux), (sy, uy) = _scale(columns, fx), _scale(columns, fy)
    pos = np.asarray(y) == miner.classes_[1]
    inside = miner.rule_matches(df)[rule]
    xs = df[fx].to_numpy(dtype=float) * sx
    ys = df[fy].to_numpy(dtype=float) * sy
    if ax is None:
        fig, ax = plt.subplots(figsize=(5, 4))
    else:
        fig = ax.figure
    ax.scatter(xs[~pos], ys[~pos], s=6, c="0.75", label="other designs")
    ax.scatter(xs[pos], ys[pos], s=10, c="tab:red", label="meets target")
    ax.scatter(
        xs[inside],
        ys[inside],
        s=40,
        facecolors="none",
        edgecolors="tab:blue",
        label=f"inside rule {rule + 1}",
    )
    bounds = dict(zip(names, miner.rule_bounds(rule), strict=True))
    for f, setter in ((fx, ax.axvline), (fy, ax.axhline)):
        b = bounds[f]
        if b is None or miner._encoding.categorical[names.index(f)]:
            continue
        for v in b:
            if math.isfinite(v):
                setter(v * _scale(columns, f)[0], color="tab:blue", ls="--", lw=1)
    ax.set_xlabel(f"{fx} [{ux}]" if ux else fx)
    ax.set_ylabel(f"{fy} [{uy}]" if uy else fy)
    ax.legend(fontsize=7, loc="best")
    return fig


def plot_feature_importance(miner: ForestRuleMiner, *, ax=None):
    """Bar chart of the forest's feature importances (encoded columns summed per feature).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    imp = miner.feature_importances_
    names = miner.feature_names_
    order = np.argsort(imp)
    if ax is None:
        fig, ax = plt.subplots(figsize=(5, 0.5 + 0.35 * len(names)))
    else:
        fig = ax.figure
    ax.barh(np.arange(len(names)), imp[order], color="tab:blue")
    ax.set_yticks(np.arange(len(names)))
    ax.set_yticklabels([names[i] for i in order])
    ax.set_xlabel("mean impurity importance")
    return fig


_NAME = r"(?:[A-Za-z_][A-Za-z0-9_.]*|`[^`]+`)"
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_SIMPLE = re.compile(rf"^({_NAME}|{_NUMBER})((?:\s*(?:<=|>=|<|>)\s*(?:{_NAME}|{_NUMBER}))+)$")
_LINK = re.compile(rf"\s*(<=|>=|<|>)\s*({_NAME}|{_NUMBER})")


def _target_thresholds(target: Target) -> list[tuple[str, float]]:
    """``(column, value)`` of each ``col < value`` / ``value < col`` condition of an and-target.

    Read from the target's canonical text (``str(target)``); a target with ``|`` or brackets
    gives none; a comparison between two columns or with ``==`` / ``!=`` is skipped.
    """
    text = str(target)
    if "|" in text or "(" in text:
        return []
    found = []
    for part in text.split(" & "):
        m = _SIMPLE.match(part.strip())
        if m is None:
            continue
        operands = [m.group(1)] + [g[1] for g in _LINK.findall(m.group(2))]
        names = [o for o in operands if re.fullmatch(_NAME, o) and not re.fullmatch(_NUMBER, o)]
        if len(names) != 1:
            continue
        col = names[0].strip("`")
        found += [(col, float(o)) for o in operands if re.fullmatch(_NUMBER, o)]
    return found


def _axis_label(name: str, units: Mapping) -> str:
    u = units.get(name)
    return f"{name} [{u}]" if u and u != "-" else name


def plot_target_scatter(
    table: pd.DataFrame,
    target,
    x: str,
    y: str,
    *,
    chosen: Mapping | None = None,
    units: Mapping | None = None,
    columns: Mapping | None = None,
    ax=None,
):
    """Scatter of a database in the (x, y) plane: rows meeting the target coloured, others grey.

    Parameters
    ----------
    table : DataFrame
        The database (features and performance, SI units); rows with a non-finite x or y are
        left out.
    target : Target or str
        The design target; a string is parsed against ``table``'s columns.
    x, y : str
        Columns for the two axes.
    chosen : mapping, optional
        The chosen design (values of at least ``x`` and ``y``), drawn as a large star.
    units : mapping, optional
        Unit per column for the axis labels, e.g. ``{"offset": "m"}``.
    columns : mapping, optional
        Name -> Column: the axes (and thresholds, chosen design) in each column's display unit
        and labelled with it (instead of ``units``).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Dashed lines mark the target's thresholds ``x < value`` / ``y > value`` where the
        target is a conjunction of such simple comparisons; an axis whose values are all
        positive and span more than two decades is logarithmic.
    """
    plt = _pyplot()
    if isinstance(target, str):
        target = parse_target(target, table.columns)
    for c in (x, y):
        if c not in table.columns:
            raise ValueError(f"column {c!r} is not in the table ({', '.join(map(str, table))})")
    units = dict(units or {})
    (sx, ux), (sy, uy) = _scale(columns, x), _scale(columns, y)
    if columns:
        units.update({x: ux, y: uy})
    meets = target.evaluate(table)
    xs = table[x].to_numpy(dtype=float) * sx
    ys = table[y].to_numpy(dtype=float) * sy
    ok = np.isfinite(xs) & np.isfinite(ys)
    hit, miss = ok & meets, ok & ~meets
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 4.5))
    else:
        fig = ax.figure
    ax.scatter(xs[miss], ys[miss], s=8, c="0.72", lw=0, label=f"other designs ({miss.sum()})")
    ax.scatter(xs[hit], ys[hit], s=14, c="tab:red", lw=0, label=f"meets the target ({hit.sum()})")
    if chosen is not None:
        ax.scatter(
            [float(chosen[x]) * sx],
            [float(chosen[y]) * sy],
            s=260,
            marker="*",
            c="gold",
            edgecolors="black",
            linewidths=0.8,
            zorder=5,
            label="chosen design",
        )
    for col, value in _target_thresholds(target):
        if col == x:
            ax.axvline(value * sx, color="tab:red", ls="--", lw=1)
        if col == y:
            ax.axhline(value * sy, color="tab:red", ls="--", lw=1)
    for values, set_scale in ((xs[ok], ax.set_xscale), (ys[ok], ax.set_yscale)):
        if values.size and values.min() > 0 and values.max() / values.min() > 100:
            set_scale("log")
    ax.set_xlabel(_axis_label(x, units))
    ax.set_ylabel(_axis_label(y, units))
    ax.set_title(f"target: {target}", fontsize=9)
    ax.legend(fontsize=8, loc="best")
    return fig


def _face_normals(polygons: Sequence[np.ndarray]) -> np.ndarray:
    """Unit normals of planar-ish polygons (Newell's method); zero for degenerate ones."""
    normals = np.zeros((len(polygons), 3))
    for i, p in enumerate(polygons):
        q = np.roll(p, -1, axis=0)
        n = np.array(
            [
                np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
                np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
                np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
            ]
        )
        length = np.linalg.norm(n)
        normals[i] = n / length if length > 0 else 0.0
    return normals


def plot_folded_design(
    vertices: np.ndarray,
    faces: Sequence,
    *,
    creases: np.ndarray | None = None,
    title: str = "",
    ax=None,
):
    """3D view of a folded design: shaded panels, thin panel edges, creases as lines.

    Parameters
    ----------
    vertices : ndarray of shape (n, 3)
        Node coordinates in m (shown in mm).
    faces : sequence of index arrays
        Panels as vertex indices (triangles or polygons).
    creases : ndarray of shape (k, 2) of int, optional
        Node pairs of the creases.
    title : str, default=""
    ax : 3D matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Orthographic view, equal aspect, seen from the front and a little above: suited to a
        strip arch whose curve lies in the x-z plane and whose width runs along y.
    """
    from matplotlib.ticker import FixedLocator, MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    plt = _pyplot()
    v = np.asarray(vertices, dtype=float)
    if v.ndim != 2 or v.shape[1] != 3 or not len(v):
        raise ValueError(f"vertices must have shape (n, 3), got {v.shape}")
    mm = v * 1e3
    polygons = [mm[np.asarray(f, dtype=int)] for f in faces]
    if ax is None:
        fig = plt.figure(figsize=(7, 4.5))
        ax = fig.add_subplot(projection="3d")
        fig.subplots_adjust(left=0.0, right=0.95, bottom=0.0, top=0.9)
    else:
        fig = ax.figure
    light = np.array([-0.3, -0.6, 0.75])
    light /= np.linalg.norm(light)
    shade = 0.45 + 0.55 * np.abs(_face_normals(polygons) @ light)
    base = np.array([0.55, 0.72, 0.9])
    colours = np.column_stack([np.clip(shade[:, None] * base, 0, 1), np.ones(len(polygons))])
    ax.add_collection3d(
        Poly3DCollection(polygons, facecolors=colours, edgecolors="0.3", linewidths=0.25)
    )
    if creases is not None and len(creases):
        c = np.asarray(creases, dtype=int).reshape(-1, 2)
        ax.add_collection3d(Line3DCollection(mm[c], colors="tab:red", linewidths=0.7))
    lo, hi = mm.min(axis=0), mm.max(axis=0)
    span = hi - lo
    pad = 1e-3 * max(span.max(), 1e-9)
    span = np.maximum(span, pad)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_zlim(lo[2] - pad, hi[2] + pad)
    ax.set_box_aspect(tuple(span + 2 * pad), zoom=1.0)
    ax.set_proj_type("ortho")
    ax.view_init(elev=20, azim=-70)
    for axis, s, a, b in zip((ax.xaxis, ax.yaxis, ax.zaxis), span, lo, hi, strict=True):
        if s < 0.2 * span.max():  # a short axis: its end ticks' labels would pile up
            step = 10.0 ** math.floor(math.log10(s))  # one tick, within s/2 of the centre
            axis.set_major_locator(FixedLocator([round((a + b) / 2 / step) * step]))
        else:
            axis.set_major_locator(MaxNLocator(nbins=max(1, round(6 * s / span.max()))))
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("z [mm]")
    if title:
        ax.set_title(title, fontsize=10)
    return fig
