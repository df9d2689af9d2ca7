"""A one-shot run of a small model skips numba in ``auto`` (mechanics.kernels.small_model;
issue 37 item 4: numba's import and loading its kernels cost such a run more than the numpy
kernels do)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from holofold.mechanics import kernels

OS = Path(__file__).parent / "data" / "origami-simulator"


def test_small_model_chooses_numpy_in_auto_only(monkeypatch):
    monkeypatch.setenv(kernels.ENV, "auto")
    fresh = kernels._COMPILED_MODULE is None  # another test may have loaded the compiled ones
    with kernels.small_model(kernels.SMALL_MODEL_PANELS - 1) as small:
        assert small == fresh
        if small:
            assert kernels.active().name == "numpy"
        with kernels.small_model(kernels.SMALL_MODEL_PANELS) as big:
            assert not big
        assert kernels._SMALL == small  # restored on the way out
    assert not kernels._SMALL
    monkeypatch.setenv(kernels.ENV, "numpy")
    with kernels.small_model(10_000):
        assert kernels.active().name == "numpy"  # a fixed path is obeyed as always


@pytest.mark.processes
def test_simulate_of_a_small_pattern_loads_no_numba(tmp_path):
    """``holofold simulate`` of 24 panels in ``auto``: no numba imported, no background compile
    started (the kernel cache folder holds no lock), the files written."""
    cache = tmp_path / "cache"
    out = tmp_path / "out"
    argv = ["simulate", str(OS / "flappingBird.svg"), "--no-contact", "-o", str(out)]
    code = (
        "import json, sys\nfrom holofold.cli import main\n"
        f"code = main({argv!r})\n"
        "print(json.dumps([code, 'numba' in sys.modules]))"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("HOLOFOLD_", "NUMBA_"))}
    env.update(HOLOFOLD_KERNELS="auto", HOLOFOLD_KERNEL_CACHE=str(cache))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, env=env, check=True)  # fmt: skip
    status, numba_loaded = json.loads(run.stdout.strip().splitlines()[-1])
    assert status in (0, 1) and not numba_loaded
    assert (out / "folded.stl").exists() and (out / "picture.png").exists()
    assert not list(cache.glob("*/compiling"))
