"""FOLD 1.2 files (JSON): write crease patterns and read them back with validation.

Written files carry ``file_spec`` 1.2, ``file_creator``, ``file_classes``, ``frame_classes``,
``frame_unit`` ("m"), ``vertices_coords``, ``edges_vertices``, ``edges_assignment``,
``edges_foldAngle`` and ``faces_vertices`` (the four keys Origami Simulator requires are always
present). Where the pattern has a flat layout, the key frame is the flat crease pattern
(``creasePattern``, 2-D coordinates) and ``file_frames[0]`` the folded form (3-D coordinates,
inheriting the topology); otherwise the key frame is the 3-D ``foldedForm``. Physical data go
under namespaced keys: ``edges_holofold:creaseWidth`` (m), ``edges_holofold:creaseThickness``
(m), ``faces_holofold:thickness`` (m), ``holofold:meta`` (the pattern's parameters) and
``holofold:curves`` (curved creases as drawn, the edges that are their straight pieces:
:func:`curves_to_fold`).

Reading checks the list of docs/bar-and-hinge.md §1.2 and raises :class:`FormatError` naming the
first problem; soft problems (no ``file_spec``, custom keys without a colon, clockwise faces,
which are reversed) are warnings. Files are parsed with :mod:`json` only.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from typing import Any

import numpy as np

from holofold.geometry.curved import Curve
from holofold.geometry.errors import FormatError
from holofold.geometry.pattern import ASSIGNMENTS, MAX_PANELS, CreasePattern

__all__ = [
    "fold_dict",
    "curves_to_fold",
    "export_fold",
    "load_fold",
    "read_fold",
    "FoldWarning",
    "MAX_FOLD_BYTES",
    "MAX_FOLD_FACES",
    "MAX_FOLD_VERTICES",
    "MAX_FOLD_EDGES",
    "MAX_NESTING",
    "PLANAR_TOL",
]

_SPEC_KEYS = {
    "file_spec", "file_creator", "file_author", "file_title", "file_description",
    "file_classes", "file_frames", "frame_author", "frame_title", "frame_description",
    "frame_classes", "frame_attributes", "frame_unit", "frame_parent", "frame_inherit",
    "vertices_coords", "vertices_vertices", "vertices_edges", "vertices_faces",
    "edges_vertices", "edges_faces", "edges_assignment", "edges_foldAngle",
    "edges_foldAngles", "edges_length", "edges_orders", "faces_vertices", "faces_edges",
    "faces_faces", "faceOrders", "edgeOrders",
}  # fmt: skip


class FoldWarning(UserWarning):
    """A FOLD file readable with a fix or an assumption (named in the message)."""


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("holofold")
    except Exception:  # noqa: BLE001 - running from a checkout
        return "dev"


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, str | int | float | bool) or obj is None:
        return obj
    return str(obj)


def fold_dict(
    pattern: CreasePattern,
    *,
    crease_width=None,
    crease_thickness=None,
    panel_thickness=None,
    title: str | None = None,
) -> dict[str, Any]:
    """The FOLD 1.2 object of ``pattern`` (a dict ready for :func:`json.dumps`).

    ``crease_width``/``crease_thickness`` (per edge or scalar, m) and ``panel_thickness``
    (per face or scalar, m) are stored under namespaced keys when given.
    """
    ne, nf = pattern.n_edges, pattern.n_faces
    frame = {
        "edges_vertices": pattern.edges.tolist(),
        "edges_assignment": pattern.assignment.tolist(),
        "edges_foldAngle": [float(a) for a in pattern.fold_angle],
        "faces_vertices": [f.tolist() for f in pattern.faces],
    }
    out: dict[str, Any] = {
        "file_spec": 1.2,
        "file_creator": f"holofold {_version()}",
        "file_classes": ["singleModel"],
    }
    if title:
        out["file_title"] = title
    if pattern.flat is not None:
        out.update(
            frame_classes=["creasePattern"],
            frame_attributes=["2D"],
            frame_unit="m",
            vertices_coords=pattern.flat.tolist(),
            **frame,
        )
        out["file_frames"] = [
            {
                "frame_classes": ["foldedForm"],
                "frame_attributes": ["3D"],
                "frame_unit": "m",
                "frame_parent": 0,
                "frame_inherit": True,
                "vertices_coords": pattern.coords.tolist(),
            }
        ]
    else:
        out.update(
            frame_classes=["foldedForm"],
            frame_attributes=["3D"],
            frame_unit="m",
            vertices_coords=pattern.coords.tolist(),
            **frame,
        )
    for key, val, n in (
        ("edges_holofold:creaseWidth", crease_width, ne),
        ("edges_holofold:creaseThickness", crease_thickness, ne),
        ("faces_holofold:thickness", panel_thickness, nf),
    ):
        if val is not None:
            out[key] = np.broadcast_to(np.asarray(val, float), (n,)).tolist()
    if pattern.meta:
        out["holofold:meta"] = _jsonable(pattern.meta)
    if pattern.curves:
        out["holofold:curves"] = curves_to_fold(pattern.curves, pattern.edge_curve)
    return out


def curves_to_fold(curves, edge_curve) -> list[dict]:
    """The ``holofold:curves`` value: per curve its ``kind``, ``assignment``, ``foldAngle``
    (degrees), ``edges`` (the indices of its straight pieces) and either ``points`` (Bezier
    control points, m) or ``centre`` (m), ``radii`` (m), ``rotation``, ``start`` and ``sweep``
    (degrees, counter-clockwise) of an elliptical arc."""
    ec = np.asarray(edge_curve)
    out = []
    for c, cv in enumerate(curves):
        d: dict[str, Any] = {"kind": cv.kind, "assignment": cv.assignment,
                             "foldAngle": float(cv.fold_angle)}  # fmt: skip
        if cv.kind == "bezier":
            d["points"] = [[float(x), float(y)] for x, y in cv.points]
        else:
            d.update(
                centre=[float(v) for v in cv.centre], radii=[float(v) for v in cv.radii],
                rotation=math.degrees(cv.rotation), start=math.degrees(cv.start),
                sweep=math.degrees(cv.sweep),
            )  # fmt: skip
        d["edges"] = np.flatnonzero(ec == c).tolist()
        out.append(d)
    return out


def _curves_from_fold(raw, ne: int, scale: float):
    """(curves, edge_curve) of a ``holofold:curves`` value (see :func:`curves_to_fold`),
    lengths times ``scale`` (metres per file unit)."""
    key = "holofold:curves"
    if not isinstance(raw, list):
        _fail(f"{key} is {_kind(raw)}; expected a list of curves")
    curves, ec = [], np.full(ne, -1, np.int64)

    def nums(d, k, n, c):
        v = d.get(k)
        flat = v if isinstance(v, list) else [v] if n == 1 else None
        flat = np.asarray(flat, dtype=object).ravel() if flat is not None else None
        if flat is None or not all(_is_number(x) for x in flat) or len(flat) != n:
            _fail(f"{key}[{c}].{k} = {_show(v)}; expected {n} number(s)")
        a = np.asarray(flat, float)
        if not np.isfinite(a).all():
            _fail(f"{key}[{c}].{k} has a number that is not finite")
        return a

    for c, d in enumerate(raw):
        if not isinstance(d, dict):
            _fail(f"{key}[{c}] is {_kind(d)}; expected an object")
        kind, asg = d.get("kind"), d.get("assignment", "U")
        if asg not in ASSIGNMENTS:
            _fail(f"{key}[{c}].assignment = {_show(asg)}; allowed: {' '.join(ASSIGNMENTS)}")
        ang = d.get("foldAngle", 0.0)
        if not _is_number(ang) or not math.isfinite(ang):
            _fail(f"{key}[{c}].foldAngle = {_show(ang)}; expected degrees")
        ang = float(ang)
        if kind == "bezier":
            pts = d.get("points")
            n = len(pts) if isinstance(pts, list) else 0
            if not 2 <= n <= 4:
                _fail(f"{key}[{c}].points: expected 2 to 4 control points [x, y]")
            P = nums(d, "points", 2 * n, c).reshape(n, 2) * scale
            cv = Curve("bezier", asg, ang, points=tuple(map(tuple, P.tolist())))
        elif kind == "arc":
            ctr, rad = nums(d, "centre", 2, c) * scale, nums(d, "radii", 2, c) * scale
            if not (rad > 0).all():
                _fail(f"{key}[{c}].radii = {_show(d.get('radii'))}; expected lengths > 0")
            rot, st, sw = (
                math.radians(nums(d, k, 1, c)[0]) for k in ("rotation", "start", "sweep")
            )  # noqa: E501
            cv = Curve("arc", asg, ang, centre=tuple(ctr.tolist()), radii=tuple(rad.tolist()),
                       rotation=rot, start=st, sweep=sw)  # fmt: skip
        else:
            _fail(f"{key}[{c}].kind = {_show(kind)}; allowed: bezier, arc")
        edges = d.get("edges", [])
        if not isinstance(edges, list) or not all(
            isinstance(k, int) and not isinstance(k, bool) and 0 <= k < ne for k in edges
        ):
            _fail(f"{key}[{c}].edges: expected edge indices in 0..{ne - 1}")
        if (ec[edges] >= 0).any():
            _fail(f"{key}[{c}].edges: an edge is listed under two curves")
        ec[edges] = c
        curves.append(cv)
    return tuple(curves), ec


def export_fold(pattern: CreasePattern, **kw) -> str:
    """FOLD 1.2 JSON text of ``pattern`` (see :func:`fold_dict` for the keywords)."""
    return json.dumps(fold_dict(pattern, **kw), indent=1)


#: the largest FOLD file read (bytes): a 100 x 100 Miura sheet written by holofold is 2.8 MB
MAX_FOLD_BYTES = 64 * 2**20
#: at most this many faces (the pattern limit), vertices and edges (a planar graph has
#: fewer than three edges per vertex)
MAX_FOLD_FACES = MAX_PANELS
MAX_FOLD_VERTICES = 4 * MAX_PANELS
MAX_FOLD_EDGES = 3 * MAX_FOLD_VERTICES
#: the deepest nesting of arrays and objects: FOLD arrays nest 2-3 deep (5 in file_frames);
#: Python's json module recurses per level and fails near 1000
MAX_NESTING = 64
#: a face with a vertex farther than this fraction of the face's size (its largest vertex
#: distance) from its least-squares plane is refused in a 3-D frame: a square saddle whose
#: corners alternate by 0.57 of its side. Fitted strips' folded quads are warped: the
#: published arch strips reach 0.020, the most warped of 360 fits swept over m 4-100, offset
#: 0.05-0.8, width 0.02-0.3 and extrude 0.05-0.4 0.139. A crease pattern must be flat to 1e-6
#: of its size.
PLANAR_TOL = 0.2
_FLAT_TOL = 1e-6

_STRING = re.compile(r'"(?:[^"\\]|\\.)*+"', re.S)
_KEY = re.compile(r'"((?:[^"\\]|\\.)*+)"\s*:', re.S)
_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "in": 0.0254,
          "pt": 0.0254 / 72, "unit": 1.0}  # fmt: skip


class _Bad(Exception):
    """A problem found while reading; :func:`load_fold` adds the file's name."""


def _fail(msg: str):
    raise _Bad(msg)


def _show(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _kind(value) -> str:
    names = {dict: "an object", list: "an array", str: "a string", bool: "a boolean",
             int: "an integer", float: "a number", type(None): "null"}  # fmt: skip
    return names.get(type(value), type(value).__name__)


def _check_nesting(text: str) -> None:
    """Refuse arrays and objects nested deeper than :data:`MAX_NESTING` before parsing: one
    pass over the text with strings blanked (their brackets do not count), in numpy."""
    if text.count("[") + text.count("{") <= MAX_NESTING:
        return
    blank = _STRING.sub(lambda m: '"' + " " * (len(m.group()) - 2) + '"', text)
    b = np.frombuffer(blank.encode("ascii", "replace"), np.uint8)
    step = (b == 91).astype(np.int32) + (b == 123) - (b == 93) - (b == 125)
    depth = np.cumsum(step, dtype=np.int64)
    if depth.max(initial=0) <= MAX_NESTING:
        return
    at = int(np.argmax(depth > MAX_NESTING))
    key = None
    for m in _KEY.finditer(text, 0, at):
        if depth[m.start()] == 1:
            key = m.group(1)
    line = text.count("\n", 0, at) + 1
    under = f" under key {key!r}" if key is not None else " at the top level"
    _fail(
        f"arrays nested {int(depth.max())} deep (line {line},{under}); expected FOLD arrays, "
        f"nested at most {MAX_NESTING} deep"
    )


def _parse(source) -> dict:
    if isinstance(source, bytes | bytearray | memoryview):
        if len(source) > MAX_FOLD_BYTES:
            _fail(f"{len(source)} bytes; expected at most {MAX_FOLD_BYTES} (64 MiB)")
        try:
            text = bytes(source).decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            _fail(f"not UTF-8 text ({exc.reason} at byte {exc.start}); expected FOLD JSON")
    elif isinstance(source, str):
        text = source.removeprefix("\ufeff")
    else:
        _fail(f"expected FOLD text, bytes or a dict, got {type(source).__name__}")
    if len(text) > MAX_FOLD_BYTES:
        _fail(f"{len(text)} characters; expected at most {MAX_FOLD_BYTES} (64 MiB)")
    _check_nesting(text)
    try:
        return json.loads(text)
    except RecursionError:  # a deep stack already: json recurses per level
        _fail(f"nested too deeply for the JSON parser; expected at most {MAX_NESTING} levels")
    except ValueError as exc:  # JSONDecodeError, or an integer of over 4300 digits
        _fail(f"not valid JSON ({exc})")


def _list(d: dict, key: str, what: str, limit: int | None = None) -> list:
    raw = d[key]
    if not isinstance(raw, list):
        _fail(f"{key}: expected an array of {what}, got {_kind(raw)}")
    if limit is not None and len(raw) > limit:
        _fail(f"{key}: {len(raw)} entries; at most {limit} are read (docs/limits.md)")
    return raw


def _is_number(x) -> bool:
    return type(x) is float or type(x) is int  # not bool, not str


def _coords(raw, where: str) -> np.ndarray:
    if not isinstance(raw, list) or not raw:
        _fail(f"{where}: expected a non-empty array of [x, y] or [x, y, z], got {_kind(raw)}")
    if len(raw) > MAX_FOLD_VERTICES:
        _fail(f"{where}: {len(raw)} vertices; at most {MAX_FOLD_VERTICES} are read")
    dim = None
    for k, v in enumerate(raw):
        if not isinstance(v, list) or len(v) not in (2, 3) or not all(map(_is_number, v)):
            _fail(f"{where}[{k}] = {_show(v)}: expected [x, y] or [x, y, z] numbers")
        if dim is None:
            dim = len(v)
        elif len(v) != dim:
            _fail(f"{where}[{k}] has {len(v)} coordinates, vertex 0 has {dim}: mixes 2-D and 3-D")
    try:
        arr = np.array(raw, dtype=float)
    except OverflowError:  # an integer beyond float range
        arr = np.array([[float("inf")] * dim if _huge(v) else v for v in raw], dtype=float)
    bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
    if bad.size:
        _fail(f"{where}[{int(bad[0])}] = {_show(raw[bad[0]])}: expected finite numbers")
    return arr


def _huge(v) -> bool:
    try:
        np.array(v, dtype=float)
    except OverflowError:
        return True
    return False


def _indices(raw: list, key: str, nv: int, *, pair: bool) -> None:
    """Every entry of ``raw`` a list of vertex indices (integers in 0..nv-1), a pair if
    ``pair``, else at least 3 distinct ones."""
    what = "a pair [u, v] of vertex indices" if pair else "an array of >= 3 vertex indices"
    for k, e in enumerate(raw):
        if not isinstance(e, list) or (len(e) != 2 if pair else len(e) < 3):
            _fail(f"{key}[{k}] = {_show(e)}: expected {what}")
        for v in e:
            if type(v) is not int:
                _fail(f"{key}[{k}] = {_show(e)}: expected integer vertex indices, got {_show(v)}")
            if not 0 <= v < nv:
                _fail(f"{key}[{k}] = {_show(e)}: vertex {_show(v)} is outside 0..{nv - 1}")
        if not pair and len(set(e)) != len(e):
            _fail(f"{key}[{k}] = {_show(e)}: a face lists a vertex twice")


def _numbers(d: dict, key: str, n: int, what: str, *, allow_null=False) -> list:
    raw = _list(d, key, "numbers")
    if len(raw) != n:
        _fail(f"{key}: {len(raw)} entries; expected one per edge/face ({n})")
    for k, a in enumerate(raw):
        if (a is None and allow_null) or (_is_number(a) and math.isfinite(a)):
            continue
        _fail(f"{key}[{k}] = {_show(a)}: expected {what}")
    return raw


def _strings(d: dict, key: str) -> list[str]:
    raw = d.get(key)
    if raw is None:
        return []
    if not isinstance(raw, list) or not all(isinstance(c, str) for c in raw):
        _fail(f"{key} = {_show(raw)}: expected an array of strings")
    return raw


def _nonplanar(coords: np.ndarray, faces: list[list[int]], tol: float) -> tuple[int, float]:
    """(first face, its offset) of the faces with a vertex farther than ``tol`` x the face's
    size (its largest vertex distance) from its least-squares plane; (-1, 0) if none. Faces of
    one vertex count are done together."""
    by_size: dict[int, list[int]] = {}
    for k, f in enumerate(faces):
        if len(f) > 3:
            by_size.setdefault(len(f), []).append(k)
    worst = (-1, 0.0)
    for ks in by_size.values():
        P = coords[np.array([faces[k] for k in ks])]  # (nf, n, 3)
        C = P - P.mean(axis=1, keepdims=True)
        normal = np.linalg.svd(C)[2][:, -1, :]  # (nf, 3)
        off = np.abs(np.einsum("fnk,fk->fn", C, normal)).max(axis=1)
        size = np.linalg.norm(P[:, :, None, :] - P[:, None, :, :], axis=-1).max(axis=(1, 2))
        rel = off / np.maximum(size, 1e-300)
        bad = np.flatnonzero(rel > tol)
        if bad.size and (worst[0] < 0 or ks[bad[0]] < worst[0]):
            worst = (ks[bad[0]], float(rel[bad[0]]))
    return worst


def read_fold(path) -> CreasePattern:
    """Read a FOLD file into a :class:`CreasePattern`, validating it (see :func:`load_fold`).

    Every problem raises :class:`FormatError` with one line naming the file, the place (key
    and index) and what was expected; a file over :data:`MAX_FOLD_BYTES` is refused before it
    is read.
    """
    from pathlib import Path

    path = Path(path)
    try:
        size = path.stat().st_size
        if size > MAX_FOLD_BYTES:
            limit = f"expected at most {MAX_FOLD_BYTES} (64 MiB)"
            raise FormatError(f"FOLD file {str(path)!r}: {size} bytes; {limit}")
        data = path.read_bytes()
    except OSError as exc:
        raise FormatError(f"FOLD file {str(path)!r}: cannot be read ({exc.strerror})") from None
    return load_fold(data, name=str(path))


def load_fold(source: str | bytes | dict, *, name: str | None = None) -> CreasePattern:
    """Read a FOLD file's text (or bytes, or parsed dict) into a :class:`CreasePattern`.

    Validates the list of docs/bar-and-hinge.md §1.2 and the limits of docs/limits.md, and
    raises :class:`FormatError` with one line naming the file (``name``), the place and what
    was expected: nesting deeper than :data:`MAX_NESTING` (checked before parsing), keys of
    the wrong type, vertex indices that are not integers in range, coordinates that are not
    finite numbers of one dimension (2 or 3), empty, repeated-vertex, duplicate or non-planar
    faces (:data:`PLANAR_TOL`), assignments outside the FOLD set, arrays of one prefix with
    different lengths, more than :data:`MAX_FOLD_FACES` faces, :data:`MAX_FOLD_VERTICES`
    vertices or :data:`MAX_FOLD_EDGES` edges.
    """
    where = "FOLD" if name is None else f"FOLD file {name!r}"
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", FoldWarning)
            pattern = _read(source)
    except _Bad as exc:
        raise FormatError(f"{where}: {exc}") from None
    for w in caught:
        if issubclass(w.category, FoldWarning):
            msg = str(w.message).removeprefix("FOLD: ")
            warnings.warn(f"{where}: {msg}", w.category, stacklevel=2)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return pattern


def _read(source) -> CreasePattern:
    d = source if isinstance(source, dict) else _parse(source)
    if not isinstance(d, dict):
        _fail(f"the top level is {_kind(d)}; expected a JSON object {{...}} of FOLD keys")
    if "file_spec" not in d:
        warnings.warn("FOLD: no file_spec; assuming 1.2", FoldWarning, stacklevel=2)
    for key in d:
        if not isinstance(key, str):
            _fail(f"key {_show(key)} is not a string")
        if key not in _SPEC_KEYS and ":" not in key:
            warnings.warn(
                f"FOLD: custom key {key!r} has no namespace colon", FoldWarning, stacklevel=2
            )
    for key in ("vertices_coords", "edges_vertices", "faces_vertices"):
        if key not in d:
            _fail(f"missing required key {key!r}")
    # same-prefix arrays have equal length
    for prefix in ("vertices_", "edges_", "faces_"):
        lens = {k: len(v) for k, v in d.items() if k.startswith(prefix) and isinstance(v, list)}
        if len(set(lens.values())) > 1:
            desc = ", ".join(f"{k} ({n})" for k, n in sorted(lens.items()))
            _fail(f"arrays of one kind must have equal lengths: {desc}")
    key_coords = _coords(d["vertices_coords"], "vertices_coords")
    nv = len(key_coords)
    raw_edges = _list(d, "edges_vertices", "[u, v] vertex pairs", MAX_FOLD_EDGES)
    _indices(raw_edges, "edges_vertices", nv, pair=True)
    edges = np.array(raw_edges, dtype=np.int64).reshape(-1, 2)
    ne = len(edges)
    circ = np.flatnonzero(edges[:, 0] == edges[:, 1])
    if circ.size:
        _fail(f"edges_vertices[{int(circ[0])}] is circular (joins a vertex to itself)")
    srt = np.sort(edges, axis=1)
    _, first, counts = np.unique(srt, axis=0, return_index=True, return_counts=True)
    if (counts > 1).any():
        _fail(f"duplicate edge {srt[first[counts > 1][0]].tolist()}")
    used = np.zeros(nv, bool)
    used[edges.ravel()] = True
    if not used.all():
        _fail(f"vertex {int(np.flatnonzero(~used)[0])} is isolated (on no edge)")
    faces = _list(d, "faces_vertices", "vertex index arrays", MAX_FOLD_FACES)
    _indices(faces, "faces_vertices", nv, pair=False)
    seen: dict[tuple[int, ...], int] = {}
    for k, f in enumerate(faces):
        j = seen.setdefault(tuple(sorted(f)), k)
        if j != k:
            _fail(f"faces_vertices[{k}] = {_show(f)} repeats face {j} (the same vertices)")
    if "edges_assignment" in d:
        asg = list(_list(d, "edges_assignment", "assignment letters"))
        if len(asg) != ne:
            _fail(f"edges_assignment: {len(asg)} entries; expected one per edge ({ne})")
        for i, a in enumerate(asg):
            if not (isinstance(a, str) and a in ASSIGNMENTS):
                _fail(f"edges_assignment[{i}] = {_show(a)}; allowed: {' '.join(ASSIGNMENTS)}")
    else:
        asg = ["U"] * ne
    ang = np.zeros(ne)
    key = next((k for k in ("edges_foldAngle", "edges_foldAngles") if d.get(k) is not None), None)
    if key is not None:
        ang_raw = _numbers(d, key, ne, "a number in [-180, 180] degrees", allow_null=True)
        for i, a in enumerate(ang_raw):
            if a is None:  # Origami Simulator: null = undriven
                asg[i] = "U" if asg[i] in ("M", "V") else asg[i]
                continue
            if abs(a) > 180:
                _fail(f"{key}[{i}] = {a!r}: expected a number in [-180, 180] degrees")
            ang[i] = float(a)
    for i, (a, x) in enumerate(zip(asg, ang, strict=True)):
        if (a == "M" and x > 0) or (a == "V" and x < 0) or (a in "BFC" and x != 0):
            _fail(f"edge {i}: assignment {a} does not match fold angle {x:g} (valley > 0)")
    classes = _strings(d, "frame_classes") if d.get("frame_classes") is not None else None
    if classes is None:
        warnings.warn(
            "FOLD: no frame_classes; treating 2-D coordinates as a crease pattern",
            FoldWarning,
            stacklevel=2,
        )
        classes = ["creasePattern"] if key_coords.shape[1] == 2 else ["foldedForm"]
    is_cp = "creasePattern" in classes or (
        key_coords.shape[1] == 3
        and np.allclose(key_coords[:, 2], 0)
        and "foldedForm" not in classes
    )
    unit = d.get("frame_unit", "unit")
    if not isinstance(unit, str) or unit not in _UNITS:
        _fail(f"frame_unit = {_show(unit)}; expected one of {' '.join(_UNITS)}")
    scale = _UNITS[unit]
    if is_cp and key_coords.shape[1] == 3:
        span = max(float(np.ptp(key_coords[:, :2], axis=0).max()), 1e-300)
        z = float(np.ptp(key_coords[:, 2]))
        if z > _FLAT_TOL * span:
            _fail(
                f"vertices_coords: a crease pattern must be flat, its z spans {z:.4g} "
                f"({z / span:.3g} of its size); expected z constant (or frame_classes "
                "['foldedForm'])"
            )
    flat = key_coords[:, :2] * scale if is_cp else None
    coords3 = None
    frames = d.get("file_frames")
    if frames is not None and not isinstance(frames, list):
        _fail(f"file_frames: expected an array of frame objects, got {_kind(frames)}")
    for n, fr in enumerate(frames or []):
        if not isinstance(fr, dict):
            _fail(f"file_frames[{n}]: expected a frame object, got {_kind(fr)}")
        if "foldedForm" in _strings(fr, "frame_classes"):
            c = _coords(fr.get("vertices_coords"), f"file_frames[{n}].vertices_coords")
            if len(c) != nv:
                _fail(
                    f"file_frames[{n}].vertices_coords: {len(c)} vertices; expected {nv}, as in "
                    "the key frame"
                )
            coords3 = np.column_stack([c, np.zeros(nv)]) if c.shape[1] == 2 else c
            coords3 = coords3 * scale
            break
    if coords3 is None:
        coords3 = (
            np.column_stack([key_coords, np.zeros(nv)]) if key_coords.shape[1] == 2 else key_coords
        ) * scale
    k, rel = _nonplanar(coords3, faces, PLANAR_TOL)
    if k >= 0:
        _fail(
            f"faces_vertices[{k}] = {_show(faces[k])} is not planar: a vertex lies {rel:.3g} of "
            f"the face's size off its plane in the 3-D frame; expected at most {PLANAR_TOL}"
        )
    if flat is not None:
        span = max(float(np.ptp(flat, axis=0).max()), 1e-300)
        order = np.lexsort(flat.T)
        gaps = np.linalg.norm(np.diff(flat[order], axis=0), axis=1)
        close = np.flatnonzero(gaps <= 1e-10 * span)
        if close.size:
            i, j = order[close[0]], order[close[0] + 1]
            _fail(f"vertices {int(i)} and {int(j)} of the crease pattern coincide")
        fixed = []
        faces = [list(f) for f in faces]
        for k, f in enumerate(faces):
            p = flat[f]
            area = 0.5 * (
                np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1])
            )
            if area < 0:
                faces[k] = f[::-1]
                fixed.append(k)
        if fixed:
            warnings.warn(
                f"FOLD: {len(fixed)} clockwise face(s) reversed (first: {fixed[0]})",
                FoldWarning,
                stacklevel=2,
            )
    meta = d.get("holofold:meta", {})
    meta = dict(meta) if isinstance(meta, dict) else {}
    physical = (
        ("edges_holofold:creaseWidth", ne, "a crease width, m"),
        ("edges_holofold:creaseThickness", ne, "a crease thickness, m"),
        ("faces_holofold:thickness", len(faces), "a panel thickness, m"),
    )
    for key, n, what in physical:
        if key in d:
            meta[key.split(":", 1)[1]] = list(_numbers(d, key, n, what))
    reach = float(np.abs(np.asarray(coords3, float)).max(initial=0.0))
    if not reach <= 1e4:  # 10 km: beyond any sheet, and 1e300 overflowed the face checks
        _fail(f"a vertex lies {reach:.3g} m from the origin, beyond 1e4 m; check the "
              "coordinates and frame_unit")  # fmt: skip
    curves, ec = (), None
    if "holofold:curves" in d:
        curves, ec = _curves_from_fold(d["holofold:curves"], ne, scale)
    try:
        return CreasePattern(
            coords3, faces, edges, asg, ang, flat=flat, meta=meta, curves=curves, edge_curve=ec
        )
    except ValueError as exc:
        _fail(str(exc))
