"""Running one scenario on the Python clock and on the fused loop, and comparing the two logs
(issue 19: same columns, same rows, values within 1e-9 relative): the helpers of test_fused*.py."""

from __future__ import annotations

import warnings

import numpy as np

from oceangnc.api import resolve_config
from oceangnc.io.logs import LogWriter, read_log


def run_path(name, over, dur, fused, tmp_path):
    """``(sim, t_end, log DataFrame, cfg)`` of ``name`` with ``over`` for ``dur`` s on one path."""
    sc, cfg = resolve_config(name, overrides=over, duration=dur)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the first-order schedule's range warning
        sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
        sim.use_fused = fused
        path = tmp_path / f"{name}-{int(fused)}.parquet"
        with LogWriter(path) as log:
            t = sim.run(dur, log=log)
    return sim, t, read_log(path), cfg


def same_log(a, b, nan_equal: bool = True) -> None:
    """Same columns and rows, values within 1e-9 rel (1e-12 abs), and more than 90 % of the columns
    bit-identical (the kernels share the Python blocks' compiled laws; an ulp of libm's hypot/atan2
    against numba's is the only difference seen). ``nan_equal``: a NaN in both logs counts as equal."""
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(b)
    x, y = a.to_numpy(), b.to_numpy()
    np.testing.assert_allclose(y, x, rtol=1e-9, atol=1e-12)
    equal = (x == y) | (np.isnan(x) & np.isnan(y)) if nan_equal else x == y
    assert equal.all(axis=0).mean() > 0.9


def run_both(name, over, dur, tmp_path, nan_equal: bool = True):
    """Both paths of one scenario; asserts which path ran, the same end time and :func:`same_log`.
    Returns ``(python sim, fused sim, python log, fused log, t_end, cfg)``."""
    sp, tp, a, cfg = run_path(name, over, dur, False, tmp_path)
    sf, tf, b, _ = run_path(name, over, dur, True, tmp_path)
    assert sp.path == "python" and sf.path == "fused"
    assert tp == tf
    same_log(a, b, nan_equal)
    return sp, sf, a, b, tp, cfg
