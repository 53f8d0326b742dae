"""The gaps between every two AGVs at a tick, compiled: the world's serial phase.

The world checked them as numpy arrays of N x N (hypot, two subtractions, the diagonal,
a row minimum, a mask and its upper triangle): with 200 AGVs eight temporaries of 40,000
values, several milliseconds of every tick during which every AGV waits. One loop over
the pairs computes each distance once and the same values bit for bit: numpy's hypot and
numba's are both the C library's; ``xi - xj`` is exactly ``-(xj - xi)``, and hypot takes
absolute values; each gap is subtracted in numpy's order, (distance - r_i) - r_j for the
row of AGV i.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def agv_gaps(xs, ys, radii):
    """(N,) each AGV's least gap to another AGV (inf for a lone AGV); (M, 2) the pairs
    (i < j) in contact: the gap of row i, (distance - r_i) - r_j, at most 0."""
    n = xs.size
    least = np.full(n, np.inf)
    touching = []
    for i in range(n):
        for j in range(i + 1, n):
            distance = math.hypot(xs[i] - xs[j], ys[i] - ys[j])
            gap_i = distance - radii[i] - radii[j]
            gap_j = distance - radii[j] - radii[i]
            least[i] = min(least[i], gap_i)
            least[j] = min(least[j], gap_j)
            if gap_i <= 0.0:
                touching.append((i, j))
    pairs = np.empty((len(touching), 2), dtype=np.int64)
    for k, (i, j) in enumerate(touching):
        pairs[k, 0], pairs[k, 1] = i, j
    return least, pairs
