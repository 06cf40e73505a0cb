"""oceangnc: guidance, navigation, control and identification of unmanned marine vehicles.

Python API first::

    import oceangnc
    res = oceangnc.run("usv-turn", overrides={"environment.current.speed": 0.1}, duration=60)
    res.summary["usv.turn_radius_m"], res.df.head()

The command line ``oceangnc`` is a thin layer over :func:`run`.
"""

from ._numba_hook import install as _install_numba_cache

# before any module of the package is compiled or loaded from numba's cache: caches in the user cache
# folder, kept across reinstalls (oceangnc.jitcache)
_install_numba_cache()

from .api import RunResult, list_scenarios, replot, resolve_config, run  # noqa: E402
from .errors import ConfigError, DivergenceError, InputError, OceanGNCError  # noqa: E402


def run_batch(*args, **kwargs):
    """K runs of a scenario in compiled batches; see :func:`oceangnc.batch.run_batch`."""
    from .batch import run_batch as _rb

    return _rb(*args, **kwargs)


__version__ = "0.1.0"

__all__ = [
    "run",
    "run_batch",
    "replot",
    "list_scenarios",
    "resolve_config",
    "RunResult",
    "ConfigError",
    "DivergenceError",
    "InputError",
    "OceanGNCError",
    "__version__",
]
