"""Euclidean distance (metres) from any world point to the nearest obstacle.

Obstacle cells are closed squares and everything outside the map is an
obstacle, so the map border is a wall. The field is sampled on a lattice of
points spaced ``res / subdivision`` apart that contains every cell corner. At
such a lattice point the nearest obstacle point is either a cell corner or the
foot of a perpendicular onto a cell edge, and both are lattice points, so an
exact EDT of the lattice (Felzenszwalb & Huttenlocher, two 1-D passes) gives
exact distances there. Between lattice points the lookup is bilinear: with the
default spacing of 0.1 m it overestimates by at most ~0.015 m (next to a
corner) and underestimates by at most half the spacing (on ridges halfway
between two obstacles, the safe side). Maps too large for MAX_SAMPLES get a
coarser lattice (at worst one point per cell corner).

The field is 0 inside obstacle cells and outside the map (it is not signed).
``distance_at`` takes world points (the map's origin is subtracted); the compiled
``lookup`` takes points relative to the map's bottom-left corner (``origin``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from planner.maps.grid import Cell, GridMap

MAX_SPACING_M = 0.1
"""Largest lattice spacing chosen by default (finer for coarse cells)."""
MAX_SAMPLES = 4_000_000
"""Largest lattice chosen by default (16 MB of float32); huge maps get a coarser one."""


def choose_subdivision(grid: GridMap) -> int:
    """Lattice points per cell edge: spacing ≤ MAX_SPACING_M within the MAX_SAMPLES budget."""
    wanted = max(1, math.ceil(grid.resolution / MAX_SPACING_M - 1e-9))
    affordable = math.floor(math.sqrt(MAX_SAMPLES / (grid.width * grid.height)))
    return max(1, min(wanted, affordable))


@dataclass(frozen=True, eq=False)
class DistanceField:
    """A precomputed distance field; ``samples[j, i]`` is the distance at (i, j) * spacing."""

    grid: GridMap
    subdivision: int
    samples: np.ndarray

    @classmethod
    def from_grid(cls, grid: GridMap, subdivision: int | None = None) -> DistanceField:
        """Build the field of ``grid`` with ``subdivision`` lattice steps per cell edge."""
        s = choose_subdivision(grid) if subdivision is None else int(subdivision)
        if s < 1:
            raise ValueError(f"subdivision must be a positive integer, got {subdivision}")
        squared = squared_edt(_obstacle_lattice(grid.blocked, s))
        samples = (np.sqrt(squared) * (grid.resolution / s)).astype(np.float32)
        samples.setflags(write=False)
        return cls(grid, s, samples)

    @classmethod
    def for_grid(cls, grid: GridMap) -> DistanceField:
        """The field of ``grid`` at its chosen subdivision, built on first use and then
        kept with the map: every AGV of a run (and the world) shares one, and AGV processes
        forked after the warm-up share its pages."""
        return grid.derived(("distance_field",), lambda: cls.from_grid(grid))

    @property
    def origin(self) -> tuple[float, float]:
        """World position of the map's bottom-left corner (the lattice's point (0, 0))."""
        return self.grid.origin

    @property
    def spacing(self) -> float:
        """Distance between neighbouring lattice points, metres."""
        return self.grid.resolution / self.subdivision

    def with_blocked(self, cells: list[Cell]) -> DistanceField:
        """The field of the same map with extra obstacle cells (col, row), same lattice."""
        return DistanceField.from_grid(self.grid.with_blocked(cells), self.subdivision)

    def distance_at(self, xs, ys) -> np.ndarray:
        """Distance at world points; arrays of any (broadcastable) shape, scalars too."""
        xs, ys = np.broadcast_arrays(np.asarray(xs, dtype=float), np.asarray(ys, dtype=float))
        ox, oy = self.grid.origin
        if ox or oy:
            xs, ys = xs - ox, ys - oy
        out = np.empty(xs.shape)
        _lookup_many(self.samples, 1.0 / self.spacing, xs.ravel(), ys.ravel(), out.reshape(-1))
        return out

    def distance_at_point(self, x: float, y: float) -> float:
        """``distance_at`` of one world point, without the arrays (a control cycle asks for
        a few such points: numpy's broadcasting took longer than the lookup)."""
        ox, oy = self.grid.origin
        return lookup(self.samples, 1.0 / self.spacing, float(x) - ox, float(y) - oy)


def _obstacle_lattice(blocked: np.ndarray, s: int) -> np.ndarray:
    """(H*s+1, W*s+1) bool: lattice points on or inside an obstacle square or the border."""
    fine = np.ones((blocked.shape[0] * s + 2, blocked.shape[1] * s + 2), dtype=bool)
    fine[1:-1, 1:-1] = np.repeat(np.repeat(blocked, s, axis=0), s, axis=1)
    # lattice point (i, j) is the shared corner of fine pixels (i-1..i, j-1..j)
    return fine[:-1, :-1] | fine[1:, :-1] | fine[:-1, 1:] | fine[1:, 1:]


@numba.njit(cache=True)
def edt_1d(f, out, v, z):
    """Lower envelope of parabolas (q - p)^2 + f[p] (Felzenszwalb & Huttenlocher 2012)."""
    n = f.shape[0]
    k = 0
    v[0] = 0
    z[0] = -np.inf
    z[1] = np.inf
    for q in range(1, n):
        while True:
            p = v[k]
            cross = ((f[q] + q * q) - (f[p] + p * p)) / (2.0 * (q - p))
            if cross > z[k]:
                break
            k -= 1
        k += 1
        v[k] = q
        z[k] = cross
        z[k + 1] = np.inf
    k = 0
    for q in range(n):
        while z[k + 1] < q:
            k += 1
        p = v[k]
        out[q] = (q - p) * (q - p) + f[p]


@numba.njit(cache=True)
def squared_edt(obstacle):
    """Squared distance, in lattice steps, to the nearest True point (one must exist per column)."""
    rows, cols = obstacle.shape
    n = max(rows, cols)
    big = 1e20  # "no obstacle yet": finite so that the envelope arithmetic stays exact
    f = np.empty(n)
    line = np.empty(n)
    v = np.empty(n, dtype=np.int64)
    z = np.empty(n + 1)
    result = np.empty((rows, cols))
    for i in range(cols):
        for j in range(rows):
            f[j] = 0.0 if obstacle[j, i] else big
        edt_1d(f[:rows], line[:rows], v, z)
        result[:, i] = line[:rows]
    for j in range(rows):
        f[:cols] = result[j, :]
        edt_1d(f[:cols], line[:cols], v, z)
        result[j, :] = line[:cols]
    return result


@numba.njit(cache=True)
def lookup(samples, inv_spacing, x, y):
    """Bilinear lookup at one point relative to the map's bottom-left corner; outside the
    map (or NaN) gives the border's 0."""
    u = min(max(x * inv_spacing, 0.0), samples.shape[1] - 1.0)
    w = min(max(y * inv_spacing, 0.0), samples.shape[0] - 1.0)
    if not (u == u and w == w):  # NaN
        return 0.0
    i = min(int(u), samples.shape[1] - 2)
    j = min(int(w), samples.shape[0] - 2)
    fu = u - i
    fw = w - j
    bottom = samples[j, i] * (1.0 - fu) + samples[j, i + 1] * fu
    top = samples[j + 1, i] * (1.0 - fu) + samples[j + 1, i + 1] * fu
    return bottom * (1.0 - fw) + top * fw


@numba.njit(cache=True)
def _lookup_many(samples, inv_spacing, xs, ys, out):
    for n in range(xs.shape[0]):
        out[n] = lookup(samples, inv_spacing, xs[n], ys[n])
