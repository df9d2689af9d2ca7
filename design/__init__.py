"""holofold.design: scenarios, databases, design rules, the design loop and its report.

The top layer of the library (imports geometry, fitting and mechanics, never the reverse), in
five parts:

- :mod:`~holofold.design.scenarios`: the paper's scenarios and the kinds of scenario files;
- :mod:`~holofold.design.database`: sampling, validated evaluation row by row on processes or a
  Dask cluster, the resumable Parquet store, tables;
- :mod:`~holofold.design.rules`: the target language, the forest rule miner, its evaluation,
  the ``mine`` workflow, rules files and figures, verification by fresh simulations;
- :mod:`~holofold.design.loop`: the design loop (what it is asked, how it searches and runs),
  its rounds, the choice of the design to build and whether it fits the printer;
- :mod:`~holofold.design.report`: the HTML report, its 3D view, what the designs reach;

and the demo (:mod:`~holofold.design.demo`). See docs/rule-miner.md and docs/scenarios.md.
"""

from holofold.geometry.lazy_face import ALL, attach

__getattr__, __dir__, __all__ = attach(
    __name__,
    __file__,
    submod_attrs={
        "demo": ALL,
        "loop.acquisition": ["likely_designs"],
        "database.folder_lock": ["folder_lock", "FolderBusyError"],
        "loop.design_loop": [
            "run_design",
            "DesignLoop",
            "LoopState",
            "DesignOutcome",
            "choose_design",
        ],
        "loop.settings": ["DesignProblem", "LoopSettings", "Execution", "DesignFiles"],
        "loop.strategies": [
            "STRATEGIES",
            "register_strategy",
            "RefineRequest",
            "Proposal",
            "refine_designs",
        ],
        "loop.objective": ["Objective", "parse_objective"],
        "loop.choice": ["choose", "Answer", "Candidate", "OVERLAP_TOLERANCE"],
        "loop.rounds": ["Round", "VerifiedRule", "Counts", "RULE_QUALIFIES"],
        "loop.summary": ["DesignSummary", "Pick", "Timings"],
        "report.describe": [
            "Distribution",
            "distributions",
            "distributions_text",
            "describe_source",
            "PILOT",
        ],
        "loop.buildability": [
            "Bed",
            "DEFAULT_BED",
            "PartFit",
            "PrintablePart",
            "parse_bed",
            "part_fit",
        ],
        "database.batches": ["batch_spans"],
        "rules.evaluation": [
            "holdout",
            "repeated_holdout",
            "rule_scores",
            "split_indices",
            "summarize",
            "HoldoutResult",
        ],
        "rules.mining": ["mine_rules", "MinedRules"],
        "report.page": ALL,
        "rules.report": [
            "rules_to_text",
            "mining_summary",
            "plot_rules",
            "plot_rule_boxes",
            "plot_rule_scatter",
            "plot_feature_importance",
            "plot_target_scatter",
            "plot_folded_design",
            "save_figure",
        ],
        "rules.rulefile": [
            "mined_rules",
            "rules_to_records",
            "write_rules",
            "read_rules",
            "RulesFileError",
        ],
        "rules": [
            "ForestRuleMiner",
            "FewRulesWarning",
            "Rule",
            "Condition",
            "Score",
            "Estimate",
            "RuleError",
        ],
        "database.runner": [
            "validate_designs",
            "evaluate_designs",
            "DesignTableError",
            "check_workers",
            "check_scheduler",
            "dask_scheduler",
        ],
        "database.row_status": ["failed_rows", "converged_rows", "row_statuses", "with_state"],
        "database.faults": ["as_environment_fault"],
        "database.pattern_batch": ALL,
        "database.row_limits": [
            "RowTimeout",
            "ON_INVALID",
            "check_on_invalid",
            "resolve_row_timeout",
        ],
        "database.sampling": ["sample_designs", "METHODS"],
        "scenarios.strip": ["StripSetting", "StripLoad", "strip_scenario", "STRIP_FEATURES"],
        "scenarios": [
            "Scenario",
            "Column",
            "format_value",
            "DISPLAY_UNITS",
            "SCENARIO_NAMES",
            "get_scenario",
            "load_scenario",
            "read_scenario",
            "shipped_scenarios",
            "shipped_text",
            "ScenarioFileError",
            "ScenarioKind",
            "register_kind",
            "scenario_kinds",
            "kind_names",
        ],
        "database.store": ["build_database", "generate_database", "load_database"],
        "database.tables": [
            "read_table",
            "write_table",
            "check_table_path",
            "column_roles",
            "table_columns",
            "ColumnRoles",
        ],
        "rules.targets": ["parse_target", "Target", "TargetError"],
        "rules.verify": ALL,
    },
)
