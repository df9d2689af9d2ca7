"""FOLD 1.2 files (JSON): write crease patterns and read them back with validation.

Written files carry ``file_spec`` 1.2, ``file_creator``, ``file_classes``, ``frame_classes``,
``frame_unit`` ("m"), ``vertices_coords``, ``edges_vertices``, ``edges_assignment``,
``edges_foldAngle`` and ``faces_vertices`` (the four keys Origami Simulator requires are always
present). Where the pattern has a flat layout, the key frame is the flat crease pattern
(``creasePattern``, 2-D coordinates) and ``file_frames[0]`` the folded form (3-D coordinates,
inheriting the topology); otherwise the key frame is the 3-D ``foldedForm``. Physical data go
under namespaced keys: ``edges_holofold:creaseWidth`` (m), ``edges_holofold:creaseThickness``
(m), ``faces_holofold:thickness`` (m) and ``holofold:meta`` (the pattern's parameters).

Reading checks the list of docs/bar-and-hinge.md §1.2 and raises :class:`FormatError` naming the
first problem; soft problems (no ``file_spec``, custom keys without a colon, clockwise faces,
which are reversed) are warnings. Files are parsed with :mod:`json` only.
"""

from __future__ import annotations

import json
import math
import warnings
from typing import Any

import numpy as np

from holofold.geometry.errors import FormatError
from holofold.geometry.pattern import ASSIGNMENTS, CreasePattern

__all__ = ["fold_dict", "export_fold", "load_fold", "FoldWarning"]

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
    return out


def export_fold(pattern: CreasePattern, **kw) -> str:
    """FOLD 1.2 JSON text of ``pattern`` (see :func:`fold_dict` for the keywords)."""
    return json.dumps(fold_dict(pattern, **kw), indent=1)


def _fail(msg: str):
    raise FormatError(f"FOLD: {msg}")


def _coords(raw, where: str) -> np.ndarray:
    if not isinstance(raw, list) or not raw:
        _fail(f"{where} must be a non-empty list of [x, y] or [x, y, z]")
    dims = {len(v) if isinstance(v, list) else -1 for v in raw}
    if -1 in dims or not dims <= {2, 3}:
        _fail(f"{where} entries must be [x, y] or [x, y, z] lists of numbers")
    if len(dims) > 1:
        _fail(f"{where} mixes 2-D and 3-D vertices; all must have the same dimension")
    try:
        arr = np.array(raw, dtype=float)
    except (TypeError, ValueError):
        _fail(f"{where} holds a value that is not a number")
    bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
    if bad.size:
        _fail(f"{where}[{int(bad[0])}] is not finite")
    return arr


def load_fold(source: str | bytes | dict) -> CreasePattern:
    """Read a FOLD file's text (or parsed dict) into a :class:`CreasePattern`, validating it."""
    if isinstance(source, dict):
        d = source
    else:
        try:
            d = json.loads(source)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            _fail(f"not valid JSON ({exc})")
    if not isinstance(d, dict):
        _fail("the top level must be a JSON object")
    if "file_spec" not in d:
        warnings.warn("FOLD: no file_spec; assuming 1.2", FoldWarning, stacklevel=2)
    for key in d:
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
    try:
        edges = np.array(d["edges_vertices"], dtype=np.int64)
    except (TypeError, ValueError):
        _fail("edges_vertices must be a list of [u, v] integer pairs")
    if edges.ndim != 2 or edges.shape[1] != 2:
        _fail("edges_vertices must be a list of [u, v] integer pairs")
    ne = len(edges)
    out = np.flatnonzero(((edges < 0) | (edges >= nv)).any(axis=1))
    if out.size:
        _fail(f"edges_vertices[{int(out[0])}] = {edges[out[0]].tolist()} is outside 0..{nv - 1}")
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
    faces = d["faces_vertices"]
    if not isinstance(faces, list):
        _fail("faces_vertices must be a list of vertex lists")
    for k, f in enumerate(faces):
        if not isinstance(f, list) or len(f) < 3 or not all(isinstance(v, int) for v in f):
            _fail(f"faces_vertices[{k}] must list at least 3 integer vertex ids")
        if min(f) < 0 or max(f) >= nv:
            _fail(f"faces_vertices[{k}] = {f} references a vertex outside 0..{nv - 1}")
    asg = d.get("edges_assignment", ["U"] * ne)
    if not all(isinstance(a, str) and a in ASSIGNMENTS for a in asg):
        bad = next(a for a in asg if not (isinstance(a, str) and a in ASSIGNMENTS))
        _fail(f"edges_assignment holds {bad!r}; allowed: {' '.join(ASSIGNMENTS)}")
    asg = list(asg)
    ang_raw = d.get("edges_foldAngle", d.get("edges_foldAngles"))
    if ang_raw is None:
        ang = np.zeros(ne)
    else:
        ang = np.zeros(ne)
        for i, a in enumerate(ang_raw):
            if a is None:  # Origami Simulator: null = undriven
                asg[i] = "U" if asg[i] in ("M", "V") else asg[i]
                continue
            if not isinstance(a, int | float) or not math.isfinite(a) or abs(a) > 180:
                _fail(f"edges_foldAngle[{i}] = {a!r} must be a number in [-180, 180] degrees")
            ang[i] = float(a)
    for i, (a, x) in enumerate(zip(asg, ang, strict=True)):
        if (a == "M" and x > 0) or (a == "V" and x < 0) or (a in "BFC" and x != 0):
            _fail(f"edge {i}: assignment {a} does not match fold angle {x:g} (valley > 0)")
    classes = d.get("frame_classes")
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
    scale = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "in": 0.0254,
             "pt": 0.0254 / 72, "unit": 1.0}.get(unit)  # fmt: skip
    if scale is None:
        _fail(f"frame_unit {unit!r} is not one of m cm mm um nm in pt unit")
    flat = key_coords[:, :2] * scale if is_cp else None
    coords3 = None
    for fr in d.get("file_frames", []) or []:
        if isinstance(fr, dict) and "foldedForm" in (fr.get("frame_classes") or []):
            c = _coords(fr.get("vertices_coords"), "file_frames[].vertices_coords")
            if len(c) != nv:
                _fail("the folded frame's vertices_coords has another vertex count")
            coords3 = np.column_stack([c, np.zeros(nv)]) if c.shape[1] == 2 else c
            coords3 = coords3 * scale
            break
    if coords3 is None:
        coords3 = (
            np.column_stack([key_coords, np.zeros(nv)]) if key_coords.shape[1] == 2 else key_coords
        ) * scale
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
    for key in ("edges_holofold:creaseWidth", "edges_holofold:creaseThickness",
                "faces_holofold:thickness"):  # fmt: skip
        if key in d:
            meta[key.split(":", 1)[1]] = list(d[key])
    try:
        return CreasePattern(coords3, faces, edges, asg, ang, flat=flat, meta=meta)
    except ValueError as exc:
        raise FormatError(f"FOLD: {exc}") from None
