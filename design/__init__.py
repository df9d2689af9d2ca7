"""holofold.design: scenarios, databases, design rules and their verification.

The top layer of the library (imports geometry, fitting and mechanics, never the reverse):
the paper's scenarios (:mod:`~holofold.design.scenarios`), sampling and validated batch
evaluation (:mod:`~holofold.design.sampling`, :mod:`~holofold.design.runner`), the resumable
Parquet store (:mod:`~holofold.design.store`), tables (:mod:`~holofold.design.tables`), the
target language (:mod:`~holofold.design.targets`), the forest rule miner and its evaluation
(:mod:`~holofold.design.rules`, :mod:`~holofold.design.evaluation`,
:mod:`~holofold.design.mining`), rules files (:mod:`~holofold.design.rulefile`), reports
(:mod:`~holofold.design.report`), verification (:mod:`~holofold.design.verify`) and the demo
(:mod:`~holofold.design.demo`). See docs/rule-miner.md and docs/scenarios.md.
"""

from holofold.design.demo import DEMO_TARGET, run_demo
from holofold.design.evaluation import (
    HoldoutResult,
    holdout,
    repeated_holdout,
    rule_scores,
    split_indices,
    summarize,
)
from holofold.design.mining import MinedRules, mine_rules
from holofold.design.report import (
    mining_summary,
    plot_feature_importance,
    plot_rule_boxes,
    plot_rule_scatter,
    plot_rules,
    rules_to_text,
    save_figure,
)
from holofold.design.rulefile import RulesFileError, read_rules, rules_to_records, write_rules
from holofold.design.rules import FewRulesWarning, ForestRuleMiner, format_rule
from holofold.design.runner import (
    DesignTableError,
    check_scheduler,
    check_workers,
    dask_scheduler,
    evaluate_designs,
    validate_designs,
)
from holofold.design.sampling import METHODS, sample_designs
from holofold.design.scenarios import SCENARIO_NAMES, Column, Scenario, get_scenario
from holofold.design.store import build_database, generate_database, load_database
from holofold.design.tables import (
    ColumnRoles,
    check_table_path,
    column_roles,
    read_table,
    write_table,
)
from holofold.design.targets import Target, TargetError, parse_target
from holofold.design.verify import Verification, verify_rule, verify_rules, write_verification
from holofold.geometry.outputs import check_output_path
from holofold.mechanics.status import Status, converged_mask, failed_mask

__all__ = [
    # scenarios
    "Scenario",
    "Column",
    "SCENARIO_NAMES",
    "get_scenario",
    # evaluating designs and databases
    "validate_designs",
    "evaluate_designs",
    "DesignTableError",
    "check_workers",
    "check_scheduler",
    "dask_scheduler",
    "sample_designs",
    "METHODS",
    "build_database",
    "generate_database",
    "load_database",
    "read_table",
    "write_table",
    "check_table_path",
    "check_output_path",
    "column_roles",
    "ColumnRoles",
    "Status",
    "failed_mask",
    "converged_mask",
    # targets and rules
    "parse_target",
    "Target",
    "TargetError",
    "ForestRuleMiner",
    "FewRulesWarning",
    "format_rule",
    "mine_rules",
    "MinedRules",
    "holdout",
    "repeated_holdout",
    "rule_scores",
    "split_indices",
    "summarize",
    "HoldoutResult",
    "rules_to_records",
    "write_rules",
    "read_rules",
    "RulesFileError",
    "rules_to_text",
    "mining_summary",
    "plot_rules",
    "plot_rule_boxes",
    "plot_rule_scatter",
    "plot_feature_importance",
    "save_figure",
    # verification and the demo
    "verify_rule",
    "verify_rules",
    "write_verification",
    "Verification",
    "run_demo",
    "DEMO_TARGET",
]
