"""The world's compiled AGV gaps are numpy's N x N computation, bit for bit."""

from __future__ import annotations

import numpy as np

from fleet.runtime.agv_gaps import agv_gaps


def numpy_gaps(xs, ys, radii):
    """What ``World._check_contacts`` computed before: the reference."""
    gaps = np.hypot(xs[:, None] - xs, ys[:, None] - ys) - radii[:, None] - radii
    np.fill_diagonal(gaps, np.inf)
    pairs = sorted(zip(*np.nonzero(np.triu(gaps <= 0)), strict=True))
    return gaps.min(axis=1), [(int(i), int(j)) for i, j in pairs]


def test_the_gaps_and_contacts_are_numpys_bit_for_bit():
    rng = np.random.default_rng(0)
    touched = 0
    for n in [2, 3, 7, 50, 200] * 8:
        xs = rng.uniform(0, 8 if n < 50 else 30, n).round(rng.integers(1, 17))
        ys = rng.uniform(0, 8 if n < 50 else 30, n)
        radii = rng.choice([0.3, 0.25, 0.1 + 0.2, 0.45], n)
        if n > 2:  # exactly touching, and on top of each other
            xs[1], ys[1] = xs[0] + radii[0] + radii[1], ys[0]
            xs[2], ys[2] = xs[0], ys[0]
        least, pairs = agv_gaps(xs, ys, radii)
        want_least, want_pairs = numpy_gaps(xs, ys, radii)
        assert least.tobytes() == want_least.tobytes()
        assert sorted(map(tuple, pairs.tolist())) == want_pairs
        touched += len(want_pairs)
    assert touched > 40  # contacts were compared, not only gaps


def test_a_lone_agv_has_no_gap():
    least, pairs = agv_gaps(np.array([1.0]), np.array([2.0]), np.array([0.3]))
    assert least.tolist() == [np.inf] and pairs.shape == (0, 2)
