"""The compiled kernels' cache cannot go stale, a warm cache serves the scenarios without
compiling, a fresh environment's first row does not wait for the compiler, and a machine
without numba runs on the numpy path (or stops in one line when the compiled one is demanded)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow


def _tree(tmp_path: Path) -> Path:
    """A copy of the package as installed (holofold/ with its layers inside)."""
    pkg = tmp_path / "src" / "holofold"
    shutil.copytree(ROOT / "holofold", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    for layer in ("geometry", "fitting", "mechanics", "design"):
        shutil.copytree(ROOT / layer, pkg / layer, ignore=shutil.ignore_patterns("__pycache__"))
    return pkg.parent


def _env(tmp_path: Path, src: Path | None = None, **extra) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("HOLOFOLD_", "NUMBA_"))}
    env["HOLOFOLD_KERNEL_CACHE"] = str(tmp_path / "cache")
    if src is not None:
        env["PYTHONPATH"] = str(src)
    env.update(extra)
    return env


_SPRINGS = textwrap.dedent(
    """
    import numpy as np
    from holofold.mechanics import kernels
    rng = np.random.default_rng(0)
    X = rng.normal(size=(20, 3)); U = 0.05 * rng.normal(size=(20, 3))
    sT = np.ascontiguousarray(np.array([rng.choice(20, 4, replace=False)
                                        for _ in range(30)]).T.astype(np.intp))
    k = rng.uniform(0.1, 2.0, 30); th0 = rng.uniform(0, 6, 30)
    e, f, K, t = np.empty(30), np.empty((3, 4, 30)), np.empty((3, 3, 10, 30)), np.empty(30)
    mod = kernels.kernel_path("compiled").module
    assert mod.__file__.startswith({src!r}), mod.__file__
    mod.spring_elements(X, U, sT, k, th0, True, False, (e, f, K, t))
    print(repr(float(e.sum())))
    """
)


def test_an_edited_kernel_is_compiled_again(tmp_path):
    """numba keys each cached function on its own file only: the callers of an edited
    _spring_loop.py kept their stale machine code. The cache folder is keyed on every kernel
    source, so the edit is seen."""
    src = _tree(tmp_path)
    code = _SPRINGS.format(src=str(src))
    run = lambda: subprocess.run(  # noqa: E731
        [sys.executable, "-c", code], env=_env(tmp_path, src), capture_output=True, text=True,
        cwd=tmp_path, check=True,
    ).stdout  # fmt: skip
    before = float(run())
    loop = src / "holofold" / "mechanics" / "_spring_loop.py"
    text = loop.read_text()
    # the energy of the force-only loop (the second one in the file) times 3
    head, sep, tail = text.rpartition("energy[s] = 0.5 * M * dth")
    assert sep
    loop.write_text(head + "energy[s] = 1.5 * M * dth" + tail)
    after = float(run())
    assert before > 0 and after == pytest.approx(3 * before, rel=1e-12)
    assert len(list((tmp_path / "cache").glob("kernels-*"))) == 2


_ROWS = textwrap.dedent(
    """
    import json, sys, time
    import numpy as np
    t0 = time.perf_counter()
    from holofold.design import get_scenario
    from holofold.mechanics import kernels
    arch = get_scenario("arch")
    row = {"m": 8, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "offset": 0.2,
           "stripeWidth": 0.02, "extrude": 0.1}
    out = arch.evaluate(row)
    first = time.perf_counter() - t0
    sm = get_scenario("single-miura").evaluate(
        {"tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "gama": 1.0})
    # a gripper: heated, then pried open (one structure's load increments in one kernel call)
    get_scenario("gripper").evaluate({"Pattern": 3.0, "L1": 4.914e-3, "L2": 2.821e-3,
        "t1": 2e-7, "t2": 8e-7, "tpanel": 2e-5, "rate": 0.476, "W": 2.65e-4})
    # a crease pattern folded by its rest angles (fold_pattern: the self-fold kernel)
    from holofold.geometry import read_pattern
    from holofold.mechanics import fold_pattern, scaled_pattern
    p = read_pattern(sys.argv[1])
    p = scaled_pattern(p, 0.2 / float(np.ptp(p.flat, axis=0).max()))
    fold = fold_pattern(p, 0.5, panel_thickness=1e-3, crease_thickness=2e-4, crease_width=1e-3,
                        E=1.5e9, nu=0.42)
    misses = []
    if kernels.active().compiled:
        from holofold.mechanics import _compiled, _spring_loop
        for mod in (_compiled, _spring_loop):
            for name in dir(mod):
                fn = getattr(mod, name)
                if hasattr(fn, "stats") and sum(fn.stats.cache_misses.values()):
                    misses.append(name)
    print(json.dumps({"path": kernels.active().name, "first": first, "misses": misses,
                      "Zstiff": out["Zstiff"], "single": sm["axialstiff60"],
                      "fold": float(np.abs(fold.coords[-1]).max())}))
    """
)


#: Origami Simulator's bird base (tests/data, MIT): 8 panels, the dense self-fold path
_BIRD_BASE = Path(__file__).parent / "data" / "origami-simulator" / "birdBase.svg"


def _rows(tmp_path, **env):
    proc = subprocess.run(
        [sys.executable, "-c", _ROWS, str(_BIRD_BASE)], env=_env(tmp_path, **env),
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc.stderr


def test_cold_start_runs_on_numpy_while_compiling_then_a_warm_cache_needs_no_compiler(tmp_path):
    cold, err = _rows(tmp_path)  # empty cache: numpy now, a compile in the background
    assert cold["path"] == "numpy", cold
    folder = next((tmp_path / "cache").glob("kernels-*"))
    deadline = time.monotonic() + 600
    while not (folder / "ready").exists():
        assert not (folder / "failed").exists(), (folder / "failed").read_text()
        assert time.monotonic() < deadline, "the background compile did not finish in 600 s"
        time.sleep(1)
    warm, _ = _rows(tmp_path)
    assert warm["path"] == "compiled" and warm["misses"] == [], warm
    for key in ("Zstiff", "single", "fold"):  # converged outputs: the paths agree to 1e-9
        assert warm[key] == pytest.approx(cold[key], rel=1e-9)
    numpy, _ = _rows(tmp_path, HOLOFOLD_KERNELS="numpy")
    assert numpy["path"] == "numpy" and numpy["Zstiff"] == pytest.approx(warm["Zstiff"], rel=1e-9)


def _without_numba(tmp_path: Path) -> Path:
    """A folder whose numba package fails to import (as where it is not installed)."""
    fake = tmp_path / "nonumba" / "numba"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ModuleNotFoundError(\"No module named 'numba'\")\n")
    return fake.parent


def test_without_numba_the_numpy_path_gives_the_same_rows(tmp_path):
    ref, _ = _rows(tmp_path, HOLOFOLD_KERNELS="numpy")
    got, err = _rows(tmp_path, PYTHONPATH=str(_without_numba(tmp_path)))
    assert got["path"] == "numpy"
    assert got["Zstiff"] == pytest.approx(ref["Zstiff"], rel=1e-12)
    assert "numba cannot be imported" in err and "pip install numba" in err


def test_without_numba_the_compiled_path_stops_in_one_line(tmp_path):
    rows = tmp_path / "rows.csv"
    rows.write_text(
        "m,tcrease,tpanel,W,offset,stripeWidth,extrude\n8,8e-4,3e-3,2e-3,0.2,0.02,0.1\n"
    )
    holofold = shutil.which("holofold", path=str(Path(sys.executable).parent))
    cmd = [holofold] if holofold else [sys.executable, "-m", "holofold.cli"]
    proc = subprocess.run(
        [*cmd, "evaluate", "arch", str(rows), "-o", str(tmp_path / "out.csv")],
        env=_env(tmp_path, PYTHONPATH=str(_without_numba(tmp_path)), HOLOFOLD_KERNELS="compiled"),
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 3, (proc.returncode, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "numba" in lines[0] and "HOLOFOLD_KERNELS=numpy" in lines[0]
    assert not (tmp_path / "out.csv").exists()
