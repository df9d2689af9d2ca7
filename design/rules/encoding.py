"""How a table's features map to the columns the trees see: categorical levels one-hot or
ordinal (:class:`Encoding`), then every column as the rank of its value (:class:`RankCodes`), so
that mining does not depend on units."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from holofold.design.rules.text import fmt_level

__all__ = ["Encoding", "RankCodes"]


@dataclass(frozen=True)
class Encoding:
    """How original features map to the encoded columns the trees see."""

    names: tuple  # original feature names
    categorical: tuple  # bool per original feature
    levels: tuple  # per original feature: ndarray of levels or None
    columns: tuple  # per encoded column: (original index, level index or -1)
    mode: str  # "onehot" or "ordinal"

    @property
    def n_encoded(self) -> int:
        return len(self.columns)

    def encode(self, X) -> np.ndarray:
        n = X.shape[0]
        Z = np.empty((n, self.n_encoded), dtype=np.float64)
        codes = {}
        for j, is_cat in enumerate(self.categorical):
            if not is_cat:
                continue
            lv = self.levels[j]
            col = X[:, j]
            idx = np.searchsorted(lv, col) if lv.dtype != object else None
            if idx is None:
                lookup = {v: i for i, v in enumerate(lv)}
                bad = [v for v in col if v not in lookup]
                idx = np.array([lookup.get(v, -1) for v in col], dtype=np.intp)
            else:
                idx = np.clip(idx, 0, len(lv) - 1)
                badmask = lv[idx] != col
                bad = list(col[badmask])
            if len(bad):
                raise ValueError(
                    f"categorical feature {self.names[j]!r} has level {fmt_level(bad[0])} not "
                    f"seen in fit; known levels: {', '.join(fmt_level(v) for v in lv)}"
                )
            codes[j] = idx
        for c, (j, li) in enumerate(self.columns):
            if not self.categorical[j]:
                Z[:, c] = X[:, j]
            elif self.mode == "ordinal":
                Z[:, c] = codes[j]
            else:
                Z[:, c] = codes[j] == li
        return Z

    def allowed_levels(self, j: int, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
        """Levels of categorical feature ``j`` allowed by each box.

        Parameters
        ----------
        lower, upper : ndarray, shape (n_boxes, n_encoded)

        Returns
        -------
        ndarray of bool, shape (n_boxes, n_levels)
        """
        cols = [c for c, (jj, _) in enumerate(self.columns) if jj == j]
        n_lv = len(self.levels[j])
        if self.mode == "ordinal":
            code = np.arange(n_lv, dtype=np.float64)
            return (code > lower[:, cols[0], None]) & (code <= upper[:, cols[0], None])
        lo, hi = lower[:, cols], upper[:, cols]
        ok_one = (1.0 > lo) & (1.0 <= hi)  # the level's own indicator is 1 ...
        ok_zero = (0.0 > lo) & (0.0 <= hi)  # ... and every other indicator is 0
        others_ok = ok_zero.sum(axis=1, keepdims=True) - ok_zero == n_lv - 1
        return ok_one & others_ok

    def decode_all(self, lower: np.ndarray, upper: np.ndarray) -> dict:
        """Per original feature, the bounds of all boxes (vectorised).

        Returns
        -------
        dict name -> (gt, le) arrays of shape (n_boxes,) for numeric features, or a list of
        tuples of allowed levels (None when unconstrained) for categorical ones.
        """
        out = {}
        for j, name in enumerate(self.names):
            if not self.categorical[j]:
                c = next(c for c, (jj, _) in enumerate(self.columns) if jj == j)
                out[name] = (lower[:, c].astype(float), upper[:, c].astype(float))
            else:
                ok = self.allowed_levels(j, lower, upper)
                lv = self.levels[j]
                out[name] = [None if row.all() else tuple(lv[row].tolist()) for row in ok]
        return out

    def decode(self, lower: np.ndarray, upper: np.ndarray) -> list:
        """Bounds of one box: per original feature (gt, le) or allowed levels (or None)."""
        d = self.decode_all(lower[None, :], upper[None, :])
        return [
            d[n][0] if self.categorical[j] else (float(d[n][0][0]), float(d[n][1][0]))
            for j, n in enumerate(self.names)
        ]


@dataclass(frozen=True)
class RankCodes:
    """The rank of each value among a column's distinct training values: what the trees see.

    scikit-learn's splitter treats feature values closer than 1e-7 as equal, so a feature in
    metres that lives at the micrometre scale cannot be split; the order of the values is all a
    tree's split search uses, so trees grown on ranks are the trees grown on any well-scaled
    copy of the table, and the same whether it is in m, mm or um. ``values[j]`` maps a code of
    encoded column ``j`` back to its value in the table's units
    (:func:`~holofold.design.rules.forest.tree_arrays` places every threshold there).
    """

    values: tuple  # per encoded column: sorted distinct training values (float64)

    @classmethod
    def fit(cls, Z: np.ndarray) -> RankCodes:
        Z = np.asarray(Z, dtype=np.float64)
        return cls(tuple(np.unique(Z[:, j]) for j in range(Z.shape[1])))

    def codes(self, Z: np.ndarray) -> np.ndarray:
        """(n, d) float32 codes of rows whose values were all seen in :meth:`fit`."""
        Z = np.asarray(Z, dtype=np.float64)
        out = np.empty(Z.shape, dtype=np.float32)
        for j, v in enumerate(self.values):
            out[:, j] = np.searchsorted(v, Z[:, j])
        if max((len(v) for v in self.values), default=0) > 2**24:
            raise ValueError("more than 2^24 distinct values in one feature")
        return out
