"""CreasePattern type: reference crease order, validation, fold-angle sign, networkx round trip."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest

from holofold.geometry.errors import DegenerateGeometryError, InvalidPatternError
from holofold.geometry.pattern import (
    CreasePattern,
    measure_fold_angles,
    newell_normals,
    orient_faces,
    reference_edges,
)

SQUARES_FLAT = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], float)
SQUARES = [[0, 1, 2, 3], [1, 4, 5, 2]]


def two_squares(fold_deg: float) -> np.ndarray:
    """Two unit squares hinged on x = 1; the right one lifted by ``fold_deg`` (z > 0 if > 0)."""
    phi = math.radians(fold_deg)
    X = np.column_stack([SQUARES_FLAT, np.zeros(6)])
    X[4] = [1 + math.cos(phi), 0, math.sin(phi)]
    X[5] = [1 + math.cos(phi), 1, math.sin(phi)]
    return X


# ---------------------------------------------------------------- reference crease order
def test_reference_edges_order_by_hand():
    # face 0 = (0 1 2 3): (C1,CN)=(0,3), (0,1), (1,2), (2,3)
    # face 1 = (1 4 5 2): (C1,CN)=(1,2) known, (1,4), (4,5), (5,2) -> (2,5)
    edges, count = reference_edges(SQUARES)
    assert edges.tolist() == [[0, 3], [0, 1], [1, 2], [2, 3], [1, 4], [4, 5], [2, 5]]
    assert count.tolist() == [1, 1, 2, 1, 1, 1, 1]


def test_reference_edges_triangles_and_min_max():
    # (C1,CN) first even when C1 > CN: face (3 1 2) gives (2,3) first, then (1,3), (1,2)
    edges, count = reference_edges([[3, 1, 2], [2, 1, 0]])
    assert edges.tolist() == [[2, 3], [1, 3], [1, 2], [0, 2], [0, 1]]
    assert count.tolist() == [1, 1, 2, 1, 1]


def test_from_faces_uses_reference_order_and_flags_borders():
    p = CreasePattern.from_faces(SQUARES_FLAT, SQUARES, flat=SQUARES_FLAT)
    assert p.edges.tolist() == reference_edges(SQUARES)[0].tolist()
    assert p.assignment.tolist() == ["B", "B", "F", "B", "B", "B", "B"]
    assert p.interior.tolist() == [False, False, True, False, False, False, False]
    assert np.all(p.fold_angle == 0.0)
    assert p.coords.shape == (6, 3) and np.all(p.coords[:, 2] == 0)
    np.testing.assert_allclose(p.edge_lengths, [1, 1, 1, 1, 1, 1, 1])


# ---------------------------------------------------------------- fold-angle sign
@pytest.mark.parametrize("fold", [10.0, 30.0, 90.0, 150.0, 179.0])
def test_valley_fold_is_positive_and_equals_geometric_angle(fold):
    X = two_squares(fold)
    p = CreasePattern.from_faces(X, SQUARES, flat=SQUARES_FLAT)
    assert p.assignment[2] == "V"
    assert p.fold_angle[2] == pytest.approx(fold, abs=1e-10)
    # the same with the faces listed the other way round
    q = CreasePattern.from_faces(X, SQUARES[::-1], flat=SQUARES_FLAT)
    k = q.edges.tolist().index([1, 2])
    assert q.fold_angle[k] == pytest.approx(fold, abs=1e-10)
    # and the same measured directly
    assert measure_fold_angles(X, SQUARES, np.array([[1, 2]]))[0] == pytest.approx(fold)


@pytest.mark.parametrize("fold", [20.0, 120.0])
def test_mountain_fold_is_negative(fold):
    p = CreasePattern.from_faces(two_squares(-fold), SQUARES, flat=SQUARES_FLAT)
    assert p.assignment[2] == "M"
    assert p.fold_angle[2] == pytest.approx(-fold, abs=1e-10)


def test_with_coords_remeasures():
    p = CreasePattern.from_faces(two_squares(40), SQUARES, flat=SQUARES_FLAT)
    q = p.with_coords(two_squares(-70))
    assert q.assignment[2] == "M" and q.fold_angle[2] == pytest.approx(-70)
    np.testing.assert_array_equal(q.edges, p.edges)


# ---------------------------------------------------------------- validation
def _pattern(**kw):
    base = dict(
        coords=SQUARES_FLAT,
        faces=SQUARES,
        edges=reference_edges(SQUARES)[0],
        assignment=["B", "B", "V", "B", "B", "B", "B"],
        fold_angle=[0, 0, 0, 0, 0, 0, 0],
        flat=SQUARES_FLAT,
    )
    base.update(kw)
    flat = base.pop("flat")
    return CreasePattern(**base, flat=flat)


def test_valid_explicit_construction():
    p = _pattern()
    assert p.n_vertices == 6 and p.n_edges == 7 and p.n_faces == 2


def test_duplicate_edge():
    e = reference_edges(SQUARES)[0].tolist() + [[3, 0]]
    with pytest.raises(InvalidPatternError, match=r"duplicate edge \[0, 3\]"):
        _pattern(edges=e, assignment=["B"] * 8, fold_angle=[0] * 8)


def test_zero_length_edge():
    X = SQUARES_FLAT.copy()
    X[4] = X[1]  # vertex 4 on top of vertex 1
    with pytest.raises(DegenerateGeometryError, match=r"edge 4 = \[1, 4\] has zero length"):
        _pattern(coords=X, flat=X)


def test_self_edge():
    e = reference_edges(SQUARES)[0].tolist() + [[2, 2]]
    with pytest.raises(InvalidPatternError, match="joins vertex 2 to itself"):
        _pattern(edges=e, assignment=["B"] * 8, fold_angle=[0] * 8)


def test_out_of_range_indices():
    with pytest.raises(InvalidPatternError, match="outside 0..5"):
        _pattern(faces=[[0, 1, 2, 3], [1, 4, 6, 2]])
    e = reference_edges(SQUARES)[0].tolist() + [[5, 9]]
    with pytest.raises(InvalidPatternError, match=r"edge 7 = \[5, 9\].*outside 0..5"):
        _pattern(edges=e, assignment=["B"] * 8, fold_angle=[0] * 8)
    with pytest.raises(InvalidPatternError, match="outside"):
        CreasePattern.from_faces(SQUARES_FLAT, [[0, 1, 2, 3], [1, -1, 5, 2]])


def test_face_edge_missing():
    e = reference_edges(SQUARES)[0][:-1]
    with pytest.raises(InvalidPatternError, match=r"face 1 uses edge \[2, 5\]"):
        _pattern(edges=e, assignment=["B"] * 6, fold_angle=[0] * 6)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_coordinates(bad):
    X = SQUARES_FLAT.copy()
    X[3, 1] = bad
    with pytest.raises(DegenerateGeometryError, match=r"non-finite coordinates at vertices \[3\]"):
        CreasePattern.from_faces(X, SQUARES)
    with pytest.raises(DegenerateGeometryError, match="non-finite flat"):
        _pattern(flat=X)


@pytest.mark.parametrize("sign", [1, -1])
def test_bow_tie_face_is_not_simple(sign):
    # net signed area +1 or -1: must be reported as non-simple, not as clockwise
    bt = np.array([[0, 0], [3, 0], [0, 1], [1, 2]], float)[::sign].copy()
    with pytest.raises(InvalidPatternError, match="not a simple polygon"):
        CreasePattern.from_faces(bt, [[0, 1, 2, 3]], flat=bt)
    # also without a flat layout (3-D only, projected on the best plane)
    with pytest.raises(InvalidPatternError, match="not a simple polygon"):
        CreasePattern.from_faces(bt, [[0, 1, 2, 3]])


def test_repeated_vertex_in_face():
    with pytest.raises(InvalidPatternError, match="repeats a vertex"):
        CreasePattern.from_faces(SQUARES_FLAT, [[0, 1, 2, 1]])


def test_clockwise_face_in_flat_layout():
    with pytest.raises(InvalidPatternError, match=r"face 1 = \[2, 5, 4, 1\] is clockwise"):
        CreasePattern.from_faces(SQUARES_FLAT, [[0, 1, 2, 3], [2, 5, 4, 1]], flat=SQUARES_FLAT)
    # a 3-D-only pattern need not be oriented
    p = CreasePattern.from_faces(SQUARES_FLAT, [[0, 1, 2, 3], [2, 5, 4, 1]])
    assert p.n_faces == 2


def test_zero_area_face():
    X = np.array([[0, 0], [1, 0], [2, 0]], float)
    with pytest.raises(DegenerateGeometryError, match="face 0 has zero area"):
        CreasePattern.from_faces(X, [[0, 1, 2]], flat=X)


@pytest.mark.parametrize(
    "code,angle,fragment",
    [
        ("M", 30.0, "is M with fold angle 30 deg"),
        ("V", -30.0, "is V with fold angle -30 deg"),
        ("F", 5.0, "is F with fold angle 5 deg"),
    ],
)
def test_inconsistent_assignment_and_angle(code, angle, fragment):
    with pytest.raises(InvalidPatternError, match=fragment):
        _pattern(
            assignment=["B", "B", code, "B", "B", "B", "B"], fold_angle=[0, 0, angle, 0, 0, 0, 0]
        )


def test_border_with_angle_and_angle_range():
    with pytest.raises(InvalidPatternError, match="edge 0 is B"):
        _pattern(fold_angle=[10, 0, 0, 0, 0, 0, 0])
    with pytest.raises(InvalidPatternError, match=r"\[-180, 180\]"):
        _pattern(fold_angle=[0, 0, 190, 0, 0, 0, 0])
    with pytest.raises(InvalidPatternError, match="length 7"):
        _pattern(fold_angle=[0, 0, 0])


@pytest.mark.parametrize("code", ["X", "m", "Vx", "mountain", ""])
def test_unknown_assignment_code(code):
    with pytest.raises(InvalidPatternError, match="allowed: M V B F C J U"):
        _pattern(assignment=["B", "B", code, "B", "B", "B", "B"])


def test_mountain_and_valley_with_zero_angle_allowed():
    for code in ("M", "V", "U", "J"):
        p = _pattern(assignment=["B", "B", code, "B", "B", "B", "B"])
        assert p.assignment[2] == code


# ---------------------------------------------------------------- derived data and helpers
def test_sector_angles_newell_and_orientation():
    p = CreasePattern.from_faces(two_squares(60), SQUARES, flat=SQUARES_FLAT)
    for ang in p.sector_angles():
        np.testing.assert_allclose(ang, math.pi / 2, atol=1e-15)
    n = newell_normals(p.coords, p.faces)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)  # unit squares: area 1
    np.testing.assert_allclose(n[0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(n[1], [-math.sin(math.radians(60)), 0, 0.5], atol=1e-15)
    flipped = orient_faces([[0, 1, 2, 3], [2, 5, 4, 1]])
    assert [f.tolist() for f in flipped] == [[0, 1, 2, 3], [1, 4, 5, 2]]


def test_moebius_strip_cannot_be_oriented():
    # a strip of 3 quads whose ends are glued with a half twist
    faces = [[0, 1, 4, 3], [1, 2, 5, 4], [2, 3, 0, 5]]
    with pytest.raises(InvalidPatternError, match="non-orientable"):
        orient_faces(faces)


def test_networkx_round_trip():
    X = two_squares(45)
    p = CreasePattern.from_faces(X, SQUARES, flat=SQUARES_FLAT, meta={"kind": "test", "m": 2})
    g = p.to_networkx()
    assert isinstance(g, nx.Graph)
    assert g.number_of_nodes() == 6 and g.number_of_edges() == 7
    assert g.edges[1, 2]["assignment"] == "V"
    assert g.edges[1, 2]["fold_angle"] == pytest.approx(45)
    assert g.edges[1, 2]["index"] == 2
    q = CreasePattern.from_networkx(g)
    np.testing.assert_array_equal(q.coords, p.coords)
    np.testing.assert_array_equal(q.flat, p.flat)
    np.testing.assert_array_equal(q.edges, p.edges)
    np.testing.assert_array_equal(q.assignment, p.assignment)
    np.testing.assert_array_equal(q.fold_angle, p.fold_angle)
    assert [f.tolist() for f in q.faces] == [f.tolist() for f in p.faces]
    assert q.meta == {"kind": "test", "m": 2}


def test_networkx_round_trip_generated_sheet():
    from holofold.geometry.miura import miura_sheet

    p = miura_sheet(4, 3, 0.01, 0.02, math.radians(65), 0.7)
    q = CreasePattern.from_networkx(p.to_networkx())
    np.testing.assert_array_equal(q.edges, p.edges)
    np.testing.assert_array_equal(q.assignment, p.assignment)
    np.testing.assert_allclose(q.fold_angle, p.fold_angle, rtol=0, atol=0)
    assert q.meta == p.meta


def test_from_networkx_rejects_non_contiguous_nodes():
    g = nx.Graph()
    g.add_node(0, coords=[0, 0, 0])
    g.add_node(2, coords=[1, 0, 0])
    with pytest.raises(InvalidPatternError, match="0..nv-1"):
        CreasePattern.from_networkx(g)
