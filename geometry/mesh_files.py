"""STL (binary), OBJ and PLY (binary) files of a triangle mesh, written by holofold with numpy.

The three unit-less mesh formats of :func:`holofold.geometry.export` are plain arrays in a
file, so holofold writes them itself: ``holofold simulate`` and the other writers of these
files load no trimesh (with networkx and scipy.spatial, 0.35-0.4 s of start-up; issue 37). The
layout is the one trimesh wrote before (and reads): STL little-endian float32 with unit face
normals (zero for a degenerate triangle), OBJ ``v`` lines with 8 decimals and 1-based ``f``
lines under an ``o NAME`` line, PLY ``binary_little_endian`` with float32 vertices and
``uchar int`` face lists. The unit is named where the format allows (the STL header, an OBJ
comment, a PLY header comment).
"""

from __future__ import annotations

import numpy as np

from holofold.geometry.units import length_factor

__all__ = ["MESH_FILE_TYPES", "mesh_file", "stl_bytes", "obj_text", "ply_bytes"]

MESH_FILE_TYPES = ("stl", "obj", "ply")


def _check(vertices, triangles) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(vertices, float)
    t = np.asarray(triangles, np.int64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be (n, 3), got {v.shape}")
    if t.size == 0:
        t = t.reshape(0, 3)
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"triangles must be (m, 3), got {t.shape}")
    if t.size and (t.min() < 0 or t.max() >= len(v)):
        raise ValueError("triangles refer to vertices that do not exist")
    return v, t


def _note(units: str) -> str:
    return f"holofold mesh, units: {units}"


def stl_bytes(vertices, triangles, units: str = "mm") -> bytes:
    """Binary STL of ``triangles`` (m, 3) over ``vertices`` (n, 3), coordinates as given (already
    in ``units``, which the 80-byte header names); unit normals, zero where a triangle has no
    area."""
    v, t = _check(vertices, triangles)
    tri = v[t]  # (m, 3, 3)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1)
    ok = norm > 0
    n[ok] /= norm[ok, None]
    n[~ok] = 0.0
    rows = np.zeros(len(t), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rows["n"] = n
    rows["v"] = tri
    head = _note(units).encode("ascii").ljust(80, b" ")[:80]  # must not start with "solid"
    return head + np.uint32(len(t)).astype("<u4").tobytes() + rows.tobytes()


def _colours(colours, n: int) -> np.ndarray | None:
    """(n, 4) uint8 RGBA vertex colours, or None; (n, 3) gets an opaque alpha."""
    if colours is None:
        return None
    c = np.asarray(colours)
    if c.ndim != 2 or c.shape[0] != n or c.shape[1] not in (3, 4):
        raise ValueError(f"vertex colours must be ({n}, 3) or ({n}, 4), got {c.shape}")
    if c.shape[1] == 3:
        c = np.column_stack([c, np.full(n, 255)])
    return np.clip(np.rint(c), 0, 255).astype(np.uint8)


def obj_text(vertices, triangles, units: str = "mm", name: str | None = None, colours=None) -> str:
    """Wavefront OBJ: a unit comment, ``o name``, ``v`` lines (8 decimals; with ``colours``
    (n, 3 or 4) uint8, each followed by its r g b in [0, 1], the extension trimesh, MeshLab and
    Blender read), ``f`` lines (1-based)."""
    v, t = _check(vertices, triangles)
    c = _colours(colours, len(v))
    parts = [f"# {_note(units)}\n"]
    if name:
        parts.append(f"\no {name}\n")
    if c is None:
        parts.append(("v %.8f %.8f %.8f\n" * len(v)) % tuple(v.ravel().tolist()))
    else:
        rows = np.column_stack([v, c[:, :3] / 255.0])
        parts.append(("v %.8f %.8f %.8f %.8f %.8f %.8f\n" * len(v)) % tuple(rows.ravel().tolist()))
    parts.append(("f %d %d %d\n" * len(t)) % tuple((t + 1).ravel().tolist()))
    return "".join(parts)


def ply_bytes(vertices, triangles, units: str = "mm", colours=None) -> bytes:
    """Binary little-endian PLY: float32 vertices (with ``colours`` (n, 3 or 4) uint8, each
    followed by its ``uchar`` red, green, blue, alpha), ``uchar int`` triangle lists."""
    v, t = _check(vertices, triangles)
    c = _colours(colours, len(v))
    rgba = "".join(f"property uchar {k}\n" for k in ("red", "green", "blue", "alpha"))
    head = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment {_note(units)}\n"
        f"element vertex {len(v)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        f"{rgba if c is not None else ''}"
        f"element face {len(t)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    ).encode("ascii")
    faces = np.zeros(len(t), dtype=[("k", "u1"), ("i", "<i4", 3)])
    faces["k"] = 3
    faces["i"] = t
    if c is None:
        verts = v.astype("<f4").tobytes()
    else:
        rows = np.zeros(len(v), dtype=[("x", "<f4", 3), ("c", "u1", 4)])
        rows["x"] = v
        rows["c"] = c
        verts = rows.tobytes()
    return head + verts + faces.tobytes()


def mesh_file(
    vertices,
    triangles,
    file_type: str,
    units: str = "mm",
    name: str | None = None,
    colours=None,
) -> bytes | str:
    """The content of a ``file_type`` (stl, obj, ply) file of a mesh whose ``vertices`` are in
    metres, written in ``units`` (the coordinates divided by its
    :func:`~holofold.geometry.units.length_factor`); str for OBJ, bytes otherwise. Vertex
    ``colours`` (n, 3 or 4) uint8 go into OBJ and PLY; STL has none, so a coloured mesh is
    refused there rather than written without them."""
    kind = file_type.lower().lstrip(".")
    if kind not in MESH_FILE_TYPES:
        raise ValueError(f"unknown mesh type {file_type!r}; known: {', '.join(MESH_FILE_TYPES)}")
    k = length_factor(units)
    v = np.asarray(vertices, float)
    if k != 1.0:
        v = v / k
    if kind == "stl":
        if colours is not None:
            raise ValueError("STL has no vertex colours: write the coloured mesh as PLY or OBJ")
        return stl_bytes(v, triangles, units)
    if kind == "obj":
        return obj_text(v, triangles, units, name, colours)
    return ply_bytes(v, triangles, units, colours)
