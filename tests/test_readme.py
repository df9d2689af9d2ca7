"""The README's Python example runs as printed (from the repository root's sibling layout)."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_readme_python_example_runs(reference_data, tmp_path, monkeypatch, capsys):
    text = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    code = code.replace(
        "../shared/reference-data/data3_ShapeFit.txt", str(reference_data.path("data3_ShapeFit"))
    )
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})  # our own README, not user input
    out = capsys.readouterr().out
    assert (tmp_path / "sheet.fold").is_file() and (tmp_path / "sheet.stl").is_file()
    assert "Zstiff" in out and "precision" in out
