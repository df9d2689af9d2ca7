"""The readers' one record and one pipeline (issue 35 item 3): every line reader returns a
:class:`LineDrawing`, :func:`pattern_from_drawing` makes the crease pattern, and every reader
reads a path, the file's bytes or a binary file object to the same pattern."""

from __future__ import annotations

import ast
import dataclasses
import io
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import holofold.geometry as g
from holofold.geometry import FormatError, ParameterError
from holofold.geometry import svg_reader as svg_mod
from holofold.geometry.dxf_reader import dxf_drawing
from holofold.geometry.line_drawing import LineDrawing, PatternWarning, pattern_from_drawing
from holofold.geometry.opx_reader import cp_drawing, opx_drawing
from holofold.geometry.svg_reader import svg_drawing

DATA = Path(__file__).parent / "data"
BIRD = DATA / "origami-simulator" / "birdBase.svg"
ROOF = DATA / "hypar-roof-6x8.fold"
GEOMETRY = Path(__file__).resolve().parents[1] / "geometry"


def _quiet(read, *a, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = read(*a, **kw)
    return out, [str(w.message) for w in caught if issubclass(w.category, PatternWarning)]


def _same(p, q):
    """The same crease pattern: vertices to 1e-12 of the sheet, topology and angles equal."""
    size = float(np.ptp(p.coords, axis=0).max())
    assert p.coords.shape == q.coords.shape
    assert np.abs(p.coords - q.coords).max() <= 1e-12 * size
    assert np.array_equal(p.edges, q.edges)
    assert [list(f) for f in p.faces] == [list(f) for f in q.faces]
    assert list(p.assignment) == list(q.assignment)
    assert np.allclose(p.fold_angle, q.fold_angle, rtol=0, atol=1e-12)


def _lines(pattern):
    """(type, x0, y0, x1, y1) in mm, y down, of a pattern's borders, mountains, valleys."""
    t = {"B": 1, "M": 2, "V": 3}
    xy = (pattern.flat * 1e3).tolist()
    pairs = zip(pattern.edges, pattern.assignment, strict=True)
    return [(t[a], xy[i][0], -xy[i][1], xy[j][0], -xy[j][1]) for (i, j), a in pairs if a in t]


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict:
    """One file of every format, written from the bird base where the format is not vendored."""
    d = tmp_path_factory.mktemp("formats")
    bird, _ = _quiet(g.read_pattern, BIRD)
    (d / "bird.dxf").write_text(g.export_dxf(bird))
    lines = _lines(bird)
    (d / "bird.cp").write_text("".join(f"{t} {a!r} {b!r} {c!r} {e!r}\n" for t, a, b, c, e in lines))
    objs = "".join(
        f'<object class="oripa.OriLineProxy"><void property="type"><int>{t}</int></void>'
        + "".join(
            f'<void property="{k}"><double>{v!r}</double></void>'
            for k, v in zip(("x0", "y0", "x1", "y1"), (a, b, c, e), strict=True)
        )  # fmt: skip
        + "</object>"
        for t, a, b, c, e in lines
    )
    (d / "bird.opx").write_text(f'<?xml version="1.0"?><java><object class="oripa.DataSet">'
                                f"{objs}</object></java>")  # fmt: skip
    return {".svg": BIRD, ".fold": ROOF, ".dxf": d / "bird.dxf", ".cp": d / "bird.cp",
            ".opx": d / "bird.opx"}  # fmt: skip


@pytest.mark.parametrize("suffix", [".svg", ".dxf", ".cp", ".opx", ".fold"])
def test_every_reader_reads_bytes_and_file_objects_as_the_path(files, suffix):
    path = files[suffix]
    reader = g.READERS[suffix].read
    ref, notes = _quiet(reader, path)
    assert ref.n_faces > 4
    data = path.read_bytes()
    for source in (data, bytearray(data), io.BytesIO(data)):
        p, n = _quiet(reader, source)
        _same(ref, p)
        where = "<bytes>" if isinstance(source, bytes | bytearray) else "<file>"
        assert [m.split(": ", 1)[1] for m in n] == [m.split(": ", 1)[1] for m in notes]
        assert all(m.startswith(f"{where}: ") for m in n)
        assert p.meta["source"] == where and p.meta["kind"] == ref.meta["kind"]
    with open(path, "rb") as fh:  # a real file object, named by its file
        p, n = _quiet(reader, fh)
    _same(ref, p)
    assert n == notes and p.meta == ref.meta
    # read_pattern: bytes name their format with suffix, a file object by its name
    _same(ref, _quiet(g.read_pattern, data, suffix=suffix.upper())[0])
    with open(path, "rb") as fh:
        _same(ref, _quiet(g.read_pattern, fh)[0])


def test_read_pattern_needs_the_format_of_bytes():
    with pytest.raises(FormatError, match=r"^<bytes>: unknown crease-pattern format '\(no suffix"):
        g.read_pattern(BIRD.read_bytes())
    with pytest.raises(FormatError, match=r"^<file>: unknown crease-pattern format '.png'"):
        g.read_pattern(io.BytesIO(b"x"), suffix=".png")


@pytest.mark.parametrize(
    ("suffix", "data", "message"),
    [
        (".svg", b"<svg><g>", r"SVG file '<bytes>' is not a readable SVG file \(not well-formed"),
        (".svg", b"<html/>", r"SVG file '<bytes>': its root element is not <svg>"),
        (".dxf", b"garbage\n", r"^<bytes>: not a readable DXF file \(File '<bytes>' is not a DXF"),
        (".cp", b"1 0 0 1\n", r"^<bytes>: line 1 is not 'type x0 y0 x1 y1'"),
        (".opx", b"<java", r"^<bytes>: not well-formed XML"),
        (".fold", b"{", r"^FOLD file '<bytes>': not valid JSON"),
    ],
)
def test_refusals_of_bytes_name_them(suffix, data, message):
    with pytest.raises(FormatError, match=message):
        g.read_pattern(data, suffix=suffix)


def test_the_bounded_checks_run_on_the_bytes_before_a_parser(monkeypatch):
    """A <use> doubling bomb (2^25 elements from a few hundred bytes) is refused by the
    streaming count, as bytes as from a file; a file object is read to the size limit + 1."""
    uses = "".join(
        f'<g id="u{k + 1}"><use href="#u{k}"/><use href="#u{k}"/></g>' for k in range(25)
    )
    bomb = f'<svg xmlns="http://www.w3.org/2000/svg"><line id="u0"/>{uses}</svg>'.encode()
    with pytest.raises(FormatError, match=r"'<bytes>' has over 500,000 elements once its <use>"):
        svg_drawing(bomb)
    monkeypatch.setattr(svg_mod, "MAX_SVG_BYTES", 100)
    stream = io.BytesIO(BIRD.read_bytes())
    with pytest.raises(FormatError, match=r"^SVG file '<file>' is over 100 bytes; at most 100"):
        svg_drawing(stream)
    assert stream.tell() == 101
    with open(BIRD, "rb") as fh:  # an open file: its size is known, nothing of it is read
        with pytest.raises(FormatError, match=r"'birdBase.svg' is [0-9,]+ bytes; at most 100 "):
            svg_drawing(fh)
        assert fh.tell() == 0
    with pytest.raises(FormatError, match=r"'birdBase.svg' is [0-9,]+ bytes; at most 100 are"):
        svg_drawing(BIRD)
    with pytest.raises(FormatError, match="open it in binary mode"):
        svg_drawing(io.StringIO("<svg/>"))


def test_every_line_reader_returns_one_drawing(files):
    readers = ((svg_drawing, ".svg", "svg"), (dxf_drawing, ".dxf", "dxf"),
               (cp_drawing, ".cp", "oripa"), (opx_drawing, ".opx", "oripa"))  # fmt: skip
    for read, suffix, kind in readers:
        d = read(files[suffix])
        assert isinstance(d, LineDrawing) and d.kind == kind and d.name == files[suffix].name
        n = len(d)
        assert d.segments.shape == (n, 2, 2) and d.assignment.shape == d.fold_angle.shape == (n,)
        assert set(d.assignment) <= {"B", "M", "V", "F", "C", "U", "J"}
        assert np.all(d.fold_angle[d.assignment == "M"] < 0) and np.all(
            d.fold_angle[d.assignment == "V"] > 0
        )
        # the pipeline of the record is the reader's pattern
        _same(_quiet(pattern_from_drawing, d)[0], _quiet(g.READERS[suffix].read, files[suffix])[0])
    # the same sheet in every format: the .cp/.opx/.dxf drawings are the bird base in mm
    svg = svg_drawing(BIRD)
    side = float(np.ptp(svg.segments.reshape(-1, 2), axis=0).max()) * svg.unit
    for suffix in (".cp", ".opx", ".dxf"):
        d = (cp_drawing if suffix == ".cp" else opx_drawing if suffix == ".opx" else dxf_drawing)(
            files[suffix]
        )
        assert (
            abs(float(np.ptp(d.segments.reshape(-1, 2), axis=0).max()) * d.unit - side)
            < 1e-9 * side
        )


def test_a_drawing_by_hand_goes_through_the_pipeline():
    """A 10 x 20 mm rectangle drawn in mm with a valley diagonal and a mountain across its
    middle that stops short of the border: the crossing is split, the mountain's loose end is
    left as drawn, the faces found."""
    S = [[[0, 0], [10, 0]], [[10, 0], [10, 20]], [[10, 20], [0, 20]], [[0, 20], [0, 0]],
         [[0, 0], [10, 20]], [[5, 10], [10, 10]]]  # fmt: skip
    d = LineDrawing(S, ["B", "B", "B", "B", "V", "M"], [0, 0, 0, 0, 90.0, -45.0], 1e-3,
                    name="hand", kind="hand", notes=("drawn by hand",))  # fmt: skip
    p, notes = _quiet(pattern_from_drawing, d)
    assert notes[0] == "hand: drawn by hand"
    assert p.meta == {"kind": "hand", "source": "hand"}
    # vertices: the 4 corners and the mountain's end (the other end lies on the diagonal)
    xy = np.round(p.flat * 1e3, 9)
    assert sorted(map(tuple, xy.tolist())) == sorted(
        [(0, 0), (10, 0), (10, 20), (0, 20), (5, 10), (10, 10)]
    )
    assert np.allclose(p.coords[:, 2], 0.0)
    # edges: 5 border pieces (the right side split at (10, 10)), 2 valley halves, 1 mountain
    counts = {a: int((p.assignment == a).sum()) for a in set(p.assignment)}
    assert counts["B"] == 5 and counts["V"] == 2 and counts["M"] == 1
    assert np.allclose(p.fold_angle[p.assignment == "V"], 90.0)
    assert np.allclose(p.fold_angle[p.assignment == "M"], -45.0)
    total = sum(_polygon_area(xy[list(f)]) for f in p.faces)
    assert abs(total - 200.0) < 1e-9  # the faces tile the 10 x 20 mm sheet
    # the unit: the same drawing read in cm is 10 times larger; unit checked
    q, _ = _quiet(pattern_from_drawing, d, unit=1e-2)
    assert np.abs(q.flat - 10 * p.flat).max() < 1e-15
    with pytest.raises(ParameterError, match=r"unit = 'mm' must be a length in metres > 0"):
        pattern_from_drawing(d, unit="mm")


def _polygon_area(p) -> float:
    return 0.5 * abs(
        float(np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1]))
    )


def test_the_record_is_frozen_and_checked():
    d = LineDrawing([[[0, 0], [1, 0]]], ["B"], [0.0], 1.0, notes=["a"], unit_note="a")
    assert d.notes == ("a",) and d.segments.dtype == float and d.assignment.dtype == "<U1"
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.unit = 2.0
    with pytest.raises(ValueError, match="read-only"):
        d.segments[0, 0, 0] = 5.0
    assert d.with_unit(None) is d
    e = d.with_unit(0.5)
    assert e.unit == 0.5 and e.notes == () and d.notes == ("a",)
    with pytest.raises(ParameterError, match=r"one entry per segment \(1\)"):
        LineDrawing([[[0, 0], [1, 0]]], ["B", "M"], [0.0], 1.0)
    with pytest.raises(ParameterError, match=r"an \(n, 2, 2\) array"):
        LineDrawing([[0, 0, 1, 0]], ["B"], [0.0], 1.0)
    with pytest.raises(ParameterError, match="must be a length in metres > 0"):
        LineDrawing([[[0, 0], [1, 0]]], ["B"], [0.0], 0.0)


def test_the_unit_assumed_is_dropped_when_the_caller_gives_one(files):
    d = cp_drawing(files[".cp"])
    assert d.unit == 1e-3 and d.unit_note in d.notes and "no unit" in d.unit_note
    _, notes = _quiet(pattern_from_drawing, d, unit=2e-3)
    assert not any("no unit" in n for n in notes)
    _, notes = _quiet(pattern_from_drawing, d)
    assert any("no unit" in n for n in notes)


def test_the_reader_modules_import_no_holofold_module_inside_a_function():
    """The readers' circle stays broken without hiding one: the registry imports the reader
    modules at its top, and no reader module imports holofold inside a function."""
    for name in ("readers", "line_drawing", "svg_reader", "dxf_reader", "opx_reader",
                 "fold_reader", "bounded"):  # fmt: skip
        tree = ast.parse((GEOMETRY / f"{name}.py").read_text(encoding="utf-8"))
        for fn in ast.walk(tree):
            if not isinstance(fn, ast.FunctionDef):
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.ImportFrom):
                    assert not (node.module or "").startswith("holofold"), (
                        f"{name}.{fn.name} imports {node.module} inside a function"
                    )


def test_recipe_a_line_reader(tmp_path):
    """CONTRIBUTING.md's line reader, run as written: a path, bytes and a file object read to
    the same 20 x 10 mm sheet with its valley."""
    text = (Path(__file__).resolve().parents[1] / "CONTRIBUTING.md").read_text(encoding="utf-8")
    source = re.search(r"```python\n(# mypackage/lines_reader\.py.*?)```", text, re.S).group(1)
    space: dict = {}
    exec(compile(source, "lines_reader.py", "exec"), space)  # noqa: S102 - the recipe's code
    f = tmp_path / "a.lines"
    f.write_text("B 0 0 20 0\nB 20 0 20 10\nB 20 10 0 10\nB 0 10 0 0\nV 10 0 10 10\n")
    with g.READERS.saved():
        g.register_reader(space["READER"])
        p, notes = _quiet(g.read_pattern, f)
        assert notes == [] and p.meta == {"kind": "lines", "source": "a.lines"}
        assert p.n_faces == 2 and abs(float(np.ptp(p.flat[:, 0])) - 0.02) < 1e-15
        assert list(p.fold_angle[p.assignment == "V"]) == [180.0]
        _same(p, _quiet(g.read_pattern, f.read_bytes(), suffix=".lines")[0])
        with open(f, "rb") as fh:
            _same(p, _quiet(g.read_pattern, fh, unit=None)[0])
        q, _ = _quiet(g.read_pattern, f, unit=1e-2)
        assert abs(float(np.ptp(q.flat[:, 0])) - 0.2) < 1e-14
    assert ".lines" not in g.READERS


def test_an_edge_barely_longer_than_the_merge_distance_is_named_with_the_tol_that_merges_it():
    """A 100 x 100 square with a valley diagonal whose end is drawn 0.3 off the corner (the
    merge distance is 0.2, 2e-3 of the square): the reader keeps the two points apart, which
    makes a 0.3-long edge and a sliver panel, and says so with the ``tol`` that merges them;
    read with that ``tol`` the corner is one vertex and nothing is said."""
    S = [[[0, 0], [100, 0]], [[100, 0], [100, 100]], [[100, 100], [0, 100]],
         [[0, 100], [0, 0]], [[0.3, 0], [100, 100]]]  # fmt: skip
    d = LineDrawing(S, ["B", "B", "B", "B", "V"], [0, 0, 0, 0, 90.0], 1e-3, name="off")
    p, notes = _quiet(pattern_from_drawing, d)
    near = [n for n in notes if "barely longer than the merge distance" in n]
    assert len(near) == 1 and p.n_vertices == 5, notes
    assert "1 edge(s)" in near[0] and "at most 0.3 drawing units" in near[0]
    tol = float(re.search(r"tol=([0-9.]+)", near[0]).group(1))
    assert 0.3 < tol < 0.31
    q, notes = _quiet(pattern_from_drawing, d, tol=tol)
    assert q.n_vertices == 4 and not [n for n in notes if "barely longer" in n], notes
