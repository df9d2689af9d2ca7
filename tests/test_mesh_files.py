"""holofold's own STL, OBJ and PLY writers (geometry/mesh_files.py): read back by trimesh to
the same triangles, and the same meshes as trimesh's writers gave (issue 37 item 4)."""

import io
import math

import numpy as np
import pytest
import trimesh

from holofold.geometry.export import export
from holofold.geometry.mesh import export_mesh, folded_mesh
from holofold.geometry.mesh_files import mesh_file, obj_text, stl_bytes
from holofold.geometry.miura import miura_sheet

KINDS = ("stl", "obj", "ply")


@pytest.fixture(scope="module")
def miura():
    return miura_sheet(3, 4, a=0.02, b=0.015, gamma=math.radians(65), ext=0.7)


def _soup(data, kind) -> np.ndarray:
    """(m, 3, 3) corners of the triangles of a file's content, read by trimesh."""
    raw = data.encode() if isinstance(data, str) else data
    mesh = trimesh.load(io.BytesIO(raw), file_type=kind, process=False, force="mesh")
    return np.asarray(mesh.vertices)[np.asarray(mesh.faces)]


def _expected(mesh, scale, kind) -> np.ndarray:
    tri = np.asarray(mesh.vertices)[np.asarray(mesh.faces)] * scale
    return tri.astype(np.float32).astype(float) if kind in ("stl", "ply") else tri  # float32 files


@pytest.mark.parametrize("kind", KINDS)
def test_holofold_files_read_back_by_trimesh(miura, kind, tmp_path):
    """The file of a pattern (no trimesh on that path) holds the folded mesh in mm: trimesh reads
    the same triangles, to 1e-9 of the size (OBJ: 8 decimals of mm; STL and PLY: the float32
    of the format, compared with the float32 of the coordinates)."""
    path = export(miura, tmp_path / f"s.{kind}")
    mesh = folded_mesh(miura)
    back = _soup(path.read_bytes(), kind)
    want = _expected(mesh, 1e3, kind)
    size = float(np.ptp(want.reshape(-1, 3), axis=0).max())
    assert back.shape == want.shape
    np.testing.assert_allclose(back, want, rtol=0, atol=1e-9 * size)
    # a trimesh.Trimesh given directly is written by the same code
    assert export_mesh(mesh, kind) == mesh_file(mesh.vertices, mesh.faces, kind, "mm",
                                                mesh.metadata["name"])  # fmt: skip


@pytest.mark.parametrize("kind", KINDS)
def test_same_mesh_as_trimesh_wrote(miura, kind):
    """The former writer (trimesh's exporter on the mesh scaled to mm) and holofold's give the
    same mesh (not the same bytes): triangles to 1e-6 mm, STL normals to 1e-6."""
    mesh = folded_mesh(miura)
    old_mesh = mesh.copy()
    old_mesh.apply_scale(1e3)
    old = trimesh.exchange.export.export_mesh(old_mesh, None, file_type=kind)
    new = export_mesh(mesh, kind)
    np.testing.assert_allclose(_soup(new, kind), _soup(old, kind), rtol=0, atol=1e-6)
    if kind == "stl":
        rec = [("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]
        n_old = np.frombuffer(old[84:], dtype=rec)["n"]
        n_new = np.frombuffer(new[84:], dtype=rec)["n"]
        np.testing.assert_allclose(n_new, n_old, atol=1e-6)
        assert np.frombuffer(new[80:84], "<u4")[0] == len(mesh.faces)
        assert len(new) == 84 + 50 * len(mesh.faces)


def test_stl_normals_and_degenerate_triangles():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0], [2, 0, 0]], float)
    t = np.array([[0, 1, 2], [0, 1, 3]])  # the second has no area
    data = stl_bytes(v, t, "mm")
    rec = np.frombuffer(data[84:], dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    np.testing.assert_array_equal(rec["n"], [[0, 0, 1], [0, 0, 0]])
    assert not data.startswith(b"solid") and b"units: mm" in data[:80]


def test_obj_text_layout_and_refusals():
    v = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 1e-3, 0]], float)
    text = mesh_file(v, [[0, 1, 2]], "obj", "mm", name="piece")
    assert text.splitlines() == ["# holofold mesh, units: mm", "", "o piece",
                                 "v 0.00000000 0.00000000 0.00000000",
                                 "v 1.00000000 0.00000000 0.00000000",
                                 "v 0.00000000 1.00000000 0.00000000", "f 1 2 3"]  # fmt: skip
    assert obj_text(v, np.zeros((0, 3), int)).count("\nf ") == 0
    with pytest.raises(ValueError, match="do not exist"):
        mesh_file(v, [[0, 1, 3]], "stl")
    with pytest.raises(ValueError, match="unknown mesh type"):
        mesh_file(v, [[0, 1, 2]], "glb")


@pytest.mark.parametrize("kind", ("ply", "obj"))
def test_vertex_colours_are_kept(miura, kind):
    """A mesh coloured per vertex (the gripper's closed_temperature.ply) keeps its colours in
    PLY (uchar RGBA) and OBJ (r g b after each vertex): trimesh reads them back (OBJ to the
    1/255 its floats round to); STL, which has none, refuses them."""
    mesh = folded_mesh(miura)
    rng = np.random.default_rng(5)
    rgba = np.column_stack(
        [rng.integers(0, 256, (len(mesh.vertices), 3)), np.full(len(mesh.vertices), 255)]
    )
    coloured = mesh.copy()
    coloured.visual.vertex_colors = rgba.astype(np.uint8)
    data = export_mesh(coloured, kind, units="mm")
    raw = data.encode() if isinstance(data, str) else data
    back = trimesh.load(io.BytesIO(raw), file_type=kind, process=False, force="mesh")
    assert back.visual.kind == "vertex"
    got = np.asarray(back.visual.vertex_colors)[:, :3].astype(int)
    assert np.abs(got - rgba[:, :3]).max() <= (1 if kind == "obj" else 0)
    with pytest.raises(ValueError, match="STL has no vertex colours"):
        mesh_file(mesh.vertices, mesh.faces, "stl", colours=rgba)
