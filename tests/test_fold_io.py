"""FOLD 1.2 write/read round trip and validation errors."""

import json
import math

import numpy as np
import pytest

from holofold.geometry.errors import FormatError
from holofold.geometry.fold_io import FoldWarning, export_fold, fold_dict, load_fold
from holofold.geometry.miura import miura_sheet
from holofold.geometry.pattern import CreasePattern
from holofold.geometry.tmp import tmp_sheet


@pytest.fixture(scope="module")
def miura():
    return miura_sheet(3, 2, a=0.02, b=0.03, gamma=math.radians(70), ext=0.5)


def _same(a: CreasePattern, b: CreasePattern):
    assert np.array_equal(a.coords, b.coords)
    assert np.array_equal(a.edges, b.edges)
    assert np.array_equal(a.assignment, b.assignment)
    assert np.array_equal(a.fold_angle, b.fold_angle)
    assert all(np.array_equal(f, g) for f, g in zip(a.faces, b.faces, strict=True))
    if a.flat is None:
        assert b.flat is None
    else:
        assert np.array_equal(a.flat, b.flat)


@pytest.mark.parametrize("make", [
    lambda: miura_sheet(3, 2, a=0.02, b=0.03, gamma=math.radians(70), ext=0.5),
    lambda: tmp_sheet(4, 6, 0.2, 0.7),
])  # fmt: skip
def test_round_trip_is_exact(make):
    p = make()
    back = load_fold(export_fold(p, crease_width=2e-3, panel_thickness=1e-3))
    _same(p, back)
    assert back.meta["creaseWidth"] == [2e-3] * p.n_edges
    assert back.meta["kind"] == p.meta["kind"]


def test_written_file_has_the_keys_origami_simulator_needs(miura):
    d = json.loads(export_fold(miura))
    needed = "vertices_coords edges_vertices edges_assignment faces_vertices edges_foldAngle"
    for k in (needed + " file_spec file_creator frame_classes frame_unit").split():
        assert k in d
    assert d["file_spec"] == 1.2 and d["frame_unit"] == "m"
    assert d["frame_classes"] == ["creasePattern"] and len(d["vertices_coords"][0]) == 2
    assert d["file_frames"][0]["frame_classes"] == ["foldedForm"]
    assert all(
        ":" in k for k in d if k not in json.loads(json.dumps(d)) or k.startswith("holofold")
    )
    # valleys positive, mountains negative, borders zero
    a = np.array(d["edges_foldAngle"])
    asg = np.array(d["edges_assignment"])
    assert (a[asg == "V"] > 0).all() and (a[asg == "M"] < 0).all() and (a[asg == "B"] == 0).all()


def _bad(miura, **change):
    d = fold_dict(miura)
    for k, v in change.items():
        if v is None:
            d.pop(k)
        else:
            d[k] = v
    return json.dumps(d)


@pytest.mark.parametrize(
    "change, message",
    [
        ({"faces_vertices": None}, "missing required key 'faces_vertices'"),
        ({"edges_assignment": ["M"]}, "equal lengths"),
        ({"edges_vertices": [[0, 99]] + [[0, 1]] * 0}, "outside 0..|equal lengths"),
        ({"vertices_coords": [[0, 0], [1, 0, 0]]}, "mixes 2-D and 3-D"),
    ],
)
def test_structural_errors(miura, change, message):
    with pytest.raises(FormatError, match=message):
        load_fold(_bad(miura, **change))


def _edge_change(d: dict, what: str) -> None:
    """Spoil one edge of FOLD dict ``d`` in place (``what`` names the mistake)."""
    v = d["edges_assignment"].index("V")
    if what == "circular":
        d["edges_vertices"][0] = [d["edges_vertices"][0][0]] * 2
    elif what == "duplicate":
        d["edges_vertices"][1] = d["edges_vertices"][0]
    elif what == "sign":
        d["edges_foldAngle"][v] = -30.0
    elif what == "range":
        d["edges_foldAngle"][v] = 200.0
    elif what == "assignment":
        d["edges_assignment"][0] = "X"
    elif what == "coincide":
        d["vertices_coords"][1] = d["vertices_coords"][0]


@pytest.mark.parametrize(
    "what, message",
    [
        ("circular", "circular"),
        ("duplicate", "duplicate edge"),
        ("sign", "does not match fold angle"),
        ("range", r"\[-180, 180\]"),
        ("assignment", "allowed: M V B F C J U"),
        ("coincide", "coincide"),
    ],
)
def test_edge_level_errors(miura, what, message):
    d = fold_dict(miura)
    _edge_change(d, what)
    with pytest.raises(FormatError, match=message):
        load_fold(d)


def test_not_json_and_soft_problems(miura):
    with pytest.raises(FormatError, match="not valid JSON"):
        load_fold("{nope")
    with pytest.raises(FormatError, match="JSON object"):
        load_fold("[1, 2]")
    d = fold_dict(miura)
    d.pop("file_spec")
    d["custom"] = 1
    d["faces_vertices"][0] = d["faces_vertices"][0][::-1]  # clockwise
    with pytest.warns(FoldWarning) as rec:
        back = load_fold(d)
    text = " ".join(str(w.message) for w in rec)
    assert "no file_spec" in text and "'custom'" in text and "clockwise" in text
    assert np.array_equal(back.faces[0], miura.faces[0])


def test_units_and_null_angles(miura):
    d = fold_dict(miura)
    d["frame_unit"] = "mm"
    d.pop("file_frames")
    d["edges_foldAngle"] = [None] * len(d["edges_foldAngle"])
    back = load_fold(d)
    assert np.allclose(back.flat, miura.flat * 1e-3)
    assert set(back.assignment) <= {"B", "U"}
