"""FOLD files as other tools write them, read into a crease pattern.

:func:`read_fold_pattern` accepts what Origami Simulator, Rabbit Ear, ORIPA exports and
editors write, normalises it, and then validates it with the strict reader of
:mod:`holofold.geometry.fold_io` (one :class:`FormatError` line per file naming the key and
index of the first problem). What it accepts, each with a :class:`PatternWarning` line:

* **any frame**: ``frame = 0`` is the key frame, ``k`` is ``file_frames[k - 1]``, with
  ``frame_inherit`` / ``frame_parent`` resolved. By default the crease pattern (the key frame,
  or the first frame of class ``creasePattern``) is read; a chosen 3-D frame gives the folded
  coordinates over the crease pattern of the same topology;
* faces of any number of vertices (split into triangles where the model needs it, the added
  edges ``J``), and no ``faces_vertices`` at all (the faces are found from the edges, as for a
  drawing);
* ``C`` cuts: the faces on both sides are separated (:mod:`holofold.geometry.cuts`);
* lower-case assignments (``m``, ``v``, ...); fold angles in degrees, as FOLD says (a file
  whose every angle lies within +-pi, some at pi, is warned about: radians?); ``null`` fold
  angles (undriven, ``U``); no ``edges_foldAngle`` (mountains and valleys fold fully);
* ``frame_unit`` of any unit FOLD names; ``"unit"`` or none is read as metres unless ``unit``
  (metres per file unit) says otherwise.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from holofold.geometry.bounded import read_source, source_name
from holofold.geometry.curved import curve_edges
from holofold.geometry.errors import FormatError
from holofold.geometry.fold_io import _UNITS, MAX_FOLD_BYTES, _Bad, _parse, load_fold
from holofold.geometry.line_drawing import (
    LineDrawing,
    PatternWarning,
    finish_pattern,
    pattern_from_drawing,
)
from holofold.geometry.pattern import ASSIGNMENTS

__all__ = ["read_fold_pattern", "fold_frames"]

_FILE_KEYS = ("file_spec", "file_creator", "file_author", "file_title", "file_description",
              "file_classes", "file_frames")  # fmt: skip


def fold_frames(d: dict) -> list[dict]:
    """Every frame of a parsed FOLD object, inheritance resolved: [key frame, file_frames...]."""
    key = {k: v for k, v in d.items() if k not in _FILE_KEYS}
    raw = d.get("file_frames") or []
    if not isinstance(raw, list):
        raise FormatError("file_frames: expected an array of frame objects")
    frames = [key]
    for n, fr in enumerate(raw, start=1):
        if not isinstance(fr, dict):
            raise FormatError(f"file_frames[{n - 1}]: expected a frame object")
        frames.append(dict(fr))
    out: list[dict | None] = [None] * len(frames)

    def resolve(i: int, depth: int = 0) -> dict:
        if out[i] is not None:
            return out[i]
        fr = frames[i]
        if fr.get("frame_inherit") and depth < len(frames):
            parent = fr.get("frame_parent", 0)
            if not isinstance(parent, int) or not 0 <= parent < len(frames) or parent == i:
                raise FormatError(f"frame {i}: frame_parent {parent!r} is not another frame")
            merged = {**resolve(parent, depth + 1), **fr}
        else:
            merged = dict(fr)
        out[i] = merged
        return merged

    return [resolve(i) for i in range(len(frames))]


def _classes(fr: dict) -> list:
    c = fr.get("frame_classes")
    return c if isinstance(c, list) else []


def _is_cp(fr: dict) -> bool:
    if "creasePattern" in _classes(fr):
        return True
    if "foldedForm" in _classes(fr):
        return False
    c = fr.get("vertices_coords")
    if not isinstance(c, list) or not c or not isinstance(c[0], list):
        return False
    return len(c[0]) == 2 or all(isinstance(v, list) and len(v) >= 3 and v[2] == 0 for v in c)


def read_fold_pattern(source, *, frame: int | None = None, unit: float | None = None,
                      split: str = "as-needed"):  # fmt: skip
    """The crease pattern of a FOLD file (a path, bytes or a binary file object; see the module
    docstring), metres."""
    name = source_name(source)
    where = f"FOLD file {name!r}"
    try:
        if isinstance(source, str | os.PathLike):
            path = Path(source)
            size = path.stat().st_size
            if size > MAX_FOLD_BYTES:
                raise FormatError(
                    f"{where}: {size} bytes; at most {MAX_FOLD_BYTES} (64 MiB) are read"
                )
            data = path.read_bytes()
        else:
            data = read_source(source, MAX_FOLD_BYTES, "FOLD file")
        d = _parse(data)
    except OSError as exc:
        raise FormatError(f"{where}: cannot be read ({exc.strerror})") from None
    except _Bad as exc:
        raise FormatError(f"{where}: {exc}") from None
    if not isinstance(d, dict):
        raise FormatError(f"{where}: the top level is not a JSON object of FOLD keys")
    try:
        frames = fold_frames(d)
    except FormatError as exc:
        raise FormatError(f"{where}: {exc}") from None
    notes: list[str] = []
    cps = [i for i, fr in enumerate(frames) if _is_cp(fr) and "vertices_coords" in fr]
    if frame is None:
        chosen = cps[0] if cps else 0
    else:
        if isinstance(frame, bool) or not isinstance(frame, int) or not 0 <= frame < len(frames):
            raise FormatError(
                f"{where}: frame {frame!r}; this file has frames 0..{len(frames) - 1}"
            )
        chosen = frame
    fr = dict(frames[chosen])
    folded = None
    flat2d = None if _is_cp(fr) else _planar(fr)
    if flat2d is not None:  # a 3-D frame that lies in a plane: a crease pattern
        fr["vertices_coords"] = flat2d.tolist()
        fr["frame_classes"] = ["creasePattern"]
        notes.append(f"frame {chosen} is flat (one plane) though 3-D: read as the crease pattern")
    if not _is_cp(fr):  # a folded state: over the crease pattern of the same topology
        same = [i for i in cps if frames[i].get("edges_vertices") == fr.get("edges_vertices")]
        if same:
            folded = fr.get("vertices_coords")
            fr = dict(frames[same[0]])
            notes.append(
                f"folded coordinates of frame {chosen} over the crease pattern of frame {same[0]}"
            )
    for k in ("vertices_coords", "edges_vertices"):
        if k not in fr:
            raise FormatError(f"{where}: frame {chosen} has no {k!r}")
    # assignments: upper case, known codes
    asg = fr.get("edges_assignment")
    if isinstance(asg, list):
        low = [a for a in asg if isinstance(a, str) and a != a.upper()]
        if low:
            notes.append(f"{len(low)} lower-case assignment(s) read as upper case")
            fr["edges_assignment"] = [a.upper() if isinstance(a, str) else a for a in asg]
        bad = [a for a in fr["edges_assignment"] if a not in ASSIGNMENTS]
        if bad:
            i = fr["edges_assignment"].index(bad[0])
            raise FormatError(
                f"{where}: edges_assignment[{i}] = {bad[0]!r}; allowed: {' '.join(ASSIGNMENTS)}"
            )
    ang = fr.get("edges_foldAngle", fr.get("edges_foldAngles"))
    if isinstance(ang, list):
        vals = [abs(a) for a in ang if isinstance(a, int | float) and not isinstance(a, bool)]
        if vals and max(vals) <= math.pi + 1e-9 and any(abs(v - math.pi) < 1e-6 for v in vals):
            notes.append(
                "every fold angle lies within +-pi and some equal pi: they look like radians, "
                "but FOLD angles are degrees (read as degrees)"
            )
    elif isinstance(fr.get("edges_assignment"), list):
        notes.append("no edges_foldAngle: mountains and valleys fold fully (-+180 degrees)")
        full = {"M": -180.0, "V": 180.0}
        fr["edges_foldAngle"] = [full.get(a, 0.0) for a in fr["edges_assignment"]]
    # units
    fu = fr.get("frame_unit", d.get("frame_unit"))
    if unit is not None:
        if not (isinstance(unit, int | float) and math.isfinite(unit) and unit > 0):
            raise FormatError(f"unit = {unit!r} must be a length in metres > 0")
        scale = float(unit)
        fr["frame_unit"] = "m"
    elif fu in (None, "unit"):
        scale = 1.0
        fr["frame_unit"] = "m"
        notes.append("no length unit (frame_unit 'unit' or none): 1 unit read as 1 m; give unit")
    else:
        scale = 1.0
    if scale != 1.0:
        fr["vertices_coords"] = _scaled(fr["vertices_coords"], scale, where)
        if folded is not None:
            folded = _scaled(folded, scale, where)
    if "faces_vertices" not in fr or not fr["faces_vertices"]:
        notes.append("no faces_vertices: faces found from the edges")
        return _from_edges(fr, where, name, split, notes)
    doc = {"file_spec": d.get("file_spec", 1.2), **fr}
    doc["frame_classes"] = ["creasePattern"] if _is_cp(fr) else ["foldedForm"]
    if folded is not None:
        doc["file_frames"] = [{"frame_classes": ["foldedForm"], "vertices_coords": folded}]
    for k in [k for k in doc if ":" not in k and k.startswith(("file_", "frame_")) and k not in (
            "file_spec", "file_frames", "frame_classes", "frame_unit")]:  # fmt: skip
        doc.pop(k)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pattern = load_fold(doc, name=name)
    for w in caught:
        text = str(w.message)
        if "custom key" in text or "no file_spec" in text:
            continue
        notes.append(text.split(": ", 1)[-1] if text.startswith("FOLD file") else text)
    if pattern.flat is None:
        for n in notes:
            warnings.warn(f"{name}: {n}", PatternWarning, stacklevel=2)
        return pattern  # a 3-D pattern only: cuts and splits need a flat layout
    _check_creases_on_faces(pattern, where)
    coords3 = pattern.coords if folded is not None else None
    done = finish_pattern(
        pattern.flat, pattern.faces, pattern.edges, pattern.assignment, pattern.fold_angle,
        name=name, notes=notes, split=split, meta={**pattern.meta, "kind": "fold", "source": name},
        coords3=coords3,
    )  # fmt: skip
    if not pattern.curves:
        return done
    # curves (holofold:curves): onto the finished edges (cuts separated, faces split)
    curves = tuple(c.mapped(scale) for c in pattern.curves)
    size = float(np.ptp(done.flat, axis=0).max())
    ec = curve_edges(done.flat, done.edges, done.assignment, curves, tol=1e-9 * size)
    return replace(done, curves=curves, edge_curve=ec)


def _check_creases_on_faces(pattern, where: str) -> None:
    """Refuse a mountain or valley that is a side of no face: the model folds only face sides,
    so a crease drawn across faces with no vertex at the crossings (or dangling) was ignored
    and the pattern 'folded rigidly' without it."""
    sides = set()
    for f in pattern.faces:
        f = [int(v) for v in f]
        sides.update(frozenset(e) for e in zip(f, f[1:] + f[:1], strict=True))
    loose = [
        i for i, (e, a) in enumerate(zip(pattern.edges, pattern.assignment, strict=True))
        if a in ("M", "V") and frozenset(int(v) for v in e) not in sides
    ]  # fmt: skip
    if loose:
        raise FormatError(
            f"{where}: {len(loose)} crease(s) (edge {loose[0]}, "
            f"{pattern.assignment[loose[0]]}) on no face side: a crease crossing faces needs "
            "vertices at the crossings, with the faces split there"
        )


def _planar(fr: dict):
    """(nv, 2) coordinates of a 3-D frame whose vertices lie in one plane (1e-6 of its size),
    oriented so that most faces run counter-clockwise; None if it is not planar."""
    try:
        X = np.asarray(fr.get("vertices_coords"), float)
    except (TypeError, ValueError):
        return None
    if X.ndim != 2 or X.shape[1] != 3 or len(X) < 3 or not np.isfinite(X).all():
        return None
    C = X - X.mean(axis=0)
    _, sv, vt = np.linalg.svd(C, full_matrices=False)
    size = float(np.ptp(X, axis=0).max())
    if size <= 0 or np.abs(C @ vt[2]).max() > 1e-6 * size:
        return None
    xy = C @ vt[:2].T
    faces = fr.get("faces_vertices")
    if isinstance(faces, list) and faces:
        area = 0.0
        for f in faces[:1000]:
            try:
                p = xy[np.asarray(f, np.int64)]
            except (IndexError, TypeError, ValueError):
                return xy
            area += np.sign(
                np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1])
            )
        if area < 0:
            xy[:, 1] *= -1.0
    return xy


def _scaled(coords, scale: float, where: str):
    try:
        return (np.asarray(coords, float) * scale).tolist()
    except (TypeError, ValueError):
        raise FormatError(f"{where}: vertices_coords: expected arrays of numbers") from None


def _from_edges(fr: dict, where: str, name: str, split: str, notes):
    try:
        X = np.asarray(fr["vertices_coords"], float)[:, :2]
        E = np.asarray(fr["edges_vertices"], np.int64).reshape(-1, 2)
        S = X[E]
    except (TypeError, ValueError, IndexError):
        raise FormatError(
            f"{where}: vertices_coords/edges_vertices are not usable arrays"
        ) from None
    n = len(E)
    asg = fr.get("edges_assignment") or ["U"] * n
    ang = fr.get("edges_foldAngle", fr.get("edges_foldAngles")) or [0.0] * n
    ang = [0.0 if a is None else a for a in ang]
    if len(asg) != n or len(ang) != n:
        raise FormatError(f"{where}: edges_assignment/edges_foldAngle: one entry per edge ({n})")
    span = float(np.ptp(X, axis=0).max()) if len(X) else 0.0
    fu = fr.get("frame_unit", "m")
    if fu not in _UNITS:
        raise FormatError(f"{where}: frame_unit = {fu!r}; expected one of {' '.join(_UNITS)}")
    drawing = LineDrawing(S, np.array(asg, dtype="<U1"), np.array(ang, float), _UNITS[fu],
                          name=name, kind="fold", notes=tuple(notes))  # fmt: skip
    return pattern_from_drawing(drawing, tol=1e-9 * span if span > 0 else None, split=split)
