"""Bounded, validating crease-pattern readers (issue 33 items 3 and 4)."""

import time
import warnings

import numpy as np
import pytest

from holofold.geometry import read_pattern
from holofold.geometry.bounded import MAX_PATTERN_ELEMENTS, path_data_problem
from holofold.geometry.errors import FormatError

SQ = (
    '<line x1="0" y1="0" x2="100" y2="0" stroke="#000"/>'
    '<line x1="100" y1="0" x2="100" y2="100" stroke="#000"/>'
    '<line x1="100" y1="100" x2="0" y2="100" stroke="#000"/>'
    '<line x1="0" y1="100" x2="0" y2="0" stroke="#000"/>'
)
HEAD = (
    '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
    'width="{w}" height="100mm" viewBox="0 0 100 100">'
)
DIAG = '<line x1="{x}" y1="0" x2="100" y2="100" stroke="#f00"/>'


def _svg(tmp_path, body, w="100mm", name="p.svg"):
    p = tmp_path / name
    p.write_text(HEAD.format(w=w) + SQ + body + "</svg>")
    return p


def _refused(path, match):
    t0 = time.perf_counter()
    with pytest.raises(FormatError, match=match):
        read_pattern(path)
    return time.perf_counter() - t0


def test_clean_svg_still_reads(tmp_path):
    p = read_pattern(_svg(tmp_path, DIAG.format(x=0)))
    assert p.n_faces == 2


@pytest.mark.parametrize("x", ["nan", "inf", "-Infinity", "NaN"])
def test_svg_non_finite_coordinate_refused(tmp_path, x):
    _refused(_svg(tmp_path, DIAG.format(x=x)), "not a finite number")


@pytest.mark.parametrize("w", ["100km", "100%", "100furlong"])
def test_svg_root_size_in_unknown_unit_refused(tmp_path, w):
    _refused(_svg(tmp_path, DIAG.format(x=0), w=w), "not a length")


def test_svg_malformed_crease_path_refused(tmp_path):
    _refused(_svg(tmp_path, '<path d="M 0 0 L 100 Q" stroke="#f00"/>'), "path data")


def test_path_data_checker():
    for good in ["M0,0L10,10z", "M 0 0 L 1 2 3 4 Z", "M0 0 h10v10H0Z", "M1e-3-2.5.5.5",
                 "M 0 0 A 5 5 0 0 1 10 10"]:  # fmt: skip
        assert path_data_problem(good) is None, good
    for bad in ["M 0 0 L 100 Q", "m 0 0 l 1", "M 0 0 L 1 x", "0 0 L 1 1"]:
        assert path_data_problem(bad) is not None, bad


def test_html_named_svg_refused(tmp_path):
    p = tmp_path / "page.svg"
    p.write_text("<html><body>hi</body></html>")
    _refused(p, "root element is not <svg>")


def test_use_doubling_bomb_refused_fast(tmp_path):
    body = '<defs><line id="l0" x1="0" y1="0" x2="1" y2="1" stroke="#f00"/>'
    for i in range(1, 26):
        body += f'<g id="l{i}"><use xlink:href="#l{i - 1}"/><use xlink:href="#l{i - 1}"/></g>'
    body += '</defs><use xlink:href="#l25"/>'
    _refused(_svg(tmp_path, body), f"at most {MAX_PATTERN_ELEMENTS:,}")


def test_use_cycle_refused(tmp_path):
    body = '<g id="a"><use xlink:href="#b"/></g><g id="b"><use xlink:href="#a"/></g>'
    _refused(_svg(tmp_path, body), "reference cycle")


def _dxf_bomb(path, levels=30):
    d = ["0", "SECTION", "2", "BLOCKS", "0", "BLOCK", "2", "B0", "0", "LINE", "8", "0",
         "10", "0", "20", "0", "11", "1", "21", "1", "0", "ENDBLK"]  # fmt: skip
    for i in range(1, levels + 1):
        d += ["0", "BLOCK", "2", f"B{i}", "0", "INSERT", "2", f"B{i - 1}", "0", "INSERT", "2",
              f"B{i - 1}", "0", "ENDBLK"]  # fmt: skip
    d += ["0", "ENDSEC", "0", "SECTION", "2", "ENTITIES", "0", "INSERT", "2", f"B{levels}",
          "0", "ENDSEC", "0", "EOF"]  # fmt: skip
    path.write_text("\n".join(d) + "\n")
    return path


def test_dxf_insert_doubling_bomb_refused(tmp_path):
    _refused(_dxf_bomb(tmp_path / "bomb.dxf"), "block INSERTs are expanded")


def test_long_cp_refused_and_content_never_quoted(tmp_path):
    p = tmp_path / "long.cp"
    p.write_text("".join(f"2 {i} 0 {i} 1\n" for i in range(MAX_PATTERN_ELEMENTS + 5)))
    _refused(p, "lines")
    secret = tmp_path / "shadow.cp"
    secret.write_text("root:$6$secretsalt$hash:19000:0:99999:7:::\n")
    with pytest.raises(FormatError) as err:
        read_pattern(secret)
    assert "secretsalt" not in str(err.value) and "root" not in str(err.value)


def test_lock_never_opened_through_a_symlink(tmp_path):
    from holofold.design.database.folder_lock import LOCK_NAME, folder_lock

    victim = tmp_path / "victim"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    (out / LOCK_NAME).symlink_to(victim)
    with pytest.raises(OSError, match="symbolic link"), folder_lock(out):
        pass
    assert victim.read_text() == "precious"


def test_no_write_through_a_linked_subfolder(tmp_path):
    from holofold.design.database.folder_lock import LOCK_NAME
    from holofold.geometry.outputs import write_text

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / LOCK_NAME).write_text("{}")
    (out / "chunks").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(OSError, match="symbolic link"):
        write_text(out / "chunks" / "part-0.txt", "x")
    assert list(elsewhere.iterdir()) == []


@pytest.mark.processes
def test_outputs_bytes_equal_across_processes():
    """Processes with different string hashes write the same DXF, SVG, FOLD, STL, OBJ and PLY.

    Seeds 4 and 7 swapped ezdxf's LAYOUT and ACDBPLACEHOLDER classes before they were
    registered in sorted order (geometry/dxf.py), so these runs differed at byte 7234.
    """
    import os
    import subprocess
    import sys

    code = (
        "import math,sys,hashlib; import holofold.geometry as g; "
        "from holofold.geometry.mesh import export_mesh; "
        "p = g.miura_sheet(3, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=1.0); "
        "out = [g.export_dxf(p), g.export_dxf(p, profile='laser'), g.export_svg(p), "
        "g.export_fold(p)] + [export_mesh(g.folded_mesh(p), t) for t in ('stl', 'obj', 'ply')]; "
        "b = [o if isinstance(o, bytes) else o.encode() for o in out]; "
        "print(' '.join(f'{len(x)}:{hashlib.sha256(x).hexdigest()}' for x in b))"
    )
    runs = []
    for seed in ("0", "4", "7"):
        env = dict(os.environ, PYTHONHASHSEED=seed)
        runs.append(subprocess.run([sys.executable, "-c", code], capture_output=True, check=True,
                                   timeout=120, env=env).stdout.decode().split())  # fmt: skip
    sizes = [int(h.split(":")[0]) for h in runs[0]]
    assert len(sizes) == 7 and min(sizes) > 900, sizes  # the PLY: 972 bytes (no trimesh comment)
    assert runs[1] == runs[0] and runs[2] == runs[0]


def test_fold_crease_across_faces_is_refused(tmp_path):
    """A mountain drawn across faces with no vertex at the crossings was ignored (a side of no
    face, so no hinge) and the pattern 'folded rigidly'; now refused with one line."""
    import json
    import math

    import holofold.geometry as g

    p = g.miura_sheet(2, 2, a=0.02, b=0.025, gamma=math.radians(60), ext=1.0)
    d = json.loads(g.export(p, tmp_path / "clean.fold").read_text())
    n = len(d["vertices_coords"])
    (x0, y0), (x1, y1) = np.min(p.flat, axis=0), np.max(p.flat, axis=0)
    dim = len(d["vertices_coords"][0])
    ends = [[x0 + 1e-3, 0.51 * (y0 + y1), 0.0], [x1 - 1e-3, 0.49 * (y0 + y1), 0.0]]
    d["vertices_coords"] += [v[:dim] for v in ends]
    for key in [k for k in d if k.startswith("edges_")]:
        d[key].append([n, n + 1] if key == "edges_vertices" else d[key][-1])
    d["edges_assignment"][-1] = "M"
    (tmp_path / "cross.fold").write_text(json.dumps(d))
    assert g.read_pattern(tmp_path / "clean.fold").n_edges == len(d["edges_vertices"]) - 1
    last = len(d["edges_vertices"]) - 1
    with pytest.raises(FormatError, match=rf"1 crease\(s\) \(edge {last}, M\) on no face side"):
        g.read_pattern(tmp_path / "cross.fold")


def test_obj_cut_at_a_line_end_is_said(tmp_path):
    """An OBJ cut at 90 % at a line end is a valid OBJ with fewer faces; the vertices left in
    no triangle are said (it was fitted without a word)."""
    import trimesh

    from holofold.geometry.mesh_reader import MeshWarning, read_mesh

    m = trimesh.creation.icosphere(3, radius=50.0)
    data = trimesh.exchange.obj.export_obj(m).encode()
    (tmp_path / "whole.obj").write_bytes(data)
    k = data.rfind(b"\n", 0, int(0.9 * len(data))) + 1
    (tmp_path / "cut.obj").write_bytes(data[:k])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        V, F = read_mesh(tmp_path / "whole.obj")
    assert (len(V), len(F)) == (642, 1280)
    with pytest.warns(MeshWarning, match=r"'cut.obj': \d+ of 642 vertices are in no triangle"):
        V, F = read_mesh(tmp_path / "cut.obj")
    assert 0 < len(F) < 1280


@pytest.mark.parametrize("t", [1e-6, 1e-9])
def test_kept_fraction_of_thin_slabs_is_at_most_one(t):
    """Bevels only remove material: a 1 nm slab said '110 % of the slabs kept'. The loss is
    proportional to t (a bevel removes t^2 per crease length), so a thin slab keeps ~100 %."""
    import math

    import holofold.geometry as g
    from holofold.geometry.thick import thick_panels

    p = g.miura_sheet(4, 4, a=0.02139, b=0.025, gamma=math.radians(60), ext=0.7)
    kept = thick_panels(p, t, 0.0, "tapered").kept
    loss_1mm = 1.0 - thick_panels(p, 1e-3, 0.0, "tapered").kept
    assert 0.02 < loss_1mm < 0.04
    assert 1.0 - 2 * loss_1mm * t / 1e-3 <= kept <= 1.0


def test_full_disk_names_the_file(tmp_path):
    """A write that fails on a full disk (ENOSPC on the open file) names the file it was
    writing, and leaves neither it nor a temporary file behind."""
    import errno
    import os

    from holofold.geometry.outputs import atomic_write

    def full(tmp):
        with open(tmp, "w") as fh:
            fh.write("x")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    target = tmp_path / "pattern.svg"
    with pytest.raises(OSError, match=r"cannot write .*pattern\.svg: No space left") as err:
        atomic_write(target, full)
    assert err.value.errno == errno.ENOSPC and "\n" not in str(err.value)
    assert list(tmp_path.iterdir()) == []
