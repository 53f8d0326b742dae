"""The compiled hypot and remainder equal CPython's, bit for bit (planner.core.cpython_math)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.core.cpython_math import hypot, remainder

SPECIAL = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1e-310, 1.0, -1.0, 1e308]


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or (
        a == b and math.copysign(1, a) == math.copysign(1, b)
    )


def _pairs():
    rng = np.random.default_rng(11)
    x = rng.normal(0.0, 5.0, 60_000) * rng.choice([1e-300, 1e-9, 1.0, 1e9, 1e300], 60_000)
    y = rng.normal(0.0, 5.0, 60_000) * rng.choice([1e-300, 1e-9, 1.0, 1e9, 1e300], 60_000)
    return [*zip(x.tolist(), y.tolist(), strict=True)]


def test_hypot_is_cpythons():
    specials = [math.inf, -math.inf, math.nan, *SPECIAL]
    cases = _pairs() + [(a, b) for a in specials for b in specials]
    differ = [(a, b) for a, b in cases if not _same(hypot(a, b), math.hypot(a, b))]
    assert differ == []
    # the C library's hypot (what numba gives) is not: the test can tell them apart
    assert any(np.hypot(a, b) != math.hypot(a, b) for a, b in cases[:5000])


def test_remainder_is_cpythons():
    cases = [(x, y) for x, y in _pairs() if y != 0.0] + [(x, math.tau) for x, _ in _pairs()]
    cases += [(a, b) for a in [*SPECIAL, math.nan] for b in [*SPECIAL, math.inf, math.nan] if b]
    cases += [(2.5, 1.0), (3.5, 1.0), (-2.5, 1.0), (1.5 * math.tau, math.tau)]  # ties: even
    differ = [(x, y) for x, y in cases if not _same(remainder(x, y), math.remainder(x, y))]
    assert differ == []


@pytest.mark.parametrize("x, y", [(math.inf, 1.0), (1.0, 0.0)])
def test_remainder_refuses_what_cpython_refuses(x, y):
    with pytest.raises(ValueError):
        math.remainder(x, y)
    with pytest.raises(ValueError):
        remainder(x, y)
