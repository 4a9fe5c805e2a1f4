"""Where a command's ``--out`` goes (its NetCDF file, figures and a sweep's checkpoint), and the output of
a result too large to hold twice: its NetCDF file written releasing its variables, then its figures
drawn from the file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["engine_keywords", "out_paths", "write_released"]


def out_paths(out: Path, stem: str) -> tuple[Path, Path]:
    """(NetCDF file, figure directory) for ``--out``: a directory, or a file name ending in .nc.

    Parameters
    ----------
    out : Path
        The value of ``--out``.
    stem : str
        File stem of the NetCDF file inside a directory (``<out>/<stem>.nc``).

    Returns
    -------
    nc, figures : Path
        The NetCDF file and the directory the figures go to.
    """
    if out.suffix == ".nc":
        return out, out.parent
    return out / f"{stem}.nc", out


def engine_keywords(values: dict[str, Any], stem: str) -> dict[str, Any]:
    """Validated keyword arguments of :func:`geardyn.sweep.run_chunks` from a command's sweep-engine options.

    With ``--out`` the finished chunks are checkpointed next to the NetCDF file (``<nc>.chunks``).  The
    progress bar goes to stderr unless ``--json``.  An engine option the command does not have takes
    its default.

    Parameters
    ----------
    values : dict
        The command's option values (``out``, ``workers``, ``processes``, ``scheduler``, ``resume``,
        ``json_out``).
    stem : str
        File stem of the NetCDF file (its checkpoint directory is named after it).

    Returns
    -------
    dict
        ``workers``, ``processes``, ``scheduler``, ``checkpoint``, ``resume`` and ``progress``.

    Raises
    ------
    ModelError
        For an invalid engine option, or ``--resume`` without ``--out``.
    """
    from .. import validate
    from ..errors import ModelError
    from ..sweep import checkpoint_dir

    out = values.get("out")
    nc = out_paths(Path(out), stem)[0] if out is not None else None
    if values.get("resume") and nc is None:
        raise ModelError("resume: needs --out (a resumable sweep keeps its finished chunks next to its output)")
    return {
        "workers": validate.workers(values.get("workers", 1)),
        "processes": bool(values.get("processes", False)),
        "scheduler": validate.scheduler(values.get("scheduler")),
        "checkpoint": checkpoint_dir(nc) if nc is not None else None,
        "resume": bool(values.get("resume", False)),
        "progress": not values.get("json_out"),
    }


def write_released(ds: Any, nc: Path, figdir: Path, fmt: Any = ("png",), dpi: int = 120) -> list[str]:
    """The NetCDF file of ``ds`` written releasing its variables (:func:`_write_releasing`), then its
    figures drawn from the file (:func:`_figures_from_file`); the files written.

    What the computation left is collected and given back first.  What is held then is frozen out of
    the garbage collector meanwhile, so that the collections before each figure walk only what the
    output made (a full collection after a sweep walks about 170 000 objects: 0.1 s each).

    Parameters
    ----------
    ds : xarray.Dataset
        The result; its data variables are dropped as they are written.
    nc : Path
        The NetCDF file.
    figdir : Path
        Where the figures go.
    fmt : sequence of str
        Their file formats (:func:`geardyn.validate.figure_formats`).
    dpi : int
        Their resolution.

    Returns
    -------
    list of str
        The NetCDF file, then the figures.
    """
    import gc

    from ..sweep.executors import release_free_memory

    gc.collect()  # what the sweep left is given back before the writer's own buffers come in
    release_free_memory()
    frozen_before = gc.get_freeze_count()
    gc.freeze()
    try:
        return [str(_write_releasing(ds, nc)), *_figures_from_file(nc, figdir, fmt, dpi)]
    finally:
        if not frozen_before:  # (what a caller froze is unfrozen by that caller)
            gc.unfreeze()


def _write_releasing(ds: Any, nc: Path) -> Path:
    """:func:`geardyn.io.write_netcdf` one variable at a time, each dropped from ``ds`` once written.

    The coordinates and attributes go first, then each data variable is added (variables
    computed when read, e.g. :func:`geardyn.analysis.physical.add_physical` with ``lazy``, are
    computed then), so that the file is written without holding a copy of the result; it reads
    back as the Dataset ``write_netcdf`` writes.  Atomic as ``write_netcdf``.
    """
    from ..io import _atomic, annotate

    annotate(ds)
    names = list(ds.data_vars)

    def write(tmp: Path) -> None:
        from xarray.backends import H5NetCDFStore

        # One open file.  Written from this thread alone, so without xarray's write lock, whose look-up of
        # a Dask scheduler imports Dask (where installed) for nothing.
        store = H5NetCDFStore.open(tmp, mode="w", lock=False)
        try:
            ds.drop_vars(names).dump_to_store(store)
            for name in names:
                ds[[name]].drop_vars(list(ds.coords)).dump_to_store(store)
                del ds[name]
        finally:
            store.close()

    return _atomic(nc, write)


def _figures_from_file(nc: Path, figdir: Path, fmt: Any = ("png",), dpi: int = 120) -> list[str]:
    """The figures of the result in ``nc``, drawn from the file opened lazily (each loads what it draws).

    Memory freed before a figure is given back first (reference cycles collected; free heap pages
    returned to the system where glibc is used), so that each figure starts from what is held.
    """
    import gc

    import xarray as xr

    from ..plot import figures_for
    from ..plot.common import save
    from ..sweep.executors import release_free_memory

    files = []
    with xr.open_dataset(nc, engine="h5netcdf", cache=False) as ds:  # nothing kept once drawn
        for spec in figures_for(ds):
            gc.collect()
            release_free_memory()
            art = spec(ds)
            files += [str(save(art, figdir / f"{spec.stem}.{f}", dpi=dpi)) for f in fmt]
    gc.collect()
    return files
