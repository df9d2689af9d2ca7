"""Output of mined rules: text, DataFrame and figures (JSON: :mod:`holofold.design.rulefile`).

Figures follow the paper: a box chart per rule (each feature's full range as a bar, the rule's
range shaded; Fig. 2F), a scatter of two features with the rows inside the rule marked against
the target (Fig. 3E), and the forest's feature importances. matplotlib is imported inside the
plotting functions (Agg backend when none is set), so importing this module costs nothing.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from holofold.design.rules import ForestRuleMiner, format_rule, level_value
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
]


def rules_frame(miner: ForestRuleMiner, test: pd.DataFrame | None = None) -> pd.DataFrame:
    """``miner.rules_``, with test metrics (from ``evaluation.rule_scores``) as ``test_*``."""
    frame = miner.rules_.copy()
    if test is not None:
        if len(test) != len(frame):
            raise ValueError(f"test has {len(test)} rows for {len(frame)} rules")
        frame = pd.concat([frame, test.reset_index(drop=True).add_prefix("test_")], axis=1)
    return frame


def _categorical_names(miner: ForestRuleMiner) -> set:
    enc = miner._encoding
    return {n for n, c in zip(enc.names, enc.categorical, strict=True) if c}


def rules_to_text(
    miner: ForestRuleMiner,
    test: pd.DataFrame | None = None,
    *,
    scale: dict | None = None,
    units: dict | None = None,
    digits: int = 4,
) -> str:
    """Human-readable list of the kept rules with their metrics.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    test : DataFrame, optional
        Test metrics per rule (``precision``, ``recall``, ``support``).
    scale, units : dict, optional
        Display factor and unit per feature, e.g. ``{"W": 1e3}``, ``{"W": "mm"}``.
    digits : int, default=4
    """
    rules = miner.rules_
    if not len(rules):
        return (
            f"no rule reaches precision >= {miner.precision_min} with support >= "
            f"{miner.min_support} ({miner.n_candidates_} candidate boxes)"
        )
    lines = []
    for i, row in rules.iterrows():
        text = format_rule(
            miner.rule_bounds(i),
            miner.feature_names_,
            categorical=_categorical_names(miner),
            digits=digits,
            scale=scale,
            units=units,
        )
        lines.append(f"rule {i + 1}: {text}")
        lines.append(
            f"    train: precision {row['precision']:.3f}  recall {row['recall']:.3f}  "
            f"support {int(row['support'])}"
        )
        if test is not None:
            t = test.iloc[i]
            lines.append(
                f"    test:  precision {t['precision']:.3f}  recall {t['recall']:.3f}  "
                f"support {int(t['support'])}"
            )
    if len(rules) < miner.n_rules:
        lines.append(f"(only {len(rules)} of the {miner.n_rules} requested rules survived)")
    return "\n".join(lines)


def mining_summary(mined, source: str) -> str:
    """What ``holofold mine`` prints: the table, target, features, split and the rules.

    ``mined``: a :class:`~holofold.design.mining.MinedRules`; ``source``: the table's name.
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
        rules_to_text(m, mined.test_scores),
    ]
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


def plot_rule_boxes(
    miner: ForestRuleMiner,
    X,
    rule: int = 0,
    *,
    ax=None,
    scale: dict | None = None,
    units: dict | None = None,
):
    """Box chart of one rule (Fig. 2F): per feature its full data range, the rule range shaded.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    X : DataFrame or array of shape (n_samples, n_features)
        Data giving each feature's full range (e.g. the whole database).
    rule : int, default=0
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    names = miner.feature_names_
    df = _frame(X, names)
    scale = scale or {}
    units = units or {}
    bounds = miner.rule_bounds(rule)
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 0.5 + 0.45 * len(names)))
    else:
        fig = ax.figure
    for k, (name, b) in enumerate(zip(names, bounds, strict=True)):
        yk = len(names) - 1 - k
        ax.barh(yk, 1.0, left=0.0, height=0.5, color="0.88", edgecolor="0.5")
        s = scale.get(name, 1.0)
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
        col = df[name].to_numpy(dtype=float)
        lo, hi = float(np.min(col)), float(np.max(col))
        span = hi - lo if hi > lo else 1.0
        a = 0.0 if not math.isfinite(b[0]) else np.clip((b[0] - lo) / span, 0, 1)
        c = 1.0 if not math.isfinite(b[1]) else np.clip((b[1] - lo) / span, 0, 1)
        ax.barh(yk, c - a, left=a, height=0.5, color="tab:blue", alpha=0.7)
        u = units.get(name, "")
        ax.text(-0.02, yk, f"{lo * s:.3g}", ha="right", va="center", fontsize=7)
        ax.text(1.02, yk, f"{hi * s:.3g} {u}".rstrip(), ha="left", va="center", fontsize=7)
    ax.set_yticks(range(len(names)))
    ax.set_yticklabels(list(reversed(names)))
    ax.set_xlim(-0.25, 1.3)
    ax.set_xticks([])
    row = miner.rules_.iloc[rule]
    ax.set_title(
        f"rule {rule + 1}: precision {row['precision']:.2f}, support {int(row['support'])}",
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
    miner: ForestRuleMiner, X, y, features, rule: int = 0, *, ax=None, scale=None
):
    """Scatter of two features (Fig. 3E): target rows vs others, rows inside the rule marked.

    Parameters
    ----------
    miner : fitted ForestRuleMiner
    X : DataFrame or array, y : array of labels
    features : (str, str)
    rule : int, default=0

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
    scale = scale or {}
    pos = np.asarray(y) == miner.classes_[1]
    inside = miner.rule_matches(df)[rule]
    xs = df[fx].to_numpy(dtype=float) * scale.get(fx, 1.0)
    ys = df[fy].to_numpy(dtype=float) * scale.get(fy, 1.0)
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
                setter(v * scale.get(f, 1.0), color="tab:blue", ls="--", lw=1)
    ax.set_xlabel(fx)
    ax.set_ylabel(fy)
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
