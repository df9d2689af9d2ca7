"""The last mile for every kind (issue 34): the printable part fitted on the bed and cut into
pieces that each fit and are one watertight body, the 3D view of the pattern and surface kinds,
buildable thickness chosen, and the lines that say so."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from holofold.cli import main
from holofold.design.scenarios.files import read_scenario
from holofold.geometry import (
    Bed,
    choose_thickness,
    miura_sheet,
    print_time_text,
    segment_part,
    thick_name,
)
from holofold.geometry.thick import miura_path, path_overlap

ROOT = Path(__file__).resolve().parents[1]
SHELL = ROOT / "examples" / "my_shell.toml"
SHELL_ROW = {"m": 6.0, "n": 6.0, "tpanel": 2e-3, "tcrease": 0.45e-3, "W": 2e-3, "ext": 0.7,
             "coverage": 0.825}  # fmt: skip
OS = Path(__file__).parent / "data" / "origami-simulator"


def _pieces_ok(folder: Path, bed_mm: tuple[float, float]) -> list:
    """Every segment_NN.stl in ``folder``: lying on the bed (z from 0), inside it, one watertight
    body; their meshes."""
    out = []
    for f in sorted(folder.glob("segment_*.stl")):
        m = trimesh.load_mesh(f)
        lo, hi = m.bounds
        assert lo == pytest.approx([0.0, 0.0, 0.0], abs=1e-6), f.name  # placed at the corner
        assert hi[0] <= bed_mm[0] + 1e-6 and hi[1] <= bed_mm[1] + 1e-6, (f.name, hi)
        assert m.is_watertight and m.body_count == 1, f.name
        out.append(m)
    return out


def test_print_time_in_hours_and_days():
    assert print_time_text(510.0) == "about 510 h (21 days)"
    assert print_time_text(30.0) == "about 30 h (1.2 days)"
    assert print_time_text(7.46) == "about 7.5 h"
    assert print_time_text(0.5) == "about 30 min"
    assert print_time_text(math.nan) == "unknown"


def test_the_surface_kind_part_is_cut_into_pieces_that_fit():
    """The shell's flat part (434 x 417 mm) on a 200 x 200 mm bed: pieces at panel boundaries,
    each inside the bed and one watertight body, their volumes the part's less the joints'
    clearance (under 3 %)."""
    from dataclasses import replace

    sc = read_scenario(SHELL)
    part = replace(sc.part(sc.complete(SHELL_ROW)), thick="centred")
    bed = Bed.parse("200x200")
    seg = segment_part(part.pattern, part.panel_thickness, part.crease_thickness,
                       part.crease_width, bed, panels=part.panels())  # fmt: skip
    assert seg.fits and not seg.whole.fits and len(seg.segments) >= 4
    for s in seg.segments:
        lo, hi = s.mesh.bounds
        assert hi[0] - lo[0] <= 0.2 + 1e-9 and hi[1] - lo[1] <= 0.2 + 1e-9
        assert s.mesh.is_watertight and s.mesh.body_count == 1
    whole = seg.whole.volume
    total = sum(s.mesh.volume for s in seg.segments)
    assert 0.97 * whole < total < whole
    # every panel is in some piece
    assert set(np.concatenate([s.panels for s in seg.segments])) == set(range(part.pattern.n_faces))


def test_offset_panels_are_cut_hinge_face_down():
    """An offset-panel Miura part (the material above the hinge face) cut for a small bed: the
    pieces are the thick_printable part's (volumes add up) and lie on the hinge face."""
    from holofold.design.loop.buildability import PrintablePart

    sheet = miura_sheet(8, 8, 0.03, 0.03, math.radians(70), 0.5)
    part = PrintablePart(sheet, 2e-3, 0.5e-3, 2e-3, thick="offset")
    panels = part.panels()
    assert path_overlap([*miura_path(sheet, 10), sheet], panels).volume.max() == 0.0
    seg = segment_part(sheet, 2e-3, 0.5e-3, 2e-3, Bed.parse("200x200"), panels=panels)
    assert seg.fits and len(seg.segments) >= 2
    total = sum(s.mesh.volume for s in seg.segments)
    assert 0.97 * seg.whole.volume < total < seg.whole.volume
    for s in seg.segments:  # each lies on its hinge face: the lowest layer is its widest
        m = s.mesh
        down = m.area_faces[m.face_normals[:, 2] < -0.99].sum()
        up = m.area_faces[m.face_normals[:, 2] > 0.99].sum()
        assert down >= up


def test_choose_thickness_keeps_the_first_technique_that_folds_clear():
    """A Miura sheet folded to ext 0.5 with 2 mm panels and 2 mm hinges: centred panels
    overlap, offset ones fold from flat without overlap (the offset technique's promise);
    with wide hinges the centred panels are kept."""
    sheet = miura_sheet(4, 4, 0.02, 0.02, math.radians(70), 0.5)
    way = miura_path(sheet, 6)[:-1]
    got = choose_thickness(sheet, 2e-3, 2e-3, path=way)
    assert got.technique == "offset" and got.tried == ("centred", "offset")
    assert got.overlap == 0.0 and thick_name(got.code) == "offset"
    fixed = choose_thickness(sheet, 2e-3, 2e-3, path=way, thick="centred")
    assert fixed.technique == "centred" and fixed.overlap > 1e-12
    assert got.clearance == pytest.approx(fixed.clearance - 2e-3, abs=1e-12)
    wide = choose_thickness(sheet, 0.5e-3, 6e-3, path=way)
    assert wide.technique == "centred" and wide.overlap <= 1e-12
    with pytest.raises(ValueError, match="thick = 'sideways'"):
        choose_thickness(sheet, 2e-3, 2e-3, thick="sideways")
    with pytest.raises(ValueError, match="no technique code"):
        thick_name(7)


def test_the_surface_view_shows_the_shell_its_target_and_loads():
    sc = read_scenario(SHELL)
    row = sc.complete(SHELL_ROW)
    view = sc.view(row)
    flat, folded = view.frames
    assert np.all(flat[:, 2] == 0.0)
    assert view.labels[0] == "flat" and view.curve_name == "target surface"
    target = sc.shape.args[0].target
    # the grid lies on the surface (its chart; the STL's facets are within 0.02 mm of it)
    assert np.abs(target.distance(view.curve)).max() < 2e-5
    assert len(view.loads) == 4 and all(ld.direction == (0.0, 0.0, -1.0) for ld in view.loads)
    assert len(view.supports) > 0
    fit = sc.shape(row)
    assert np.allclose(folded, fit.coords)
    assert len(view.triangles()) == 2 * 36


def test_the_pattern_view_folds_from_flat(tmp_path):
    from test_simulate_pattern import SCENARIO

    shutil.copy(OS / "waterbombBase.svg", tmp_path / "wb.svg")
    (tmp_path / "wb.toml").write_text(SCENARIO, encoding="utf-8")
    sc = read_scenario(tmp_path / "wb.toml")
    row = sc.complete({"tpanel": 1e-3, "tcrease": 0.3e-3, "W": 1e-3, "fold": 0.5, "scale": 1.0})
    view = sc.view(row)
    assert view.labels[0] == "flat" and view.labels[-1] == "fold 50%"
    assert np.all(view.frames[0][:, 2] == 0.0) and np.ptp(view.frames[-1][:, 2]) > 1e-3
    x = view.frames[0][:, 0]
    assert np.allclose(x[view.supports], x.min()) and np.allclose(
        x[[ld.vertex for ld in view.loads]], x.max()
    )
    part = sc.part(row)
    assert part is not None and part.pattern.flat is not None


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::UserWarning")
def test_fit_surface_says_the_bed_and_writes_pieces(tmp_path, capsys):
    """`holofold fit --surface` with --printable: one line with extent, bed fit, pieces and
    print time, and pieces that each fit the bed (the 434 x 417 mm dome part on 250 x 210)."""
    out = tmp_path / "dome"
    dome = str(ROOT / "examples/data/dome_r400mm.stl")
    code = main(["fit", "--surface", dome, "--units", "mm", "--cells", "6x6",
                 "--panel-thickness", "0.002", "--crease-width", "0.002", "--crease-thickness",
                 "0.0005", "--printable", "--no-check", "-o", str(out)])  # fmt: skip
    text = capsys.readouterr().out
    assert code == 0
    line = next(t for t in text.splitlines() if "printable.stl:" in t)
    assert (
        "does not fit the 250 x 210 mm bed whole: cut into" in line and "print time about" in line
    )
    summary = json.loads(text.strip().splitlines()[-1])
    fab = summary["fabrication"]
    assert fab["pieces"] >= 2 and fab["pieces"] == len(list((out / "segments").glob("*.stl")))
    assert max(fab["extent_m"][:2]) > 0.25
    _pieces_ok(out / "segments", (250.0, 210.0))
    assert (out / "segments" / "assembly.svg").is_file()


@pytest.mark.slow
def test_pattern_command_takes_a_bed_and_the_slicer_slices_the_pieces(tmp_path, capsys):
    """`holofold pattern miura ... --bed 200x200`: pieces within 200 x 200 mm, one watertight
    body each, and PrusaSlicer slices every one (10 layers of 0.2 mm for 2 mm panels)."""
    from test_real_clients import _slice

    exe = shutil.which("prusa-slicer") or shutil.which("slic3r")
    out = tmp_path / "m"
    code = main(["pattern", "miura", "--m", "8", "--n", "8", "--a", "0.03", "--b", "0.03",
                 "--gamma", "70", "--ext", "0.5", "--thickness", "0.002", "--crease-width",
                 "0.002", "--crease-thickness", "0.0005", "--printable", "--thick", "offset",
                 "--bed", "200x200", "-o", str(out)])  # fmt: skip
    text = capsys.readouterr().out
    assert code == 0 and "does not fit the 200 x 200 mm bed whole: cut into" in text
    meshes = _pieces_ok(out / "segments", (200.0, 200.0))
    n = int(text.split("cut into ")[1].split()[0])
    assert len(meshes) == n >= 2
    whole = trimesh.load_mesh(out / "printable.stl").volume
    assert 0.97 * whole < sum(m.volume for m in meshes) < whole
    if exe is None:
        pytest.skip("no slicer on PATH: apt-get install prusa-slicer")
    for f in sorted((out / "segments").glob("segment_*.stl"))[:3]:
        layers, minutes, z = _slice([exe], f)
        assert layers == 10 and z[-1] == pytest.approx(2.0) and minutes


def _roof_solid(n: int = 21, thick: float = 4.0) -> trimesh.Trimesh:
    """A hyperbolic-paraboloid roof 300 x 300 mm, z = (x^2 - y^2) / 600 mm, thickened by
    ``thick`` mm downwards into a closed solid (what OpenSCAD exports), in mm."""
    x = np.linspace(-150.0, 150.0, n)
    X, Y = np.meshgrid(x, x)
    top = np.column_stack([X.ravel(), Y.ravel(), ((X**2 - Y**2) / 600.0).ravel()])
    quads = [(i * n + j, i * n + j + 1, i * n + j + n + 1, i * n + j + n)
             for i in range(n - 1) for j in range(n - 1)]  # fmt: skip
    tri = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    k = len(top)
    faces = [*tri.tolist(), *(tri[:, ::-1] + k).tolist()]
    idx = np.arange(k).reshape(n, n)
    ring = [*idx[0, :], *idx[1:, -1], *idx[-1, -2::-1], *idx[-2:0:-1, 0]]
    for a, b in zip(ring, ring[1:] + ring[:1], strict=True):
        faces += [[b, a, a + k], [b, a + k, b + k]]
    solid = trimesh.Trimesh(np.vstack([top, top - [0.0, 0.0, thick]]), np.array(faces))
    trimesh.repair.fix_normals(solid)
    return solid


def test_a_closed_cad_solid_gives_its_upper_skin(tmp_path):
    """A closed solid is read as its upward faces over the best-fit plane, said in one warning:
    the 800 triangles of the roof's top skin, the surface through the hypar's saddle point."""
    from holofold.fitting import read_surface

    solid = _roof_solid()
    assert solid.is_watertight
    path = tmp_path / "roof.stl"
    solid.export(path)
    with pytest.warns(UserWarning, match=r"closed solid: its 800 upward faces") as said:
        target = read_surface(path, "mm")
    assert len(said) == 1
    assert target.domain == pytest.approx((-0.15, 0.15, -0.15, 0.15), abs=1e-9)
    pts = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.1 * 0.1 / 0.6], [0.0, 0.1, -0.1 * 0.1 / 0.6]])
    assert np.abs(target.distance(pts)).max() < 2e-4  # on the top skin (chords of 15 mm)


def test_margins_rules_and_sources_say_units_names_and_relative_paths():
    from holofold.design.report.page import _condition_text
    from holofold.design.rules.text import box_text
    from holofold.design.scenarios.base import Column
    from holofold.design.scenarios.files import shipped_scenarios
    from holofold.design.scenarios.sheet import SHEET_FEATURES

    cols = {"rms_error": Column("rms_error", "m", "", display="mm"),
            "k": Column("k", "N/m", "")}  # fmt: skip
    nb = "\u00a0"
    assert (
        _condition_text("rms_error < 5e-05", ("rms_error",), cols) == f"rms_error &lt; 0.05{nb}mm"
    )
    assert (
        _condition_text("3000 < k < 4000", ("k",), cols) == f"3000{nb}N/m &lt; k &lt; 4000{nb}N/m"
    )
    pattern = SHEET_FEATURES[0]
    text = box_text([(2.0,)], ["pattern"], categorical=("pattern",), columns={"pattern": pattern})
    assert text == "pattern = 2 (TMP)" and pattern.format(1.0) == "1 (Miura-ori)"
    with pytest.raises(ValueError, match="1 names for 2 choices"):
        Column("c", "-", choices=(1.0, 2.0), names=("a",))
    sc = read_scenario(shipped_scenarios()["arch"])
    assert sc.source == "holofold/design/scenarios/shipped/arch.toml"
