"""The installed package: one import name, public faces, the quickstart, a real `pip install .`."""

import doctest
import importlib
import os
import shutil
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import pytest

import holofold

ROOT = Path(__file__).resolve().parents[1]
FACES = ["holofold", "holofold.geometry", "holofold.fitting", "holofold.mechanics",
         "holofold.design"]  # fmt: skip


def test_quickstart_doctest():
    result = doctest.testmod(holofold, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 12 and result.failed == 0


def test_the_top_level_face_is_curated():
    """At most ~40 names at the top (issue 35: it had 28, the layer faces 380 more); each is
    a layer's, and the quickstart shows the design loop's records."""
    assert len(holofold.__all__) <= 40
    assert {"DesignProblem", "LoopSettings", "Execution", "run_design"} <= set(holofold.__all__)
    assert "hf.DesignProblem(" in holofold.__doc__


@pytest.mark.parametrize("name", FACES)
def test_every_public_name_resolves(name):
    face = importlib.import_module(name)
    assert face.__all__ and len(set(face.__all__)) == len(face.__all__)
    missing = [n for n in face.__all__ if not hasattr(face, n)]
    assert not missing, f"{name}.__all__ names what it does not have: {missing}"


def test_top_level_names_are_those_of_the_layers():
    assert holofold.fit_strip is importlib.import_module("holofold.fitting").fit_strip
    assert holofold.PAPER is importlib.import_module("holofold.mechanics.compat").PAPER
    with pytest.raises(AttributeError, match="nope"):
        holofold.nope  # noqa: B018


@pytest.mark.slow
def test_pip_install_dot_gives_one_import_name(tmp_path):
    """A fresh virtual environment, ``pip install .`` (a wheel, not editable): ``import
    holofold`` and the ``holofold`` command work from any folder; ``import design`` fails."""
    env_dir = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(env_dir)], check=True)
    py = env_dir / "bin" / "python"
    # the dependencies come from this environment (a path, not its .pth files: no editable
    # holofold leaks in); the package itself is built and installed from the checkout
    site = subprocess.run(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True, capture_output=True, text=True,
    ).stdout.strip()  # fmt: skip
    Path(site, "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    build = tmp_path / "src"  # the working tree as it is, without environments and caches
    skip = shutil.ignore_patterns(".git", ".venv*", "build", "*.egg-info", "__pycache__", ".*cache")
    shutil.copytree(ROOT, build, symlinks=True, ignore=skip)
    proc = subprocess.run(
        [str(py), "-m", "pip", "install", "-q", "--no-deps", str(build)],
        capture_output=True, text=True,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    code = textwrap.dedent(
        """
        import importlib.util, holofold
        assert "site-packages" in holofold.__file__, holofold.__file__
        fit = holofold.fit_strip(holofold.builtin_curve("half-circle", radius=2.0),
                                 m=8, offset=0.2, strip_width=0.02, extrude=0.1)
        print(fit.pattern.n_vertices)
        for name in ("design", "geometry", "fitting", "mechanics"):
            assert importlib.util.find_spec(name) is None, name
        try:
            import design
        except ModuleNotFoundError:
            print("no design")
        """
    )
    work = tmp_path / "elsewhere"
    (work / "design").mkdir(parents=True)  # a user's own design/ folder shadows nothing
    (work / "design" / "__init__.py").write_text("raise RuntimeError('wrong design')\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    run = subprocess.run([str(py), "-c", code], cwd=tmp_path, capture_output=True, text=True,
                         env=env)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["51", "no", "design"]
    # the console script, from a folder that holds a design/ package of the user's
    cli = subprocess.run([str(env_dir / "bin" / "holofold"), "--help"], cwd=work,
                         capture_output=True, text=True, env=env)  # fmt: skip
    assert cli.returncode == 0 and "usage: holofold" in cli.stdout, cli.stderr[-2000:]


def test_checkout_has_no_symlinks_and_every_face_imports_from_the_tree():
    """The repository carries no symlinks (checkouts without them must work), and the layer
    faces resolve through the installed package-dir mapping to the top-level folders."""
    if (ROOT / ".git").exists():
        listed = subprocess.run(["git", "ls-files", "-s"], cwd=ROOT, capture_output=True,
                                text=True, check=True).stdout.splitlines()  # fmt: skip
        links = [line.split("\t", 1)[1] for line in listed if line.startswith("120000")]
        assert not links, f"symlinks in the repository: {links[:5]}"
    for name in FACES[1:]:
        mod = importlib.import_module(name)
        folder = name.split(".")[1]
        assert Path(mod.__file__).resolve().parent == ROOT / folder, mod.__file__
