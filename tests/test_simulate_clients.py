"""The folded FOLD file of ``holofold simulate`` in a real FOLD tool: Rabbit Ear (npm).

Rabbit Ear validates the key frame (the crease pattern with its targets) and every frame of the
fold path (the key frame's topology with the frame's coordinates), and folds the crease pattern
rigidly from the last frame's measured fold angles: for a pattern that folds rigidly, that is
holofold's last state up to a rigid motion. Skips where node/npm or the registry are missing.
"""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
from test_real_clients import _node_modules, _rigid_residual

import holofold.geometry as g
from holofold.mechanics import PatternLoad, PatternSetting, simulate_pattern, write_simulation

pytestmark = pytest.mark.slow

FRAMES_JS = r"""
const ear = require("rabbit-ear");
const fs = require("fs");
const fold = JSON.parse(fs.readFileSync(process.argv[2], "utf8"));
const topo = {
  edges_vertices: fold.edges_vertices,
  edges_assignment: fold.edges_assignment,
  faces_vertices: fold.faces_vertices,
};
const key = { ...topo, vertices_coords: fold.vertices_coords,
  edges_foldAngle: fold.edges_foldAngle };
const out = { key: ear.graph.validate(key).summary, frames: [] };
for (const fr of fold.file_frames) {
  const g = { ...topo, vertices_coords: fr.vertices_coords, edges_foldAngle: fr.edges_foldAngle };
  out.frames.push(ear.graph.validate(g).summary);
}
const last = fold.file_frames[fold.file_frames.length - 1];
const flat = { ...topo, vertices_coords: fold.vertices_coords,
  edges_foldAngle: last.edges_foldAngle };
flat.faces_faces = ear.graph.makeFacesFaces(flat);
out.refolded = ear.graph.makeVerticesCoordsFolded(flat, 0);
process.stdout.write(JSON.stringify(out));
"""


def test_rabbit_ear_reads_the_fold_path(tmp_path):
    cache = _node_modules()
    p = g.miura_sheet(4, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=0.6)
    setting = PatternSetting(
        supports=("side:-x",), loads=(PatternLoad("tip", "side:+x", (0, 0, -1), 0.05),),
    )  # fmt: skip
    sim = simulate_pattern(p, setting)
    write_simulation(sim, tmp_path / "out")
    script = tmp_path / "frames.js"
    script.write_text(FRAMES_JS)
    env = {"NODE_PATH": str(cache / "node_modules"), "PATH": "/usr/bin:/bin:/usr/local/bin"}
    run = subprocess.run(["node", str(script), str(tmp_path / "out" / "folded.fold")],
                         capture_output=True, text=True, timeout=120, env=env)  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    out = json.loads(run.stdout)
    assert out["key"] == "valid"
    assert len(out["frames"]) == len(sim.fold.fractions)
    assert set(out["frames"]) == {"valid"}
    A = np.asarray(out["refolded"], float)
    assert _rigid_residual(A, sim.fold.coords[-1]) < 1e-6 * 0.1
