"""Rules as text, in the units people read: ``tcrease <= 0.779 mm and m in {16, 24}``.

Thresholds are shown in each feature's display unit through
:func:`holofold.design.scenarios.format_value` (a feature without a column reads as a bare SI
number); the text is for reading, the rule's SI bounds are what is applied.
"""

from __future__ import annotations

import numpy as np

from holofold.design.scenarios.base import format_value

__all__ = ["condition_text", "box_text", "level_value", "fmt_level"]


def level_value(v):
    """A categorical level as a plain Python number (8.0 -> 8) for text and JSON."""
    if isinstance(v, float | np.floating) and float(v).is_integer():
        return int(v)
    if isinstance(v, np.generic):
        return v.item()
    return v


def fmt_level(v) -> str:
    return str(level_value(v))


def condition_text(name: str, gt=None, le=None, levels=None, column=None, digits: int = 3) -> str:
    """One condition as text: ``name <= 0.779 mm``, ``0.5 < W <= 2 mm`` (the unit once, after
    the upper end), ``name > 65.8 deg``, ``m = 16`` or ``m in {16, 24}``; a category whose
    column names its levels with the name: ``pattern = 2 (TMP)``.

    ``gt``/``le`` are SI (None for an open side), ``levels`` the allowed categorical values,
    ``column`` the feature's :class:`~holofold.design.scenarios.Column` (its display unit).
    """
    if levels is not None:
        named = column is not None and getattr(column, "names", ())
        lv = [
            fmt_level(v) + (f" ({column.level_name(v)})" if named and column.level_name(v) else "")
            for v in levels
        ]
        return f"{name} = {lv[0]}" if len(lv) == 1 else f"{name} in {{{', '.join(lv)}}}"
    if gt is not None and le is not None:
        f = 1.0 if column is None else column.display_factor
        return f"{format_value(gt * f, digits=digits)} < {name} <= " + format_value(
            le, column, digits=digits
        )
    if gt is not None:
        return f"{name} > {format_value(gt, column, digits=digits)}"
    return f"{name} <= {format_value(le, column, digits=digits)}"


def box_text(bounds, names, *, categorical=(), columns=None, digits: int = 3) -> str:
    """A decoded box as text: per feature ``(gt, le)`` (+-inf when open) or a tuple of allowed
    levels (None when unconstrained), joined by ``and``; ``"(any design)"`` for no condition.
    ``columns``: name -> Column for display units."""
    cols = columns or {}
    parts = []
    for name, b in zip(names, bounds, strict=True):
        if b is None:
            continue
        if name in categorical:
            parts.append(condition_text(name, levels=b, column=cols.get(name)))
            continue
        gt, le = (None if not np.isfinite(v) else float(v) for v in b)
        if gt is not None or le is not None:
            parts.append(condition_text(name, gt, le, column=cols.get(name), digits=digits))
    return " and ".join(parts) if parts else "(any design)"
