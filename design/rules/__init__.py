"""Random-forest rule mining: human-readable design rules from a performance database.

The method of Zhu & Filipov (2022), done exactly and fast:

1. train a forest of decision trees (entropy, balanced classes, deep, lightly pruned), each on a
   random subset of the training rows drawn *without* replacement;
2. every leaf that predicts the target class is a candidate rule: an axis-aligned box with
   scikit-learn's own semantics (``x <= t`` left, ``x > t`` right, X compared as float32), the
   tightest bound per feature and side, any real threshold (0 included);
3. identical boxes found by several trees are merged;
4. each rule is scored on the training rows (precision, recall, support) -- or, optionally, on
   the out-of-bag rows of the trees that found it -- filtered by ``precision_min`` and
   ``min_support`` and ranked by F-beta (or by F-beta of a lower confidence bound of precision);
5. the best ``n_rules`` that are not near-copies of a better one are kept; ``predict`` is
   "inside any kept rule".

holofold adds, chosen on a suite of 45 targets (``benchmarks/bench_rule_suite.py``): each kept
rule's numeric bounds move in to its outermost target training rows (``tighten``), conditions
that change none of its rows are dropped (``simplify``), and every rule carries an *estimate*
of its precision on new designs with a 95 % interval: the out-of-bag rows of the trees that
found it, shrunk by an empirical-Bayes prior fitted to all candidate leaves.

Extraction is one top-down pass over the concatenated node arrays of all trees (a loop over
depth levels, vectorised over all nodes of the forest); scoring uses each tree's ``apply`` and a
``bincount`` over all (row, tree) pairs, which is exact because a leaf's region *is* its box.

The package holds one concept per module: :mod:`.forest` (trees to boxes), :mod:`.statistics`,
:mod:`.boxes` (rows in boxes, tightening and simplifying), :mod:`.encoding` (categorical
features), :mod:`.text`, :mod:`.miner` (the estimator) and :mod:`.record` (a rule as a typed
record: its JSON form and how it is applied).
"""

from holofold.design.rules.boxes import boxes_contain
from holofold.design.rules.forest import ForestArrays, forest_boxes, stack_trees
from holofold.design.rules.miner import SELECTION_PARAMS, FewRulesWarning, ForestRuleMiner
from holofold.design.rules.record import Condition, Estimate, Rule, RuleError, Score
from holofold.design.rules.text import level_value

__all__ = [
    "Rule",
    "Condition",
    "Score",
    "Estimate",
    "RuleError",
    "ForestRuleMiner",
    "FewRulesWarning",
    "SELECTION_PARAMS",
    "ForestArrays",
    "stack_trees",
    "forest_boxes",
    "boxes_contain",
    "level_value",
]
