"""Excitation tables in files: read (NetCDF, CSV, JSON, tooth-pair TOML), write (CSV, JSON), apply to a model.

Formats (``docs/excitation.md``):

* NetCDF written by ``geardyn stiffness --out FILE.nc``: ``mesh_stiffness`` (N/µm) and
  ``ste_equivalent`` (µm) over ``phase`` (mesh cycles).
* CSV: a header line ``phase_cycles,stiffness_N_per_m,ste_m`` (the STE column optional), one row per
  phase, equally spaced from 0 (P = N·Δphase mesh cycles), or any non-decreasing phases with a phase
  given twice at a jump (left value, then right value; P = ⌊last phase⌋ + 1).
* JSON: ``{"cycles": P, "stiffness_N_per_m": [...], "ste_m": [...]}`` (``ste_m`` optional; ``phase_cycles``
  optional, with jumps as in the CSV).
* TOML: a tooth-pair file (``[tooth_pair]``, ``[modifications]``, ``[[fault]]``, ``[mesh]``; see
  :mod:`geardyn.tooth.config`), whose stiffness and STE are computed by the potential-energy method.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, ModelError
from .excitation import Excitation, excitation_model

__all__ = ["apply_excitation", "read_table", "refuse_series_options", "table_of", "write_table"]

_CSV_HEADER = ("phase_cycles", "stiffness_N_per_m", "ste_m")


def table_of(ms: Any, jumps: bool = False) -> Excitation:
    """The :class:`Excitation` of a :class:`~geardyn.tooth.mesh.MeshStiffness` (stiffness and e_eq).

    Parameters
    ----------
    ms : MeshStiffness
        The mesh stiffness and STE over its P mesh cycles (on its equally spaced grid).
    jumps : bool
        Also locate every phase where the number of pairs in contact changes between two neighbouring
        grid phases (bisection to 1e-13 cycle with :func:`~geardyn.tooth.mesh.mesh_stiffness` at the mid
        phases) and give it twice, with the left and the right value (a grid phase that is one takes
        the left value in a new row before it).

    Returns
    -------
    Excitation
        Its stiffness and equivalent-STE table over the same cycles (with ``phase`` when ``jumps``).
    """
    k = np.asarray(ms.stiffness, dtype=float)
    e = np.asarray(ms.ste_equivalent, dtype=float)
    if not jumps:
        return Excitation(k, e, int(ms.cycles))
    return _with_jumps(ms, k, e)


def _with_jumps(ms: Any, k: np.ndarray, e: np.ndarray) -> Excitation:
    from .mesh import mesh_stiffness

    P, phase, count = int(ms.cycles), np.asarray(ms.phase, dtype=float), np.asarray(ms.pairs_in_contact)
    n = phase.size
    at = np.flatnonzero(count != np.roll(count, -1))  # a change between grid phase i and i + 1 (cyclic)
    if at.size == 0:
        return Excitation(k, e, P, phase=phase.copy())

    def mesh(th):
        return mesh_stiffness(
            ms.geometry,
            ms.force * ms.geometry.r_b[0],
            faults=ms.faults,
            modifications=ms.modifications,
            cycles=P,
            slices=ms.slices,
            phases=th,
        )

    lo = phase[at].copy()
    hi = np.where(at + 1 < n, phase[(at + 1) % n], float(P))
    c_lo = count[at]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        same = mesh(np.mod(mid, P)).pairs_in_contact == c_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        if np.all(hi - lo <= 1e-13 * max(1.0, P)):
            break
    left, right = mesh(np.mod(lo, P)), mesh(np.mod(hi, P))
    rows = [(phase[i], 0, k[i], e[i]) for i in range(n)]  # (phase, order at that phase, k, e)
    for j, i in enumerate(at):
        nxt = float(phase[(i + 1) % n])
        lv = (left.stiffness[j], left.ste_equivalent[j])
        if abs(hi[j] - nxt - (P if i + 1 == n else 0.0)) <= 1e-9:  # at a grid phase: its row is the right value
            rows.append((nxt, -1, *lv))
        else:
            x = float(np.mod(hi[j], P))
            rows += [(x, 1, *lv), (x, 2, right.stiffness[j], right.ste_equivalent[j])]
    a = np.array(sorted(rows), dtype=float)
    return Excitation(a[:, 2], a[:, 3], P, phase=a[:, 0])


def _cycles_from_phase(where: str, phase: np.ndarray) -> int:
    n = phase.size
    if n < 2:
        raise ConfigError(f"{where}: an excitation table needs at least 2 rows")
    d = np.diff(phase)
    step = float(d.mean())
    if not (step > 0 and np.allclose(d, step, rtol=1e-6, atol=0) and abs(phase[0]) <= 1e-9 * max(1.0, step * n)):
        raise ConfigError(f"{where}: phase_cycles must be equally spaced from 0")
    span = step * n
    P = round(span)
    if P < 1 or abs(span - P) > 1e-6 * span:
        raise ConfigError(f"{where}: the table spans {span:.9g} mesh cycles; it must span a whole number of cycles")
    return int(P)


def _phased(
    where: str, phase: np.ndarray, k: np.ndarray, e: np.ndarray | None, cycles: int | None = None
) -> Excitation:
    """The table of rows at ``phase``: equally spaced from 0 (as before), else explicit node phases with jumps."""
    d = np.diff(phase)
    if phase.size >= 2 and np.all(d > 0):
        try:
            P = _cycles_from_phase(where, phase)
        except ConfigError:
            P = None
        if P is not None and (cycles is None or cycles == P):
            return Excitation(k, e, P)
    if phase.size < 2 or np.any(d < 0):
        raise ConfigError(
            f"{where}: phase_cycles must be equally spaced from 0, or non-decreasing with a phase at "
            "most twice (a jump: left value, then right value)"
        )
    P = int(math.floor(phase[-1])) + 1 if cycles is None else int(cycles)
    return Excitation(k, e, P, phase=phase)


def read_table(path: str | Path, *, cycles: int | None = None, points: int | None = None) -> Excitation:
    """The excitation table of a file (the formats of the module docstring), within the physical ranges of
    :func:`geardyn.plausible.excitation_table` (stiffness in N/m, STE in m).

    Parameters
    ----------
    path : str or Path
        ``.nc``, ``.csv``, ``.json`` or ``.toml`` (a tooth-pair file).
    cycles, points : int, optional
        For a tooth-pair file: mesh cycles and phases per cycle (see :func:`_read_table`).

    Returns
    -------
    Excitation

    Raises
    ------
    ConfigError
        For a missing, unreadable or too large file, an unknown suffix, a malformed table or values outside
        the physical ranges (one line naming the file).
    """
    from ..plausible import excitation_table

    exc = _read_table(path, cycles=cycles, points=points)
    try:
        excitation_table(exc.stiffness, exc.ste, where="excitation")
    except ModelError as e:
        raise ConfigError(f"{path}: {e}") from None
    return exc


def _read_table(path: str | Path, *, cycles: int | None = None, points: int | None = None) -> Excitation:
    """The excitation table of a file (the formats of the module docstring).

    Parameters
    ----------
    path : str or Path
        ``.nc``, ``.csv``, ``.json`` or ``.toml`` (a tooth-pair file).
    cycles, points : int, optional
        For a tooth-pair file: mesh cycles (default the file's ``[mesh]`` or
        :func:`~geardyn.tooth.mesh.default_cycles`) and phases per cycle (default the file's, else 64).

    Returns
    -------
    Excitation

    Raises
    ------
    ConfigError
        For a missing or unreadable file, an unknown suffix or a malformed table (one line naming the file).
    """
    p = Path(path)
    where = str(p)
    if not p.is_file():
        raise ConfigError(f"{where}: excitation file not found")
    suffix = p.suffix.lower()
    from ..plausible import MAX_TABLE_BYTES, file_size

    file_size(p, MAX_TABLE_BYTES, "excitation table", "resample the table to fewer phases")
    try:
        if suffix == ".nc":
            import xarray as xr

            with xr.open_dataset(p) as ds:
                if ds.attrs.get("geardyn_kind") != "stiffness" or "mesh_stiffness" not in ds:
                    raise ConfigError(f"{where}: not a NetCDF file of geardyn stiffness (no mesh_stiffness)")
                k = np.asarray(ds["mesh_stiffness"].values, dtype=float) * 1e6
                e = np.asarray(ds["ste_equivalent"].values, dtype=float) * 1e-6 if "ste_equivalent" in ds else None
                P = _cycles_from_phase(where, np.asarray(ds["phase"].values, dtype=float))
            return Excitation(k, e, P)
        if suffix == ".csv":
            with p.open(newline="", encoding="utf-8") as fh:
                rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
            head = tuple(c.strip() for c in rows[0]) if rows else ()
            if head not in (_CSV_HEADER[:2], _CSV_HEADER):
                raise ConfigError(
                    f"{where}: the header must be {','.join(_CSV_HEADER)} (ste_m optional), got {','.join(head)!r}"
                )
            a = np.array([list(map(float, r)) for r in rows[1:]], dtype=float)
            if a.ndim != 2 or a.shape[1] != len(head):
                raise ConfigError(f"{where}: every row needs {len(head)} numbers")
            return _phased(where, a[:, 0], a[:, 1], a[:, 2] if a.shape[1] == 3 else None)
        if suffix == ".json":
            d = json.loads(p.read_text(encoding="utf-8"))
            if not isinstance(d, dict) or "stiffness_N_per_m" not in d:
                raise ConfigError(f"{where}: a JSON excitation needs stiffness_N_per_m (and cycles, ste_m)")
            unknown = set(d) - {"cycles", "stiffness_N_per_m", "ste_m", "phase_cycles", "name"}
            if unknown:
                raise ConfigError(f"{where}: unknown keys {sorted(unknown)}")
            k = np.asarray(d["stiffness_N_per_m"], dtype=float)
            P = int(d.get("cycles", 1))
            e = np.asarray(d["ste_m"], dtype=float) if d.get("ste_m") is not None else None
            if "phase_cycles" in d:
                ph = np.asarray(d["phase_cycles"], dtype=float)
                if np.all(np.diff(ph) > 0) and _cycles_from_phase(where, ph) != P:
                    raise ConfigError(f"{where}: phase_cycles does not span cycles = {P} mesh cycles")
                return _phased(where, ph, k, e, P)
            return Excitation(k, e, P)
        if suffix == ".toml":
            from .config import load_case

            return table_of(load_case(p).mesh_stiffness(cycles, points))
    except ConfigError:
        raise
    except (OSError, ValueError, TypeError, KeyError, ModelError) as exc:
        raise ConfigError(f"{where}: {exc}") from None
    raise ConfigError(f"{where}: an excitation file is .nc (geardyn stiffness), .csv, .json or a tooth-pair .toml")


def write_table(exc: Excitation, path: str | Path, name: str = "") -> Path:
    """Write ``exc`` as CSV or JSON (by the suffix), the formats :func:`read_table` reads.

    Parameters
    ----------
    exc : Excitation
    path : str or Path
        ``.csv`` or ``.json``.
    name : str
        Name stored in a JSON file.

    Returns
    -------
    Path
    """
    p = Path(path)
    phase = exc.nodes()
    if p.suffix.lower() == ".csv":
        cols = [phase, exc.stiffness] + ([exc.ste] if exc.ste is not None else [])
        head = _CSV_HEADER[: len(cols)]
        lines = [",".join(head)] + [",".join(repr(float(v)) for v in row) for row in zip(*cols)]
        p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    elif p.suffix.lower() == ".json":
        d = {
            "name": name,
            "cycles": exc.cycles,
            "phase_cycles": list(map(float, phase)),
            "stiffness_N_per_m": list(map(float, exc.stiffness)),
        }
        if exc.ste is not None:
            d["ste_m"] = list(map(float, exc.ste))
        p.write_text(json.dumps(d) + "\n", encoding="utf-8")
    else:
        raise ModelError(f"table: {p}: write .csv or .json")
    return p


def apply_excitation(
    model: Any, path: str | Path, *, b_c: float | None, harmonics: int | None = None, evaluation: str = "series"
) -> Any:
    """``model`` with the stiffness and STE of an excitation file (:func:`read_table`).

    Parameters
    ----------
    model : GearModel
        The pair's model (its ω is the mesh frequency and stays so).
    path : str or Path
        The excitation file.
    b_c : float or None
        Characteristic length (m) the STE is divided by; None is refused when the table has an STE.
    harmonics : int, optional
        Harmonics of ω/P kept (default all of the table's, at most MAX_HARMONICS·P).
    evaluation : {"series", "table"}
        ``"table"``: the accurate mode evaluates the table as given (:func:`excitation_model`).

    Returns
    -------
    GearModel
    """
    exc = read_table(path)
    if exc.ste is not None and (b_c is None or not math.isfinite(b_c) or b_c <= 0):
        raise ModelError(
            f"excitation: {path}: the STE needs the characteristic length b_c; give the configuration's "
            "gear pair or [excitation] b_c"
        )
    return excitation_model(
        model, exc, harmonics=harmonics, b_c=b_c if exc.ste is not None else 1.0, evaluation=evaluation
    )


def refuse_series_options(values: dict[str, Any]) -> None:
    """Refuse the command-line series options (``--kappa1``, ``--fe``, ``--xi1`` and phases) beside a table.

    Parameters
    ----------
    values : dict
        The model options by keyword (``None`` = not given).

    Raises
    ------
    ModelError
        Naming the options given.
    """
    clash = [d for d in ("kappa1", "fe", "phi_k", "phi_e", "xi1", "phi_c") if values.get(d) is not None]
    if clash:
        raise ModelError(
            f"{', '.join('--' + d.replace('_', '-') for d in clash)}: not with an excitation table "
            "(it gives the stiffness and STE series over P mesh cycles)"
        )
