"""The parameter registry: one row per parameter family of the non-dimensional model.

Everything that names a model parameter is generated from :data:`FAMILIES`: the name grammar
(:func:`canonical_param`: ``omega``, ``xi0``, ``xi1``…, ``kappa1``…, ``fp``, ``eps1``… with alias ``fe``,
``D`` with alias ``backlash``, ``phi_c1``…, ``phi_k1``…, ``phi_e1``…), the model's field defaults (the
paper's Table 1, held only here), the CLI model options (:func:`cli_options`), the keys of a configuration
file's ``[model]`` table, the sweep names and the ``units``/``long_name`` of a swept coordinate.

Adding a scalar parameter to the model means one row here, one field in
:class:`~geardyn.model.GearModel` (and its place in :meth:`~geardyn.model.GearModel.coefficients` or the
kernel), one line in ``docs/model.md`` and a test; see ``docs/architecture.md``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from ._docfill import attributes
from .errors import ModelError

__all__ = [
    "ALIASES",
    "EXCITATION_HELP",
    "FAMILIES",
    "LISTING_ORDER",
    "MAX_HARMONICS",
    "PARAMETER_HELP",
    "CliOption",
    "Family",
    "canonical_param",
    "cli_options",
    "describe",
    "family_of",
    "parameter_names",
    "slot",
]

#: Largest number of harmonics of any one Fourier series (of mesh orders: a model whose forcing period spans
#: P mesh cycles takes MAX_HARMONICS·P harmonics of ω/P; :class:`~geardyn.model.GearModel` ``cycles``).
MAX_HARMONICS = 64

#: Help of the common ``--excitation`` option (:mod:`geardyn.tooth.table`).
EXCITATION_HELP = (
    "Mesh stiffness and STE over P mesh cycles (.nc of geardyn stiffness, .csv, .json, or a tooth-pair "
    ".toml) instead of their harmonics; ω stays the mesh frequency, the forcing period is P·2π/ω "
    "(docs/excitation.md)."
)


@dataclass(frozen=True)
@attributes
class Family:
    """One parameter family of the non-dimensional model."""

    #: The field of :class:`~geardyn.model.GearModel` it lives in (``"omega"``, ``"xi"``, ``"phi_c"``…).
    name: str
    #: ``True`` for a Fourier series: its members are named ``<name><k>``, k = 1 … :data:`MAX_HARMONICS`
    #: (``xi`` is the exception: its mean is the separate scalar ``xi0``).
    series: bool
    #: Mathematical symbol (``"ω"``, ``"ξ_k"``…) for labels.
    symbol: str
    #: What it is (used as the ``long_name`` of a swept coordinate; ``{k}`` is replaced by the harmonic).
    long_name: str
    #: ``"1"`` (non-dimensional) or ``"rad"``.
    units: str
    #: The paper's Table 1 value (ω is not given there: 1).
    default: float | tuple[float, ...]
    #: The common CLI option that sets it (for a series, its first harmonic), e.g. ``"--kappa1"``.
    flag: str | None
    #: Help text of that option.
    flag_help: str
    #: For a phase family, the amplitude family it belongs to (a phase for a harmonic not yet present
    #: adds that harmonic with amplitude 0).
    amplitude: str | None = None

    @property
    def pattern(self) -> str:
        """The sweep-name pattern shown in help texts (``"kappaR"`` style for a series)."""
        return f"{self.name}{_INDEX_LETTER.get(self.name, 'K')}" if self.series else self.name


#: The families, in the order of :class:`~geardyn.model.GearModel`'s fields.
FAMILIES: Mapping[str, Family] = MappingProxyType(
    {
        f.name: f
        for f in (
            Family(
                "omega",
                False,
                "ω",
                "mesh frequency ω = ω_e/ω_n",
                "1",
                1.0,
                "--omega",
                "Mesh frequency ω = ω_e/ω_n (non-dimensional, > 0).",
            ),
            Family("xi0", False, "ξ0", "mean damping ratio ξ0", "1", 0.1, "--xi0", "Mean damping ratio ξ0."),
            Family("xi", True, "ξ_{k}", "damping harmonic ξ_{k}", "1", (0.05,), "--xi1", "First damping harmonic ξ1."),
            Family(
                "phi_c",
                True,
                "φ_c{k}",
                "phase of damping harmonic {k}",
                "rad",
                (),
                "--phi-c",
                "Phase of the first damping harmonic (rad).",
                amplitude="xi",
            ),
            Family(
                "kappa",
                True,
                "κ_{k}",
                "stiffness harmonic κ_{k}",
                "1",
                (0.2,),
                "--kappa1",
                "First stiffness harmonic κ1 (|κ| sum < 1).",
            ),
            Family(
                "phi_k",
                True,
                "φ_k{k}",
                "phase of stiffness harmonic {k}",
                "rad",
                (),
                "--phi-k",
                "Phase of the first stiffness harmonic (rad).",
                amplitude="kappa",
            ),
            Family(
                "eps",
                True,
                "ε_{k}",
                "STE harmonic ε_{k}",
                "1",
                (0.5,),
                "--fe",
                "First STE harmonic ε1 (forcing ω² ε1 cos θ; the paper's 0.5).",
            ),
            Family(
                "phi_e",
                True,
                "φ_e{k}",
                "phase of STE harmonic {k}",
                "rad",
                (),
                "--phi-e",
                "Phase of the first STE harmonic (rad).",
                amplitude="eps",
            ),
            Family("fp", False, "f_p", "mean load f_p", "1", 0.2, "--fp", "Mean load f_p (non-dimensional)."),
            Family(
                "D",
                False,
                "D",
                "half backlash D",
                "1",
                1.0,
                "--backlash",
                "Half backlash D (non-dimensional, >= 0; 0 = no backlash).",
            ),
        )
    }
)

#: Other spellings accepted for a parameter name.
ALIASES: Mapping[str, str] = MappingProxyType({"fe": "eps1", "backlash": "D", "b": "D"})

_INDEX_LETTER = {"xi": "K", "phi_c": "K", "kappa": "R", "phi_k": "R", "eps": "L", "phi_e": "L"}
_SERIES_NAMES = tuple(n for n, f in FAMILIES.items() if f.series)
_SERIES = re.compile(r"^(" + "|".join(sorted(_SERIES_NAMES, key=len, reverse=True)) + r")([1-9][0-9]*)$")


def _help_entry(f: Family) -> str:
    if not f.series:
        return {"D": "half backlash (alias backlash)"}.get(f.name, f.long_name)
    k = _INDEX_LETTER[f.name]
    text = f.long_name.replace("{k}", k)
    if f.amplitude is not None:
        return text + " (rad)"
    return text + (" (alias fe = eps1)" if f.name == "eps" else f" ({k} = 1, 2, …)")  # xi, kappa: the index


#: The order in which parameters are listed to people (help texts, CLI options).
LISTING_ORDER = ("omega", "xi0", "xi", "kappa", "fp", "eps", "D", "phi_c", "phi_k", "phi_e")

#: Parameter names accepted by sweeps, :meth:`~geardyn.model.GearModel.get` and ``with_param``.
PARAMETER_HELP: Mapping[str, str] = MappingProxyType(
    {FAMILIES[n].pattern: _help_entry(FAMILIES[n]) for n in LISTING_ORDER}
)


def parameter_names() -> str:
    """The parameter names a sweep or a continuation takes, for a help text: each family's pattern in
    :data:`LISTING_ORDER`, its :data:`ALIASES` in parentheses
    (``"omega, xi0, xiK, …, epsL (fe), D (backlash, b), …"``)."""

    def aliases(f: Family) -> str:
        names = [a for a, target in ALIASES.items() if family_of(target) is f]
        return f" ({', '.join(names)})" if names else ""

    return ", ".join(FAMILIES[n].pattern + aliases(FAMILIES[n]) for n in LISTING_ORDER)


def canonical_param(name: str) -> str:
    """Canonical spelling of a parameter name; raises :class:`~geardyn.errors.ModelError` for unknown names.

    Parameters
    ----------
    name : str
        A scalar name (``omega``, ``xi0``, ``fp``, ``D``), a series member (``kappa2``, ``phi_e1``…, index
        1 … :data:`MAX_HARMONICS`) or an alias (``fe``, ``backlash``, ``b``).

    Raises
    ------
    ModelError
        If the name is not one of these.
    """
    n = ALIASES.get(name, name) if isinstance(name, str) else name
    if isinstance(n, str):
        f = FAMILIES.get(n)
        if f is not None and not f.series:
            return n
        m = _SERIES.match(n)
        if m and int(m.group(2)) <= MAX_HARMONICS:
            return n
    allowed = ", ".join(PARAMETER_HELP)
    raise ModelError(f"unknown parameter {name!r}; allowed: {allowed} (aliases: fe, backlash)")


def slot(name: str) -> tuple[str, int | None]:
    """(family name, harmonic index from 0) of a parameter name; index ``None`` for a scalar.

    Parameters
    ----------
    name : str
        A parameter name or alias (``kappa2``, ``fe``, ``backlash`` …).

    Returns
    -------
    family : str
    index : int or None

    Raises
    ------
    ModelError
        For a name outside the grammar.
    """
    n = canonical_param(name)
    if n in FAMILIES:  # canonical_param returns a family name only for a scalar
        return n, None
    m = _SERIES.match(n)
    assert m is not None
    return m.group(1), int(m.group(2)) - 1


def family_of(name: str) -> Family:
    """The :class:`Family` of a parameter name.

    Parameters
    ----------
    name : str
        Any name :func:`canonical_param` accepts (a series member gives its series).

    Returns
    -------
    Family
        The registry row (:data:`FAMILIES`); a name outside the grammar raises :class:`ModelError`.
    """
    return FAMILIES[slot(name)[0]]


def describe(name: str) -> tuple[str, str]:
    """(``long_name``, ``units``) of a parameter, e.g. ``("stiffness harmonic κ_2", "1")`` for ``kappa2``.

    Parameters
    ----------
    name : str
        Parameter name (``kappa2``) or alias (``fe``).

    Returns
    -------
    long_name, units : str
        For the Dataset metadata of the parameter (:mod:`geardyn.io`); an unknown name raises
        :class:`ModelError`.
    """
    fam, idx = slot(name)
    f = FAMILIES[fam]
    return f.long_name.replace("{k}", str(idx + 1) if idx is not None else ""), f.units


@dataclass(frozen=True)
class CliOption:
    """A common model option of the command line: its flag, the parameter it sets and its help.

    Parameters
    ----------
    flag : str
        The option (``--xi0``).
    param : str
        The canonical parameter it sets.
    help : str
        Its help text.
    """

    flag: str
    param: str
    help: str

    @property
    def dest(self) -> str:
        """The Python keyword it is passed as (``--phi-c`` → ``phi_c``)."""
        return self.flag.lstrip("-").replace("-", "_")


def cli_options() -> tuple[CliOption, ...]:
    """The model options every analysis command takes, generated from :data:`FAMILIES`."""
    return tuple(
        CliOption(f.flag, canonical_param(f.name + "1" if f.series else f.name), f.flag_help)
        for f in (FAMILIES[n] for n in LISTING_ORDER)
        if f.flag is not None
    )
