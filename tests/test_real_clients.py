"""The fabrication files in the programs that use them: a slicer and Rabbit Ear.

* PrusaSlicer (or Slic3r), Debian's packages (``.ci/run`` installs prusa-slicer when missing),
  slices the printable part of a fitted strip and of a Miura sheet, and a folded-shape STL,
  written in millimetres: G-code with layers and an estimated print time must come out.
* Rabbit Ear (the npm package, installed once into a cache folder with ``npm``) validates the
  FOLD files and folds the Miura sheet from its fold angles: the vertices it computes must be
  holofold's folded coordinates (up to a rigid motion, not a mirror image).

Each test skips with a message where its program cannot be had (no slicer on PATH; no node or
npm, or the npm registry out of reach).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import trimesh

from holofold.fitting import export_strip_files, fit_strip
from holofold.geometry import export_pattern_files, miura_sheet, printable_solid
from holofold.geometry.export import export
from holofold.geometry.solid import SolidWarning

pytestmark = pytest.mark.slow

RABBIT_EAR = "rabbit-ear@0.9.32"
SLICE = ["--layer-height", "0.2", "--first-layer-height", "0.2"]

REFOLD_JS = r"""
// Validate FOLD files with Rabbit Ear and fold each from its fold angles (root face 0).
const ear = require("rabbit-ear");
const fs = require("fs");
const out = {};
for (const file of process.argv.slice(2)) {
  const fold = JSON.parse(fs.readFileSync(file, "utf8"));
  const g = {
    vertices_coords: fold.vertices_coords,
    edges_vertices: fold.edges_vertices,
    edges_assignment: fold.edges_assignment,
    edges_foldAngle: fold.edges_foldAngle,
    faces_vertices: fold.faces_vertices,
  };
  const report = ear.graph.validate(g);
  g.faces_faces = ear.graph.makeFacesFaces(g);
  out[file] = {
    summary: report.summary,
    counts: [g.vertices_coords.length, g.edges_vertices.length, g.faces_vertices.length],
    folded: ear.graph.makeVerticesCoordsFolded(g, 0),
  };
}
process.stdout.write(JSON.stringify(out));
"""


@pytest.fixture(scope="module")
def slicer() -> list[str]:
    for name in ("prusa-slicer", "slic3r"):
        exe = shutil.which(name)
        if exe:
            return [exe]
    pytest.skip("no slicer on PATH: apt-get install prusa-slicer (or slic3r); .ci/run does")


def _slice(slicer, stl: Path) -> tuple[int, str, list[float]]:
    """Layer count, estimated print time and layer heights (mm) of the G-code of ``stl``."""
    gcode = stl.with_suffix(".gcode")
    if Path(slicer[0]).name == "prusa-slicer":
        cmd = [*slicer, "--export-gcode", *SLICE, str(stl), "-o", str(gcode)]
    else:  # Slic3r 1.3
        cmd = [*slicer, "--layer-height", "0.2", "--first-layer-height", "0.2", str(stl),
               "--output", str(gcode)]  # fmt: skip
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    text = gcode.read_text()
    assert "No layers were detected" not in run.stdout + run.stderr
    layers = text.count(";LAYER_CHANGE") or len(re.findall(r"^G1 Z", text, re.M))
    z = [float(v) for v in re.findall(r"^;Z:([0-9.]+)", text, re.M)]
    when = re.search(r"estimated printing time \(normal mode\) = (.+)", text)
    return layers, (when.group(1).strip() if when else ""), z


def _on_bed(p, size=0.19):
    """The pattern scaled so that its flat layout is ``size`` (m) long: it fits a 200 mm bed."""
    s = size / float(np.ptp(p.flat, axis=0).max())
    return dataclasses.replace(p, coords=p.coords * s, flat=p.flat * s), s


def test_slicer_prints_the_fitted_arch_and_a_miura_sheet(slicer, tmp_path):
    # the paper's arch (m = 12, offset 0.2, stripeWidth 0.02, extrude 0.1 on a 2 m half circle)
    # scaled by 1/43 to a 190 mm part; real print dimensions: 2 mm panels, 0.6 mm hinges, 1.5 mm
    arch, s = _on_bed(fit_strip("half-circle", 12, 0.2, 0.02, 0.1).flat_pattern)
    assert 1 / s == pytest.approx(42.89, abs=0.01)
    export(printable_solid(arch, 2e-3, 0.6e-3, 1.5e-3), tmp_path / "arch.stl")
    layers, minutes, z = _slice(slicer, tmp_path / "arch.stl")
    assert layers == 10  # 2 mm in 0.2 mm layers
    assert z[:3] == pytest.approx([0.2, 0.4, 0.6]) and z[-1] == pytest.approx(2.0)
    assert minutes, "no estimated print time in the G-code"
    print(f"arch printable.stl: {layers} layers, {minutes}")
    # a 6 x 6 Miura sheet of 20 mm panels (104 x 130 mm), its printable part and its folded
    # thick panels (a folded-shape STL: 16 loose bodies)
    sheet = miura_sheet(6, 6, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    with pytest.warns(SolidWarning, match="thick panels intersect"):  # centred 2 mm panels
        files = export_pattern_files(
            sheet, tmp_path / "miura", thickness=2e-3, crease_width=2e-3, crease_thickness=0.6e-3
        )
    names = {p.name: p for p in files}
    layers, minutes, _ = _slice(slicer, names["printable.stl"])
    assert layers == 10 and minutes
    print(f"Miura printable.stl: {layers} layers, {minutes}")
    folded_layers, folded_minutes, _ = _slice(slicer, names["thick.stl"])
    height = np.ptp(trimesh.load(names["thick.stl"]).bounds[:, 2])  # mm: the file's unit
    assert 15 < height < 20 and abs(folded_layers - height / 0.2) <= 1 and folded_minutes
    print(f"Miura thick.stl (folded): {folded_layers} layers, {folded_minutes}")
    bent_layers, bent_minutes, _ = _slice(slicer, names["printable_folded.stl"])
    assert abs(bent_layers - folded_layers) <= 3 and bent_minutes  # the bends stand out < 0.6 mm
    print(f"Miura printable_folded.stl: {bent_layers} layers, {bent_minutes}")


def test_slicer_reads_the_strip_files_in_millimetres(slicer, tmp_path):
    # the strip's files as holofold fit writes them: a 1:25 arch (8 cm radius)
    fit = fit_strip("half-circle:radius=0.08", 12, 0.008, 0.0008, 0.016)
    files = export_strip_files(fit, tmp_path, panel_thickness=2e-3, crease_width=2e-3,
                               crease_thickness=0.6e-3)  # fmt: skip
    names = {p.name: p for p in files}
    layers, minutes, _ = _slice(slicer, names["strip_solid.stl"])  # folded thick panels
    assert 400 < layers < 450 and minutes  # an 8 cm tall arch (+ offset) in 0.2 mm layers
    # its printable part is 326 mm long (the development is twice the span): too long for the
    # 200 mm bed, which the slicer says rather than slicing it
    assert np.ptp(trimesh.load(names["printable.stl"]).bounds[:, 0]) > 300


def _node_modules() -> Path:
    node, npm = shutil.which("node"), shutil.which("npm")
    if not (node and npm):
        pytest.skip("node or npm not on PATH: Rabbit Ear (npm) cannot run here")
    cache = Path(os.environ.get("HOLOFOLD_NODE_CACHE", Path.home() / ".cache" / "holofold-node"))
    pkg = cache / "node_modules" / "rabbit-ear" / "package.json"
    if not pkg.is_file():
        cache.mkdir(parents=True, exist_ok=True)
        run = subprocess.run(
            [npm, "install", "--no-audit", "--no-fund", "--prefix", str(cache), RABBIT_EAR],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        if run.returncode != 0 or not pkg.is_file():
            pytest.skip(f"npm install {RABBIT_EAR} failed: {run.stderr.strip()[-300:]}")
    return cache


def _rabbit_ear(files: list[Path], tmp_path: Path) -> dict:
    cache = _node_modules()
    script = tmp_path / "refold.js"
    script.write_text(REFOLD_JS)
    env = {**os.environ, "NODE_PATH": str(cache / "node_modules")}
    run = subprocess.run(["node", str(script), *map(str, files)], capture_output=True,
                         text=True, timeout=120, env=env, cwd=tmp_path)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    return json.loads(run.stdout)


def _rigid_residual(A: np.ndarray, B: np.ndarray) -> float:
    """Largest distance after the best proper rigid motion of A onto B (Kabsch)."""
    a, b = A - A.mean(axis=0), B - B.mean(axis=0)
    U, _, Vt = np.linalg.svd(a.T @ b)
    d = np.sign(np.linalg.det(U @ Vt))
    R = U @ np.diag([1.0, 1.0, d]) @ Vt
    return float(np.abs(a @ R - b).max())


def test_rabbit_ear_validates_and_refolds_the_miura_sheet(tmp_path):
    sheet = miura_sheet(4, 4, a=0.02, b=0.03, gamma=math.radians(60), ext=0.6)
    files = export_pattern_files(sheet, tmp_path / "miura")
    fit = fit_strip("half-circle", 12, 0.2, 0.02, 0.1)
    files += export_strip_files(fit, tmp_path / "strip")
    folds = [p for p in files if p.suffix == ".fold"]
    out = _rabbit_ear(folds, tmp_path)
    miura, strip = out[str(folds[0])], out[str(folds[1])]
    assert miura["summary"] == "valid" and strip["summary"] == "valid"
    assert miura["counts"] == [sheet.n_vertices, sheet.n_edges, sheet.n_faces]
    assert strip["counts"] == [6 * 12 + 3, 10 * 12 + 2, 4 * 12]
    # folded from the flat crease pattern and the fold angles: holofold's folded sheet
    A = np.asarray(miura["folded"], float)
    assert _rigid_residual(A, sheet.coords) < 1e-12
    assert _rigid_residual(A * [1, 1, -1], sheet.coords) > 1e-3  # M and V not swapped
    # the strip's quads are warped: folding its development rigidly cannot give the strip
    B = np.asarray(strip["folded"], float)
    assert _rigid_residual(B, fit.pattern.coords) > 1e-3
