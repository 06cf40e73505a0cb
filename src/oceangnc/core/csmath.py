"""Scalar math for compiled right-hand sides that also runs in complex arithmetic (complex step).

A model's ``f(t, x, u, p, out)`` is differentiated by complex step (:mod:`oceangnc.core.linearize`):
df/dy = Im f(y + i h) / h. That needs every operation on the state to accept complex numbers and to
carry the derivative in the imaginary part. ``math.sin`` and friends refuse complex arguments in
numba, ``abs`` returns the modulus (which kills the derivative) and ``<`` is not defined on complex
numbers. The functions here dispatch on the argument type when numba compiles the caller:

* on floats they are exactly ``math.sin``, ``math.cos``, ``math.sqrt``, ``math.atan2``, ``abs``
  (bit-identical results: a model rewritten with them computes the same numbers as before);
* on complex numbers they are the analytic continuations (``cmath.sin`` ...), ``cabs(z)`` is
  ``z`` or ``-z`` by the sign of the real part (the derivative of |x| away from 0), ``catan2`` is
  atan2 of the real parts plus i times its first-order derivative.

Branches on the state compare real parts: ``x.real`` works on floats and complex numbers alike.
"""

from __future__ import annotations

import cmath
import math

from numba import types
from numba.extending import overload


def csin(x):
    """sin(x) (real or complex)."""
    return cmath.sin(x) if isinstance(x, complex) else math.sin(x)


def ccos(x):
    """cos(x) (real or complex)."""
    return cmath.cos(x) if isinstance(x, complex) else math.cos(x)


def ctan(x):
    """tan(x) (real or complex)."""
    return cmath.tan(x) if isinstance(x, complex) else math.tan(x)


def csqrt(x):
    """sqrt(x) (real x >= 0, or complex)."""
    return cmath.sqrt(x) if isinstance(x, complex) else math.sqrt(x)


def _is_c(*tys) -> bool:
    return any(isinstance(t, types.Complex) for t in tys)


@overload(csin)
def _ov_sin(x):
    if _is_c(x):
        return lambda x: cmath.sin(x)
    return lambda x: math.sin(x)


@overload(ccos)
def _ov_cos(x):
    if _is_c(x):
        return lambda x: cmath.cos(x)
    return lambda x: math.cos(x)


@overload(ctan)
def _ov_tan(x):
    if _is_c(x):
        return lambda x: cmath.tan(x)
    return lambda x: math.tan(x)


@overload(csqrt)
def _ov_sqrt(x):
    if _is_c(x):
        return lambda x: cmath.sqrt(x)
    return lambda x: math.sqrt(x)


def cabs(x):
    """|x| whose complex continuation keeps the derivative: x or -x by the sign of Re x."""
    if isinstance(x, complex):
        return x if x.real >= 0 else -x
    return abs(x)


@overload(cabs)
def _ov_abs(x):
    if _is_c(x):
        return lambda x: x if x.real >= 0.0 else -x
    return lambda x: abs(x)


def catan2(y, x):
    """atan2(y, x); on complex arguments atan2 of the real parts + i times its first-order derivative."""
    if isinstance(y, complex) or isinstance(x, complex):
        yr, xr = complex(y).real, complex(x).real
        d = xr * xr + yr * yr
        return math.atan2(yr, xr) + 1j * ((xr * complex(y).imag - yr * complex(x).imag) / d if d else 0.0)
    return math.atan2(y, x)


@overload(catan2)
def _ov_atan2(y, x):
    if _is_c(y, x):

        def impl(y, x):
            yr = y.real
            xr = x.real
            d = xr * xr + yr * yr
            im = 0.0
            if d > 0.0:
                im = (xr * y.imag - yr * x.imag) / d
            return complex(math.atan2(yr, xr), im)

        return impl
    return lambda y, x: math.atan2(y, x)
