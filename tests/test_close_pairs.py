"""close_pairs (the grid search that stands in for a k-d tree's query_pairs) against
scipy.spatial.cKDTree on the same points: the same pairs, exactly (integer sets)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from holofold.geometry.close_pairs import close_pairs


def _sorted(pairs):
    pairs = np.asarray(pairs, np.intp).reshape(-1, 2)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("n, r", [(300, 0.05), (2000, 0.01), (2000, 0.3)])
def test_the_pairs_of_a_kd_tree(dim, n, r):
    rng = np.random.default_rng(dim * n)
    p = rng.random((n, dim)) * [3.0, 1.0, 0.2][:dim] - 0.7
    p[: n // 5] = p[n // 5 : 2 * (n // 5)] + rng.normal(scale=r / 3, size=(n // 5, dim))
    got = _sorted(close_pairs(p, r))
    want = _sorted(cKDTree(p).query_pairs(r, output_type="ndarray"))
    assert len(want) > 0
    assert np.array_equal(got, want)
    assert (got[:, 0] < got[:, 1]).all()


def test_points_on_a_cell_border_and_at_exactly_r():
    """Points exactly ``r`` apart pair (``<= r``, as query_pairs), across cell borders too."""
    p = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [3.5, 1.0], [0.0, 3.0]])
    assert _sorted(close_pairs(p, 1.0)).tolist() == [[0, 1], [1, 2], [2, 3]]


def test_few_points_and_a_tiny_radius():
    assert close_pairs(np.zeros((0, 2)), 1.0).shape == (0, 2)
    assert close_pairs(np.zeros((1, 3)), 1.0).shape == (0, 2)
    # a radius 1e-15 of the spread: more cells than int64 keys hold, the k-d tree answers
    p = np.array([[0.0, 0.0], [1e-16, 0.0], [10.0, 10.0]])
    assert _sorted(close_pairs(p, 1e-15)).tolist() == [[0, 1]]
