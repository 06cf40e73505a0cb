"""oceangnc: guidance, navigation, control and identification of unmanned marine vehicles.

Python API first::

    import oceangnc
    res = oceangnc.run("usv-turn", overrides={"environment.current.speed": 0.1}, duration=60)
    res.summary["usv.turn_radius_m"], res.df.head()

The command line ``oceangnc`` is a thin layer over :func:`run`.
"""

from ._version import __version__
from .core.caches import configure_numba as _configure_numba

# before numba is imported: its cache folder is keyed by the content of every source file, so a
# compiled function never runs with an old callee (oceangnc.core.caches)
_configure_numba()

from typing import TYPE_CHECKING  # noqa: E402

if TYPE_CHECKING:
    from .api import RunResult, list_scenarios, replot, resolve_config, run
    from .errors import ConfigError, DivergenceError, InputError, OceanGNCError

#: the public names and the module that defines them: imported on first use (PEP 562), so that
#: ``import oceangnc.cli`` costs nothing and ``oceangnc run`` can fork its plot drawer before numpy,
#: pydantic and pyarrow are imported (oceangnc.postproc)
_LAZY = {
    "run": "api",
    "replot": "api",
    "list_scenarios": "api",
    "resolve_config": "api",
    "RunResult": "api",
    "ConfigError": "errors",
    "DivergenceError": "errors",
    "InputError": "errors",
    "OceanGNCError": "errors",
}


def __getattr__(name: str):
    import importlib

    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    try:  # a subpackage or module used as an attribute (``oceangnc.api``) without its own import
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as e:
        if e.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])


def run_batch(*args, **kwargs):
    """K runs of a scenario in compiled batches; see :func:`oceangnc.batch.run_batch`."""
    from .batch import run_batch as _rb

    return _rb(*args, **kwargs)


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
