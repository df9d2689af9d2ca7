"""FOLD files of a fold path: the crease pattern as the key frame, every state a frame.

The key frame is the flat crease pattern with its target fold angles (what Origami Simulator
opens and simulates); ``file_frames`` hold the states of the path in order, each a
``foldedForm`` frame that inherits the topology from the key frame (``frame_parent`` 0,
``frame_inherit`` true) and carries its own ``vertices_coords`` (3-D, metres) and measured
``edges_foldAngle`` (degrees), titled by its fold fraction (Rabbit Ear reads every frame).
``file_classes`` says ``animation``. Namespaced keys keep the physics:
``holofold:foldFraction`` per frame.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

import numpy as np

from holofold.geometry.fold_io import fold_dict
from holofold.geometry.pattern import CreasePattern

__all__ = ["fold_path_dict", "export_fold_path"]


def fold_path_dict(
    pattern: CreasePattern,
    coords: Sequence[np.ndarray],
    fractions: Sequence[float],
    fold_angles: Sequence[np.ndarray] | None = None,
    *,
    title: str | None = None,
    **physical,
) -> dict:
    """The FOLD object of a fold path.

    Parameters
    ----------
    pattern : CreasePattern
        The crease pattern (flat layout, assignments, target fold angles).
    coords : sequence of (nv, 3) float
        Vertex coordinates of every state, metres.
    fractions : sequence of float
        Fold fraction of every state.
    fold_angles : sequence of (ne,) float, optional
        Measured fold angles of every state, degrees.
    physical
        ``crease_width``, ``crease_thickness``, ``panel_thickness`` (see
        :func:`~holofold.geometry.fold_io.fold_dict`).
    """
    if len(coords) != len(fractions):
        raise ValueError("one fold fraction per state")
    out = fold_dict(pattern, title=title, **physical)
    out["file_classes"] = ["singleModel", "animation"]
    frames = []
    for k, (X, f) in enumerate(zip(coords, fractions, strict=True)):
        X = np.asarray(X, float)
        if X.shape != (pattern.n_vertices, 3) or not np.isfinite(X).all():
            raise ValueError(f"state {k}: expected {pattern.n_vertices} finite 3-D vertices")
        fr = {
            "frame_title": f"fold {100 * float(f):.1f} %",
            "frame_classes": ["foldedForm"],
            "frame_attributes": ["3D"],
            "frame_unit": "m",
            "frame_parent": 0,
            "frame_inherit": True,
            "vertices_coords": X.tolist(),
            "holofold:foldFraction": float(f),
        }
        if fold_angles is not None:
            a = np.asarray(fold_angles[k], float)
            fr["edges_foldAngle"] = [float(x) for x in np.clip(a, -180.0, 180.0)]
        frames.append(fr)
    out["file_frames"] = frames
    return out


def export_fold_path(pattern: CreasePattern, coords, fractions, fold_angles=None, **kw) -> str:
    """FOLD JSON text of a fold path (see :func:`fold_path_dict`)."""
    return json.dumps(fold_path_dict(pattern, coords, fractions, fold_angles, **kw), indent=1)
