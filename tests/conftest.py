"""Shared test fixtures.

The published databases of Zhu & Filipov (2022) live outside the repository, in
``../shared/reference-data`` (or wherever ``HOLOFOLD_REFERENCE_DATA`` points). Tests read
them only through the ``reference_data`` fixture, which skips with a clear message when
the folder is absent. Nothing from it is copied into the repository.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _reference_dir() -> Path | None:
    env = os.environ.get("HOLOFOLD_REFERENCE_DATA")
    candidates = [Path(env)] if env else []
    candidates.append(ROOT.parent / "shared" / "reference-data")
    for c in candidates:
        if (c / "README.md").is_file():
            return c
    return None


class ReferenceData:
    """Reader of the published, headerless ``data*_*.txt`` files.

    ``load("data0_SingleMiura")`` returns a DataFrame whose columns are named from the
    matching ``data0_FeatureName.txt``; ``path(stem)`` gives the file itself.
    """

    def __init__(self, folder: Path):
        self.folder = folder

    def path(self, stem: str) -> Path:
        p = self.folder / f"{stem}.txt"
        if not p.is_file():
            pytest.skip(f"reference file {p} is missing")
        return p

    def columns(self, stem: str) -> list[str]:
        prefix = stem.split("_", 1)[0]
        return (self.folder / f"{prefix}_FeatureName.txt").read_text().split()

    def load(self, stem: str) -> pd.DataFrame:
        arr = np.loadtxt(self.path(stem), delimiter=",", ndmin=2)
        return pd.DataFrame(arr, columns=self.columns(stem))


def pytest_configure(config):
    """One kernel path for the whole run: ``HOLOFOLD_KERNELS`` as set (CI runs the fast tier
    with ``numpy`` too), or else the compiled path, compiled ahead here once, before any worker
    starts (the numpy path where numba is missing). So no test sees the default ``auto`` mode
    switch paths halfway; tests/test_kernel_cache.py tests ``auto`` itself in fresh cache
    folders."""
    if os.environ.get("HOLOFOLD_KERNELS") or hasattr(config, "workerinput"):
        return
    from holofold.mechanics import kernels
    from holofold.mechanics.kernel_compile import compile_kernels

    try:
        compile_kernels(marker=True)
        os.environ["HOLOFOLD_KERNELS"] = "compiled"
    except kernels.EnvironmentFault as exc:
        os.environ["HOLOFOLD_KERNELS"] = "numpy"
        print(f"\nholofold tests run on the numpy kernels: {exc}")


@pytest.fixture(scope="session")
def reference_data() -> ReferenceData:
    folder = _reference_dir()
    if folder is None:
        pytest.skip(
            "published reference databases not found: expected ../shared/reference-data "
            "next to the repository or HOLOFOLD_REFERENCE_DATA pointing to it"
        )
    return ReferenceData(folder)
