"""``oceangnc identify <method> LOG ...``: dispatches to the identification methods' own parsers.

Each method module in :data:`METHODS` defines ``register(subparsers)`` adding ``first-order`` or
``ekf`` under ``identify``; absent modules are skipped.
"""

from __future__ import annotations

import importlib

METHODS = ("oceangnc.identification.first_order_cli", "oceangnc.identification.ekf_cli")


def register(sub) -> None:
    p = sub.add_parser("identify", help="identify a model from a log (first-order, ekf)")
    methods = p.add_subparsers(dest="method", metavar="METHOD")
    for name in METHODS:
        try:
            mod = importlib.import_module(name)
        except ModuleNotFoundError as e:
            if e.name == name:
                continue
            raise
        mod.register(methods)
    p.set_defaults(func=lambda a: (p.print_help(), 2)[1])
