"""Damaged surface meshes are refused before a library can drop or repair part of them
(issue 33): one NaN vertex, a file cut off, garbage bytes, a header that promises too much."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from holofold.fitting.surfaces import read_surface
from holofold.geometry.errors import FormatError


def _grid(n=8):
    x, y = np.meshgrid(np.linspace(0, 0.1, n), np.linspace(0, 0.1, n))
    V = np.c_[x.ravel(), y.ravel(), 0.01 * np.sin(30 * x.ravel())]
    F = []
    for i in range(n - 1):
        for j in range(n - 1):
            a = i * n + j
            F += [[a, a + 1, a + n], [a + 1, a + n + 1, a + n]]
    return V, np.array(F)


@pytest.fixture
def files(tmp_path):
    V, F = _grid()
    for ext in ("stl", "obj", "off"):
        trimesh.Trimesh(V, F, process=False).export(tmp_path / f"ok.{ext}")
    W = V.copy()
    W[10, 2] = np.nan
    trimesh.Trimesh(W, F, process=False).export(tmp_path / "nan.stl")
    return tmp_path, V, F


def test_clean_files_read_with_every_triangle(files):
    folder, V, F = files
    for ext in ("stl", "obj", "off"):
        s = read_surface(folder / f"ok.{ext}", check_size=False)
        assert s is not None


@pytest.mark.parametrize(
    "make, says",
    [
        (lambda d: (d / "nan.stl").read_bytes(), "vertices with non-finite coordinates"),
        (lambda d: (d / "ok.stl").read_bytes()[:-30], "a binary STL of 98 triangles is 4,984"),
        (lambda d: b"\x00\xff" * 500, "refused before reading"),
    ],
)
def test_damaged_stl_is_refused(files, make, says):
    folder = files[0]
    bad = folder / "bad.stl"
    bad.write_bytes(make(folder))
    with pytest.raises(FormatError, match=says):
        read_surface(bad, check_size=False)


def test_damaged_obj_is_refused_at_its_line(files):
    folder = files[0]
    text = (folder / "ok.obj").read_text()
    lines = text.splitlines()
    v = [k for k, line in enumerate(lines) if line.startswith("v ")]
    f = [k for k, line in enumerate(lines) if line.startswith("f ")]
    cases = {
        "nan": ([*lines[: v[10]], "v nan 0.1 0.2", *lines[v[10] + 1 :]], "a vertex needs three"),
        # cut off inside a face line: two of its vertices left
        "cut": (text[: text.rindex("f ", 0, int(0.9 * len(text)))] + "f 12 13\n", "a face needs"),
        "zero": ([*lines[: f[0]], "f 0 1 2", *lines[f[0] + 1 :]], "face vertex 0 does not"),
        "far": ([*lines[: f[0]], "f 1 2 999", *lines[f[0] + 1 :]], "face vertex 999 does not"),
    }
    for name, (body, says) in cases.items():
        p = folder / f"{name}.obj"
        p.write_text(body if isinstance(body, str) else "\n".join(body) + "\n")
        with pytest.raises(FormatError, match=says):
            read_surface(p, check_size=False)


def test_off_shorter_than_its_header_is_refused(files):
    folder = files[0]
    lines = (folder / "ok.off").read_text().splitlines()
    (folder / "cut.off").write_text("\n".join(lines[:-5]) + "\n")
    with pytest.raises(FormatError, match="the header promises 64 vertices and 98 faces"):
        read_surface(folder / "cut.off", check_size=False)
