"""Print a pip constraints file pinning each declared dependency to its floor.

Reads pyproject.toml (the runtime dependencies and every extra but 'test') and prints one
`name==floor` line for each, from its `>=` bound; .ci/min-versions installs with it. A
dependency without a `>=` floor is an error, and so is a package that two groups declare with
different floors. The test tools of the 'test' extra are not pinned.
Usage: python .ci/min-constraints.py [--extras] [pyproject.toml] > constraints.txt
(--extras prints the extras to install instead, comma-separated, 'test' included.)
"""

import re
import sys
import tomllib
from pathlib import Path

# name, optional [extras], then the specifiers; an environment marker (after ';') is left out:
# a constraint on a package that the platform does not install is ignored by pip
_REQ = re.compile(r"^\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*(\[[^\]]*\])?\s*(.*)$")
_FLOOR = re.compile(r">=\s*([0-9][0-9A-Za-z.+!-]*)")


def _floor(requirement: str) -> tuple[str, str | None]:
    """(normalised name, floor or None) of one requirement string."""
    match = _REQ.match(requirement.split(";")[0])
    if match is None:
        sys.exit(f"min-constraints: cannot read the requirement {requirement!r}")
    floor = _FLOOR.search(match.group(3))
    return re.sub(r"[-_.]+", "-", match.group(1)).lower(), floor and floor.group(1)


def floors(project: dict) -> dict[str, str]:
    """Normalised name -> floor of every runtime dependency and every extra's but 'test''s."""
    extras = project.get("optional-dependencies", {})
    pins: dict[str, str] = {}
    pinned = [project["dependencies"]] + [reqs for name, reqs in extras.items() if name != "test"]
    for requirement in (r for group in pinned for r in group):
        name, floor = _floor(requirement)
        if floor is None:
            sys.exit(f"min-constraints: {requirement!r} has no '>=' floor")
        if pins.setdefault(name, floor) != floor:
            sys.exit(f"min-constraints: {name} is declared with floors {pins[name]} and {floor}")
    for requirement in extras.get("test", []):
        name, floor = _floor(requirement)
        if name in pins and floor != pins[name]:
            sys.exit(f"min-constraints: the test extra's {requirement!r} differs from {pins[name]}")
    return pins


if __name__ == "__main__":
    args = sys.argv[1:]
    want_extras = "--extras" in args
    args = [a for a in args if a != "--extras"]
    path = Path(args[0]) if args else Path(__file__).resolve().parents[1] / "pyproject.toml"
    project = tomllib.loads(path.read_text())["project"]
    if want_extras:
        sys.stdout.write(",".join(sorted(project.get("optional-dependencies", {}))) + "\n")
    else:
        sys.stdout.writelines(f"{name}=={floor}\n" for name, floor in floors(project).items())
