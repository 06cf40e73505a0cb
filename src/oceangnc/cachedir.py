"""The folder of oceangnc's caches (no heavy import here: used at start-up).

``$OCEANGNC_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/oceangnc`` (default ``~/.cache/oceangnc``). It
holds, per package version, the numba caches of the package (``numba-<version>``,
:mod:`oceangnc.jitcache`), the generated steppers and fused drivers (``steppers-<version>``,
:mod:`oceangnc.core.integrators`) and derived values (``derived-<version>``, :mod:`oceangnc.derived`).
It lives outside the installed package, so a reinstall of the same version keeps all of it.
"""

from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """``$OCEANGNC_CACHE_DIR``, else ``$XDG_CACHE_HOME/oceangnc`` (default ``~/.cache/oceangnc``)."""
    root = os.environ.get("OCEANGNC_CACHE_DIR")
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(base, "oceangnc")
    return Path(root)


def versioned(kind: str) -> Path:
    """``<cache_root>/<kind>-<version>``."""
    from . import __version__

    return cache_root() / f"{kind}-{__version__}"
