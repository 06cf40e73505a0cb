"""The steepest sea a wave configuration may ask for: past it the waves would have broken.

* Irregular sea (``jonswap``, ``pierson-moskowitz``): the average steepness S_p = 2 pi Hs / (g Tp^2) (Hs over
  the deep-water length of the peak period) may not exceed the limiting values DNV-RP-C205 (2010), sec. 3.5.5
  (short-term sea states, the steepness criteria of the JONSWAP parameters) gives as guidance: 1/15 for
  Tp <= 8 s, 1/25 for Tp >= 15 s, linear in Tp between. A 1 m sea at Tp = 0.6 s has S_p = 1.8, 27 times the
  limit; the shortest peak period of a 1 m sea is 3.1 s.
* Regular wave (``regular``; ``hs`` is its height H): Miche's breaking limit H / lambda <= 0.142 tanh(k h)
  (Miche 1944; the limit of a Stokes wave, 1/7 in deep water), lambda = 2 pi / k from the dispersion
  relation at the configured depth.

:func:`steepness_error` gives the one-line refusal, naming the keys, or None.
"""

from __future__ import annotations

import math

from ..units import G

#: DNV-RP-C205 sec. 3.5.5: the limiting average steepness S_p, 1/15 up to Tp = 8 s, 1/25 from Tp = 15 s
SP_SHORT, SP_LONG, TP_SHORT, TP_LONG = 1.0 / 15.0, 1.0 / 25.0, 8.0, 15.0
#: Miche (1944): the breaking steepness of a regular wave in deep water, H / lambda = 0.142 tanh(k h)
MICHE = 0.142


def limiting_steepness(tp: float) -> float:
    """The largest average steepness S_p = 2 pi Hs / (g Tp^2) of an irregular sea of peak period ``tp`` (s)
    (DNV-RP-C205 sec. 3.5.5: 1/15 at Tp <= 8 s, 1/25 at Tp >= 15 s, linear between)."""
    if tp <= TP_SHORT:
        return SP_SHORT
    if tp >= TP_LONG:
        return SP_LONG
    return SP_SHORT + (SP_LONG - SP_SHORT) * (tp - TP_SHORT) / (TP_LONG - TP_SHORT)


def _shortest_period(hs: float) -> float:
    """The shortest peak period (s) of an irregular sea of height ``hs`` (m) within the limit, by bisection
    (S_p / limit falls with Tp: S_p as 1/Tp^2, the limit by at most 1/15 -> 1/25 over 8-15 s)."""
    lo, hi = 0.0, 60.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if 2.0 * math.pi * hs / (G * mid * mid) > limiting_steepness(mid):
            lo = mid
        else:
            hi = mid
    return hi


def steepness_error(kind: str, hs: float, tp: float, depth: float) -> str | None:
    """The refusal of a sea steeper than it can be (module docstring), or None when it can exist."""
    if kind == "none":
        return None
    if kind == "regular":
        from .dispersion import wave_number

        k = float(wave_number(2.0 * math.pi / tp, depth)[0])
        lam = 2.0 * math.pi / k
        limit = MICHE * math.tanh(k * depth)
        if hs / lam > limit:
            return (
                f"hs = {hs:g} m at tp = {tp:g} s: a regular wave of height/length {hs / lam:.3g} breaks above "
                f"{limit:.3g} (Miche 1944, depth {depth:g} m); allowed hs <= {limit * lam:.3g} m at this tp"
            )
        return None
    sp = 2.0 * math.pi * hs / (G * tp * tp)
    lim = limiting_steepness(tp)
    if sp > lim:
        tp_min = _shortest_period(hs)
        return (
            f"hs = {hs:g} m at tp = {tp:g} s: a sea of steepness 2 pi Hs/(g Tp^2) = {sp:.3g}, above the limit "
            f"{lim:.3g} (DNV-RP-C205 sec. 3.5.5); allowed hs <= {lim * G * tp * tp / (2.0 * math.pi):.3g} m "
            f"at this tp, or tp >= {tp_min:.3g} s for this hs"
        )
    return None
