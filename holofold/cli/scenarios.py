"""``holofold scenarios``: list the scenarios, or print a shipped scenario file to copy."""

from __future__ import annotations

import argparse

from holofold.design import (
    SCENARIO_NAMES,
    get_scenario,
    scenario_kinds,
    shipped_scenarios,
    shipped_text,
)

__all__ = ["HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]


HELP = "list the scenarios; 'show NAME' prints a scenario file to copy and edit"
DESCRIPTION = (
    "List the paper's scenarios and the scenario files shipped with holofold, or print "
    "one file (TOML) to copy and edit for your own problem: your curve, material, "
    "supports, loads and feature ranges. Every command that takes a scenario name also "
    "takes the path of such a file."
)
EPILOG = "example: holofold scenarios show arch > my_arch.toml"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("action", nargs="?", choices=("list", "show"), default="list")
    p.add_argument("name", nargs="?", help="shipped scenario to print (with 'show')")


def run(args) -> int:
    files = shipped_scenarios()
    if args.action == "show":
        if not args.name:
            raise ValueError(f"say which scenario to show: {', '.join(files)}")
        print(shipped_text(args.name), end="")
        return 0
    if args.name:
        raise ValueError(f"'list' takes no name (did you mean 'show {args.name}'?)")
    print("scenarios (use the name, or copy the file with 'holofold scenarios show NAME'):")
    for name in SCENARIO_NAMES:
        sc = get_scenario(name)
        file = "  [file: scenarios show " + name + "]" if name in files else ""
        print(f"  {name:18s} {sc.description}{file}")
    print("scenario file kinds (kind = ... in a .toml file):")
    for name, kind in scenario_kinds().items():
        print(f"  {name:18s} {kind.description}")
    return 0
