"""The miner's parameters and their one check (scikit-learn's message form, without its private
validation module): ``The 'beta' parameter of ForestRuleMiner must be a float in the range
(0, inf). Got 0 instead.``"""

from __future__ import annotations

from numbers import Integral, Real

import numpy as np

__all__ = ["check_params", "PARAMETERS"]


def _int(v) -> bool:
    return isinstance(v, Integral) and not isinstance(v, bool)


def _real(v) -> bool:
    return isinstance(v, Real) and not isinstance(v, bool) and not np.isnan(v)


def _range(kind, lo, hi, closed):
    """A number of ``kind`` ('int' or 'float') in an interval; ``closed`` as in 'left'."""
    test = _int if kind == "int" else _real
    left = "[" if closed in ("left", "both") else "("
    right = "]" if closed in ("right", "both") else ")"
    end = "inf" if hi is None else str(hi)
    text = f"{'an int' if kind == 'int' else 'a float'} in the range {left}{lo}, {end}"

    def ok(v):
        if not test(v):
            return False
        above = v >= lo if left == "[" else v > lo
        below = hi is None or (v <= hi if right == "]" else v < hi)
        return above and below

    return ok, text + right


def _options(*values):
    return (lambda v: isinstance(v, str) and v in values), (
        "a str among {" + ", ".join(repr(x) for x in sorted(values)) + "}"
    )


_NONE = ((lambda v: v is None), "None")
_BOOL = ((lambda v: isinstance(v, bool | np.bool_)), "an instance of 'bool'")
_DICT = ((lambda v: isinstance(v, dict)), "an instance of 'dict'")
_ARRAY = (
    (lambda v: isinstance(v, list | tuple | np.ndarray) or hasattr(v, "__array__")),
    "an array-like",
)
_SEED = (
    (lambda v: v is None or _int(v) or isinstance(v, np.random.RandomState)),
    "an int, a numpy.random.RandomState instance or None",
)
_ANY_INT = ((_int), "an int")

#: parameter -> the alternatives it may take, each (test, description)
PARAMETERS = {
    "n_estimators": [_range("int", 1, None, "left")],
    "criterion": [_options("entropy", "gini", "log_loss")],
    "max_depth": [_range("int", 1, None, "left"), _NONE],
    "ccp_alpha": [_range("float", 0, None, "left")],
    "min_samples_leaf": [_range("int", 1, None, "left")],
    "min_samples_split": [_range("int", 2, None, "left")],
    "max_features": [
        _range("int", 1, None, "left"),
        _range("float", 0, 1, "right"),
        _options("sqrt", "log2"),
        _NONE,
    ],
    "max_samples": [_range("int", 1, None, "left"), _range("float", 0, 1, "right")],
    "class_weight": [_options("balanced"), _DICT, _NONE],
    "precision_min": [_range("float", 0, 1, "both")],
    "recall_min": [_range("float", 0, 1, "both")],
    "min_support": [_range("int", 1, None, "left")],
    "beta": [_range("float", 0, None, "neither")],
    "n_rules": [_range("int", 1, None, "left")],
    "max_overlap": [_range("float", 0, 1, "right"), _NONE],
    "scoring": [_options("train", "oob", "estimate")],
    "ranking": [_options("fbeta", "lcb")],
    "prior_strength": [_options("auto"), _range("float", 0, None, "left"), _NONE],
    "simplify": [_options("none", "idle", "estimate")],
    "tighten": [_BOOL],
    "categorical_features": [_ARRAY, _NONE],
    "categorical_encoding": [_options("onehot", "ordinal")],
    "tree_seeds": [_options("random", "index")],
    "random_state": [_SEED],
    "n_jobs": [_ANY_INT, _NONE],
}


def check_params(estimator) -> None:
    """Refuse a parameter value outside :data:`PARAMETERS` in one line (a ValueError in
    scikit-learn's form, which ``holofold mine`` turns into its option's name)."""
    name = type(estimator).__name__
    for key, value in estimator.get_params(deep=False).items():
        alternatives = PARAMETERS.get(key)
        if alternatives is None or any(ok(value) for ok, _ in alternatives):
            continue
        texts = [text for _, text in alternatives]
        must = texts[0] if len(texts) == 1 else ", ".join(texts[:-1]) + " or " + texts[-1]
        raise ValueError(f"The {key!r} parameter of {name} must be {must}. Got {value!r} instead.")
