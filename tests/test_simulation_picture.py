"""picture.png drawn with Pillow (mechanics/_picture.py; issue 37 item 4): the crease pattern in
its assignment colours on the left, the folded panels in viridis by their bend on the right."""

import numpy as np
from PIL import Image

from holofold.mechanics._picture import H, W, nice_ticks, simulation_picture, viridis

COLOURS = {"M": "#e41a1c", "V": "#1f5fd6", "B": "#000000", "C": "#2ca02c", "F": "#999999",
           "U": "#bbbbbb", "J": "#dddddd"}  # fmt: skip


def test_viridis_ends_and_ticks():
    ends = [[68, 1, 84], [253, 231, 37]]
    np.testing.assert_array_equal(viridis([0.0, 1.0, -1.0, 2.0]), ends + ends)
    np.testing.assert_allclose(nice_ticks(0.0, 8.38, 7), [0, 2, 4, 6, 8])
    np.testing.assert_allclose(nice_ticks(-0.3, 0.3, 7), [-0.3, -0.2, -0.1, 0, 0.1, 0.2, 0.3],
                               atol=1e-12)  # fmt: skip


def _count(img: np.ndarray, rgb, tol=40) -> int:
    return int((np.abs(img.astype(int) - np.array(rgb)).sum(axis=-1) < tol).sum())


def test_picture_shows_pattern_and_folded_panels(tmp_path):
    # two squares sharing a valley crease, folded 90 deg about it; one panel bends 6 deg
    flat = np.array([[0, 0], [100, 0], [200, 0], [0, 100], [100, 100], [200, 100]], float)
    edges = np.array([[0, 1], [1, 2], [3, 4], [4, 5], [0, 3], [2, 5], [1, 4]])
    assignment = np.array(["B", "B", "B", "B", "B", "B", "V"])
    folded = np.array([[0, 0, 0], [100, 0, 0], [100, 0, 100], [0, 100, 0], [100, 100, 0],
                       [100, 100, 100]], float)  # fmt: skip
    faces = [np.array([0, 1, 4, 3]), np.array([1, 2, 5, 4])]
    path = tmp_path / "p.png"
    simulation_picture(path, flat_xy=flat, edges=edges, assignment=assignment, colours=COLOURS,
                       folded=folded, faces=faces, bend_deg=np.array([0.0, 6.0]), reached=0.5,
                       title="a status line")  # fmt: skip
    img = np.asarray(Image.open(path).convert("RGB"))
    assert img.shape == (H, W, 3)
    left, right = img[:, : W // 2], img[:, W // 2 : 1190]  # the right half without the colour bar
    px = left.astype(int)
    blue = (px[..., 2] - px[..., 0] > 60).sum()  # the valley crease (anti-aliased)
    red = (px[..., 0] - px[..., 2] > 60).sum()
    assert blue > 100 and red == 0  # no mountain in this pattern
    assert _count(right, viridis([0.0])[0], 10) > 2000  # the flat panel: viridis(0)
    assert _count(right, viridis([1.0])[0], 10) > 2000  # the bent one: the top of the scale
