"""Crease patterns drawn in other tools: the line arrangement, cuts, facets and the readers of
FOLD, SVG (Origami Simulator's convention), DXF and ORIPA files (geometry/readers.py)."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

import holofold.geometry as g
from holofold.geometry import FormatError, ParameterError
from holofold.geometry.arrangement import arrange_lines
from holofold.geometry.cuts import separate_cuts
from holofold.geometry.facets import nonconvex_faces, split_faces
from holofold.geometry.readers import PatternWarning, read_pattern

OS = Path(__file__).parent / "data" / "origami-simulator"
SQUARE = [[[0, 0], [1, 0]], [[1, 0], [1, 1]], [[1, 1], [0, 1]], [[0, 1], [0, 0]]]


def _read(path, **kw):
    """read_pattern, returning the pattern and the warning lines."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = read_pattern(path, **kw)
    return p, [str(w.message) for w in caught if issubclass(w.category, PatternWarning)]


def _area(xy, f):
    p = xy[f]
    return 0.5 * float(
        np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1])
    )


def _same_pattern(p, q, tol=1e-8):
    """Same vertices (up to order, within tol x size: SVG keeps 1e-9 m), edges, assignments,
    fold angles, faces."""
    size = float(np.ptp(p.flat, axis=0).max())
    a, b = p.flat - p.flat.min(axis=0), q.flat - q.flat.min(axis=0)
    dist, idx = cKDTree(b).query(a)
    assert dist.max() <= tol * size
    assert len(np.unique(idx)) == p.n_vertices == q.n_vertices
    pe = {
        tuple(sorted(idx[e])): (c, x)
        for e, c, x in zip(p.edges, p.assignment, p.fold_angle, strict=True)
    }
    qe = {
        tuple(e): (c, x)
        for e, c, x in zip(q.edges.tolist(), q.assignment, q.fold_angle, strict=True)
    }
    assert pe.keys() == qe.keys()
    assert all(pe[k][0] == qe[k][0] for k in pe)
    assert max(abs(pe[k][1] - qe[k][1]) for k in pe) <= 1e-6
    assert {frozenset(idx[f]) for f in p.faces} == {frozenset(f.tolist()) for f in q.faces}


# ------------------------------------------------------------------ arrangement
def test_crossings_t_junctions_and_overlaps_split_lines():
    segs = SQUARE + [[[0, 0], [1, 1]], [[1, 0], [0, 1]], [[0.5, 0.5], [0.5, 1.0]],
                     [[0.2, 0], [0.8, 0]]]  # fmt: skip
    asg = ["B"] * 4 + ["V", "M", "V", "M"]
    a = arrange_lines(segs, asg, [0] * 4 + [180, -180, 90, -90])
    assert len(a.vertices) == 6 and len(a.faces) == 5  # centre and the T-junction on top
    assert sorted(round(abs(_area(a.vertices, f)), 6) for f in a.faces) == [
        0.125,
        0.125,
        0.25,
        0.25,
        0.25,
    ]
    bottom = [k for k, e in enumerate(a.edges) if set(a.vertices[e][:, 1]) == {0.0}]
    assert len(bottom) == 1 and a.assignment[bottom[0]] == "B"  # the M over it lost to B
    assert any("drawn twice" in n and "B/M" in n for n in a.notes)
    assert all(_area(a.vertices, f) > 0 for f in a.faces)


def test_near_misses_merge_and_dangling_lines_go():
    eps = 1e-4
    segs = SQUARE + [[[0.5, -eps], [0.5 + eps, 1 + eps]], [[0.2, 0.2], [0.3, 0.3]]]
    a = arrange_lines(segs, ["B"] * 4 + ["V", "M"], [0] * 4 + [180, -180], tol=1e-3)
    assert len(a.faces) == 2 and len(a.vertices) == 6
    assert any("dangling" in n for n in a.notes)


def test_border_only_faces_are_holes_and_inner_pieces_are_joined():
    hole = [[[0.4, 0.4], [0.6, 0.4]], [[0.6, 0.4], [0.6, 0.6]], [[0.6, 0.6], [0.4, 0.6]],
            [[0.4, 0.6], [0.4, 0.4]]]  # fmt: skip
    a = arrange_lines(SQUARE + hole, ["B"] * 8, [0] * 8)
    total = sum(_area(a.vertices, f) for f in a.faces)
    assert total == pytest.approx(1 - 0.04, abs=1e-12)  # the square less the hole
    assert set(a.assignment) == {"B", "J"}
    inner = arrange_lines(SQUARE + hole, ["B"] * 4 + ["M"] * 4, [0] * 4 + [-90] * 4)
    assert sum(_area(inner.vertices, f) for f in inner.faces) == pytest.approx(1.0, abs=1e-12)
    m_edges = inner.edges[inner.assignment == "M"]
    used = {tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in inner.faces for i in range(len(f))}
    count = {
        tuple(e): sum(
            1 for f in inner.faces for i in range(len(f)) if {f[i], f[(i + 1) % len(f)]} == set(e)
        )
        for e in m_edges.tolist()
    }
    assert all(tuple(e) in used for e in m_edges.tolist()) and set(count.values()) == {2}


def test_nothing_enclosed_is_refused():
    with pytest.raises(FormatError, match="enclose no panel"):
        arrange_lines([[[0, 0], [1, 0]], [[0, 0], [0, 1]]], ["M", "V"], [0, 0])


# ------------------------------------------------------------------ cuts and facets
def test_a_cut_from_the_border_opens_and_stays_joined_at_its_end():
    # square, valley from (0.5, 0.5) up, cut from the bottom border to (0.5, 0.5), and a
    # horizontal crease through the centre
    segs = SQUARE + [[[0.5, 0], [0.5, 0.5]], [[0.5, 0.5], [0.5, 1]], [[0, 0.5], [1, 0.5]]]
    a = arrange_lines(segs, ["B"] * 4 + ["C", "V", "M"], [0] * 4 + [0, 90, -90])
    xy, faces, e, asg, ang, origin, notes = separate_cuts(
        a.vertices, a.faces, a.edges, a.assignment, a.fold_angle
    )
    assert len(xy) == len(a.vertices) + 1  # the border end of the cut is doubled, not the centre
    assert (asg == "C").sum() == 2  # one cut edge per side
    p = g.CreasePattern(np.c_[xy, np.zeros(len(xy))], faces, e, asg, ang, flat=xy)
    assert (p.edge_face_count[p.assignment == "C"] == 1).all()
    assert not notes


def test_a_closed_cut_frees_the_piece_inside():
    inner = [[[0.3, 0.3], [0.7, 0.3]], [[0.7, 0.3], [0.7, 0.7]], [[0.7, 0.7], [0.3, 0.7]],
             [[0.3, 0.7], [0.3, 0.3]]]  # fmt: skip
    a = arrange_lines(SQUARE + inner, ["B"] * 4 + ["C"] * 4, [0] * 8)
    xy, faces, e, asg, ang, origin, notes = separate_cuts(
        a.vertices, a.faces, a.edges, a.assignment, a.fold_angle
    )
    assert len(xy) == len(a.vertices) + 4
    from holofold.mechanics.folding import _components

    p = g.CreasePattern(np.c_[xy, np.zeros(len(xy))], faces, e, asg, ang, flat=xy)
    assert len(np.unique(_components(p))) == 2


def test_cuts_and_split_faces_return_named_records():
    """``separate_cuts`` and ``split_faces`` return named tuples (issue 35: no bare tuples of
    4+ across modules): the fields are the unpacked values."""
    segs = SQUARE + [[[0.5, 0], [0.5, 0.5]], [[0.5, 0.5], [0.5, 1]], [[0, 0.5], [1, 0.5]]]
    a = arrange_lines(segs, ["B"] * 4 + ["C", "V", "M"], [0] * 4 + [0, 90, -90])
    cut = separate_cuts(a.vertices, a.faces, a.edges, a.assignment, a.fold_angle)
    assert cut._fields == ("coords", "faces", "edges", "assignment", "fold_angle", "origin",
                           "notes")  # fmt: skip
    assert len(cut.coords) == len(a.vertices) + 1 and (cut.assignment == "C").sum() == 2
    np.testing.assert_allclose(cut.coords, a.vertices[cut.origin], rtol=0, atol=0)  # copies
    L = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    p = g.CreasePattern.from_faces(np.c_[L, np.zeros(6)], [np.arange(6)], flat=L)
    sp = split_faces(L, p.faces, p.edges, p.assignment, p.fold_angle)
    assert sp.n_split == 1 and len(sp.faces) == 4 and len(sp.edges) == len(sp.assignment)
    assert sum(_area(L, f) for f in sp.faces) == pytest.approx(3.0, abs=1e-12)
    assert (sp.assignment[p.n_edges :] == "J").all() and len(sp.edges) == p.n_edges + 3


def test_only_non_convex_faces_are_split_and_areas_kept():
    L = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    sq = np.array([[2, 0], [3, 0], [3, 1], [2, 1]], float)
    xy = np.vstack([L, sq[[1, 2]]])
    faces = [np.arange(6), np.array([1, 6, 7, 2])]
    p = g.CreasePattern.from_faces(np.c_[xy, np.zeros(8)], faces, flat=xy)
    assert nonconvex_faces(xy, p.faces).tolist() == [0]
    f2, e2, a2, x2, n = split_faces(xy, p.faces, p.edges, p.assignment, p.fold_angle)
    assert n == 1 and len(f2) == 5 and (a2[p.n_edges :] == "J").all() and len(a2) == p.n_edges + 3
    assert sum(_area(xy, f) for f in f2) == pytest.approx(4.0, abs=1e-12)
    assert all(_area(xy, f) > 0 for f in f2)
    assert len(split_faces(xy, p.faces, p.edges, p.assignment, p.fold_angle, "all")[0]) == 6
    # a corner a hair off straight (1e-6 inward) is fanned whole, not split into a sliver
    hair = np.array([[0, 0], [2, 0], [2, 1], [1, 1 - 1e-6], [0, 1]], float)
    assert nonconvex_faces(hair, [np.arange(5)]).tolist() == [0]
    from holofold.geometry.facets import unfannable_faces

    assert unfannable_faces(hair, [np.arange(5)]).size == 0
    with pytest.raises(ParameterError, match="allowed"):
        split_faces(xy, p.faces, p.edges, p.assignment, p.fold_angle, "some")


# ------------------------------------------------------------------ SVG
def test_origami_simulator_examples_read(tmp_path):
    vertex, _ = _read(OS / "simpleVertex.svg")
    assert (vertex.n_vertices, vertex.n_faces) == (9, 4)
    assert sorted(vertex.assignment[vertex.interior]) == ["M", "M", "M", "V"]
    bird, notes = _read(OS / "birdBase.svg")
    assert (bird.n_vertices, bird.n_faces) == (13, 16) and not notes
    side = float(np.ptp(bird.flat[:, 0]))
    assert side == pytest.approx(2016 * 0.0254 / 96, rel=1e-12)  # 2016 px, CSS pixels
    half = bird.fold_angle[(bird.assignment == "V") & (np.abs(bird.fold_angle) < 179)]
    assert half.size == 4 and np.allclose(half, 90.0)  # opacity 0.5 on the diagonals
    miura, _ = _read(OS / "miura-ori.svg")
    assert miura.n_faces > 100 and set(np.unique(miura.assignment)) <= {"B", "M", "V"}
    popup, notes = _read(OS / "popupSimple.svg")
    assert any("cuts separated" in n for n in notes)
    assert (popup.edge_face_count[popup.assignment == "C"] == 1).all()
    for name in ("waterbombBase.svg", "singlesquaretwist.svg"):
        p, _ = _read(OS / name)
        assert p.n_faces > 4 and p.flat is not None and not p.coords[:, 2].any()


def _svg(tmp_path, body, size='width="100mm" height="100mm" viewBox="0 0 100 100"'):
    f = tmp_path / "cp.svg"
    f.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" {size}>{body}</svg>', encoding="utf-8")
    return f


def test_svg_groups_transforms_units_and_styles(tmp_path):
    body = (
        "<style>.m {stroke: #f00; stroke-opacity: 0.25}</style>"
        '<g transform="translate(10 10)"><g transform="scale(2)">'
        '<rect x="0" y="0" width="20" height="20" stroke="black" fill="none"/>'
        '<line class="m" x1="0" y1="0" x2="20" y2="20"/>'
        '<path d="M 0 20 L 20 0" style="stroke: rgb(0,0,255); opacity: 0.5"/>'
        "</g></g>"
        '<line x1="0" y1="0" x2="5" y2="5" stroke="#ff0000" style="display: none"/>'
        '<line x1="90" y1="90" x2="95" y2="95" stroke="#123456"/>'
    )
    p, notes = _read(_svg(tmp_path, body))
    assert np.ptp(p.flat, axis=0) == pytest.approx([0.040, 0.040], rel=1e-9)  # 2 x 20 mm
    assert p.n_faces == 4
    m = p.fold_angle[p.assignment == "M"]
    v = p.fold_angle[p.assignment == "V"]
    assert np.allclose(m, -45.0) and np.allclose(v, 90.0)
    assert any("#123456" in n for n in notes)
    # y is turned up: the mountain runs from the top-left to the bottom-right corner
    e = p.edges[p.assignment == "M"][0]
    xy = p.flat[e] - p.flat.min(axis=0)
    assert (xy[np.argmin(xy[:, 0])] == pytest.approx([0.0, 0.040])) or (
        xy[np.argmin(xy[:, 0])] == pytest.approx([0.0, 0.020])
    )


def test_svg_curves_and_attributes(tmp_path):
    border = '<circle cx="50" cy="50" r="40" stroke="#000" fill="none"/>'
    crease = '<path d="M 10 50 Q 50 10 90 50" stroke="#0000ff"/>'
    with pytest.raises(FormatError, match="curved crease"):
        read_pattern(_svg(tmp_path, border + crease), curves="refuse")
    straight = (
        '<line x1="10" y1="50" x2="90" y2="50" stroke="#000" data-assignment="V" '
        'data-foldAngle="33"/>'
    )
    p, notes = _read(_svg(tmp_path, border + straight))
    assert any("curve(s) kept" in n for n in notes)  # the circle, by chord deviation
    assert any(
        "flattened" in n for n in _read(_svg(tmp_path, border + straight), curves="refuse")[1]
    )
    assert np.allclose(p.fold_angle[p.assignment == "V"], 33.0)
    # two half discs, meshed along their rulings (issue 36): triangles, no vertex added
    halves = read_pattern(_svg(tmp_path, border + straight), split="none")
    assert halves.n_faces == 2 and p.n_faces == sum(len(f) - 2 for f in halves.faces)
    with pytest.raises(FormatError, match="data-assignment 'X'"):
        read_pattern(_svg(tmp_path, border + straight.replace('"V"', '"X"')))
    with pytest.raises(FormatError, match="no crease-pattern lines"):
        read_pattern(_svg(tmp_path, '<line x1="0" y1="0" x2="9" y2="9" stroke="#abcdef"/>'))
    (tmp_path / "broken.svg").write_text("<svg><line", encoding="utf-8")
    with pytest.raises(FormatError, match="not a readable SVG"):
        read_pattern(tmp_path / "broken.svg")


@pytest.mark.parametrize(
    "pattern",
    [
        g.miura_sheet(4, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=0.6),
        g.tmp_sheet(4, 3, 0.1, 0.7),
        g.gripper_pattern(1, 0.02, 0.01, 0.5).pattern,
    ],
    ids=["miura", "tmp", "gripper"],
)
def test_own_patterns_round_trip_through_svg_and_fold(tmp_path, pattern):
    for suffix in (".svg", ".fold"):
        path = g.export(pattern, tmp_path / f"p{suffix}")
        q, notes = _read(path)
        assert not notes
        _same_pattern(pattern, q)


# ------------------------------------------------------------------ FOLD
def _fold(tmp_path, d, name="p.fold"):
    f = tmp_path / name
    f.write_text(json.dumps(d), encoding="utf-8")
    return f


def test_fold_as_origami_simulator_writes_it(tmp_path):
    """A flat pattern in the xz plane labelled foldedForm, an F facet with a null angle, a
    pentagon, lower-case assignments and frame_unit 'unit'; then a cut between two faces."""
    xy = [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1], [2, 0.5]]
    d = {
        "file_spec": 1.1, "frame_classes": ["foldedForm"], "frame_attributes": ["3D"],
        "frame_unit": "unit", "vertices_coords": [[x, 0, -y] for x, y in xy],
        "edges_vertices": [[0, 1], [1, 2], [2, 6], [6, 3], [3, 4], [4, 5], [5, 0], [1, 4],
                           [0, 4]],
        "edges_assignment": ["b", "B", "B", "B", "B", "B", "B", "v", "F"],
        "edges_foldAngle": [None] * 7 + [90, None],
        "faces_vertices": [[0, 1, 4], [0, 4, 5], [1, 2, 6, 3, 4]],
    }  # fmt: skip
    p, notes = _read(_fold(tmp_path, d))
    assert any("flat (one plane)" in n for n in notes)
    assert any("1 unit read as 1 m" in n for n in notes) and any("lower-case" in n for n in notes)
    assert p.flat is not None and np.ptp(p.flat, axis=0) == pytest.approx([2.0, 1.0])
    assert all(_area(p.flat, f) > 0 for f in p.faces) and max(len(f) for f in p.faces) == 5
    assert p.fold_angle[p.assignment == "V"].tolist() == [90.0]
    assert "F" in p.assignment
    scaled, _ = _read(_fold(tmp_path, d), unit=1e-3)
    assert np.ptp(scaled.flat, axis=0) == pytest.approx([2e-3, 1e-3])
    cut = dict(d, edges_assignment=d["edges_assignment"][:7] + ["C", "F"],
               edges_foldAngle=[None] * 9)  # fmt: skip
    c, notes = _read(_fold(tmp_path, cut))
    assert c.n_vertices == 9 and (c.assignment == "C").sum() == 2
    assert (c.edge_face_count[c.assignment == "C"] == 1).all()


def test_fold_frames_faces_from_edges_and_problems(tmp_path):
    base = g.miura_sheet(2, 2, a=0.02, b=0.02, gamma=1.0, ext=0.7)
    d = json.loads(g.fold_io.export_fold(base))
    p, _ = _read(_fold(tmp_path, d))
    assert np.allclose(p.coords[:, 2], 0)  # the crease pattern by default
    folded, notes = _read(_fold(tmp_path, d), frame=1)
    assert any("folded coordinates of frame 1" in n for n in notes)
    dist = cKDTree(folded.coords).query(base.coords)[0]
    assert dist.max() < 1e-12
    no_faces = {k: v for k, v in d.items() if k not in ("faces_vertices", "file_frames")}
    q, notes = _read(_fold(tmp_path, no_faces))
    assert any("faces found from the edges" in n for n in notes)
    _same_pattern(base, q)
    rad = dict(
        d, edges_foldAngle=[math.copysign(math.pi, a) if a else 0 for a in d["edges_foldAngle"]]
    )
    _, notes = _read(_fold(tmp_path, rad))
    assert any("look like radians" in n for n in notes)
    with pytest.raises(FormatError, match="frame 7; this file has frames 0..1"):
        read_pattern(_fold(tmp_path, d), frame=7)
    with pytest.raises(FormatError, match=r"edges_assignment\[0\] = 'Q'"):
        read_pattern(_fold(tmp_path, dict(d, edges_assignment=["Q"] * len(d["edges_vertices"]))))
    (tmp_path / "bad.fold").write_text("{", encoding="utf-8")
    with pytest.raises(FormatError, match="not valid JSON"):
        read_pattern(tmp_path / "bad.fold")


# ------------------------------------------------------------------ DXF, ORIPA
def test_dxf_layers_colours_blocks_and_units(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new("R2010", units=4)  # mm
    msp = doc.modelspace()
    for name in ("BOUNDARY", "SCORE_M", "SCORE_V", "REGISTRATION"):
        doc.layers.add(name)
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 100), (0, 100)], close=True,
                       dxfattribs={"layer": "BOUNDARY"})  # fmt: skip
    msp.add_line((0, 0), (100, 100), dxfattribs={"layer": "SCORE_M"})
    half = msp.add_line((0, 100), (100, 0), dxfattribs={"layer": "0", "color": 5})  # blue: V
    half.transparency = 0.5
    block = doc.blocks.new("CREASE")
    block.add_line((0, 0), (10, 0), dxfattribs={"layer": "SCORE_V"})
    msp.add_blockref("CREASE", (0, 50), dxfattribs={"xscale": 5})  # (0, 50) -> (50, 50)
    msp.add_circle((120, 120), 3, dxfattribs={"layer": "REGISTRATION"})
    msp.add_line((0, 0), (1, 1), dxfattribs={"layer": "NOTES", "color": 4})
    path = tmp_path / "cp.dxf"
    doc.saveas(path)
    p, notes = _read(path)
    assert np.ptp(p.flat, axis=0) == pytest.approx([0.1, 0.1])
    assert (p.n_vertices, p.n_faces) == (6, 5)
    assert sorted(np.unique(p.assignment)) == ["B", "M", "V"]
    assert np.allclose(p.fold_angle[p.assignment == "M"], -180.0)
    v = np.sort(p.fold_angle[p.assignment == "V"])
    assert v[0] == pytest.approx(90.0, abs=0.5) and v[-1] == 180.0  # transparency 0.5
    assert any("NOTES" in n for n in notes)
    inches, _ = _read(path, unit=0.0254)
    assert np.ptp(inches.flat, axis=0) == pytest.approx([2.54, 2.54])
    msp.add_arc((50, 50), 10, 0, 90, dxfattribs={"layer": "SCORE_M"})
    doc.saveas(path)
    with pytest.raises(FormatError, match="curved crease"):
        read_pattern(path, curves="refuse")


def test_oripa_opx_and_cp(tmp_path):
    def line(t, x0, y0, x1, y1):
        props = "".join(
            f'<void property="{k}"><double>{v}</double></void>'
            for k, v in (("x0", x0), ("y0", y0), ("x1", x1), ("y1", y1))
            if v != 0
        )
        kind = f'<void property="type"><int>{t}</int></void>' if t else ""
        return f'<void index="0"><object class="oripa.OriLineProxy">{kind}{props}</object></void>'

    lines = [(1, -200, -200, 200, -200), (1, 200, -200, 200, 200), (1, 200, 200, -200, 200),
             (1, -200, 200, -200, -200), (2, -200, -200, 200, 200), (3, 0, -200, 0, 200),
             (0, -200, 0, 200, 0)]  # fmt: skip
    xml = ('<?xml version="1.0" encoding="UTF-8"?><java class="java.beans.XMLDecoder">'
           '<object class="oripa.DataSet"><void property="lines"><array class="oripa.OriLineProxy">'
           + "".join(line(*x) for x in lines) + "</array></void></object></java>")  # fmt: skip
    (tmp_path / "cp.opx").write_text(xml, encoding="utf-8")
    opx, notes = _read(tmp_path / "cp.opx")
    assert (opx.n_vertices, opx.n_faces) == (7, 4)
    assert np.ptp(opx.flat, axis=0) == pytest.approx([0.4, 0.4])
    assert any("auxiliary" in n for n in notes) and any("1 mm" in n for n in notes)
    (tmp_path / "cp.cp").write_text(
        "\n".join(" ".join(map(str, x)) for x in lines), encoding="utf-8"
    )
    cp, _ = _read(tmp_path / "cp.cp")
    _same_pattern(opx, cp)
    (tmp_path / "bad.cp").write_text("2 0 0 1\n", encoding="utf-8")
    with pytest.raises(FormatError, match="line 1"):
        read_pattern(tmp_path / "bad.cp")


def test_read_pattern_refuses_in_one_line(tmp_path):
    with pytest.raises(FormatError, match=r"unknown crease-pattern format '\.stl'; known: \.fold"):
        read_pattern(tmp_path / "x.stl")
    with pytest.raises(FormatError, match="no such file"):
        read_pattern(tmp_path / "x.svg")
    with pytest.raises(ParameterError, match="take no option 'frame'"):
        read_pattern(OS / "simpleVertex.svg", frame=1)


_SQUARE = (
    '<rect x="0" y="0" width="50" height="50" stroke="black" fill="none"/>'
    '<line x1="0" y1="0" x2="{x2}" y2="50" stroke="#f00"/>'
)


@pytest.mark.parametrize("bad", ["nan", "NaN", "inf", "-Infinity"])
def test_svg_non_finite_coordinates_are_refused_not_read_as_zero(tmp_path, bad):
    """svgelements reads 'nan' and 'inf' as 0, which moved the crease to the corner (and the
    warning said 'drawn twice'); now the line is refused at its attribute."""
    f = _svg(tmp_path, _SQUARE.format(x2=bad))
    with pytest.raises(FormatError, match=r"'cp.svg': <line> x2 is not a finite number \(line 1\)"):
        read_pattern(f)
    ok = read_pattern(_svg(tmp_path, _SQUARE.format(x2="50")))
    assert ok.n_faces == 2


@pytest.mark.parametrize("width", ["100km", "100%", "3ft"])
def test_svg_width_in_an_unknown_unit_is_refused(tmp_path, width):
    """width='100km' or '100%' was read as px (13.23 mm across): refused with what to give."""
    f = _svg(tmp_path, _SQUARE.format(x2="50"),
             size=f'width="{width}" height="{width}" viewBox="0 0 100 100"')  # fmt: skip
    with pytest.raises(FormatError, match=f'root width="{width}" is not a length in px, mm, cm'):
        read_pattern(f)
    for good, mm in (("100mm", 50.0), ("10cm", 50.0), ("72pt", 25.4 / 2), ("96", 25.4 / 2)):
        g = _svg(tmp_path, _SQUARE.format(x2="50"),
                 size=f'width="{good}" height="{good}" viewBox="0 0 100 100"')  # fmt: skip
        p = read_pattern(g)
        assert np.ptp(p.flat[:, 0]) * 1e3 == pytest.approx(mm, rel=1e-6), good


def test_a_zero_length_line_is_dropped_without_a_division_by_zero():
    """A point drawn as a line (Origami Simulator's russianTriangle.svg has one) stayed in the
    arrangement when no other line was short and divided by its zero length (RuntimeWarning)."""
    from holofold.geometry.arrangement import arrange_lines

    square = [[[0, 0], [1, 0]], [[1, 0], [1, 1]], [[1, 1], [0, 1]], [[0, 1], [0, 0]]]
    segs = np.array([*square, [[0, 0], [1, 1]], [[0.5, 0.5], [0.5, 0.5]]], float)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        arr = arrange_lines(segs, ["B"] * 4 + ["V", "M"], [0, 0, 0, 0, 90, -90])
    assert len(arr.faces) == 2 and len(arr.edges) == 5 and not arr.notes
