"""Sums and normalisation as numpy computes them, compiled: the choice stays bit for bit.

DWA divides each critic's term by its sum over the admissible samples (Eq. 10). Compiled,
the sum follows numpy's pairwise order (``pairwise_sum``), so a choice compiled is the
choice numpy's array expressions made.
"""

from __future__ import annotations

import numba
import numpy as np

_PAIRWISE_BLOCK = 128  # numpy's PW_BLOCKSIZE


@numba.njit(cache=True)
def _block_sum(values, start, count):
    """numpy's sum of one block (at most 128 values): eight running sums, combined in
    pairs, then the rest one by one (below 8 values, one by one from 0)."""
    if count < 8:
        total = 0.0
        for i in range(count):
            total += values[start + i]
        return total
    r = values[start : start + 8].copy()  # eight running sums
    i = 8
    while i < count - count % 8:
        for j in range(8):
            r[j] += values[start + i + j]
        i += 8
    total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < count:
        total += values[start + i]
        i += 1
    return total


@numba.njit(cache=True)
def pairwise_sum(values):
    """The sum of a 1-D float array as ``ndarray.sum`` computes it, bit for bit: numpy's
    ``pairwise_sum`` halves a run (at a multiple of 8) until it is a block of at most 128
    values, and adds each half's sum. Its recursion is walked here with a stack (a
    recursive compiled function crashed when loaded from numba's cache)."""
    frames = 64  # halving: deep enough for any array
    start = np.empty(frames, dtype=np.int64)
    count = np.empty(frames, dtype=np.int64)
    phase = np.zeros(frames, dtype=np.int64)  # 0: left half next, 1: right next, 2: add
    left = np.empty(frames)
    top, start[0], count[0] = 0, 0, values.size
    done = 0.0  # the sum of the run last finished
    while True:
        s, c = start[top], count[top]
        half = c // 2 - (c // 2) % 8
        if c <= _PAIRWISE_BLOCK:
            done = _block_sum(values, s, c)
        elif phase[top] < 2:
            if phase[top] == 1:
                left[top] = done
            phase[top] += 1
            start[top + 1] = s if phase[top] == 1 else s + half
            count[top + 1] = half if phase[top] == 1 else c - half
            phase[top + 1] = 0
            top += 1
            continue
        else:
            done = left[top] + done
        top -= 1
        if top < 0:
            return 0.0 + done


@numba.njit(cache=True)
def normalised(term):
    """``term`` divided by its sum (all zeros when the sum is zero)."""
    total = pairwise_sum(term)
    out = np.zeros(term.size)
    if total > 0:
        for i in range(term.size):
            out[i] = term[i] / total
    return out
