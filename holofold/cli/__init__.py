"""The ``holofold`` command line.

Each sub-command lives in its own module of this package and exposes two names:

``register(subparsers) -> argparse.ArgumentParser``
    adds the sub-command's parser (with ``help=`` and its own ``--help``);
``run(args) -> int``
    does the work and returns the exit status.

Modules are discovered automatically, so adding a sub-command means adding one module.
User errors (``ValueError``, ``OSError``) become one line on stderr and exit status 2;
nothing is written in that case, which each sub-command guarantees by validating its
inputs before it creates any output file.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import pkgutil
import sys

__all__ = ["main", "build_parser"]

# preferred order in --help; modules not listed here follow alphabetically
_ORDER = ["demo", "pattern", "fit", "evaluate", "generate", "mine", "verify", "design"]


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
    try:
        return int(args._run(args) or 0)
    except (ValueError, OSError) as exc:
        print(f"holofold {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"holofold {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
