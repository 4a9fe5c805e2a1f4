"""Registers the ``ds.geardyn`` accessor when xarray is imported, without importing xarray.

``import geardyn`` calls :func:`register_accessor`: with xarray already imported the accessor
(:mod:`geardyn.accessor`) is registered at once; otherwise a finder on :data:`sys.meta_path`
waits for the import of xarray (by the user, or by geardyn when a command builds a Dataset),
registers the accessor right after it and removes itself.  A command that builds no Dataset
never imports xarray.
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Sequence
from importlib.abc import Loader, MetaPathFinder
from importlib.machinery import ModuleSpec
from typing import Any

__all__ = ["register_accessor"]


def _register() -> None:
    from . import accessor  # noqa: F401  (the decorator registers the accessor)


class _RegisteringLoader(Loader):
    """The loader found for xarray, which registers the accessor once xarray has been executed."""

    def __init__(self, loader: Loader) -> None:
        self.loader = loader

    def create_module(self, spec: ModuleSpec) -> Any:
        return self.loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        module.__loader__ = module.__spec__.loader = self.loader  # the module keeps its own loader
        self.loader.exec_module(module)
        _register()


class _XarrayFinder(MetaPathFinder):
    """Finds nothing itself: wraps the loader that the other finders give for ``xarray``."""

    def find_spec(self, fullname: str, path: Sequence[str] | None, target: Any = None) -> ModuleSpec | None:
        if fullname != "xarray":
            return None
        _remove_finder()
        spec = importlib.util.find_spec(fullname)
        if spec is not None and hasattr(spec.loader, "exec_module"):
            spec.loader = _RegisteringLoader(spec.loader)
        return spec


_FINDER = _XarrayFinder()


def _remove_finder() -> None:
    while _FINDER in sys.meta_path:
        sys.meta_path.remove(_FINDER)


def register_accessor() -> None:
    """Register ``ds.geardyn`` now if xarray is imported, else when it is (once)."""
    if "xarray" in sys.modules:
        _remove_finder()
        _register()
    elif _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)
