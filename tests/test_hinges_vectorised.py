"""The array-speed builders (issue 37) against the per-corner, per-crease loops they replace.

``_compliant_reference.reference_build_compliant`` is ``build_compliant`` as it was before
(a verbatim copy of its loops); every array of the structure must agree to 1e-12 relative to
its scale, and every index array exactly, on patterns with quads, triangles, border creases,
varying widths and both corner-offset profiles.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _compliant_reference import reference_build_compliant

from holofold.geometry.miura import miura_sheet_paper
from holofold.geometry.pattern import CreasePattern
from holofold.mechanics.compat import PAPER, PHYSICAL
from holofold.mechanics.hinges import (
    PatternTopology,
    build_compliant,
    build_concentrated,
    concentrated_layout,
    pattern_topology,
)
from holofold.mechanics.structure import CreaseModel

MAT = dict(E_panel=2e9, E_crease=1e9, nu_panel=0.3, nu_crease=0.25)


def _four_vertex(z=0.1) -> CreasePattern:
    X = np.array([[i % 3, i // 3, 0.0] for i in range(9)])
    X[4, 2] = z
    faces = [np.array(f) - 1 for f in ([2, 5, 4, 1], [5, 2, 3, 6], [7, 4, 5, 8], [6, 9, 8, 5])]
    return CreasePattern.from_faces(X, faces)


def _triangulated(seed=3) -> CreasePattern:
    """A 4 x 3 grid of squares split into triangles, its vertices lifted at random."""
    rng = np.random.default_rng(seed)
    nx, ny = 5, 4
    X = np.array([[i, j, 0.0] for j in range(ny) for i in range(nx)], float)
    X[:, 2] = 0.05 * rng.standard_normal(len(X))
    faces = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i
            faces += [np.array([a, b, c]), np.array([a, c, d])] if (i + j) % 2 else [
                np.array([a, b, d]), np.array([b, c, d])]  # fmt: skip
    return CreasePattern.from_faces(X, faces)


def _patterns():
    yield "four-vertex", _four_vertex(), 0.1
    yield "miura 2x2", miura_sheet_paper(2, 2, 0.04, 1.1, 0.6), 2.5e-3
    yield "miura 5x3", miura_sheet_paper(5, 3, 0.04, 0.9, 0.4), 1e-3
    yield "triangulated", _triangulated(), 0.05
    gripper = pytest.importorskip("holofold.geometry.gripper")
    yield "miura gripper", gripper.miura_based_gripper(5e-3, 4e-3, 0.4).pattern, 2e-4
    yield "split gripper", gripper.splitted_miura_gripper(5e-3, 4e-3, 0.4).pattern, 2e-4


def _assert_same(a, b, where: str):
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, CreaseModel):
            _assert_same(x, y, f"{where}.{f.name}")
        elif isinstance(x, np.ndarray):
            assert x.shape == y.shape, f"{where}.{f.name}: {x.shape} != {y.shape}"
            if x.dtype.kind in "iub":
                np.testing.assert_array_equal(x, y, err_msg=f"{where}.{f.name}")
            else:
                scale = max(float(np.abs(y).max(initial=0.0)), 1e-300)
                np.testing.assert_allclose(
                    x, y, rtol=0, atol=1e-12 * scale, err_msg=f"{where}.{f.name}"
                )
        else:
            assert x == y, f"{where}.{f.name}"


@pytest.mark.parametrize("profile", [PAPER, PHYSICAL], ids=["paper", "physical"])
def test_compliant_matches_the_loop_builder(profile):
    n = 0
    for name, p, W in _patterns():
        rng = np.random.default_rng(len(name))
        widths = W * (0.5 + rng.random(p.n_edges))  # a width per crease
        for w in (W, widths):
            kw = dict(crease_width=w, crease_thickness=W / 4, panel_thickness=W, **MAT)
            got = build_compliant(p, profile=profile, diagonal_rate=3.0, **kw)
            ref = reference_build_compliant(p, profile=profile, diagonal_rate=3.0, **kw)
            _assert_same(got, ref, name)
            n += 1
    assert n >= 10


def test_compliant_offsets_moved_some_corners_and_not_others():
    """The comparison is not vacuous: crease corners move, border-only corners stay."""
    p = miura_sheet_paper(2, 2, 0.04, 1.1, 0.6)
    s = build_compliant(p, crease_width=2e-3, crease_thickness=1e-4, panel_thickness=1e-3, **MAT)
    t = pattern_topology(p)
    moved = np.linalg.norm(s.nodes[: t.n_corners] - p.coords[t.verts], axis=1)
    assert (moved > 1e-4).sum() > 0 and (moved < 1e-15).sum() == 4  # the 4 sheet corners


def test_topology_record_and_shared_layout():
    p = _four_vertex()
    t = pattern_topology(p)
    assert isinstance(t, PatternTopology) and pattern_topology(p) is t
    assert t.edge_corners.shape == (p.n_edges, 2)
    side_in = t.side[t.prv]
    for e in range(p.n_edges):  # the corners entering along each edge, ascending
        q = np.flatnonzero(side_in == e).tolist()
        assert t.edge_corners[e].tolist() == (q + [-1, -1])[:2]
    lay = concentrated_layout(p)
    s = build_concentrated(p, crease_width=0.1, crease_thickness=1e-3, panel_thickness=1e-2)
    assert s.bars is lay.bars and not lay.bars.flags.writeable
    with pytest.raises(ValueError):
        s.bars[0, 0] = 3  # shared by every structure of the pattern: read-only
