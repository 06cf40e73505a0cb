"""Runnable scenarios; each module defines ``SCENARIOS``. See :mod:`oceangnc.scenarios.base`.

The names below are imported on first use (PEP 562): a light module of this package (a scenario's
plot module, :data:`oceangnc.scenario_index.LIGHT_PLOTS`) imports without the config and log machinery.
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .base import Scenario, get_scenario, registry

__all__ = ["Scenario", "get_scenario", "registry"]


def __getattr__(name: str):
    if name in __all__:
        from . import base

        return getattr(base, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
