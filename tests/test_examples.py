"""The example scripts run and leave their results where the README says."""

import runpy
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_render_miura_writes_a_png(tmp_path, monkeypatch):
    png = tmp_path / "miura.png"
    monkeypatch.setattr(sys, "argv", ["render_miura.py", str(png)])
    ns = runpy.run_path(str(ROOT / "examples" / "render_miura.py"))
    res = ns["RESULT"]
    assert res["png"] == png and res["watertight"] and res["panels"] == 36
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width = int.from_bytes(data[16:20], "big")
    height = int.from_bytes(data[20:24], "big")
    assert (width, height) == (1400, 600)
