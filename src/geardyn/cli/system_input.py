"""``--system FILE``: what the option gives the commands, a multi-DOF system (``examples/systems/*.toml``).

:data:`geardyn.cli.options.SYSTEM` is the option group of the commands that run on a multi-DOF system; with
``--system`` their :meth:`~geardyn.cli.options.Inputs.model` is the system of the file (:func:`load_cli_system`:
``--omega`` / ``--rpm`` and the model options applied to its reference mesh), and the command runs its own analysis
on it; the summary adds ``meshes`` (:func:`mesh_summary`), printed as one more table
(:func:`geardyn.cli.render.meshes`).
"""

from __future__ import annotations

from typing import Any

from ..errors import ModelError

__all__ = ["load_cli_system", "coordinates", "mesh_summary"]


def load_cli_system(values: dict[str, Any]):
    """The system of ``--system`` with ``--omega``/``--rpm`` and the model options applied to its reference mesh.

    Parameters
    ----------
    values : dict
        The command's shared option values (``system`` the file).

    Returns
    -------
    SystemModel
    """
    from .. import params
    from ..systems import load_system

    path = values["system"]
    if values.get("config") is not None:
        raise ModelError("system: --system and --config cannot be combined (the system file holds the gear data)")
    if values.get("torque") is not None or values.get("fp") is not None:
        raise ModelError("system: the loads come from the system file; --torque and --fp do not apply with --system")
    if values.get("excitation") is not None:
        raise ModelError(
            'excitation: with --system a mesh\'s excitation table is the key excitation = "FILE" of '
            "that mesh in the system file (docs/excitation.md); --excitation applies to --config"
        )
    s = load_system(path)
    if values.get("rpm") is not None and values.get("omega") is not None:
        raise ModelError("rpm: give --rpm or --omega, not both")
    if values.get("rpm") is not None:
        if not float(values["rpm"]) > 0:  # nan too
            raise ModelError(f"rpm: pinion speed must be > 0 rpm, got {float(values['rpm']):g} rpm")
        s = s.with_param("omega", s.scaling.omega_from_rpm(float(values["rpm"])))
    for o in params.cli_options():  # --omega first, as the registry lists it (--fp is refused above)
        v = values.get(o.dest)
        if v is not None:
            s = s.with_param(o.param, float(v))
    check_counts(values)
    _forcing_period_note(s, values)
    _unsettled_note(s, values)
    return s


def check_counts(values: dict[str, Any]) -> None:
    """Refuse an impossible ``--dtau``, ``--periods`` or numeric ``--transient`` before the run's notes are said
    (the one line of the refusal, not after a note built on the impossible count), with the messages of
    :func:`geardyn.validate.options`."""
    from .. import validate

    t = values.get("transient")
    if isinstance(t, str):  # a count written as text; auto and Ncycles are read later
        t = int(t) if t.strip().lstrip("+-").isdigit() else None
    validate.counts(values.get("dtau"), t, values.get("periods"))


def _unsettled_note(s: Any, values: dict[str, Any]) -> None:
    """Before a run (not with ``--json``), one line on stderr when the transient (a count, not ``auto``) leaves the
    least damped mode undecayed (:func:`geardyn.analysis.settle.unsettled_note`)."""
    from ..analysis.settle import unsettled_note
    from .app import say_error

    p = s.period_multiple()
    if p is None or values.get("transient") is None or values.get("json_out"):
        return
    # the transient alone; none at a default with a long-run plan, which settles by the physics (Inputs.long_run)
    n = _periods_given({**values, "periods": 0}, p)
    if n > 0 and (note := unsettled_note(s, n)):
        say_error(note)


def _forcing_period_note(s: Any, values: dict[str, Any]) -> None:
    """Before a run, one line on stderr when the forcing period spans several reference mesh cycles: how many, and
    the RK4 steps that makes (a gearbox's stages repeat together only after their least common period)."""
    import math
    from fractions import Fraction

    from ..systems.assemble import MAX_RATIO_DENOMINATOR
    from .app import say_error

    p = s.period_multiple()
    if p is None or p <= 1:
        return
    parts = [
        f"{m.name} at {Fraction(m.ratio * m.cycles).limit_denominator(MAX_RATIO_DENOMINATOR)}"
        for m in s.meshes
        if m.name != s.scaling.reference
    ]
    parts += [f"order at {r}" for r, _, _ in getattr(s, "orders", ())]
    parts += [  # rolling bearings: their ball-pass frequency
        f"ball pass of {b.name} at {Fraction(b.ratio).limit_denominator(MAX_RATIO_DENOMINATOR)}"
        for b in getattr(s, "bearings", ())
    ]
    text = f"forcing period: {p} cycles of mesh {s.scaling.reference!r} (the least common period; {', '.join(parts)})"
    dtau = values.get("dtau")
    if dtau:
        steps = math.ceil(p * 2.0 * math.pi / s.omega / float(dtau))
        text += f"; at omega = {s.omega:.4g}, {steps:,} RK4 steps per forcing period (dtau = {float(dtau):g})"
        n = _periods_given(values, p)
        if n:
            text += f", {steps * n:,} for --transient + --periods = {n} forcing periods"
    say_error(text)


def _periods_given(values: dict[str, Any], p: int) -> int:
    """--transient + --periods in forcing periods (``Ncycles`` converted with ``p``); 0 when the transient is
    ``auto`` or not yet known (not given, with a forcing period of several cycles: the long-run plan says it)."""
    from ..analysis.settle import transient_cycles

    if values.get("transient_default") and p > 1:
        return 0
    t = values.get("transient") or 0
    if isinstance(t, str):
        cycles = transient_cycles(t)
        if cycles is not None:
            t = -(-cycles // p)
        elif t.strip().isdigit():
            t = int(t.strip())
        else:
            return 0
    return int(t) + int(values.get("periods") or 0)


def coordinates(s: Any, text: str | None, n: int) -> list[int] | None:
    """The state coordinates of ``--coords`` (DOF labels, ``label'`` for a rate, or indices), at least ``n``.

    Parameters
    ----------
    s : System
        The system whose state is indexed.
    text : str or None
        The option's value, comma-separated.
    n : int
        How many coordinates are needed.

    Returns
    -------
    list of int or None
        None without ``--coords``.
    """
    from ..analysis.basins import coordinate_index

    if text is None:
        return None
    idx = [coordinate_index(s, p) for p in str(text).split(",") if p.strip()]
    if len(idx) < n:
        raise ModelError(f"coords: give {n} coordinate(s) separated by commas, got {text!r}")
    return idx


def mesh_summary(
    s: Any, summary: dict[str, Any], ds: Any = None, result: Any = None, state0: Any = (0.0, 0.0)
) -> dict[str, Any]:
    """``summary`` with what a system adds.

    That is ``meshes`` of a sweep's Dataset (:func:`geardyn.systems.report.result_meshes`) or of a continuation's
    branches, the reference mesh's forces and dynamic factor for one point, and a note on a system without
    excitation.

    Parameters
    ----------
    s : SystemModel
        The system of the command.
    summary : dict
        The command's summary (the pair's keys).
    ds : xarray.Dataset, optional
        A sweep, map or basin result (its per-mesh variables).
    result : ContinuationResult, optional
        A continuation (its per-element extremes along the branches).
    state0 : (u0, v0)
        The initial state of the command (for the note on a system without excitation).

    Returns
    -------
    dict
    """
    import numpy as np

    from ..labels import IMPACT_LABELS, impact_state
    from ..systems.notes import excitation_note
    from ..systems.report import result_meshes

    if ds is not None:
        summary["meshes"] = result_meshes(ds)
    elif result is not None:
        ext = [b.extrema for b in result.branches if b.extrema is not None]
        ext = np.concatenate(ext) if ext else np.zeros((0, len(s.elements), 2))
        um = s.scaling.b_c_m * 1e6
        amp = 0.5 * (ext[:, :, 1] - ext[:, :, 0])
        summary["meshes"] = [
            {
                "name": e.name,
                "backlash_um": e.gap * um,
                "u_min": ext[:, i, 0].tolist(),
                "u_max": ext[:, i, 1].tolist(),
                "amplitude": amp[:, i].tolist(),
                "dte_amplitude_um": (amp[:, i] * um).tolist(),
                "impact": [IMPACT_LABELS[impact_state(float(lo), e.gap)] for lo in ext[:, i, 0]],
                "dynamic_factor": None,
            }
            for i, e in enumerate(s.elements)
            if e.kind == "mesh"
        ]
        r = s.rigid_basis().shape[1]
        summary["rigid_body_modes"] = r
        if r:
            summary["notes"] = summary["notes"] + [
                f"{2 * r} multipliers equal to 1 belong to the rigid-body mode(s) "
                f"and are left out; the multipliers listed are the elastic ones"
            ]
    ref = next((m for m in summary.get("meshes", []) if m["name"] == summary.get("reference_mesh")), None)
    if ref is not None:  # one point: the reference mesh's forces and dynamic factor, as the pair's keys
        for k in (
            "dynamic_factor",
            "mesh_force_max_N",
            "mesh_force_min_N",
            "contact_force_max_N",
            "contact_force_min_N",
            "static_force_N",
            "dte_min_um",
            "dte_max_um",
            "dte_amplitude_um",
        ):
            summary[k] = ref.get(k)
    if (note := excitation_note(s, tuple(state0))) is not None:
        summary["note"] = note
    return summary
