"""Fan-triangulated surfaces and trimesh exports."""

import math

import numpy as np
import pytest
import trimesh

from holofold.geometry.export import export
from holofold.geometry.mesh import export_mesh, fan_triangulation, flat_mesh, folded_mesh
from holofold.geometry.miura import miura_sheet


@pytest.fixture(scope="module")
def miura():
    return miura_sheet(3, 4, a=0.02, b=0.015, gamma=math.radians(65), ext=0.7)


def test_fan_keeps_vertex_ids_and_area(miura):
    v, t, owner = fan_triangulation(miura.coords, miura.faces)
    assert np.array_equal(v[: miura.n_vertices], miura.coords)
    assert len(t) == 4 * miura.n_faces and np.array_equal(np.bincount(owner), [4] * miura.n_faces)
    # planar parallelogram panels: the fan area equals |a x b| of each panel
    mesh = folded_mesh(miura)
    a, b = 0.02, 0.015
    assert mesh.area == pytest.approx(miura.n_faces * a * b * math.sin(math.radians(65)), rel=1e-12)


def test_folded_mesh_is_consistently_oriented_and_flat_mesh_is_flat(miura):
    mesh = folded_mesh(miura)
    assert mesh.is_winding_consistent
    flat = flat_mesh(miura)
    assert np.allclose(flat.vertices[:, 2], 0)
    assert flat.area == pytest.approx(mesh.area, rel=1e-12)  # rigid folding keeps the area
    assert (flat.face_normals[:, 2] > 0.999).all()  # counter-clockwise panels face +z


@pytest.mark.parametrize("kind", ["stl", "obj", "ply"])
def test_round_trip_through_trimesh_in_mm_by_default(miura, kind, tmp_path):
    path = export(miura, tmp_path / f"s.{kind}")
    back = trimesh.load(path, force="mesh", process=True)
    mesh = folded_mesh(miura)
    assert back.area == pytest.approx(mesh.area * 1e6, rel=1e-6)  # mm^2
    assert np.allclose(back.bounds, mesh.bounds * 1e3, atol=1e-4)
    data = export_mesh(mesh, kind)
    raw = data if isinstance(data, bytes) else data.encode()
    assert b"holofold mesh, units: mm" in raw[:200]  # STL header, OBJ and PLY comments
    metres = trimesh.load(export(miura, tmp_path / f"m.{kind}", units="m"), force="mesh")
    assert np.allclose(metres.bounds, mesh.bounds, atol=1e-7)
    assert b"units: m\n" in path.with_name(f"m.{kind}").read_bytes()[:200] or kind == "stl"


def test_units_are_checked_before_writing(miura, tmp_path):
    from holofold.geometry import ParameterError

    with pytest.raises(ParameterError, match="unknown length unit 'furlong'"):
        export(miura, tmp_path / "x.stl", units="furlong")
    with pytest.raises(ParameterError, match="applies to mesh files only"):
        export(miura, tmp_path / "x.fold", units="mm")
    assert not list(tmp_path.iterdir())


def test_unknown_export_type_is_named(miura, tmp_path):
    with pytest.raises(ValueError, match="unknown file type 'step'; known: fold, svg, dxf, stl"):
        export(miura, tmp_path / "x.step")
    assert not (tmp_path / "x.step").exists()
    with pytest.raises(ValueError, match="unknown mesh type"):
        export_mesh(folded_mesh(miura), "gltf")


def test_format_registry_unit_policies(miura, tmp_path):
    """Each format's own writer and unit: glTF is metres by its specification (a registered
    format, not a branch that assumes PLY), STL the caller's unit (mm by default)."""
    import io

    from holofold.geometry import FORMATS, ParameterError

    assert FORMATS["glb"].unit == "m" and FORMATS["stl"].unit is None
    path = export(miura, tmp_path / "m.glb")
    assert path.read_bytes()[:4] == b"glTF"
    scene = trimesh.load(io.BytesIO(path.read_bytes()), file_type="glb")
    (mesh,) = scene.geometry.values()
    extent = np.ptp(folded_mesh(miura).vertices, axis=0)  # metres
    np.testing.assert_allclose(np.sort(np.ptp(mesh.vertices, axis=0)), np.sort(extent), rtol=1e-6)
    with pytest.raises(ParameterError, match="written in m"):
        export(miura, tmp_path / "mm.glb", units="mm")
    stl = trimesh.load(export(miura, tmp_path / "m.stl"))
    np.testing.assert_allclose(np.ptp(stl.vertices, axis=0), 1000 * extent, rtol=1e-6)
    with pytest.raises(TypeError, match="needs a CreasePattern"):
        export(folded_mesh(miura), tmp_path / "x.dxf")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.glb", "m.stl"]
