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

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "demo": ["run_demo", "DEMO_TARGET"],
        "acquisition": ["likely_designs"],
        "folder_lock": ["folder_lock", "FolderBusyError"],
        "loop": ["run_design", "DesignLoop", "LoopState", "DesignOutcome", "choose_design"],
        "settings": ["DesignProblem", "LoopSettings", "Execution", "DesignFiles"],
        "strategies": [
            "STRATEGIES",
            "register_strategy",
            "RefineRequest",
            "Proposal",
            "refine_designs",
        ],
        "objective": ["Objective", "parse_objective"],
        "choice": ["choose", "Answer", "Candidate", "OVERLAP_TOLERANCE"],
        "rounds": ["Round", "VerifiedRule", "Counts", "RULE_QUALIFIES"],
        "summary": ["DesignSummary", "Pick", "Timings"],
        "describe": [
            "Distribution",
            "distributions",
            "distributions_text",
            "describe_source",
            "PILOT",
        ],
        "buildability": [
            "Bed",
            "DEFAULT_BED",
            "PartFit",
            "PrintablePart",
            "parse_bed",
            "part_fit",
        ],
        "batches": ["batch_spans"],
        "evaluation": [
            "holdout",
            "repeated_holdout",
            "rule_scores",
            "split_indices",
            "summarize",
            "HoldoutResult",
        ],
        "mining": ["mine_rules", "MinedRules"],
        "report_page": ["write_report_page", "report_page_html"],
        "report": [
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
        "rulefile": [
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
        "runner": [
            "validate_designs",
            "evaluate_designs",
            "DesignTableError",
            "check_workers",
            "check_scheduler",
            "dask_scheduler",
        ],
        "row_status": ["failed_rows", "converged_rows", "row_statuses", "with_state"],
        "faults": ["as_environment_fault"],
        "pattern_batch": [
            "pattern_files",
            "file_sha256",
            "recorded_files",
            "check_pattern_file",
            "run_pattern_batch",
        ],
        "row_limits": ["RowTimeout", "ON_INVALID", "check_on_invalid", "resolve_row_timeout"],
        "sampling": ["sample_designs", "METHODS"],
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
        "store": ["build_database", "generate_database", "load_database"],
        "tables": [
            "read_table",
            "write_table",
            "check_table_path",
            "column_roles",
            "table_columns",
            "ColumnRoles",
        ],
        "targets": ["parse_target", "Target", "TargetError"],
        "verify": [
            "verify_rule",
            "verify_rules",
            "write_verification",
            "Verification",
            "rule_mask",
            "rule_ranges",
            "as_rule",
            "rule_key",
        ],
    },
)
