"""Runnable scenarios; each module defines ``SCENARIOS``. See :mod:`oceangnc.scenarios.base`."""

from .base import Scenario, get_scenario, registry

__all__ = ["Scenario", "get_scenario", "registry"]
