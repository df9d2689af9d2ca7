"""The ``holofold`` command line.

Each sub-command lives in its own module of this package and declares:

``HELP`` (a string literal), ``DESCRIPTION``, optionally ``EPILOG`` and ``FORMATTER``
    the sub-command's help line, its ``--help`` text and argparse formatter class;
``add_arguments(parser) -> None``
    adds its arguments to the parser :func:`build_parser` made from those declarations;
``run(args) -> int``
    does the work and returns the exit status.

Modules are discovered automatically, so adding a sub-command means adding one module; a run
imports only the module of its command, and ``holofold --help`` none (their help lines are read
from their sources), so the command line starts fast. A
sub-command parses its arguments and calls the library through the layers' public faces
(``holofold.geometry``, ``holofold.fitting``, ``holofold.mechanics``, ``holofold.design``);
an import-linter contract in pyproject.toml keeps it so.

User errors (``ValueError``, ``OSError``) become one line on stderr and exit status 2;
nothing is written in that case (the library checks its inputs before it creates any output
file, and writes every file atomically). An environment fault (a missing module, a library
that fails to load, out of memory, a compile failure:
``holofold.geometry.EnvironmentFault``) stops the run with one line naming the cause and the
fix, exit status 3; nothing of it is stored. Warnings become one line each on stderr.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import logging
import pkgutil
import sys
import warnings
from pathlib import Path

__all__ = ["main", "build_parser"]

# preferred order in --help; modules not listed here follow alphabetically
_ORDER = ["demo", "design", "describe", "scenarios", "pattern", "fit", "evaluate", "generate",
          "mine", "verify"]  # fmt: skip


def _command_names() -> list[str]:
    names = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    names.sort(key=lambda n: (_ORDER.index(n) if n in _ORDER else len(_ORDER), n))
    return names


def _command_modules():
    return [importlib.import_module(f"{__name__}.{n}") for n in _command_names()]


def _help_line(name: str) -> str | None:
    """The literal ``HELP = "..."`` of command ``name``'s source, read without importing it
    (the commands import the library, which ``holofold --help`` must not pay for), or None
    if it is not a string literal."""
    try:
        tree = ast.parse((Path(__file__).parent / f"{name}.py").read_text(encoding="utf-8"))
    except (OSError, SyntaxError):
        return None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            getattr(t, "id", "") == "HELP" for t in node.targets
        ):
            v = node.value
            return v.value if isinstance(v, ast.Constant) and isinstance(v.value, str) else None
    return None


def _add_command(sub, name: str, mod) -> argparse.ArgumentParser:
    """Command ``name``'s parser, made from module ``mod``'s declarations (module docstring)."""
    p = sub.add_parser(
        name,
        help=mod.HELP,
        description=mod.DESCRIPTION,
        epilog=getattr(mod, "EPILOG", None),
        formatter_class=getattr(mod, "FORMATTER", argparse.HelpFormatter),
    )
    mod.add_arguments(p)
    p.set_defaults(_run=mod.run)
    return p


def _command_of(argv: list[str]) -> str | None:
    """The sub-command named in ``argv`` (its first word that is not an option), or None."""
    for a in argv:
        if a == "--":
            return None
        if not a.startswith("-"):
            return a
    return None


def build_parser(command: str | None = None, *, lazy: bool = False) -> argparse.ArgumentParser:
    """The ``holofold`` parser.

    Every command module is imported and registered, unless ``lazy``: then only ``command``
    (if it is one) is, and the others get a stand-in parser with the help line read from
    their source, so that ``holofold --help`` and a single command start without importing
    the library for every other command.
    """
    parser = argparse.ArgumentParser(
        prog="holofold",
        description="Holistic inverse design of origami: shape and function.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in _command_names():
        line = _help_line(name) if lazy and name != command else None
        if line is None:
            _add_command(sub, name, importlib.import_module(f"{__name__}.{name}"))
        else:
            sub.add_parser(name, help=line)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(_command_of(argv), lazy=True)
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )

    def one_line(message, category, *_args, **_kw):
        print(f"holofold {args.command}: warning: {message}", file=sys.stderr)

    from holofold.geometry import EnvironmentFault  # a lazy face: loads geometry.errors only

    try:
        with warnings.catch_warnings():
            warnings.showwarning = one_line
            return int(args._run(args) or 0)
    except EnvironmentFault as exc:
        print(f"holofold {args.command}: error: {exc}", file=sys.stderr)
        return 3
    except (ValueError, OSError) as exc:
        print(f"holofold {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"holofold {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
