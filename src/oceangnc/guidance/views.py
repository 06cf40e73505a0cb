"""Block attributes that are entries of a :class:`~oceangnc.core.law.LawBlock`'s state or parameter array.

:func:`oceangnc.core.law.param` makes a float attribute a view of one parameter; the guidance blocks
also show entries of their *state* (the active leg, the waypoints reached, the pilot's stick) and
integer or yes/no entries, with the Python type their users have always read. Reading and setting the
attribute reads and sets the array entry, so the law (Python step or fused loop) sees every change.
"""

from __future__ import annotations

from collections.abc import Callable


def entry(array: str, offset: int, cast: Callable = float, doc: str = "") -> property:
    """An attribute that *is* ``self.<array>[offset]`` (``array`` "st" or "pa"), read as ``cast``
    (``float``, ``int`` or ``bool``) and stored as a float (a bool as 1.0 / 0.0)."""

    def fget(self):
        return cast(getattr(self, array)[offset])

    def fset(self, value) -> None:
        getattr(self, array)[offset] = float(value)

    return property(fget, fset, doc=doc)


__all__ = ["entry"]
