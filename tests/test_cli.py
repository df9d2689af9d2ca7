"""The ``holofold`` command: every sub-command has --help, unknown ones fail cleanly."""

import subprocess
import sys
from pathlib import Path

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


def test_demo_time_is_the_same_in_readme_and_help():
    """One demo time: README.md gives the figure ``holofold --help`` gives (issue 37)."""
    from holofold.cli import demo

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    assert f"In {demo.DEMO_TIME} (" in " ".join(readme.split())
    for lazy in (True, False):  # ``holofold --help`` reads the help line from the source
        assert demo.DEMO_TIME in " ".join(build_parser(lazy=lazy).format_help().split())


def test_demo_default_target_is_the_library_one():
    from holofold.cli import demo
    from holofold.design import DEMO_TARGET

    assert demo.TARGET == DEMO_TARGET


def test_help_lines_read_from_the_sources_are_the_registered_ones():
    from holofold.cli import _command_names, _help_line

    sub = next(a for a in build_parser()._actions if a.dest == "command")
    registered = {c.dest: c.help for c in sub._choices_actions}
    assert {n: _help_line(n) for n in _command_names()} == registered


def test_top_level_help_imports_no_library():
    # `holofold --help` must stay fast: no command module, no numpy/pandas/scipy (issue 14)
    code = (
        "import sys\nfrom holofold.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "heavy = [m for m in ('numpy', 'scipy', 'pandas', 'trimesh', 'holofold.design',"
        " 'holofold.mechanics', 'holofold.cli.evaluate') if m in sys.modules]\n"
        "print('HEAVY', heavy)"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "HEAVY []" in proc.stdout
    assert "evaluate" in proc.stdout and "simulate a table of designs" in proc.stdout


def test_a_command_imports_only_its_own_module():
    code = (
        "import sys\nfrom holofold.cli import main\n"
        "try:\n    main(['generate', '--help'])\nexcept SystemExit:\n    pass\n"
        "print('LOADED', sorted(m for m in sys.modules if m.startswith('holofold.cli.')))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert "LOADED ['holofold.cli._parallel', 'holofold.cli.generate']" in proc.stdout


def test_evaluate_help_lists_every_scenario_s_columns(capsys):
    from holofold.design import SCENARIO_NAMES, get_scenario

    with pytest.raises(SystemExit):
        main(["evaluate", "--help"])
    out = capsys.readouterr().out
    for name in SCENARIO_NAMES:
        sc = get_scenario(name)
        assert f"  {name}: " in out
        assert f"-> {', '.join(sc.performance_names)}, status" in out
    assert "<the scenarios' columns>" not in out
