"""The range gain the controller law of :mod:`mylaw.blocks` calls (the test edits this file)."""

from numba import njit


@njit(cache=True)
def range_gain():
    """Stern thrust per metre of range error, N/m."""
    return 20.0
