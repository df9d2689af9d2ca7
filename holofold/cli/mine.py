"""``holofold mine``: design rules for a target from a performance database."""

from __future__ import annotations

import argparse
import re
import sys
import warnings

__all__ = ["HELP", "DESCRIPTION", "add_arguments", "run"]

_PLOT_SUFFIXES = (".png", ".pdf", ".svg")
#: ForestRuleMiner parameter -> the argument that sets it (--trees sets n_estimators, ...)
_MINER_ARGS = {
    "n_estimators": "trees",
    "max_depth": "depth",
    "precision_min": "precision_min",
    "min_support": "min_support",
    "beta": "beta",
    "n_rules": "rules",
    "max_overlap": "max_overlap",
    "scoring": "scoring",
    "ranking": "ranking",
    "tighten": "tighten",
    "simplify": "simplify",
    "ccp_alpha": "ccp_alpha",
    "criterion": "criterion",
    "max_samples": "max_samples",
    "n_jobs": "jobs",
}


def _fraction_or_count(text: str):
    """--max-samples: a fraction of the training rows (0.5, 1.0) or a count of rows (300)."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is neither a fraction of the rows (0.5) nor a number of rows (300)"
        ) from None


def _names(text: str | None) -> list[str] | None:
    return None if text is None else [t for t in text.replace(",", " ").split() if t]


HELP = "mine interpretable design rules for a target from a database"
DESCRIPTION = (
    "Train a forest of decision trees on a hold-out training split of a performance "
    "database, turn its leaves into axis-aligned design rules, and print the best "
    "rules with their estimated precision (95 % interval), their train and held-out "
    "precision, recall and support, and the features the target does not depend on. "
    "The split is train_test_split(test_size=0.4, random_state=SEED) over the rows in "
    "file order. The paper's method: --scoring train --ranking fbeta (the default "
    "ranking, without tightening)."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
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
    p.add_argument(
        "--trees",
        type=int,
        default=100,
        help="number of trees (default 100); a forest estimated to need over 4 GiB or 5 min is "
        "refused without --force (docs/limits.md)",
    )
    p.add_argument(
        "--depth", type=int, default=20, help="maximum tree depth (default 20, at most 1000)"
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="train a forest over the memory and time limits all the same",
    )
    p.add_argument("--precision-min", type=float, default=0.9, help="default 0.9")
    p.add_argument("--min-support", type=int, default=10, help="default 10")
    p.add_argument("--beta", type=float, default=0.2, help="F-beta for ranking (default 0.2)")
    p.add_argument(
        "--max-overlap",
        type=float,
        default=0.5,
        metavar="J",
        help="skip a rule whose covered training rows overlap an earlier rule's by Jaccard > J "
        "(default 0.5; 1 keeps near-copies)",
    )
    p.add_argument(
        "--scoring",
        choices=("train", "oob", "estimate"),
        default=None,
        help="precision used for ranking: training rows (default, as the paper), out-of-bag "
        "rows, or the shown estimate",
    )
    p.add_argument(
        "--ranking",
        choices=("fbeta", "lcb"),
        default=None,
        help="rank by F-beta of the precision (default, as the paper) or of its 95 %% lower "
        "confidence bound",
    )
    p.add_argument(
        "--tighten",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="move the kept rules' bounds in to their outermost target rows (default: yes; "
        "no when --scoring train --ranking fbeta are given, which select the paper's method)",
    )
    p.add_argument(
        "--simplify",
        choices=("none", "idle", "estimate"),
        default="idle",
        help="drop conditions that do not change the rule's rows (idle, default), also those "
        "that do not raise the estimate (estimate), or none",
    )
    p.add_argument(
        "--ccp-alpha",
        type=float,
        default=None,
        metavar="A",
        help="minimal cost-complexity pruning of each tree (default 1e-4, as the paper)",
    )
    p.add_argument(
        "--criterion",
        choices=("entropy", "gini", "log_loss"),
        default=None,
        help="split criterion of the trees (default entropy, as the paper)",
    )
    p.add_argument(
        "--max-samples",
        type=_fraction_or_count,
        default=None,
        metavar="R",
        help="rows per tree, drawn without replacement: a fraction of the training rows in "
        "(0, 1] (default 0.5, as the paper) or a number of rows",
    )
    p.add_argument("--jobs", type=int, default=None, help="threads for training")
    p.add_argument("--json", metavar="PATH", help="write the rules (best first) as JSON")
    p.add_argument("--plot", metavar="PATH", help="write box charts of the rules (.png/.pdf/.svg)")


def _in_option_terms(exc: ValueError) -> ValueError:
    """scikit-learn's parameter message, naming the command's option instead."""
    m = re.match(r"The '(\w+)' parameter of \w+ (must be .*?)\. Got (.*) instead\.", str(exc))
    if not m or m.group(1) not in _MINER_ARGS:
        return exc
    flag = "--" + _MINER_ARGS[m.group(1)].replace("_", "-")
    return ValueError(f"{flag} {m.group(2)}, got {m.group(3)}")


def run(args) -> int:
    from holofold.design import (
        FewRulesWarning,
        column_roles,
        mine_rules,
        mined_rules,
        mining_summary,
        plot_rules,
        read_table,
        save_figure,
        table_columns,
        write_rules,
    )
    from holofold.geometry import check_output_path

    json_path = args.json and check_output_path(args.json, "--json")
    plot_path = args.plot and check_output_path(args.plot, "--plot", _PLOT_SUFFIXES)
    if args.tighten is None and (args.scoring, args.ranking) == ("train", "fbeta"):
        args.tighten = False  # asked for the paper's method by name: its leaves as they are
    table = read_table(args.database, columns=_names(args.columns))
    with warnings.catch_warnings():  # the summary says when fewer rules survive
        warnings.simplefilter("ignore", FewRulesWarning)
        try:
            mined = mine_rules(
                table,
                args.target,
                roles=column_roles(table.columns, args.database),
                features=_names(args.features),
                categorical=_names(args.categorical),
                test_size=args.test_size,
                seed=args.seed,
                source=args.database,
                force=args.force,
                progress=lambda line: print(f"holofold mine: {line}", file=sys.stderr),
                **{
                    param: getattr(args, arg)
                    for param, arg in _MINER_ARGS.items()
                    if getattr(args, arg) is not None  # unset: the miner's default
                },
            )
        except ValueError as exc:
            raise _in_option_terms(exc) from None
    columns = table_columns(table.columns, args.database)  # display units (mm, um, deg)
    print(mining_summary(mined, args.database, columns))
    # the figure is drawn before any file is written: a failing plot leaves no JSON behind
    fig = plot_path and plot_rules(mined.miner, mined.table[list(mined.features)], columns=columns)
    if json_path:
        write_rules(json_path, mined_rules(mined.miner, mined.test_scores), columns)
        print(f"wrote {json_path}")
    if plot_path:
        save_figure(fig, plot_path)
        print(f"wrote {plot_path}")
    return 0
