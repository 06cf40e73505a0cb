"""Register oceangnc's numba cache locator (:mod:`oceangnc.jitcache`) as soon as numba is imported.

numba chooses a function's cache folder when the function is decorated, so the locator must be
registered before the first ``@njit(cache=True)`` of the package runs, yet ``import oceangnc`` (and
``oceangnc list``) must not import numba (0.4 s). :func:`install` registers at once if numba is
already imported; otherwise it adds a one-shot finder to ``sys.meta_path`` that lets numba's own
loader run and registers right after, then removes itself.
"""

from __future__ import annotations

import sys


def _register() -> None:
    mod = sys.modules.get("oceangnc.jitcache")
    if mod is None:
        from . import jitcache  # noqa: F401  (registers when imported)
    elif hasattr(mod, "register"):
        mod.register()
    # else: oceangnc.jitcache is being imported (it imported numba) and registers at its end


class _AfterNumba:
    """Meta-path finder: find ``numba`` with the other finders, register once its module has run."""

    def find_spec(self, name, path=None, target=None):
        if name != "numba":
            return None
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        spec = None
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            spec = find(name, path, target) if find is not None else None
            if spec is not None:
                break
        loader = getattr(spec, "loader", None)
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        run = loader.exec_module

        def exec_module(module):
            run(module)
            _register()

        loader.exec_module = exec_module  # this spec's own loader object
        return spec


def install() -> None:
    """Make sure :class:`oceangnc.jitcache.PackageCacheLocator` is registered before numba caches anything."""
    if "numba" in sys.modules:
        _register()
    elif not any(isinstance(f, _AfterNumba) for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterNumba())
