"""What a triangle-mesh file holds, checked before a library may drop or repair any of it.

trimesh, asked to process a mesh, silently removes vertices that are not finite and the
triangles that use them, and its OBJ reader skips a face line cut off mid-way, so a damaged
file would be fitted as another shape. :func:`check_mesh_file` reads the file's own counts
and lines (streaming, bounded) and refuses, in one line naming the file and the place:

* a binary STL whose size does not match its header's triangle count (cut off or padded),
  or whose count exceeds the limit (refused from the header, before anything is read);
* an ASCII STL with a ``facet`` left open (a file cut off) or a vertex with a non-number;
* an OBJ line ``v`` with fewer than three numbers, a face with fewer than three vertices or
  an index 0 or beyond the vertices read so far (OBJ indices start at 1; negative ones count
  back): what a file cut off mid-line leaves, unless the cut falls inside a face's last index;
* an OFF file whose vertex or face lines are fewer than its header says.

Non-finite coordinates are refused after loading with ``process=False`` (nothing dropped):
:func:`check_loaded_vertices`.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from holofold.geometry.errors import FormatError

__all__ = ["check_mesh_file", "check_loaded_vertices"]

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def check_mesh_file(path: str | os.PathLike, suffix: str, max_faces: int) -> None:
    """Refuse a mesh file whose own counts or lines show it damaged (see the module)."""
    path = Path(path)
    suffix = suffix.lower().lstrip(".")
    with open(path, "rb") as fh:
        head = fh.read(84)
    size = path.stat().st_size
    if suffix == "stl" and not _ascii_stl(path, head):
        if size < 84:
            raise FormatError(f"{path.name!r}: {size} bytes, too short for a binary STL")
        n = int(np.frombuffer(head[80:84], "<u4")[0])
        if n > max_faces:
            raise FormatError(
                f"{path.name!r} declares {n:,} triangles, more than {max_faces:,}: refused "
                "before reading"
            )
        if size != 84 + 50 * n:
            raise FormatError(
                f"{path.name!r}: a binary STL of {n:,} triangles is {84 + 50 * n:,} bytes, this "
                f"file {size:,} (cut off, or not an STL)"
            )
        return
    if suffix == "stl":
        _check_ascii_stl(path)
    elif suffix == "obj":
        _check_obj(path, max_faces)
    elif suffix == "off":
        _check_off(path)


def check_loaded_vertices(name: str, vertices: np.ndarray) -> None:
    """Refuse non-finite vertex coordinates of a mesh loaded without processing."""
    bad = ~np.isfinite(np.asarray(vertices, float)).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FormatError(
            f"{name!r} has {int(bad.sum())} vertices with non-finite coordinates (the first: "
            f"vertex {k + 1}); a reader that dropped them would fit another shape"
        )


def _ascii_stl(path: Path, head: bytes) -> bool:
    if not head.lstrip().lower().startswith(b"solid"):
        return False
    with open(path, "rb") as fh:  # a binary STL may start with 'solid' too: look for 'facet'
        return b"facet" in fh.read(4096).lower()


def _lines(path: Path):
    with open(path, "rb") as fh:
        for k, raw in enumerate(fh, start=1):
            yield k, raw.decode("utf-8", "replace")


def _check_ascii_stl(path: Path) -> None:
    open_facet, last = 0, ""
    for k, line in _lines(path):
        words = line.split()
        if not words:
            continue
        key = words[0].lower()
        last = key
        if key == "facet":
            if open_facet:
                raise FormatError(f"{path.name!r}, line {k}: a facet starts inside another")
            open_facet = k
        elif key == "endfacet":
            open_facet = 0
        elif key == "vertex":
            if len(words) != 4 or not all(_NUMBER.match(w) for w in words[1:]):
                raise FormatError(
                    f"{path.name!r}, line {k}: a vertex needs three numbers (got "
                    f"{len(words) - 1} words)"
                )
    if open_facet:
        raise FormatError(
            f"{path.name!r}: the facet of line {open_facet} is never closed (the file is cut off)"
        )
    if last != "endsolid":
        raise FormatError(f"{path.name!r}: no 'endsolid' at the end (the file is cut off)")


def _check_obj(path: Path, max_faces: int) -> None:
    nv = nf = 0
    for k, line in _lines(path):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if words[0] == "v":
            if len(words) < 4 or not all(_NUMBER.match(w) for w in words[1:4]):
                raise FormatError(
                    f"{path.name!r}, line {k}: a vertex needs three numbers "
                    "(a damaged or cut-off file)"
                )
            nv += 1
        elif words[0] == "f":
            refs = words[1:]
            if len(refs) < 3:
                raise FormatError(
                    f"{path.name!r}, line {k}: a face needs at least three vertices, it has "
                    f"{len(refs)} (a damaged or cut-off file)"
                )
            for r in refs:
                head = r.split("/")[0]
                try:
                    i = int(head)
                except ValueError:
                    raise FormatError(
                        f"{path.name!r}, line {k}: a face's vertex is not an index"
                    ) from None
                if i == 0 or i > nv or -i > nv:
                    raise FormatError(
                        f"{path.name!r}, line {k}: face vertex {i} does not exist ({nv} vertices "
                        "so far; OBJ counts from 1)"
                    )
            nf += len(refs) - 2
            if nf > max_faces:
                raise FormatError(f"{path.name!r}: more than {max_faces:,} triangles")


def _check_off(path: Path) -> None:
    it = (line for _, line in _lines(path) if line.split() and not line.lstrip().startswith("#"))
    first = next(it, "").split()
    if first and first[0].upper().endswith("OFF"):
        first = first[1:] or next(it, "").split()
    try:
        nv, nf = int(first[0]), int(first[1])
    except (IndexError, ValueError):
        raise FormatError(f"{path.name!r}: no vertex and face counts after 'OFF'") from None
    got = sum(1 for _ in zip(range(nv + nf), it, strict=False))
    if got < nv + nf:
        raise FormatError(
            f"{path.name!r}: the header promises {nv} vertices and {nf} faces, the file holds "
            f"{got} lines of them (cut off)"
        )
