"""Physical copies of large arrays computed when read (:func:`geardyn.analysis.physical.add_physical` with
``lazy=True``); imports xarray, so :mod:`geardyn.analysis.physical` imports it only when it builds a Dataset."""

from __future__ import annotations

from typing import Any

import numpy as np
from xarray.backends import BackendArray
from xarray.core import indexing

__all__ = ["Converted"]


class Converted(BackendArray):
    """A physical copy of an array, computed when read: ``fn(source[key])`` for any key.

    ``fn`` is one of the elementwise scale conversions, so a slice of the copy has the bits of the
    same slice of ``fn(source)``.  Written to NetCDF, such a variable is computed while it is
    written and not held besides its source.

    Parameters
    ----------
    source : numpy.ndarray
        The non-dimensional values.
    fn : callable
        The elementwise conversion (a :class:`~geardyn.units.PhysicalScales` method).
    """

    def __init__(self, source: np.ndarray, fn: Any) -> None:
        self.source, self.fn = source, fn
        self.shape, self.dtype = source.shape, np.dtype(float)

    def __getitem__(self, key: Any) -> np.ndarray:
        return indexing.explicit_indexing_adapter(key, self.shape, indexing.IndexingSupport.BASIC, self._get)

    def _get(self, key: Any) -> np.ndarray:
        return np.asarray(self.fn(self.source[key]), dtype=float)
