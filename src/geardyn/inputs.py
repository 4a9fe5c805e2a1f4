"""The gear pair of a run from its files, each read once: the model with its options and operating point, and its
physical scales.

A run of the pair names at most a configuration file (``--config``; the paper's Table 1 pair when none is given)
and an excitation file (``--excitation``).  :class:`PairInputs` reads each of them once, however often the
model and the scales are asked for, and builds:

* the model: the configuration's, with the excitation's stiffness and STE, the operating point (a pinion speed
  gives ω, a pinion torque f_p, through the pair's scales) and the non-dimensional model options on top;
* the physical scales of the pair (rpm ↔ ω, N·m ↔ f_p, µm ↔ u, Hz).

**A tooth-pair excitation is its own pair.**  An excitation given as a tooth-pair file (``examples/tooth_*.toml``,
:mod:`geardyn.tooth.config`) without a configuration is the pair of that file, never the paper's: z1 from its
``[tooth_pair]``, k0 the mean of its mesh stiffness (potential-energy method), the pinion torque its
``torque_Nm`` (f_p = T1/(r_b1 k0 b_c), balanced), the equivalent mass of solid gear blanks, and b_c, the
backlash and ξ0 from its ``[signature]`` table (defaults 10 µm, 100 µm and 0.05): the model ``geardyn
signature`` runs on the same file (:func:`geardyn.tooth.excitation.pair_model`).  With a configuration, the
configuration's pair gives the scales and the tooth file must have the same pinion teeth, else it is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

from .errors import ModelError

__all__ = ["PairInputs", "ToothPair", "is_tooth_pair_file", "tooth_pair"]

#: Defaults of a tooth-pair file's ``[signature]`` values that set its model's scales (as ``geardyn signature``).
TOOTH_DEFAULTS = {"b_c": 10e-6, "backlash": 100e-6, "xi0": 0.05}


def is_tooth_pair_file(path: Any) -> bool:
    """Whether an excitation file is a tooth-pair file (a ``.toml``; the other tables are ``.nc``, ``.csv``, ``.json``).

    Parameters
    ----------
    path : str or Path or None

    Returns
    -------
    bool
    """
    return path is not None and Path(path).suffix.lower() == ".toml"


@dataclass(frozen=True)
class ToothPair:
    """A tooth-pair file's pair: its excitation table, scales and model parameters.

    Attributes
    ----------
    source : str
        The file.
    name : str
        The pair's name.
    z1, z2 : int
        Teeth of pinion and gear.
    torque : float
        The file's pinion torque (N·m), at which its mesh stiffness is computed.
    table : Excitation
        Its mesh stiffness and STE over its mesh cycles.
    scales : PhysicalScales
        Its scales (k0 the mean mesh stiffness, m_e of solid blanks, R1 = r_b1).
    xi0, fp, D : float
        The non-dimensional mean damping ratio, load and half backlash of its model.
    """

    source: str
    name: str
    z1: int
    z2: int
    torque: float
    table: Any
    scales: Any
    xi0: float
    fp: float
    D: float

    def summary(self) -> dict[str, Any]:
        """The pair in a JSON summary: file, name, teeth, mean mesh stiffness (N/µm) and torque (N·m)."""
        return {
            "source": self.source,
            "name": self.name,
            "z1": self.z1,
            "z2": self.z2,
            "k0_N_per_um": self.scales.k0_N_per_m * 1e-6,
            "mesh_torque_N_m": self.torque,
            "cycles": int(self.table.cycles),
        }


def tooth_pair(path: str | Path) -> ToothPair:
    """Read a tooth-pair file and compute its mesh: the pair that drives a run's physical scales.

    Parameters
    ----------
    path : str or Path
        The TOML file (:mod:`geardyn.tooth.config`).

    Returns
    -------
    ToothPair

    Raises
    ------
    ConfigError, ModelError
        For a file that cannot be read or a pair that cannot be meshed (one line naming the file).
    """
    from .geometry.scales import PhysicalScales
    from .tooth.config import load_case
    from .tooth.excitation import pair_model
    from .tooth.table import table_of

    case = load_case(path)
    ms = case.mesh_stiffness()
    given = {k: case.signature[k] for k in TOOTH_DEFAULTS if k in case.signature}
    values = {**TOOTH_DEFAULTS, **given}
    b_c, backlash, xi0 = values["b_c"], values["backlash"], values["xi0"]
    if not (b_c > 0 and math.isfinite(b_c)) or not (backlash >= 0 and math.isfinite(backlash)):
        raise ModelError(f"{path}: [signature] b_c_um must be > 0 and backlash_um >= 0")
    _, sc = pair_model(ms, 1000.0, b_c=b_c, backlash=backlash, xi0=xi0)
    geo = ms.geometry
    assumed = tuple(["m_e"] + [k for k in ("b_c", "backlash") if k not in given])
    scales = PhysicalScales(
        title=f"{case.name} (tooth pair {geo.gears[0].teeth}/{geo.gears[1].teeth})",
        source=str(path),
        z1=int(sc["z1"]),
        b_c_m=float(b_c),
        k0_N_per_m=float(sc["k0"]),
        m_e_kg=float(sc["m_e"]),
        omega_n_rad_s=float(sc["omega_n"]),
        R1_m=float(geo.r_b[0]),
        R2_m=float(geo.r_b[1]),
        D=0.5 * backlash / b_c,
        assumed=assumed,
        k0_source=f"the mean mesh stiffness of {path} (potential-energy method, {int(ms.cycles)} mesh cycle(s))",
    )
    return ToothPair(
        source=str(path),
        name=case.name,
        z1=int(sc["z1"]),
        z2=int(sc["z2"]),
        torque=float(case.torque),
        table=table_of(ms),
        scales=scales,
        xi0=float(xi0),
        fp=float(ms.force / (sc["k0"] * b_c)),
        D=0.5 * backlash / b_c,
    )


class PairInputs:
    """The files of a run of the pair, each read once, and the model and scales built from them.

    Parameters
    ----------
    config : str or Path, optional
        The configuration file (default: the paper's Table 1 pair, or the pair of a tooth-pair ``excitation``).
    excitation : str or Path, optional
        An excitation table (``.nc``, ``.csv``, ``.json``) or a tooth-pair file (``.toml``).
    evaluation : str, optional
        ``"series"`` or ``"table"``: how the excitation table is evaluated (default: the configuration's, else
        series).

    Examples
    --------
    >>> from geardyn.inputs import PairInputs
    >>> run = PairInputs()  # the paper's pair
    >>> m = run.model(rpm=2000.0)
    >>> round(m.omega, 4), run.scales().z1
    (0.668, 23)
    """

    def __init__(
        self, config: str | Path | None = None, excitation: str | Path | None = None, evaluation: str | None = None
    ) -> None:
        self.config = config
        self.excitation = excitation
        self.evaluation = evaluation

    @cached_property
    def tooth(self) -> ToothPair | None:
        """The pair of a tooth-pair excitation file (read and meshed once), else None."""
        return tooth_pair(self.excitation) if is_tooth_pair_file(self.excitation) else None

    @cached_property
    def loaded(self) -> Any:
        """The configuration (:func:`geardyn.config.load_config`, read once); None for a tooth pair's own run."""
        if self.config is None and self.tooth is not None:
            return None
        from .config import load_config

        cfg = load_config(self.config)
        if self.tooth is not None and cfg.pair is not None and int(cfg.pair.z1) != self.tooth.z1:
            raise ModelError(
                f"excitation: the tooth pair of {self.tooth.source} has z1 = {self.tooth.z1} teeth, the pair of "
                f"{cfg.source} z1 = {cfg.pair.z1}; give a configuration of the same pair, or no --config"
            )
        return cfg

    def scales(self) -> Any:
        """The physical scales of the run's pair: the configuration's, or the tooth-pair file's.

        Returns
        -------
        PhysicalScales
        """
        return self.tooth.scales if self.loaded is None else self.loaded.scales

    @cached_property
    def _table(self) -> Any:
        """The excitation table (read once), or None."""
        if self.excitation is None:
            return None
        if self.tooth is not None:
            return self.tooth.table
        from .tooth.table import read_table

        return read_table(self.excitation)

    def base_model(self, given: dict[str, Any] | None = None) -> Any:
        """The model of the files, before the operating point and the model options.

        Parameters
        ----------
        given : dict, optional
            The model options by keyword (the series options are refused beside an excitation table).

        Returns
        -------
        GearModel
        """
        from .model import GearModel
        from .tooth.excitation import excitation_model
        from .tooth.table import refuse_series_options

        if self.config is None and self.excitation is None and self.evaluation is None:
            return GearModel()
        cfg = self.loaded
        if cfg is None:  # the tooth pair's own model
            t = self.tooth
            base = GearModel(xi0=t.xi0, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=(), fp=t.fp, D=t.D)
            b_c = t.scales.b_c_m
        else:
            if self.evaluation is not None and self.excitation is None and self.evaluation != cfg.model.evaluation:
                raise ModelError(
                    f"--excitation-evaluation {self.evaluation}: needs an excitation table (--excitation FILE, or "
                    '[excitation] of the configuration with evaluation = "table")'
                )
            base, b_c = cfg.model, cfg.b_c
        m = base
        if self.excitation is not None:
            exc = self._table
            if exc.ste is not None and (b_c is None or not math.isfinite(b_c) or b_c <= 0):
                raise ModelError(
                    f"excitation: {self.excitation}: the STE needs the characteristic length b_c; give the "
                    "configuration's gear pair or [excitation] b_c"
                )
            m = excitation_model(
                base, exc, b_c=b_c if exc.ste is not None else 1.0, evaluation=self.evaluation or "series"
            )
        if self.excitation is not None or m.cycles != 1:
            refuse_series_options(given or {})
        return m

    def model(
        self,
        *,
        rpm: float | None = None,
        torque: float | None = None,
        torque_orders: Any = None,
        **values: float | None,
    ) -> Any:
        """The run's model with the operating point and the model options applied (validated).

        Parameters
        ----------
        rpm, torque : float, optional
            Pinion speed (rpm) and pinion torque (N·m, balanced): they set ω and f_p through the scales of the
            run's pair and cannot be combined with ``omega`` / ``fp``.
        torque_orders : list of str, optional
            Torque orders ``ORDER:AMPLITUDE[:PHASE]`` (:func:`geardyn.torque_orders.parse_cli`): orders of the
            pinion speed with amplitudes in N·m for a configuration's gear pair, else orders of the mesh frequency
            with non-dimensional amplitudes.
        **values : float or None
            The registry's model options by keyword (``omega``, ``xi0``, …); ``None`` keeps the files' value.

        Returns
        -------
        GearModel

        Raises
        ------
        ModelError
            For an unknown keyword, an invalid value or a conflicting speed or torque.
        """
        from . import params

        by_dest = {o.dest: o.param for o in params.cli_options()}
        unknown = set(values) - set(by_dest)
        if unknown:
            raise ModelError(f"model options: unknown {sorted(unknown)}; allowed: {sorted(by_dest)}")
        m = self.base_model(values)
        if rpm is not None or torque is not None:
            from .units import operating_overrides

            phys = operating_overrides(
                self.scales(), rpm=rpm, torque=torque, omega=values.get("omega"), fp=values.get("fp")
            )
            values = {**values, **phys}
        for dest, param in by_dest.items():
            if values.get(dest) is not None:
                m = m.with_param(param, values[dest])
        if torque_orders:
            from .torque_orders import parse_cli

            given = [parse_cli(t) for t in torque_orders]
            cfg = self.loaded
            if cfg is not None and cfg.pair is not None:
                from .config import pinion_orders

                given = pinion_orders(cfg, given)
            m = m.replace(torque_orders=m.torque_orders + tuple(given))
        return m

    def summary(self) -> dict[str, Any] | None:
        """What a JSON summary says of a tooth pair that drives the scales (None otherwise)."""
        return None if self.loaded is not None or self.tooth is None else self.tooth.summary()
