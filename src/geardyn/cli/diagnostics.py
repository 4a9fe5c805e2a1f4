"""Commands from tooth geometry to vibration signature: ``stiffness`` and ``signature``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..errors import ModelError
from .app import console
from .options import OUTPUT, Inputs, command, finish, option
from .render import plain, table

STIFFNESS_OPTIONS = [
    option("torque", float | None, help="Pinion torque (N·m) instead of the file's torque_Nm."),
    option(
        "fault",
        list[str] | None,
        help="Add a fault: KIND:key=value,... e.g. crack:gear=0,tooth=0,depth=0.5 (repeatable; lengths in m).",
    ),
    option(
        "cycles",
        int | None,
        help="Mesh cycles computed (default: 1 healthy, z1 or z2 with faults on one gear, the hunting period "
        "lcm(z1, z2) with faults on both).",
    ),
    option("points", int, 64, help="Mesh phases per mesh cycle."),
    option(
        "slices",
        int | None,
        help="Slices across the face width (default 1 spur, 40 helical, crowned or with partial faults).",
    ),
    option("harmonics", int, 8, help="Fourier harmonics of the excitation's period listed."),
    option(
        "table",
        Path | None,
        help="Also write the stiffness and STE table as .csv or .json (an --excitation file for the analyses).",
    ),
    *OUTPUT,
]


def _fault(text: str) -> Any:
    from ..tooth.faults import fault_from_dict

    kind, _, rest = text.partition(":")
    d: dict[str, Any] = {"kind": kind.strip()}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        k, sep, v = item.partition("=")
        if not sep:
            raise ModelError(f"fault: expected key=value in {text!r}, got {item!r}")
        try:
            d[k.strip()] = int(v) if v.strip().lstrip("-").isdigit() else float(v)
        except ValueError:
            d[k.strip()] = v.strip()
    return fault_from_dict(d)


def _teeth(case: Any) -> tuple[int, int]:
    """The teeth of a tooth-pair case's pinion and wheel."""
    return case.geometry.gears[0].teeth, case.geometry.gears[1].teeth


def _case(file: Path, inp: Inputs):
    from ..tooth.config import load_case

    case = load_case(file)
    case.faults = case.faults + [_fault(f) for f in (inp.fault or [])]
    if inp.torque is not None:
        case.torque = float(inp.torque)
    return case


@command("stiffness", STIFFNESS_OPTIONS)
def stiffness_cmd(
    inp: Inputs,
    file: Annotated[Path, typer.Argument(help="Tooth-pair file (TOML: [tooth_pair], [modifications], [[fault]]).")],
) -> None:
    """Mesh stiffness and static transmission error of a spur or helical pair by the potential-energy method,
    healthy or with tooth faults, over the mesh cycle or the hunting period: table, Fourier harmonics, and
    ISO 6336-1 c′ and c_γ beside it."""
    from ..tooth.mesh import default_cycles, mesh_stiffness
    from ..tooth.result import stiffness_dataset, stiffness_summary

    case = _case(file, inp)
    cycles = inp.cycles if inp.cycles is not None else case.mesh.get("cycles")
    points = int(case.mesh.get("points", inp.points))
    n = (cycles or default_cycles(*_teeth(case), case.faults)) * points
    if not 1 <= inp.harmonics <= n // 2:
        raise ModelError(f"harmonics: from 1 to {n // 2} (half the {n} phases computed), got {inp.harmonics}")
    ms = mesh_stiffness(
        case.geometry,
        case.torque,
        faults=case.faults,
        modifications=case.modifications,
        cycles=cycles,
        points=points,
        slices=inp.slices if inp.slices is not None else case.mesh.get("slices"),
    )
    summary = stiffness_summary(ms, harmonics=inp.harmonics)
    summary["name"] = case.name
    ds = stiffness_dataset(ms, summary)
    paths = inp.write(ds, "stiffness")
    if inp.table is not None:
        from ..tooth.table import table_of, write_table

        paths.append(str(write_table(table_of(ms, jumps=True), inp.table, case.name)))
    finish(summary, paths, inp, _show_stiffness)


def _show_stiffness(s: dict[str, Any]) -> None:
    iso = s["iso6336"]
    plain(
        f"{s['name']}: z = {s['z1']}/{s['z2']}, m_n = {s['m_n_mm']:g} mm, β = {s['beta_deg']:g}°, "
        f"b = {s['face_width_mm']:g} mm, ε_α = {s['eps_alpha']:.4f}, ε_β = {s['eps_beta']:.4f}, "
        f"F = {s['force_N']:.5g} N, {s['cycles']} mesh cycle(s), {len(s['faults'])} fault(s)"
    )
    t = table("Mesh stiffness and STE", "quantity", "value")
    rows = [
        ("mean k_m (N/µm)", s["k_mean_N_per_um"]),
        ("min / max k_m (N/µm)", f"{s['k_min_N_per_um']:.5g} / {s['k_max_N_per_um']:.5g}"),
        ("loaded STE mean, p-p (µm)", f"{s['ste_mean_um']:.4g}, {s['ste_peak_to_peak_um']:.4g}"),
        ("mean k_m / b (N/(mm·µm))", iso["mesh_mean"]),
        ("ISO 6336-1 c_γ (N/(mm·µm))", iso["c_gamma_iso"]),
        ("ratio to c_γ", iso["mesh_mean_over_c_gamma"]),
        ("max single pair / b", iso["single_pair_max"]),
        ("ISO 6336-1 c′ (N/(mm·µm))", iso["c_prime_iso"]),
    ]
    for k, v in rows:
        t.add_row(
            k,
            "— (virtual gears: ISO 10300, geardyn geometry)"
            if v is None
            else f"{v:.5g}"
            if isinstance(v, float)
            else str(v),
        )
    console.print(t)
    h = table(
        f"Fourier harmonics (orders of the mesh frequency; Σ|κ| over all = {s['kappa_abs_sum_all']:.4g})",
        "mesh order",
        "κ",
        "φ_k (rad)",
        "STE e_eq (µm)",
        "φ_e (rad)",
        justify="right",
    )
    for o, k, pk, e, pe in zip(s["harmonic_order_of_mesh"], s["kappa"], s["phi_k"], s["ste_harmonics_um"], s["phi_e"]):
        h.add_row(f"{o:.4g}", f"{k:.5g}", f"{pk:.4g}", f"{e:.4g}", f"{pe:.4g}")
    console.print(h)


SIGNATURE_OPTIONS = [
    option(
        "rpm",
        float | None,
        help="Pinion speed (rpm; default the file's [signature] rpm, else 3000; with --system the system's "
        "operating point).",
    ),
    option("revolutions", int | None, help="Pinion revolutions recorded."),
    option(
        "fs",
        float | None,
        help="Sampling rate (Hz; default 20 samples per mesh period and 2.5 per period of the highest mesh "
        "harmonic the model holds; with --system 20 per mesh period and 5 per period of the system's highest "
        "natural frequency).",
    ),
    option("noise", float | None, help="Measurement noise as a share of the signal RMS (0.02; 0 to 1)."),
    option(
        "sweep",
        str | None,
        None,
        "--sweep-depths",
        help="Crack depths d1,d2,... : indicators against the depth of the file's first crack (or a crack on "
        "pinion tooth 0).",
    ),
    option("fault", list[str] | None, help="Add a fault (as for stiffness)."),
    option("torque", float | None, help="Pinion torque (N·m) instead of the file's."),
    option("points", int, 32, help="Mesh phases per mesh cycle of the excitation table."),
    option(
        "system",
        list[Path] | None,
        panel="Multi-DOF system",
        help="A system file (examples/systems): the signature of a bearing sensor, a translational DOF. Once: "
        "the tooth-pair files (or excitation tables) become its mesh's excitation, one run each (none: the "
        "system as given; with --sweep-depths and no file, its mesh's tooth-pair excitation file); twice: "
        "the two systems side by side.",
    ),
    option(
        "sensor",
        str | None,
        panel="Multi-DOF system",
        help="With --system: the sensor, a translational DOF body.x|y|z (default the translation of the mesh's "
        "pinion most nearly along its line of action).",
    ),
    option(
        "mesh",
        str | None,
        panel="Multi-DOF system",
        help="With --system: the mesh that takes the files' excitation and whose pinion and wheel are analysed "
        "(default the reference mesh).",
    ),
    *OUTPUT,
]


def _depths(text: str) -> list[float]:
    try:
        depths = [float(x) for x in text.split(",")]
    except ValueError:
        raise ModelError(f"sweep-depths: comma-separated numbers, got {text!r}") from None
    for d in depths:
        if not 0.0 <= d <= 0.95:  # (a nan fails too)
            raise ModelError(f"sweep-depths: crack depths in [0, 0.95], got {d!r}")
    return depths


def _depth_sweep(inp: Inputs, case: Any, period: int, build: Any) -> tuple[list[float], Any]:
    """The depths of ``--sweep-depths`` and ``make(depth)``: ``build(faults, period, name)`` with the sweep's crack
    (the case's first, else one on pinion tooth 0) at that depth beside the other faults, over the period the
    crack's gear needs."""
    import dataclasses

    from ..tooth.faults import Crack

    depths = _depths(inp.sweep)
    crack = next((f for f in case.faults if isinstance(f, Crack)), Crack(0, 0, 0.0))
    others = [f for f in case.faults if f is not crack]
    period = max(period, _teeth(case)[crack.gear])
    return depths, lambda d: build(others + [dataclasses.replace(crack, depth=d)], period, f"d{d:g}")


def _period(cases: list[Any]) -> int:
    """The excitation period (mesh cycles) every run shares, so that healthy and faulty compare on equal terms."""
    from ..tooth.mesh import default_cycles

    if not cases:
        return 1
    period = max(1, *[c.mesh.get("cycles", 0) or 0 for c in cases])
    return max(period, *[default_cycles(*_teeth(cases[0]), c.faults) for c in cases])


@command("signature", SIGNATURE_OPTIONS)
def signature_cmd(
    inp: Inputs,
    files: Annotated[
        list[Path] | None,
        typer.Argument(
            help="One tooth-pair file, or two (healthy beside faulty); with --system none, one or two tooth-pair files "
            "or excitation tables for its mesh."
        ),
    ] = None,
) -> None:
    """Vibration signature of a pair: the acceleration along the line of action sampled with a once-per-revolution
    tachometer, order spectrum, TSA per shaft, regular/residual/difference signals and the condition indicators;
    healthy beside faulty with two files; indicators against crack depth with --sweep-depths. With --system: the
    same for a bearing sensor (a translational DOF) of a multi-DOF system."""
    from ..signature.run import signature, signature_sweep

    files = list(files or [])
    if inp.system:
        _system_signature(inp, files)
        return
    for name in ("sensor", "mesh"):
        if getattr(inp, name) is not None:
            raise ModelError(f"{name}: --{name} applies with --system")
    if not 1 <= len(files) <= 2:
        raise ModelError(f"files: one or two tooth-pair files, got {len(files)}")
    cases = [_case(f, inp) for f in files]
    first = cases[0].signature
    rpm = inp.rpm if inp.rpm is not None else float(first.get("rpm", 3000.0))
    kw = _record(inp, first)
    kw.update({key: float(first[key]) for key in ("backlash", "b_c", "xi0") if key in first})
    period = _period(cases)
    if inp.sweep:
        case = cases[-1]
        depths, make = _depth_sweep(inp, case, period, lambda faults, p, _: _mesh(case, faults, p, inp.points))
        _finish_sweep(inp, signature_sweep(make, depths, rpm, **kw))
        return
    _finish_runs(inp, [signature(_mesh(c, c.faults, period, inp.points), rpm, label=c.name, **kw) for c in cases])


def _finish_runs(inp: Inputs, runs: list[Any]) -> None:
    """Report the signature of one run, or of two side by side."""
    import json

    from ..signature.run import combine

    ds = combine(runs) if len(runs) > 1 else runs[0]
    finish(json.loads(ds.attrs["summary"]), inp.write(ds, "signature"), inp, _show_signature)


def _record(inp: Inputs, first: dict[str, Any]) -> dict[str, Any]:
    """The recording keywords of a signature run: the options, else the first file's ``[signature]`` values."""
    return {
        "revolutions": inp.revolutions if inp.revolutions is not None else first.get("revolutions"),
        "fs": inp.fs if inp.fs is not None else first.get("fs_Hz"),
        "noise": inp.noise if inp.noise is not None else float(first.get("noise", 0.02)),
    }


def _mesh(case: Any, faults: list[Any], period: int, points: int) -> Any:
    """The mesh stiffness of a tooth-pair case with ``faults`` over ``period`` mesh cycles."""
    from ..tooth.mesh import mesh_stiffness

    return mesh_stiffness(
        case.geometry, case.torque, faults=faults, modifications=case.modifications, cycles=period, points=points
    )


def _finish_sweep(inp: Inputs, ds: Any, **keys: str) -> None:
    """Report a crack-depth sweep: its summary (with ``keys``) and the indicators of each shaft."""
    import json

    summary = {**json.loads(ds.attrs["summary"]), **keys}
    ds.attrs["summary"] = json.dumps(summary)
    summary["indicators"] = {
        k: {sh: [float(v) for v in ds[k].sel(shaft=sh).values] for sh in ds["shaft"].values} for k in ds.data_vars
    }
    finish(summary, inp.write(ds, "signature_sweep"), inp, _show_sweep)


def _show_signature(s: dict[str, Any]) -> None:
    from ..signature.run import INDICATORS

    r0 = s["runs"][0]
    where = f"sensor {r0['sensor']} (mesh {r0['mesh']!r}), " if "sensor" in r0 else ""
    plain(
        f"{where}z = {r0['z1']}/{r0['z2']} at {r0['rpm']:.6g} rpm (mesh {r0['mesh_frequency_Hz']:.5g} Hz), "
        f"fs = {r0['fs_Hz']:g} Hz, {r0['revolutions']} pinion revolutions, excitation period "
        f"{r0['excitation_cycles']} mesh cycles ({r0['harmonics']} harmonics)"
    )
    wheel = all("wheel" in r["indicators"] for r in s["runs"])
    t = table("Condition indicators (TSA of the pinion" + (" | of the wheel)" if wheel else ")"), "indicator")
    for r in s["runs"]:
        t.add_column(r["label"], justify="right")
    for k in INDICATORS:
        t.add_row(
            k,
            *[
                f"{r['indicators']['pinion'][k]:.4g}" + (f" | {r['indicators']['wheel'][k]:.4g}" if wheel else "")
                for r in s["runs"]
            ],
        )
    console.print(t)


def _show_sweep(s: dict[str, Any]) -> None:
    where = f" (sensor {s['sensor']})" if "sensor" in s else ""
    names = ("kurtosis", "fm4", "na4", "m6a", "fm0", "energy_ratio")
    title = f"Indicators of the pinion's TSA against {s['size_name']} at {s['rpm']:.6g} rpm{where}"
    t = table(title, s["size_name"], *names, justify="right")
    for i, d in enumerate(s["sizes"]):
        t.add_row(f"{d:g}", *[f"{s['indicators'][n]['pinion'][i]:.4g}" for n in names])
    console.print(t)


def _system_signature(inp: Inputs, files: list[Path]) -> None:
    """``geardyn signature --system``: a bearing sensor of one or two systems, the system with the excitation of
    each tooth-pair file (or table) on a mesh, or over a crack-depth sweep of a tooth-pair file."""
    import tempfile

    from ..signature.run import SIGNATURE_HARMONICS
    from ..signature.system import (
        check_sensor,
        default_sensor,
        mesh_shafts,
        system_signature,
        system_signature_sweep,
        with_excitation,
    )
    from ..systems import load_system
    from ..tooth.faults import fault_to_dict
    from ..tooth.table import read_table, table_of, write_table

    paths = list(inp.system)
    if len(paths) > 2:
        raise ModelError(f"system: one or two system files, got {len(paths)}")
    if len(paths) == 2 and (files or inp.sweep):
        raise ModelError(
            "system: two system files are compared as given; give tooth-pair files or --sweep-depths with one --system"
        )
    if len(files) > 2:
        raise ModelError(
            f"files: with --system none, one or two tooth-pair files or excitation tables, got {len(files)}"
        )
    systems = [load_system(p) for p in paths]
    rpm = inp.rpm if inp.rpm is not None else systems[0].scaling.rpm_from_omega(systems[0].omega)
    systems = [s.with_param("omega", s.scaling.omega_from_rpm(rpm)) for s in systems]
    s0 = systems[0]
    mesh = inp.mesh
    z1, z2, _ = mesh_shafts(s0, mesh)
    dof = inp.sensor if inp.sensor is not None else default_sensor(s0, mesh)
    for s in systems:
        check_sensor(s, dof)
        mesh_shafts(s, mesh)
    desc_mesh = next(m for m in s0.description.meshes if m.name == (mesh or s0.scaling.reference))
    tooth = [f for f in files if f.suffix.lower() == ".toml"]
    if inp.sweep and not files:
        if desc_mesh.excitation is None or not desc_mesh.excitation.lower().endswith(".toml"):
            raise ModelError(
                f"sweep-depths: give the tooth-pair file whose crack is swept (mesh {desc_mesh.name!r} "
                f"of the system has no tooth-pair excitation file)"
            )
        tooth = [Path(desc_mesh.excitation)]
    if (inp.fault or inp.torque is not None) and not tooth:
        raise ModelError("fault: --fault and --torque apply to tooth-pair files")
    cases = {f: _case(f, inp) for f in tooth}
    for f, c in cases.items():
        zc = _teeth(c)
        if zc[0] != z1 or (z2 is not None and zc[1] != z2):
            raise ModelError(
                f"{f}: z = {zc[0]}/{zc[1]}, but mesh {desc_mesh.name!r} of the system has "
                f"{z1}/{z2 if z2 is not None else '?'} teeth"
            )
        z2 = zc[1]
    kw = {**_record(inp, next(iter(cases.values())).signature if cases else {}), "z2": z2}
    period = _period(list(cases.values()))
    H = None if desc_mesh.excitation_harmonics is not None else SIGNATURE_HARMONICS
    tmp = tempfile.TemporaryDirectory()

    def on_mesh(path, n):  # the system with the table at ``path`` (n harmonics) as the mesh's excitation
        return with_excitation(s0, mesh, path, None if H is None else min(H, n))

    def excited(case, faults, p, name):
        ms = _mesh(case, faults, p, inp.points)
        return on_mesh(write_table(table_of(ms), Path(tmp.name) / f"{name}.csv"), ms.stiffness.size // 2)

    with tmp:
        if inp.sweep:
            case = cases[tooth[-1]]
            depths, make = _depth_sweep(inp, case, period, lambda faults, p, name: excited(case, faults, p, name))
            ds = system_signature_sweep(make, depths, dof=dof, mesh=mesh, **kw)
            _finish_sweep(inp, ds, system=str(paths[0]), excitation=str(tooth[-1]))
            return
        runs_in = [  # (system, label, summary keys)
            (
                excited(cases[f], cases[f].faults, period, f.stem),
                cases[f].name,
                {"excitation": str(f), "faults": [fault_to_dict(x) for x in cases[f].faults]},
            )
            if f in cases
            else (on_mesh(f, read_table(f).stiffness.size // 2), f.stem, {"excitation": str(f)})
            for f in files
        ] or [(s, p.stem, {"excitation": None}) for s, p in zip(systems, paths)]
        labels = [r[1] for r in runs_in]  # a label given twice is numbered
        runs = [
            system_signature(
                s,
                dof,
                mesh=mesh,
                label=lab if labels.count(lab) == 1 else f"{lab} ({i + 1})",
                **kw,
                extra={"system": str(paths[min(i, len(paths) - 1)]), **keys},
            )
            for i, (s, lab, keys) in enumerate(runs_in)
        ]
    _finish_runs(inp, runs)
