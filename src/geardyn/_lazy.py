"""Heavy modules imported on first use, so that a command imports only what it runs.

``xr = lazy_module("xarray")`` stands for ``import xarray as xr`` at the top of a module: the
module is imported the first time one of its attributes is read (``xr.Dataset``), and never by a
command that does not read one.  Type annotations (strings under ``from __future__ import
annotations``) read nothing.
"""

from __future__ import annotations

import sys
from importlib import import_module
from types import ModuleType
from typing import Any

__all__ = ["lazy_module"]


class _LazyModule:
    __slots__ = ("_name",)

    def __init__(self, name: str) -> None:
        self._name = name

    def __getattr__(self, attr: str) -> Any:
        module = sys.modules.get(self._name)
        if module is None:
            module = import_module(self._name)
        return getattr(module, attr)

    def __repr__(self) -> str:
        return f"<module {self._name!r}, imported on first use>"


def lazy_module(name: str) -> ModuleType:
    """A stand-in for the module ``name`` that imports it when an attribute is first read.

    Parameters
    ----------
    name : str
        The module's absolute name, e.g. ``"xarray"``.

    Returns
    -------
    module
        An object whose attributes are those of the module (typed as the module for checkers).
    """
    return _LazyModule(name)  # type: ignore[return-value]
