"""The ``holofold`` command line.

Each sub-command lives in its own module of this package and exposes two names:

``register(subparsers) -> argparse.ArgumentParser``
    adds the sub-command's parser (with ``help=`` and its own ``--help``);
``run(args) -> int``
    does the work and returns the exit status.

Modules are discovered automatically, so adding a sub-command means adding one module. A
sub-command parses its arguments and calls the library through the layers' public faces
(``holofold.geometry``, ``holofold.fitting``, ``holofold.mechanics``, ``holofold.design``);
an import-linter contract in pyproject.toml keeps it so.

User errors (``ValueError``, ``OSError``) become one line on stderr and exit status 2;
nothing is written in that case (the library checks its inputs before it creates any output
file, and writes every file atomically). Warnings become one line each on stderr.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import pkgutil
import sys
import warnings

__all__ = ["main", "build_parser"]

# preferred order in --help; modules not listed here follow alphabetically
_ORDER = ["demo", "design", "scenarios", "pattern", "fit", "evaluate", "generate", "mine", "verify"]


def _command_modules():
    names = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    names.sort(key=lambda n: (_ORDER.index(n) if n in _ORDER else len(_ORDER), n))
    return [importlib.import_module(f"{__name__}.{n}") for n in names]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="holofold",
        description="Holistic inverse design of origami: shape and function.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for mod in _command_modules():
        p = mod.register(sub)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )

    def one_line(message, category, *_args, **_kw):
        print(f"holofold {args.command}: warning: {message}", file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.showwarning = one_line
            return int(args._run(args) or 0)
    except (ValueError, OSError) as exc:
        print(f"holofold {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"holofold {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
