"""CPython's ``math.hypot`` and ``math.remainder`` for compiled code, bit for bit.

numba compiles ``math.hypot`` to the C library's, which differs from CPython's (correctly
rounded since Python 3.10) in the last bit for about one pair of arguments in 200, and it
has no ``math.remainder``. Kernels that replace pure-Python code (the motion model, a
tight corner's straight approach) use these, so that they decide exactly as the Python
code did, and as the Python code that still calls them decides.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_VELTKAMP = 134217729.0  # 2**27 + 1: splits a double into two 26-bit halves
_DBL_MIN = 2.2250738585072014e-308


@numba.njit(cache=True)
def _product(x, y):
    """x * y as an unevaluated sum hi + lo, exactly (Dekker's mul12 on Veltkamp splits)."""
    t = x * _VELTKAMP
    x_hi = t - (t - x)
    x_lo = x - x_hi
    t = y * _VELTKAMP
    y_hi = t - (t - y)
    y_lo = y - y_hi
    p = x_hi * y_hi
    q = x_hi * y_lo + x_lo * y_hi
    hi = p + q
    return hi, p - hi + q + x_lo * y_lo


@numba.njit(cache=True)
def hypot(x, y):
    """``math.hypot(x, y)`` of CPython: Modules/mathmodule.c's ``vector_norm`` for two
    coordinates (scaled to [0.5, 1), squared and summed exactly, one Newton correction)."""
    largest, found_nan = 0.0, False
    for value in (abs(x), abs(y)):
        found_nan |= value != value
        if value > largest:
            largest = value
    if math.isinf(largest):
        return largest
    if found_nan:
        return math.nan
    if largest == 0.0:
        return largest
    factor = 1.0
    _, exponent = math.frexp(largest)
    if exponent < -1023:  # subnormal: made normal first, as CPython does
        x, y, largest, factor = x / _DBL_MIN, y / _DBL_MIN, largest / _DBL_MIN, _DBL_MIN
        _, exponent = math.frexp(largest)
    scale = math.ldexp(1.0, -exponent)
    total, frac1, frac2 = 1.0, 0.0, 0.0
    for value in (x, y):
        value *= scale
        hi, lo = _product(value, value)
        summed = total + hi
        frac1 += lo
        frac2 += (total - summed) + hi
        total = summed
    h = math.sqrt(total - 1.0 + (frac1 + frac2))
    hi, lo = _product(-h, h)
    summed = total + hi
    frac1 += lo
    frac2 += (total - summed) + hi
    total = summed
    h += (total - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return factor * (h / scale)


@numba.njit(cache=True)
def remainder(x, y):
    """``math.remainder(x, y)`` of CPython (IEEE 754 remainder: x - n y, n the integer
    nearest x / y, ties to even), and its ValueError for an infinite x or a zero y."""
    if math.isnan(x):
        return x
    if math.isnan(y):
        return y
    if math.isinf(x) or y == 0.0:
        raise ValueError("math domain error")
    if math.isinf(y):
        return x
    absx, absy = abs(x), abs(y)
    m = np.fmod(absx, absy)
    c = absy - m
    if m < c:
        r = m
    elif m > c:
        r = -c
    else:  # halfway between two multiples of y: the even one
        r = m - 2.0 * np.fmod(0.5 * (absx - m), absy)
    return math.copysign(1.0, x) * r
