"""Scenario files (TOML text) shared by the tests of ``kind = "pattern"`` scenarios."""


def pattern_scenario(name: str, pattern: str, support: str, load_at: str, force: str,
                     features: str) -> str:  # fmt: skip
    """A pattern scenario's file text: ``pattern`` and ``features`` are the bodies of their
    tables; a 2 GPa, nu 0.38, 1270 kg/m^3 sheet held at vertex set ``support`` and pushed
    down (-z) at ``load_at`` by one load "tip" of ``force`` N."""
    return f"""
kind = "pattern"
name = "{name}"

[pattern]
{pattern}

[material]
E = 2.0e9
nu = 0.38
density = 1270.0

[supports]
at = ["{support}"]

[[load]]
name = "tip"
at = "{load_at}"
direction = [0, 0, -1]
force = {force}

[features]
{features}
"""


def waterbomb_scenario(support: str = "side:-x") -> str:
    """The Origami Simulator waterbomb (``wb.svg`` next to the file) at 0.1 m, held at
    ``support``, tipped at side +x by 0.1 N; features tpanel and fold."""
    return pattern_scenario(
        "waterbomb", 'file = "wb.svg"\nsize = 0.1', support, "side:+x", "0.1",
        "tpanel = [0.5e-3, 2e-3]\nfold = [0.3, 0.6]",
    )  # fmt: skip
