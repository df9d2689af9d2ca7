"""Triangle meshes read from STL, OBJ, PLY and OFF files, checked before any library sees them.

trimesh drops non-finite vertices and their triangles, repairs cut-off files and merges what it
likes while loading, so a damaged file would be fitted as another shape without a word. Here the
file is parsed with numpy first: counts are checked against the header (a binary STL's triangle
count against the file size, before reading), numbers must be finite and of a plausible size
(|x| <= :data:`MAX_MESH_COORD`), face indices in range; each problem is one line naming the
file (:class:`~holofold.geometry.errors.FormatError`). :func:`read_mesh` returns the arrays as
they are in the file (vertices in the file's numbers, shape (n, 3); triangles, shape (m, 3),
polygons fanned).
"""

from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np

from holofold.geometry.errors import FormatError

__all__ = [
    "MESH_TYPES",
    "MAX_MESH_FACES",
    "MAX_MESH_BYTES",
    "MAX_MESH_COORD",
    "read_mesh",
    "mesh_difference",
    "MeshWarning",
]


class MeshWarning(UserWarning):
    """A mesh file read whole that looks incomplete (vertices that are in no triangle)."""


#: file types read
MESH_TYPES = ("stl", "obj", "ply", "off")
#: the most triangles a mesh file may declare or hold (docs/limits.md)
MAX_MESH_FACES = 2_000_000
#: the largest mesh file read, bytes (2e6 binary STL triangles are 100 MB; text is ~2x)
MAX_MESH_BYTES = 256 * 1024 * 1024
#: the largest coordinate magnitude accepted, in the file's numbers (1e300 overflowed Qhull)
MAX_MESH_COORD = 1e9

_PLY_TYPES = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}


def read_mesh(path, *, max_faces: int = MAX_MESH_FACES) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float and triangles (m, 3) int of the mesh file ``path``, as written.

    Refused with one line naming the file: unknown type, over :data:`MAX_MESH_BYTES` or
    ``max_faces`` (a binary STL's declared count is checked before reading), counts that do not
    match the header (a truncated file), non-finite or huge numbers, indices out of range (an
    OBJ index 0), no triangles, or all vertices on one line.
    """
    path = Path(path)
    name = path.name
    kind = path.suffix.lower().lstrip(".")
    if kind not in MESH_TYPES:
        raise FormatError(f"{name!r}: mesh files must be {', '.join('.' + t for t in MESH_TYPES)}")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise FormatError(f"cannot read {name!r}: {exc.strerror}") from None
    if size > MAX_MESH_BYTES:
        raise FormatError(
            f"{name!r} is {size / 2**20:.0f} MiB, over the {MAX_MESH_BYTES >> 20} MiB "
            "limit for mesh files (docs/limits.md)"
        )
    with open(path, "rb") as fh:
        head = fh.read(84)
    if kind == "stl" and _is_binary_stl(head, size):
        V, F = _binary_stl(path, name, size, max_faces)
    else:
        try:
            text = path.read_bytes().decode("ascii")
        except UnicodeDecodeError:
            if kind == "ply":
                V, F = _ply(path, name, max_faces, None)
                return _checked(V, F, name, max_faces)
            raise FormatError(
                f"{name!r} is not a .{kind} file: it holds bytes that are not text"
                + (" and no binary STL header matching its size" if kind == "stl" else "")
            ) from None
        if kind == "stl":
            V, F = _ascii_stl(text, name)
        elif kind == "obj":
            V, F = _obj(text, name)
        elif kind == "off":
            V, F = _off(text, name, max_faces)
        else:
            V, F = _ply(path, name, max_faces, text)
    return _checked(V, F, name, max_faces)


def mesh_difference(name: str, V, F, mesh) -> str | None:
    """One line saying what a library removed from the mesh (``V``, ``F`` as read) when it built
    ``mesh`` (a trimesh), or None when every triangle was kept."""
    lost = len(F) - len(mesh.faces)
    if lost <= 0:
        return None
    return (
        f"{name!r}: {lost} of {len(F)} triangles were dropped as degenerate or duplicate "
        "when the mesh was built; the rest is used"
    )


# --------------------------------------------------------------------------- checks
def _checked(V, F, name, max_faces):
    V = np.asarray(V, float).reshape(-1, 3)
    F = np.asarray(F, np.int64).reshape(-1, 3)
    if len(F) == 0:
        raise FormatError(f"{name!r} holds no triangles")
    if len(F) > max_faces:
        raise FormatError(
            f"{name!r} has {len(F)} triangles, more than {max_faces} (docs/limits.md)"
        )
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise FormatError(f"{name!r}: vertex {i + 1} is not finite ({bad.sum()} such vertices)")
    big = float(np.abs(V).max()) if len(V) else 0.0
    if big > MAX_MESH_COORD:
        raise FormatError(f"{name!r} has a coordinate of {big:.3g}, beyond +-{MAX_MESH_COORD:g}")
    if F.min() < 0 or F.max() >= len(V):
        j = int(np.flatnonzero((F < 0).any(axis=1) | (F >= len(V)).any(axis=1))[0])
        raise FormatError(
            f"{name!r}: triangle {j + 1} refers to a vertex that does not exist "
            f"(the file has {len(V)} vertices)"
        )
    ids = np.unique(F)
    if len(ids) < len(V):
        warnings.warn(
            f"{name!r}: {len(V) - len(ids)} of {len(V)} vertices are in no triangle: is the "
            "file cut short? (only its triangles are used)",
            MeshWarning,
            stacklevel=3,
        )
    used = V[ids]
    centred = used - used.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False) if len(used) >= 2 else np.zeros(3)
    if not (s[0] > 0 and s[1] > 1e-9 * s[0]):
        raise FormatError(f"{name!r}: its vertices lie on one line or point (no surface)")
    return V, F


def _count(token, what, name):
    try:
        n = int(token)
    except ValueError:
        raise FormatError(
            f"{name!r}: the {what} count {token[:20]!r} is not a whole number"
        ) from None
    if n < 0:
        raise FormatError(f"{name!r}: the {what} count is negative ({n})")
    return n


def _floats(tokens, name, where):
    try:
        return np.array(tokens, float)
    except ValueError:
        raise FormatError(f"{name!r}: {where} has a number that cannot be read") from None


# --------------------------------------------------------------------------- STL
def _is_binary_stl(head: bytes, size: int) -> bool:
    if len(head) < 84:
        return False
    n = struct.unpack("<I", head[80:84])[0]
    if 84 + 50 * n == size:
        return True
    return not head.lstrip().lower().startswith(b"solid")


def _binary_stl(path, name, size, max_faces):
    with open(path, "rb") as fh:
        head = fh.read(84)
        if len(head) < 84:
            raise FormatError(f"{name!r} is too short for a binary STL ({size} bytes)")
        n = struct.unpack("<I", head[80:84])[0]
        if n > max_faces:
            raise FormatError(
                f"{name!r} declares {n} triangles, more than {max_faces} (docs/limits.md)"
            )
        if 84 + 50 * n != size:
            raise FormatError(
                f"{name!r}: its header declares {n} triangles ({84 + 50 * n} bytes) "
                f"but the file is {size} bytes (truncated or not an STL)"
            )
        dt = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
        rec = np.frombuffer(fh.read(50 * n), dtype=dt, count=n)
    V = rec["v"].reshape(-1, 3).astype(float)
    return V, np.arange(3 * n).reshape(-1, 3)


def _ascii_stl(text, name):
    tokens = text.split()
    if not tokens or tokens[0].lower() != "solid":
        raise FormatError(f"{name!r} is not an STL file (neither binary nor 'solid ...' text)")
    low = [t.lower() for t in tokens]
    idx = [i for i, t in enumerate(low) if t == "vertex"]
    n_facets = low.count("facet")
    n_end = low.count("endfacet")
    if len(idx) != 3 * n_facets or n_end != n_facets or "endsolid" not in low:
        raise FormatError(
            f"{name!r}: {n_facets} facets but {len(idx)} vertices and {n_end} "
            "'endfacet' (a truncated or damaged ASCII STL)"
        )
    vals = [tokens[i + 1 : i + 4] for i in idx]
    if any(len(v) < 3 for v in vals):
        raise FormatError(f"{name!r}: a vertex line has fewer than 3 numbers")
    V = _floats(vals, name, "a vertex line")
    return V, np.arange(len(V)).reshape(-1, 3)


# --------------------------------------------------------------------------- OBJ
def _obj(text, name):
    verts, faces = [], []
    for k, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            if len(parts) < 4:
                raise FormatError(f"{name!r} line {k}: a vertex needs 3 numbers")
            verts.append(parts[1:4])
        elif parts[0] == "f":
            if len(parts) < 4:
                raise FormatError(f"{name!r} line {k}: a face needs at least 3 vertices")
            try:
                ids = [int(p.split("/")[0]) for p in parts[1:]]
            except ValueError:
                raise FormatError(
                    f"{name!r} line {k}: a face index is not a whole number"
                ) from None
            nv = len(verts)
            out = []
            for i in ids:
                if i == 0 or i > nv or i < -nv:
                    raise FormatError(
                        f"{name!r} line {k}: face index {i} is out of range "
                        f"(1..{nv}, or negative from the end; 0 is not valid)"
                    )
                out.append(i - 1 if i > 0 else nv + i)
            faces.extend([out[0], out[j], out[j + 1]] for j in range(1, len(out) - 1))
    V = _floats(verts, name, "a 'v' line") if verts else np.zeros((0, 3))
    return V, np.array(faces, np.int64).reshape(-1, 3)


# --------------------------------------------------------------------------- OFF
def _off(text, name, max_faces):
    lines = [ln.split("#")[0].split() for ln in text.splitlines()]
    tokens = [t for ln in lines for t in ln]
    if not tokens or not tokens[0].upper().endswith("OFF"):
        raise FormatError(f"{name!r} is not an OFF file (no 'OFF' header)")
    if len(tokens) < 4:
        raise FormatError(f"{name!r}: the OFF header has no vertex and face counts")
    nv = _count(tokens[1], "vertex", name)
    nf = _count(tokens[2], "face", name)
    if nf > max_faces:
        raise FormatError(f"{name!r} declares {nf} faces, more than {max_faces} (docs/limits.md)")
    pos = 4
    if len(tokens) < pos + 3 * nv:
        raise FormatError(
            f"{name!r}: the header declares {nv} vertices but the file ends before them (truncated)"
        )
    V = _floats(tokens[pos : pos + 3 * nv], name, "a vertex").reshape(-1, 3)
    pos += 3 * nv
    faces = []
    for j in range(nf):
        if pos >= len(tokens):
            raise FormatError(
                f"{name!r}: the header declares {nf} faces but the file holds {j} (truncated)"
            )
        k = _count(tokens[pos], "face vertex", name)
        ids = tokens[pos + 1 : pos + 1 + k]
        if k < 3 or len(ids) < k:
            raise FormatError(f"{name!r}: face {j + 1} is cut off or has fewer than 3 vertices")
        try:
            ids = [int(t) for t in ids]
        except ValueError:
            raise FormatError(
                f"{name!r}: face {j + 1} has an index that is not a whole number"
            ) from None
        faces.extend([ids[0], ids[i], ids[i + 1]] for i in range(1, k - 1))
        pos += 1 + k
    return V, np.array(faces, np.int64).reshape(-1, 3)


# --------------------------------------------------------------------------- PLY
def _ply(path, name, max_faces, text):
    data = path.read_bytes()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise FormatError(f"{name!r} is not a PLY file (no 'ply' ... 'end_header' header)")
    nl = data.find(b"\n", end)
    body_at = len(data) if nl < 0 else nl + 1
    try:
        header = data[:end].decode("ascii").splitlines()
    except UnicodeDecodeError:
        raise FormatError(f"{name!r}: its PLY header is not text") from None
    fmt, elements = None, []
    for line in header:
        p = line.split()
        if not p:
            continue
        if p[0] == "format" and len(p) >= 2:
            fmt = p[1]
        elif p[0] == "element" and len(p) >= 3:
            elements.append([p[1], _count(p[2], p[1], name), []])
        elif p[0] == "property" and elements:
            elements[-1][2].append(p[1:])
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise FormatError(f"{name!r}: unknown PLY format {str(fmt)[:30]!r}")
    for el, n, _ in elements:
        if el == "face" and n > max_faces:
            raise FormatError(
                f"{name!r} declares {n} faces, more than {max_faces} (docs/limits.md)"
            )
    if fmt == "ascii":
        return _ply_ascii(data[body_at:].decode("ascii", "replace"), elements, name)
    return _ply_binary(
        data[body_at:], elements, "<" if fmt.endswith("little_endian") else ">", name
    )


def _ply_type(t, name):
    if t not in _PLY_TYPES:
        raise FormatError(f"{name!r}: unknown PLY property type {t[:20]!r}")
    return _PLY_TYPES[t]


def _ply_ascii(body, elements, name):
    rows = iter(body.splitlines())
    V, faces = np.zeros((0, 3)), []
    for el, n, props in elements:
        names = [p[-1] for p in props]
        block = []
        for j in range(n):
            line = next(rows, None)
            while line is not None and not line.strip():
                line = next(rows, None)
            if line is None:
                raise FormatError(
                    f"{name!r}: the header declares {n} '{el}' rows but the file "
                    f"holds {j} (truncated)"
                )
            block.append(line.split())
        if el == "vertex":
            try:
                cols = [names.index(c) for c in "xyz"]
            except ValueError:
                raise FormatError(f"{name!r}: its vertices have no x, y, z") from None
            if any(len(r) < len(names) for r in block):
                raise FormatError(f"{name!r}: a vertex row has fewer numbers than its properties")
            V = _floats([[r[c] for c in cols] for r in block], name, "a vertex row").reshape(-1, 3)
        elif el == "face":
            for j, r in enumerate(block):
                try:
                    k = int(r[0])
                    ids = [int(t) for t in r[1 : 1 + k]]
                except (ValueError, IndexError):
                    raise FormatError(f"{name!r}: face {j + 1} cannot be read") from None
                if k < 3 or len(ids) < k:
                    raise FormatError(
                        f"{name!r}: face {j + 1} is cut off or has fewer than 3 vertices"
                    )
                faces.extend([ids[0], ids[i], ids[i + 1]] for i in range(1, k - 1))
    return V, np.array(faces, np.int64).reshape(-1, 3)


def _ply_binary(body, elements, order, name):
    pos, V, faces = 0, np.zeros((0, 3)), []
    for el, n, props in elements:
        if any(p[0] == "list" for p in props):
            if el != "face" or len(props) != 1:
                raise FormatError(f"{name!r}: PLY element {el!r} with lists is not read")
            ct = np.dtype(order + _ply_type(props[0][1], name))
            it = np.dtype(order + _ply_type(props[0][2], name))
            for j in range(n):
                if pos + ct.itemsize > len(body):
                    raise FormatError(
                        f"{name!r}: the header declares {n} faces but the file "
                        f"holds {j} (truncated)"
                    )
                k = int(np.frombuffer(body, ct, 1, pos)[0])
                pos += ct.itemsize
                if k < 3 or pos + k * it.itemsize > len(body):
                    raise FormatError(
                        f"{name!r}: face {j + 1} is cut off or has fewer than 3 vertices"
                    )
                ids = np.frombuffer(body, it, k, pos).astype(np.int64)
                pos += k * it.itemsize
                faces.extend([ids[0], ids[i], ids[i + 1]] for i in range(1, k - 1))
            continue
        dt = np.dtype([(p[-1], order + _ply_type(p[0], name)) for p in props])
        if pos + dt.itemsize * n > len(body):
            raise FormatError(
                f"{name!r}: the header declares {n} '{el}' rows but the file is shorter (truncated)"
            )
        rec = np.frombuffer(body, dt, n, pos)
        pos += dt.itemsize * n
        if el == "vertex":
            if not all(c in dt.names for c in "xyz"):
                raise FormatError(f"{name!r}: its vertices have no x, y, z")
            V = np.stack([rec[c].astype(float) for c in "xyz"], axis=1)
    return V, np.array(faces, np.int64).reshape(-1, 3)
