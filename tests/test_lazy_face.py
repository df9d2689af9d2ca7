"""The layers' faces read ``ALL`` entries from their submodules' ``__all__`` without importing."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

from holofold.geometry.lazy_face import source_all


@pytest.mark.parametrize(
    "package, module",
    [("holofold.geometry", "miura"), ("holofold.fitting", "curve_files"),
     ("holofold.mechanics", "fold_check"), ("holofold.design", "database.pattern_batch")],
)  # fmt: skip
def test_source_all_is_the_modules_all(package, module):
    pkg = importlib.import_module(package)
    got = source_all(pkg.__file__, module)
    assert got == importlib.import_module(f"{package}.{module}").__all__
    assert set(got) <= set(pkg.__all__)


def test_a_face_still_imports_no_submodule():
    code = (
        "import sys, holofold.geometry, holofold.fitting, holofold.mechanics, holofold.design\n"
        "print(sorted(m for m in sys.modules if m.startswith('holofold.')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert eval(out.stdout) == [
        "holofold.design", "holofold.fitting", "holofold.geometry", "holofold.geometry.lazy_face",
        "holofold.mechanics",
    ]  # fmt: skip


def test_a_computed_all_is_refused(tmp_path):
    (tmp_path / "__init__.py").write_text("")
    (tmp_path / "mod.py").write_text('__all__ = ["a", NAME]\n')
    with pytest.raises(ImportError, match="not a list of quoted names"):
        source_all(str(tmp_path / "__init__.py"), "mod")
    (tmp_path / "other.py").write_text("__all__ = ('a',)\n")
    with pytest.raises(ImportError, match="no literal"):
        source_all(str(tmp_path / "__init__.py"), "other")
