"""The kernel paths a test runs on: numpy always, compiled where numba imports.

``NO_COMPILED`` is why the compiled path is missing (``None`` where it runs); ``PATHS`` are the
parameters of the ``path`` fixture, which a test module imports to run on each path."""

from __future__ import annotations

import pytest

from holofold.mechanics import kernels

__all__ = ["NO_COMPILED", "PATHS", "path"]


def _compiled_available():
    try:
        kernels.kernel_path("compiled")
    except Exception as exc:  # EnvironmentFault: no numba here
        return str(exc)
    return None


NO_COMPILED = _compiled_available()
PATHS = [
    "numpy",
    pytest.param(
        "compiled",
        marks=pytest.mark.skipif(bool(NO_COMPILED), reason=f"compiled path: {NO_COMPILED}"),
    ),
]


@pytest.fixture(params=PATHS)
def path(request, monkeypatch):
    """Run the test on one kernel path (HOLOFOLD_KERNELS)."""
    monkeypatch.setenv(kernels.ENV, request.param)
    return kernels.kernel_path(request.param)
