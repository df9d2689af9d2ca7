"""Mesh files checked before trimesh may drop or repair them (issue 33 item 1)."""

import struct

import numpy as np
import pytest

from holofold.geometry.errors import FormatError
from holofold.geometry.mesh_reader import MAX_MESH_FACES, read_mesh

TRI = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]], float)
FACES = [(0, 1, 2), (1, 3, 2)]


def _binary_stl(path, V=TRI, faces=FACES, count=None):
    body = b"".join(struct.pack("<12fH", 0, 0, 1, *V[list(f)].ravel(), 0) for f in faces)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", len(faces) if count is None else count) + body)
    return path


def _ascii_stl(path, V=TRI, faces=FACES):
    lines = ["solid t"]
    for f in faces:
        lines += ["facet normal 0 0 1", "outer loop"]
        lines += [f"vertex {x:.17g} {y:.17g} {z:.17g}" for x, y, z in V[list(f)]]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join(lines + ["endsolid t"]) + "\n")
    return path


def _obj(path, V=TRI, faces=FACES, base=1):
    text = "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V)
    text += "".join("f " + " ".join(str(i + base) for i in f) + "\n" for f in faces)
    path.write_text(text)
    return path


def _off(path, V=TRI, faces=FACES):
    text = f"OFF\n{len(V)} {len(faces)} 0\n" + "".join(
        f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V
    )
    path.write_text(text + "".join(f"3 {a} {b} {c}\n" for a, b, c in faces))
    return path


def _ply(path, V=TRI, faces=FACES):
    head = (f"ply\nformat ascii 1.0\nelement vertex {len(V)}\nproperty float x\n"
            f"property float y\nproperty float z\nelement face {len(faces)}\n"
            "property list uchar int vertex_indices\nend_header\n")  # fmt: skip
    text = head + "".join(f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V)
    path.write_text(text + "".join(f"3 {a} {b} {c}\n" for a, b, c in faces))
    return path


WRITERS = {"stl": _binary_stl, "ascii.stl": _ascii_stl, "obj": _obj, "off": _off, "ply": _ply}


@pytest.mark.parametrize("kind", list(WRITERS))
def test_clean_file_reads_its_own_numbers(tmp_path, kind):
    V, F = read_mesh(WRITERS[kind](tmp_path / f"m.{kind}"))
    assert F.shape == (2, 3)
    # every triangle's corners are the written ones
    np.testing.assert_allclose(V[F].reshape(-1, 3), TRI[np.array(FACES)].reshape(-1, 3), atol=1e-6)


@pytest.mark.parametrize("kind", list(WRITERS))
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_vertex_refused(tmp_path, kind, bad):
    V = TRI.copy()
    V[3, 2] = bad
    with pytest.raises(FormatError, match="not finite"):
        read_mesh(WRITERS[kind](tmp_path / f"m.{kind}", V=V))


@pytest.mark.parametrize("kind", ["ascii.stl", "obj", "off", "ply"])
def test_huge_coordinates_refused(tmp_path, kind):
    V = TRI * 1e300
    with pytest.raises(FormatError, match="beyond"):
        read_mesh(WRITERS[kind](tmp_path / f"m.{kind}", V=V))


@pytest.mark.parametrize("kind", list(WRITERS))
def test_collinear_refused(tmp_path, kind):
    V = np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]], float)
    with pytest.raises(FormatError, match="one line"):
        read_mesh(WRITERS[kind](tmp_path / f"m.{kind}", V=V))


def test_obj_index_zero_and_out_of_range(tmp_path):
    with pytest.raises(FormatError, match="index 0 is out of range"):
        read_mesh(_obj(tmp_path / "z.obj", base=0))
    with pytest.raises(FormatError, match="out of range"):
        read_mesh(_obj(tmp_path / "o.obj", faces=[(0, 1, 9)]))


@pytest.mark.parametrize("kind", ["off", "ply", "ascii.stl"])
def test_truncated_text_refused(tmp_path, kind):
    p = WRITERS[kind](tmp_path / f"m.{kind}")
    text = p.read_text()
    p.write_text(text[: int(0.9 * len(text))])
    with pytest.raises(FormatError):
        read_mesh(p)


def test_truncated_binary_stl_refused(tmp_path):
    p = _binary_stl(tmp_path / "m.stl")
    p.write_bytes(p.read_bytes()[:-10])
    with pytest.raises(FormatError, match="truncated"):
        read_mesh(p)


def test_declared_count_over_limit_refused_before_reading(tmp_path):
    p = _binary_stl(tmp_path / "big.stl", count=MAX_MESH_FACES + 1)
    with pytest.raises(FormatError, match="declares 2000001 triangles"):
        read_mesh(p)


def test_garbage_bytes_named(tmp_path):
    p = tmp_path / "junk.stl"
    p.write_bytes(bytes(range(256)) * 3)
    with pytest.raises(FormatError, match="junk.stl"):
        read_mesh(p)


def test_surface_refuses_nan_stl_rather_than_dropping(tmp_path):
    from holofold.fitting.surfaces import read_surface

    V = TRI.copy()
    V[0, 0] = np.nan
    with pytest.raises(FormatError, match="not finite"):
        read_surface(_binary_stl(tmp_path / "nan.stl", V=V), units="m", check_size=False)
