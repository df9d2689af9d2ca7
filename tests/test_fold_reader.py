"""The validated FOLD reader (issue 15, section 3): every bad file is one line naming the file,
the place and what was expected, never another exception; holofold's own files read back."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from holofold.fitting import builtin_curve, export_strip_files, fit_strip
from holofold.geometry import (
    FormatError,
    export_fold,
    export_pattern_files,
    fold_dict,
    gripper_pattern,
    load_fold,
    miura_sheet,
    read_fold,
    tmp_sheet,
)
from holofold.geometry.fold_io import MAX_FOLD_BYTES, MAX_FOLD_FACES, MAX_NESTING, PLANAR_TOL


@pytest.fixture(scope="module")
def miura():
    return miura_sheet(3, 2, a=0.02, b=0.03, gamma=math.radians(70), ext=0.5)


@pytest.fixture(scope="module")
def base(miura):
    return fold_dict(miura)


def _refused(source, match, **kw):
    with pytest.raises(FormatError, match=match) as info:
        load_fold(source, **kw)
    assert "\n" not in str(info.value)
    return str(info.value)


# ------------------------------------------------------------------ holofold's own files
@pytest.mark.parametrize(
    "make",
    [
        lambda: miura_sheet(6, 5, a=0.02, b=0.02, gamma=math.radians(60), ext=0.4),
        lambda: tmp_sheet(6, 6, 0.2, 0.5),
        *(lambda p=p: gripper_pattern(p, 0.02, 0.01, 0.3).pattern for p in (1, 2, 3)),
        lambda: fit_strip(builtin_curve("half-circle", radius=2.0), 16, 0.2, 0.02, 0.15).pattern,
    ],
    ids=["miura", "tmp", "gripper1", "gripper2", "gripper3", "strip"],
)
def test_holofold_files_read_back(make):
    p = make()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = load_fold(export_fold(p))
    assert np.array_equal(back.edges, p.edges)
    np.testing.assert_array_equal(back.coords, p.coords)


def test_written_files_read_back_from_disk(tmp_path):
    sheet = miura_sheet(4, 4, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    export_pattern_files(sheet, tmp_path / "sheet")
    assert read_fold(tmp_path / "sheet" / "pattern.fold").n_faces == 16
    # a strongly warped fitted strip (its quads warp by 13 %): planar within PLANAR_TOL
    fit = fit_strip(builtin_curve("half-circle", radius=2.0), 40, 0.2, 0.1, 0.15)
    assert fit.warp.max() > 0.1
    paths = export_strip_files(fit, tmp_path / "strip")
    fold = next(p for p in paths if p.suffix == ".fold")
    assert read_fold(fold).n_faces == 160


# ------------------------------------------------------------------------ bad files
def test_deep_nesting_is_one_line_naming_the_file_and_key(tmp_path):
    path = tmp_path / "deep.fold"
    path.write_text("[" * 1000 + "]" * 1000)  # 2 KB
    msg = str(pytest.raises(FormatError, read_fold, path).value)
    assert msg.startswith(f"FOLD file {str(path)!r}: arrays nested 1000 deep")
    assert f"at most {MAX_NESTING} deep" in msg
    text = '{"file_spec": 1.2, "vertices_coords": ' + "[" * 1000 + "]" * 1000 + "}"
    _refused(text, "under key 'vertices_coords'", name="x.fold")
    _refused(text.encode(), "nested 1001 deep")
    # brackets inside strings do not count
    ok = {"file_title": "[" * 5000, "vertices_coords": [], "edges_vertices": [],
          "faces_vertices": []}  # fmt: skip
    _refused(json.dumps(ok), "vertices_coords: expected a non-empty array")


def test_deep_nesting_inside_a_deep_stack_is_still_a_format_error():
    def nest(n):
        return _refused("[" * 60 + "]" * 60, "too deeply|JSON object") if n == 0 else nest(n - 1)

    nest(900)  # within 100 frames of the recursion limit: the parser's RecursionError converts


@pytest.mark.parametrize(
    "edge, match",
    [
        ([0, 10**30], r"edges_vertices\[0\] = \[0, 10{30}\]: vertex 10{30} is outside 0\.\.11"),
        ([0, 1.0], r"edges_vertices\[0\] = \[0, 1\.0\]: expected integer vertex indices"),
        ([0, 1.5], r"expected integer vertex indices, got 1\.5"),
        ([0, -1], r"vertex -1 is outside 0\.\.11"),
        ([0, 12], r"vertex 12 is outside 0\.\.11"),
        ([0, True], "expected integer vertex indices, got True"),
        ([0, "1"], "expected integer vertex indices"),
        ([0], r"expected a pair \[u, v\]"),
        (7, r"edges_vertices\[0\] = 7: expected a pair"),
    ],
)
def test_edge_indices_must_be_integers_in_range(base, edge, match):
    d = {**base, "edges_vertices": [edge, *base["edges_vertices"][1:]]}
    _refused(json.dumps(d), match)


@pytest.mark.parametrize(
    "key, value, match",
    [
        ("vertices_coords", "abc", "vertices_coords: expected a non-empty array.*got a string"),
        ("edges_vertices", "abc", "edges_vertices: expected an array.*got a string"),
        ("faces_vertices", {"a": 1}, "faces_vertices: expected an array.*got an object"),
        ("edges_assignment", "MVB", "edges_assignment: expected an array.*got a string"),
        ("edges_foldAngle", 3, "edges_foldAngle: expected an array of numbers, got an integer"),
        ("frame_classes", "creasePattern", "frame_classes = 'creasePattern': expected an array"),
        ("frame_unit", ["m"], r"frame_unit = \['m'\]; expected one of m cm mm"),
        ("file_frames", 5, "file_frames: expected an array of frame objects, got an integer"),
        ("file_frames", [3], r"file_frames\[0\]: expected a frame object"),
        ("edges_holofold:creaseWidth", 2e-3, "creaseWidth: expected an array of numbers"),
    ],
)
def test_wrong_types_are_named(base, key, value, match):
    _refused(json.dumps({**base, key: value}), match)


def test_coordinates_are_finite_numbers_of_one_dimension(base):
    coords = base["vertices_coords"]
    for first, match in [
        ([1e999, 0], r"vertices_coords\[0\] = \[inf, 0\]: expected finite numbers"),
        ([10**400, 0], "expected finite numbers"),
        ([True, 0], r"expected \[x, y\] or \[x, y, z\] numbers"),
        (["0", 0], r"expected \[x, y\] or \[x, y, z\] numbers"),
        ([0, 0, 0, 0], r"expected \[x, y\] or \[x, y, z\]"),
    ]:
        d = {**base, "vertices_coords": [first, *coords[1:]]}
        text = json.dumps(d) if first[0] != 1e999 else json.dumps(d).replace("Infinity", "1e999")
        _refused(text, match)
    d = {**base, "vertices_coords": [coords[0], [*coords[1], 0.0], *coords[2:]]}
    _refused(json.dumps(d), r"vertices_coords\[1\] has 3 coordinates, vertex 0 has 2")
    nan = '{"vertices_coords": [[NaN, 0]], "edges_vertices": [], "faces_vertices": []}'
    _refused(nan, r"vertices_coords\[0\] = \[nan, 0\]: expected finite numbers")


def test_faces_empty_repeated_duplicate_or_non_planar_are_refused(base):
    faces = base["faces_vertices"]
    cases = [
        ([[], *faces[1:]], r"faces_vertices\[0\] = \[\]: expected an array of >= 3 vertex"),
        ([[0, 1], *faces[1:]], "expected an array of >= 3 vertex indices"),
        ([[0, 3, 3, 1], *faces[1:]], "lists a vertex twice"),
        ([faces[0], faces[0][::-1], *faces[2:]], r"faces_vertices\[1\].* repeats face 0"),
        ([[0, 1.0, 4], *faces[1:]], "expected integer vertex indices, got 1.0"),
    ]
    for value, match in cases:
        _refused(json.dumps({**base, "faces_vertices": value}), match)
    d = json.loads(json.dumps(base))  # warp a panel of the folded frame into a saddle
    f = d["faces_vertices"][0]
    folded = np.array(d["file_frames"][0]["vertices_coords"])
    P = folded[f]
    normal = np.cross(P[2] - P[0], P[3] - P[1])
    size = np.linalg.norm(P[2] - P[0])
    folded[[f[1], f[3]]] += 0.5 * size * normal / np.linalg.norm(normal)  # two opposite corners
    d["file_frames"][0]["vertices_coords"] = folded.tolist()
    msg = _refused(json.dumps(d), r"faces_vertices\[0\] = .* is not planar")
    assert f"expected at most {PLANAR_TOL}" in msg
    flat = np.array(base["vertices_coords"])  # a crease pattern with z: not flat
    d = {**base, "vertices_coords": np.column_stack([flat, flat[:, 0]]).tolist()}
    _refused(json.dumps(d), "a crease pattern must be flat")


def test_assignments_are_the_fold_set_one_per_edge(base):
    asg = base["edges_assignment"]
    _refused(json.dumps({**base, "edges_assignment": ["X", *asg[1:]]}),
             r"edges_assignment\[0\] = 'X'; allowed: M V B F C J U")  # fmt: skip
    _refused(json.dumps({**base, "edges_assignment": [None, *asg[1:]]}), "= None; allowed")
    _refused(json.dumps({**base, "edges_assignment": asg[:-1]}), "equal lengths")


def test_sizes_are_limited(base, tmp_path):
    tri = [[0, 1, 2]] * (MAX_FOLD_FACES + 1)
    _refused(json.dumps({**base, "faces_vertices": tri}), f"at most {MAX_FOLD_FACES} are read")
    big = tmp_path / "big.fold"
    with open(big, "wb") as fh:  # sparse: no 64 MiB written
        fh.truncate(MAX_FOLD_BYTES + 1)
    with pytest.raises(FormatError, match=r"big\.fold.*bytes; expected at most"):
        read_fold(big)
    with pytest.raises(FormatError, match="cannot be read"):
        read_fold(tmp_path / "missing.fold")


def test_not_text_or_not_json(tmp_path):
    _refused(b"\xff\xfe\x00garbage", "not UTF-8 text", name="b.fold")
    _refused("{nope", "not valid JSON")
    _refused('{"a": ' + "1" * 5000 + "}", "not valid JSON")
    _refused("[1, 2]", "the top level is an array; expected a JSON object")
    _refused('"text"', "the top level is a string")
    _refused(3, "expected FOLD text, bytes or a dict, got int")


def test_warnings_name_the_file(base):
    d = dict(base)
    d.pop("file_spec")
    with pytest.warns(UserWarning, match=r"FOLD file 'w\.fold': no file_spec"):
        load_fold(json.dumps(d), name="w.fold")


# ------------------------------------------------------------------- property tests
def _check(source):
    try:
        load_fold(source, name="fuzz.fold")
    except FormatError as exc:
        assert "\n" not in str(exc)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_any_bytes_give_a_pattern_or_format_error(data):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _check(data)


JSONISH = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**40), 10**40)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.sampled_from([0, 1, 2, 3, -1, 0.5, 1.0, 180, 1e308, "M", "V", "B", "U", "m", "x"]),
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=3), inner),
    max_leaves=25,
)
KEYS = ["vertices_coords", "edges_vertices", "faces_vertices", "edges_assignment",
        "edges_foldAngle", "frame_classes", "frame_unit", "file_frames",
        "edges_holofold:creaseWidth", "faces_holofold:thickness", "holofold:meta"]  # fmt: skip


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_any_json_or_mutated_fold_gives_a_pattern_or_format_error(base, data):
    """Arbitrary JSON values, and a valid file with 1-3 keys, entries or texts replaced."""
    how = data.draw(st.sampled_from(["value", "keys", "entries", "text"]))
    if how == "value":
        source = json.dumps(data.draw(JSONISH))
    else:
        d = json.loads(json.dumps(base))
        for _ in range(data.draw(st.integers(1, 3))):
            key = data.draw(st.sampled_from(KEYS))
            if how == "keys":
                d[key] = data.draw(JSONISH)
            elif isinstance(d.get(key), list) and d[key]:
                i = data.draw(st.integers(0, len(d[key]) - 1))
                d[key][i] = data.draw(JSONISH)
        source = json.dumps(d)
        if how == "text":
            i = data.draw(st.integers(0, len(source) - 1))
            source = source[:i] + data.draw(st.sampled_from('[]{}",:0-e.')) + source[i + 1 :]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _check(source)
