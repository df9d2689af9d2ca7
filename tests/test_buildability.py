"""The part to print on the designer's bed: its fit, its pieces when too large, the advice."""

from __future__ import annotations

import pytest
import trimesh

from holofold.design import DEFAULT_BED, Bed, PartFit, get_scenario, parse_bed, part_fit

ROW = {"m": 8, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "offset": 0.2, "stripeWidth": 0.02,
       "extrude": 0.1}  # fmt: skip


def _box(tmp_path, x, y, z, name="part.stl"):
    """A box of x by y by z mm lying on z = 0, written as an STL in mm."""
    mesh = trimesh.creation.box((x, y, z))
    mesh.apply_translation(-mesh.bounds[0])
    path = tmp_path / name
    mesh.export(path)
    return path


def test_bed_parsing_and_the_default():
    assert parse_bed("250x210") == DEFAULT_BED
    assert parse_bed(" 300 X 300 mm").width == pytest.approx(0.3)
    for bad in ("250 by 210", "250", "x210", "0.25x0.21"):
        with pytest.raises(ValueError, match="--bed"):
            parse_bed(bad)


def test_a_part_that_fits_and_one_that_cannot_be_cut(tmp_path):
    ok = part_fit(_box(tmp_path, 100, 50, 3), root=tmp_path)
    assert ok.fits and ok.pieces == 1 and ok.extent == pytest.approx((0.1, 0.05, 0.003))
    assert ok.file == "part.stl" and ok.volume == pytest.approx(100 * 50 * 3 * 1e-9)
    assert ok.advice == "It fits the 250 x 210 mm bed as it lies."
    diag = part_fit(_box(tmp_path, 300, 20, 3, "diag.stl"))  # only along the bed's diagonal
    assert diag.fits and 0 < abs(diag.turn) < 90 and "turned by" in diag.advice
    big = part_fit(_box(tmp_path, 1619, 173, 3, "big.stl"))  # no pattern: nothing to cut at
    assert not big.fits and big.pieces == 0 and big.problem
    assert "at least 1619 x 173 mm" in big.advice and "Do not scale" in big.advice
    assert PartFit.from_json(big.to_json()) == big


def test_a_strip_too_long_for_the_bed_is_printed_in_pieces(tmp_path):
    """The arch's printable part (about 6.6 m long) is cut at panel boundaries into pieces
    that each fit the bed; their files and the assembly sheet are written beside the part."""
    sc = get_scenario("arch")
    fab = sc.write_files(ROW, tmp_path / "files", units="mm")
    part = sc.part(ROW)
    assert part.pattern.flat is not None and part.crease_width == 2e-3
    small = Bed(0.6, 0.5)  # a large-format bed keeps the test short
    got = part_fit(fab["printable"].path, small, root=tmp_path, part=part)
    assert not got.fits and got.pieces > 1 and got.segments == "files/segments"
    pieces = sorted((tmp_path / "files" / "segments").glob("segment_*.stl"))
    assert len(pieces) == got.pieces and (tmp_path / "files/segments/assembly.svg").is_file()
    for p in pieces:  # each piece lies on the bed and fits it
        lo, hi = trimesh.load_mesh(p).bounds
        assert lo[2] == pytest.approx(0, abs=1e-6) and hi[0] <= 600 + 1e-6 and hi[1] <= 500 + 1e-6
    assert f"into {got.pieces} pieces" in got.advice and "assembly.svg" in got.advice
    # a rerun on the same folder leaves no piece of the earlier run (validation/last_mile's arch
    # kept segment_14 and 15 of a 15-piece design beside the 13 pieces of the next one)
    seg = tmp_path / "files" / "segments"
    (seg / "segment_99.stl").write_bytes(pieces[0].read_bytes())
    again = part_fit(fab["printable"].path, small, root=tmp_path, part=part)
    assert sorted(seg.glob("segment_*.stl")) == pieces and again.pieces == got.pieces
    whole = part_fit(fab["printable"].path, Bed(8.0, 8.0), root=tmp_path, part=part)
    assert whole.fits and whole.pieces == 1 and not seg.exists()  # no pieces left to print


def test_a_film_is_cut_not_printed(tmp_path):
    film = part_fit(_box(tmp_path, 12, 3, 0.02, "film.stl"))
    assert film.film and film.fits and film.extent_text() == "12 x 3 x 0.02 mm"
    assert "cut it from a sheet" in film.advice and "do not print" in film.advice
    assert film.to_json()["print_class"] == "not printed: a film"
    assert not part_fit(_box(tmp_path, 12, 3, 0.2, "plate.stl")).film
