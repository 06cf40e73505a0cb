"""Extreme-tension estimates with an interval, and verdicts with confidence, of a sea state (issue 40).

Each sea state is run with K seeds (``oceangnc sweep ... --seeds K``); each run's largest tension over
its integration steps (``cable.top_max_N``, over a window of T_w = ``analysis.window_s``) is one sample
of the maximum over T_w. A **Gumbel** (type I extreme value) distribution F(x) = exp(-exp(-(x - u)/b))
is fitted by the method of moments (Gumbel 1958, *Statistics of Extremes*, Columbia Univ. Press, ch. 6):
b = s sqrt(6)/pi, u = mean - 0.5772 b (s: the sample standard deviation of the K maxima).

* **Most probable maximum** over an exposure T_e: the mode of the maximum over T_e. For maxima of
  independent windows the maximum over T_e = n T_w is Gumbel with the same b and the mode
  u_e = u + b ln n (max-stability), so MPM = u + b ln(T_e / T_w); with T_e = T_w (the default) the
  MPM is the mode u of the fitted distribution.
* **Interval**: the MPM is the quantile x_T = mean + K_T s with K_T = (MPM - mean) / s; its standard
  error under the method of moments is s_e = s sqrt((1 + 1.1396 K_T + 1.1 K_T^2) / K) (Kite 1977,
  *Frequency and Risk Analyses in Hydrology*, Water Resources Publications; Chow, Maidment & Mays 1988,
  *Applied Hydrology*, sec. 12.5), and the interval is MPM +- t_{K-1} s_e at ``level`` (Student's t,
  two-sided; 90 % default). Checked by Monte Carlo in tests/test_sea_verdicts.py.
* **Verdict** against the tension limit L: ``pass`` when the interval lies below L, ``fail`` when it
  lies above, ``marginal`` when it straddles L. With one seed there is no interval: the verdict is the
  run's own (its maximum against L).
"""

from __future__ import annotations

import math

import numpy as np

EULER = 0.5772156649015329


def gumbel_mpm(maxima, window_s: float, exposure_s: float | None = None, level: float = 0.9):
    """(MPM N, lower N, upper N, b N) of the maxima ``maxima`` (one per seed, each over ``window_s`` s) for
    an exposure of ``exposure_s`` s (default: the window), interval at ``level`` (module docstring). With
    fewer than two maxima: (the maximum, nan, nan, nan)."""
    x = np.asarray(maxima, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan, math.nan, math.nan, math.nan
    if x.size < 2:
        return float(x[0]), math.nan, math.nan, math.nan
    from scipy.stats import t as student

    k = x.size
    s = float(np.std(x, ddof=1))
    b = s * math.sqrt(6.0) / math.pi
    u = float(np.mean(x)) - EULER * b
    ratio = (exposure_s or window_s) / window_s if window_s > 0 else 1.0
    mpm = u + b * math.log(max(ratio, 1e-12))
    if s == 0.0:
        return mpm, mpm, mpm, 0.0
    kt = (mpm - float(np.mean(x))) / s
    se = s * math.sqrt(max(1.0 + 1.1396 * kt + 1.1 * kt * kt, 0.0) / k)
    half = float(student.ppf(0.5 + 0.5 * level, k - 1)) * se
    return mpm, mpm - half, mpm + half, b


def tension_verdict(mpm: float, lo: float, hi: float, limit: float) -> str:
    """``pass``, ``fail`` or ``marginal`` (the interval [lo, hi] straddles ``limit``); with no interval
    (nan bounds) the estimate's own side of the limit."""
    if not math.isfinite(limit):
        return "pass"
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "pass" if mpm <= limit else "fail"
    if hi <= limit:
        return "pass"
    if lo > limit:
        return "fail"
    return "marginal"


def cell_verdict(tension: str, other_fraction: float) -> str:
    """The verdict of a sea state from its tension verdict and the fraction of its runs that met every
    other limit (snap, depth and pitch std): ``fail`` if either fails outright (fraction 0), ``marginal``
    if either is marginal (a fraction strictly between 0 and 1: the seeds disagree), else ``pass``."""
    if tension == "fail" or other_fraction <= 0.0:
        return "fail"
    if tension == "marginal" or other_fraction < 1.0:
        return "marginal"
    return "pass"
