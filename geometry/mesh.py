"""Triangulated surfaces of crease patterns, as ``trimesh.Trimesh``.

Every panel is fanned from a centre vertex at the mean of its corners, one triangle per panel
edge, exactly like the concentrated-hinge model of the mechanics layer. The mesh therefore
has the pattern's vertices first (ids kept) and one centre per panel after them
(``nv + panel id``); triangle ``3k..`` belong to panel ``face_index[k]``. A fan of a warped
(non-planar) quad is the same surface the simulator sees. Faces are oriented consistently
(:func:`holofold.geometry.pattern.orient_faces`), so normals point to one side of the sheet.

STL, OBJ and PLY are written by holofold's own array code (:mod:`holofold.geometry.mesh_files`,
no trimesh: :func:`export_mesh`, and :func:`holofold.geometry.export` of a pattern, which builds
no ``trimesh.Trimesh``), in millimetres unless asked otherwise (the convention of slicers and CAD
programs, which read these unit-less formats as mm); the unit is stated where the format allows:
an OBJ comment, a PLY header comment and the STL's 80-byte header (which no reader interprets).
"""

from __future__ import annotations

import lazy_loader
import numpy as np

from holofold.geometry.mesh_files import MESH_FILE_TYPES, mesh_file
from holofold.geometry.pattern import CreasePattern, orient_faces

# trimesh (with scipy.spatial and scipy.optimize) costs 0.5-1 s to import; it loads on first use
trimesh = lazy_loader.load("trimesh")

__all__ = [
    "fan_triangulation",
    "folded_mesh",
    "folded_arrays",
    "flat_mesh",
    "export_mesh",
    "MESH_TYPES",
    "MESH_UNITS",
]

MESH_TYPES = MESH_FILE_TYPES

#: default length unit of mesh files (slicers and CAD read STL/OBJ/PLY as millimetres)
MESH_UNITS = "mm"


def fan_triangulation(coords: np.ndarray, faces) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fan every polygon from a centre vertex.

    Parameters
    ----------
    coords : (nv, d) float
    faces : sequence of (k,) int vertex loops

    Returns
    -------
    vertices : (nv + nf, d) float
        ``coords`` then one centre per face.
    triangles : (sum k, 3) int
        (corner j, corner j+1, centre) for each face, in face order.
    face_index : (sum k,) int
        Face of each triangle.
    """
    coords = np.asarray(coords, float)
    faces = [np.asarray(f, np.int64) for f in faces]
    nv = len(coords)
    sizes = np.array([len(f) for f in faces])
    fv = np.concatenate(faces)
    owner = np.repeat(np.arange(len(faces)), sizes)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    nxt = np.arange(len(fv)) + 1
    nxt[starts + sizes - 1] = starts
    centres = np.stack(
        [np.bincount(owner, weights=coords[fv, d]) / sizes for d in range(coords.shape[1])], 1
    )
    tris = np.stack([fv, fv[nxt], nv + owner], axis=1)
    return np.vstack([coords, centres]), tris, owner


def folded_arrays(pattern: CreasePattern) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arrays of :func:`folded_mesh` without trimesh: vertices (nv + nf, 3) m, triangles
    (sum k, 3) int, face_index (sum k,) panel ids."""
    return fan_triangulation(pattern.coords, orient_faces(pattern.faces))


def folded_mesh(pattern: CreasePattern) -> trimesh.Trimesh:
    """The folded (3-D) surface of ``pattern``; metadata holds ``face_index`` (panel ids)."""
    v, t, owner = folded_arrays(pattern)
    mesh = trimesh.Trimesh(vertices=v, faces=t, process=False)
    mesh.metadata["face_index"] = owner
    mesh.metadata["name"] = pattern.meta.get("kind", "pattern")
    return mesh


def flat_mesh(pattern: CreasePattern) -> trimesh.Trimesh:
    """The flat crease pattern as a mesh in the z = 0 plane (raises if there is none)."""
    if pattern.flat is None:
        raise ValueError("this pattern has no flat layout")
    flat = np.column_stack([pattern.flat, np.zeros(pattern.n_vertices)])
    v, t, owner = fan_triangulation(flat, pattern.faces)
    mesh = trimesh.Trimesh(vertices=v, faces=t, process=False)
    mesh.metadata["face_index"] = owner
    return mesh


def export_mesh(mesh: trimesh.Trimesh, file_type: str, units: str = MESH_UNITS) -> bytes | str:
    """Serialise ``mesh`` (metres) as STL (binary), OBJ or PLY (binary) in ``units``
    (:func:`holofold.geometry.mesh_files.mesh_file`: the coordinates divided by
    :func:`~holofold.geometry.units.length_factor` of ``units``; the unit named in an OBJ comment
    ``# holofold mesh, units: mm``, a PLY header comment and the STL header; the OBJ object named
    by ``mesh.metadata["name"]``; per-vertex colours kept in OBJ and PLY, as trimesh wrote
    them)."""
    file_type = file_type.lower().lstrip(".")
    if file_type not in MESH_TYPES:
        raise ValueError(f"unknown mesh type {file_type!r}; known: {', '.join(MESH_TYPES)}")
    name = mesh.metadata.get("name") if isinstance(mesh.metadata, dict) else None
    colours = None
    if file_type != "stl" and getattr(mesh.visual, "kind", None) == "vertex":
        colours = np.asarray(mesh.visual.vertex_colors)  # kept in OBJ and PLY
    return mesh_file(mesh.vertices, mesh.faces, file_type, units, name, colours)
