"""The ``holofold`` command: every sub-command has --help, unknown ones fail cleanly."""

import subprocess
import sys

import pytest

from holofold.cli import _command_modules, build_parser, main


def test_subcommands_are_discovered():
    names = {m.__name__.rsplit(".", 1)[1] for m in _command_modules()}
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert names == set(sub.choices)


@pytest.mark.parametrize("name", [m.__name__.rsplit(".", 1)[1] for m in _command_modules()])
def test_each_subcommand_has_help(name, capsys):
    with pytest.raises(SystemExit) as exc:
        main([name, "--help"])
    assert exc.value.code == 0
    assert "usage: holofold " + name in capsys.readouterr().out


def test_unknown_subcommand_exits_nonzero():
    proc = subprocess.run(
        [sys.executable, "-m", "holofold.cli", "no-such-command"], capture_output=True, text=True
    )
    assert proc.returncode == 2
    assert "invalid choice" in proc.stderr


def test_demo_default_target_is_the_library_one():
    from holofold.cli import demo
    from holofold.design import DEMO_TARGET

    assert demo.TARGET == DEMO_TARGET
