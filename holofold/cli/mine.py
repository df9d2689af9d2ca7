"""``holofold mine``: design rules for a target from a performance database."""

from __future__ import annotations

import argparse
import json
import logging
import warnings
from pathlib import Path

__all__ = ["register", "run"]

logger = logging.getLogger(__name__)

_PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def _names(text: str | None) -> list[str] | None:
    if text is None:
        return None
    items = [t for t in text.replace(",", " ").split() if t]
    return items


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "mine",
        help="mine interpretable design rules for a target from a database",
        description=(
            "Train a forest of decision trees on a hold-out training split of a performance "
            "database, turn its leaves into axis-aligned design rules, and print the best "
            "rules with their train and test precision, recall and support. The split is "
            "train_test_split(test_size=0.4, random_state=SEED) over the rows in file order."
        ),
    )
    p.add_argument("database", metavar="DB", help="CSV/Parquet with a header, or published .txt")
    p.add_argument(
        "--target",
        required=True,
        metavar="EXPR",
        help="target over performance columns, e.g. 'Zstiff > 800 & Xstiff > 600 & error < 0.1'",
    )
    p.add_argument(
        "--columns",
        metavar="NAMES",
        help="column names of a headerless .txt (comma/space separated; default: the sibling "
        "*_FeatureName.txt)",
    )
    p.add_argument(
        "--features",
        metavar="NAMES",
        help="design features to use (default: the database's design features)",
    )
    p.add_argument(
        "--categorical",
        metavar="NAMES",
        help="categorical features, e.g. m,pattern (default: those of the published database)",
    )
    p.add_argument("--rules", type=int, default=3, metavar="K", help="rules to keep (default 3)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="split and forest seed")
    p.add_argument("--test-size", type=float, default=0.4, help="test fraction (default 0.4)")
    p.add_argument("--trees", type=int, default=100, help="number of trees (default 100)")
    p.add_argument("--depth", type=int, default=20, help="maximum tree depth (default 20)")
    p.add_argument("--precision-min", type=float, default=0.9, help="default 0.9")
    p.add_argument("--min-support", type=int, default=10, help="default 10")
    p.add_argument("--beta", type=float, default=0.2, help="F-beta for ranking (default 0.2)")
    p.add_argument(
        "--max-overlap",
        type=float,
        default=None,
        metavar="J",
        help="keep only alternatives whose covered rows overlap earlier rules' by Jaccard <= J",
    )
    p.add_argument(
        "--scoring",
        choices=("oob", "train"),
        default="oob",
        help="rows that estimate precision for ranking (default oob; paper: train)",
    )
    p.add_argument(
        "--ranking",
        choices=("lcb", "fbeta"),
        default="lcb",
        help="rank by F-beta of the precision's lower confidence bound (default) or of "
        "the precision itself (paper)",
    )
    p.add_argument("--jobs", type=int, default=None, help="threads for training")
    p.add_argument("--json", metavar="PATH", help="write the rules (best first) as JSON")
    p.add_argument("--plot", metavar="PATH", help="write box charts of the rules (.png/.pdf/.svg)")
    return p


def _check_output(path: str | None, what: str, suffixes=None) -> Path | None:
    if path is None:
        return None
    p = Path(path)
    if not p.parent.is_dir():
        raise ValueError(f"{what} directory {p.parent} does not exist")
    if suffixes and p.suffix.lower() not in suffixes:
        raise ValueError(f"{what} {p.name}: unknown type, expected one of {', '.join(suffixes)}")
    return p


def run(args) -> int:
    from holofold.design.database import column_roles, read_table
    from holofold.design.evaluation import rule_scores, split_indices
    from holofold.design.report import plot_rules, rules_to_records, rules_to_text
    from holofold.design.rules import FewRulesWarning, ForestRuleMiner
    from holofold.design.targets import parse_target
    from holofold.mechanics.status import failed_mask

    # ---- validate everything before any output --------------------------------------------
    if args.rules < 1:
        raise ValueError(f"--rules must be >= 1, got {args.rules}")
    if not 0 < args.test_size < 1:
        raise ValueError(f"--test-size must be in (0, 1), got {args.test_size}")
    if args.trees < 1:
        raise ValueError(f"--trees must be >= 1, got {args.trees}")
    if args.depth < 1:
        raise ValueError(f"--depth must be >= 1, got {args.depth}")
    if not 0 <= args.precision_min <= 1:
        raise ValueError(f"--precision-min must be in [0, 1], got {args.precision_min}")
    if args.min_support < 1:
        raise ValueError(f"--min-support must be >= 1, got {args.min_support}")
    if args.beta <= 0:
        raise ValueError(f"--beta must be > 0, got {args.beta}")
    if args.max_overlap is not None and not 0 < args.max_overlap <= 1:
        raise ValueError(f"--max-overlap must be in (0, 1], got {args.max_overlap}")
    json_path = _check_output(args.json, "--json")
    plot_path = _check_output(args.plot, "--plot", _PLOT_SUFFIXES)

    table = read_table(args.database, columns=_names(args.columns))
    if "status" in table.columns:  # a holofold database: failed simulations have no outputs
        failed = failed_mask(table["status"])
        if failed.any():
            print(f"note: {int(failed.sum())} failed simulation(s) left out")
            table = table.loc[~failed].reset_index(drop=True)
    columns = [str(c) for c in table.columns]
    target = parse_target(args.target, columns=columns)
    roles = column_roles(columns, args.database)
    features = _names(args.features)
    if features is None:
        if roles is None:
            raise ValueError(
                "cannot tell design features from performance columns in "
                f"{Path(args.database).name} ({', '.join(columns)}); list them with --features"
            )
        features = list(roles.features)
    for f in features:
        if f not in columns:
            raise ValueError(f"feature {f!r} is not a column; columns: {', '.join(columns)}")
    if len(set(features)) != len(features):
        raise ValueError(f"--features lists a column twice: {', '.join(features)}")
    performance = set(roles.performance) if roles is not None else set()
    bad = [f for f in features if f in performance or f in target.columns]
    if bad:
        raise ValueError(
            f"{bad[0]!r} is a performance column (or used by the target) and cannot be a feature"
        )
    cats = _names(args.categorical)
    if cats is None:
        cats = [c for c in (roles.categorical if roles else ()) if c in features]
    for c in cats:
        if c not in features:
            raise ValueError(
                f"categorical feature {c!r} is not among the features: {', '.join(features)}"
            )

    y = target.evaluate(table)
    n_hit = int(y.sum())
    if n_hit == 0 or n_hit == y.size:
        raise ValueError(
            f"the target {args.target!r} is met by {n_hit} of {y.size} rows; rules need both "
            "designs that meet it and designs that do not"
        )
    X = table[features]
    train, test = split_indices(len(table), test_size=args.test_size, random_state=args.seed)
    if y[train].all() or not y[train].any():
        raise ValueError("the training split holds only one class; change --seed or --test-size")

    miner = ForestRuleMiner(
        n_estimators=args.trees,
        max_depth=args.depth,
        precision_min=args.precision_min,
        min_support=args.min_support,
        beta=args.beta,
        n_rules=args.rules,
        max_overlap=args.max_overlap,
        scoring=args.scoring,
        ranking=args.ranking,
        categorical_features=cats or None,
        random_state=args.seed,
        n_jobs=args.jobs,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FewRulesWarning)
        miner.fit(X.iloc[train], y[train])
    scores = rule_scores(miner, X.iloc[test], y[test])

    print(f"database: {args.database} ({len(table)} rows)")
    print(f"target:   {target} (met by {n_hit} rows, {100 * n_hit / y.size:.1f} %)")
    cat_note = f" (categorical: {', '.join(cats)})" if cats else ""
    print(f"features: {', '.join(features)}{cat_note}")
    print(
        f"split:    {len(train)} train / {len(test)} test rows (seed {args.seed}); "
        f"{miner.n_candidates_} candidate boxes, {len(miner.candidate_rules_)} pass the filters"
    )
    print(rules_to_text(miner, scores))

    if json_path is not None:
        json_path.write_text(json.dumps(rules_to_records(miner, scores), indent=2) + "\n")
        print(f"wrote {json_path}")
    if plot_path is not None:
        fig = plot_rules(miner, X)
        fig.savefig(plot_path, dpi=120)
        print(f"wrote {plot_path}")
    return 0
