"""Options and messages shared by the subcommands of ``oceangnc`` (:mod:`oceangnc.cli` and its plugins).

* :func:`add_set` / :func:`set_overrides`: the repeatable ``--set KEY=VALUE`` and its flat dotted-key dict;
* :func:`add_live_options`: ``--speed``, ``--set``, ``--out`` of the live subcommands (console, mavlink);
* :func:`needs_package`: the one-line message for a missing optional package.
"""

from __future__ import annotations

SET_HELP = "override a config key (repeatable)"


def add_set(p, help: str = SET_HELP) -> None:
    """``--set KEY=VALUE`` (repeatable) on parser ``p``."""
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help=help)


def set_overrides(args) -> dict:
    """``args.set`` as a flat ``{dotted key: value}`` dict (empty without ``--set``); ConfigError if malformed."""
    from .io.config import flatten, parse_sets

    return flatten(parse_sets(args.set))


def add_live_options(p, set_help: str, out_help: str) -> None:
    """``--speed`` (simulated s per wall s), ``--set`` and ``--out`` (default runs/) of a live subcommand."""
    p.add_argument("--speed", type=float, default=1.0, help="simulated seconds per wall-clock second (default 1)")
    add_set(p, set_help)
    p.add_argument("--out", default="runs", help=out_help)


def needs_package(what: str, name: str | None, extra: str) -> str:
    """``"<what> needs the optional package '<name>'; install with pip install 'oceangnc[<extra>]'"``."""
    return f"{what} needs the optional package '{name}'; install with pip install 'oceangnc[{extra}]'"
