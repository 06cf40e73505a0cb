"""Exceptions that the API raises and the CLI turns into one-line messages and exit codes.

* :class:`ConfigError` and :class:`InputError` -> exit code 2 (bad input).
* :class:`DivergenceError` -> exit code 1 (the simulation blew up; the log so far is kept).
"""

from __future__ import annotations


class OceanGNCError(Exception):
    """Base class of every error oceangnc raises on purpose."""

    exit_code = 1


class ConfigError(OceanGNCError, ValueError):
    """A configuration value is unknown, of the wrong type or out of its allowed range.

    The message is one line that names the dotted key and the allowed range.
    """

    exit_code = 2


class InputError(OceanGNCError, ValueError):
    """Bad input that is not a config key: a log without a needed column, a bad file, a bad name."""

    exit_code = 2


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised by the command line's handler (:func:`oceangnc.cli.main`) so that a terminated
    run ends as Ctrl-C does: log closed, ``summary.json`` with ``status = "interrupted"``; exit 143."""


class DivergenceError(OceanGNCError, RuntimeError):
    """A simulation produced a non-finite or absurd state.

    Attributes
    ----------
    t : float
        Simulated time of the failure (s).
    block : str
        Name of the block whose state blew up.
    state : dict
        The block's last state, signal name -> value.
    """

    exit_code = 1

    def __init__(self, t: float, block: str, state: dict[str, float], reason: str = "non-finite state"):
        self.t = float(t)
        self.block = block
        self.state = dict(state)
        shown = ", ".join(f"{k}={v:.4g}" for k, v in list(self.state.items())[:12])
        super().__init__(f"simulation diverged at t={self.t:.3f} s in block '{block}' ({reason}): {shown}")
