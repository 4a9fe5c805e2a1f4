"""Linear modes of a geared two-shaft rotor: geardyn's gearbox against ROSS, side by side.

The shared model is ``benchmarks/peer_gearbox_model.toml``: two steel shafts (Timoshenko elements with
Cowper's shear coefficient, 8 and 10 elements), a spur pair of 23/56 teeth (module 4 mm, 20°) with a mesh
stiffness of 400 N/µm, isotropic bearings, and an axial spring on one bearing of each shaft.  ROSS
(ross-rotordynamics 2.3.0: ``ShaftElement``, ``GearElement``, ``BearingElement``, ``MultiRotor``) builds the
same model from the same numbers; both give the undamped natural frequencies at standstill (no gyroscopic
terms).  The isotropic bearings make the frequencies independent of the direction of the line of centres,
which the two tools define differently.

With ``--rpm N`` the two also compare at the driver's speed N rpm with the gyroscopic terms: ROSS's
``run_modal(speed)`` (the driven rotor's gyroscopic matrix at −23/56 of the driver's speed) against geardyn's
modes of the same file with ``[gearbox] gyroscopic = true`` (``modal_analysis(desc, rpm=N)``), forward and
backward whirl split.

Usage::

    python benchmarks/peer_gearbox_ross.py [--ross-python PATH] [--json OUT] [--rpm N --json-gyro OUT]

ROSS needs ``plotly<6`` (the ``bench`` extra); when it is not importable by this interpreter, give a Python
that has it with ``--ross-python`` (the ROSS side runs there and prints its frequencies as JSON).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "peer_gearbox_model.toml"
MODES = 40  # the lowest elastic modes compared
TOL = 0.01  # the agreement asked: 1 %


def ross_frequencies(rpm: float = 0.0) -> list[float]:
    """The natural frequencies (Hz) of the shared model in ROSS at the driver's speed (rpm), ascending, rigid-body
    modes left out."""
    import numpy as np
    import ross as rs

    steel = rs.Material(name="steel_peer", rho=7850.0, E=2.1e11, Poisson=0.3)
    rb1 = 23 * 4e-3 / 2 * math.cos(math.radians(20))
    rb2 = 56 * 4e-3 / 2 * math.cos(math.radians(20))

    def rotor(n_el, length, d, gear, kr, nb_gear):
        shaft = [
            rs.ShaftElement(L=length / n_el, idl=0.0, odl=d, material=steel, shear_method_calc="cowper")
            for _ in range(n_el)
        ]
        bearings = [
            rs.BearingElement(n=0, kxx=kr, kyy=kr, kzz=1e8, cxx=0.0),
            rs.BearingElement(n=n_el, kxx=kr, kyy=kr, cxx=0.0),
        ]
        return rs.Rotor(shaft, [gear], bearings)

    pinion = rs.GearElement(
        n=4, m=3.2, Id=0.0047, Ip=0.0085, n_teeth=23, base_diameter=2 * rb1, pr_angle=math.radians(20)
    )
    wheel = rs.GearElement(
        n=5, m=19.5, Id=0.155, Ip=0.305, n_teeth=56, base_diameter=2 * rb2, pr_angle=math.radians(20)
    )
    r1 = rotor(8, 0.4, 0.05, pinion, 2e8, 4)
    r2 = rotor(10, 0.5, 0.06, wheel, 3e8, 5)
    mr = rs.MultiRotor(r1, r2, coupled_nodes=(4, 5), gear_mesh_stiffness=4e8, orientation_angle=0.0)
    modal = mr.run_modal(speed=2 * math.pi * rpm / 60, num_modes=2 * MODES + 20, sparse=False)
    wn = np.sort(np.asarray(modal.wn, dtype=float))
    f = wn / (2 * math.pi)
    return [float(x) for x in f if x > 1e-3 * f.max()]


def geardyn_frequencies(rpm: float | None = None) -> list[float]:
    """geardyn's natural frequencies (Hz) of the shared model: at standstill, or with the gyroscopic terms at the
    driver's speed ``rpm`` (the file with ``[gearbox] gyroscopic = true``)."""
    import tempfile

    from geardyn.systems import load_description
    from geardyn.systems.modes import modal_analysis

    if rpm is None:
        res = modal_analysis(load_description(MODEL))
    else:
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / MODEL.name
            path.write_text(MODEL.read_text() + "\n[gearbox]\ngyroscopic = true\n")
            res = modal_analysis(load_description(path), rpm=rpm)
    return [float(x) for x in res.frequencies_hz if x > 0]


def _compare(ours: list[float], ross: list[float], what: str) -> tuple[int, float]:
    n = min(MODES, len(ross), len(ours))
    rows = [(i + 1, ours[i], ross[i], ours[i] / ross[i] - 1) for i in range(n)]
    print(what)
    print(f"{'mode':>4} {'geardyn [Hz]':>14} {'ROSS [Hz]':>14} {'difference':>11}")
    for i, g, r, d in rows:
        print(f"{i:>4} {g:>14.6g} {r:>14.6g} {d:>+11.2e}")
    worst = max(abs(d) for *_, d in rows)
    print(f"largest difference over the lowest {n} elastic modes: {worst:.3e} (asked: below {TOL:g})")
    return n, worst


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ross-python", default=None, help="a Python with ross-rotordynamics 2.3.0 and plotly<6")
    ap.add_argument("--json", default=None, help="write the numbers here")
    ap.add_argument("--ross-only", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--rpm", type=float, default=None, help="also compare at this driver speed (rpm), gyroscopic")
    ap.add_argument("--json-gyro", default=None, help="write the numbers at --rpm here")
    a = ap.parse_args(argv)
    if a.ross_only:
        print(json.dumps(ross_frequencies(a.rpm or 0.0)))
        return 0

    def ross(rpm: float | None) -> list[float]:
        if not a.ross_python:
            return ross_frequencies(rpm or 0.0)
        cmd = [a.ross_python, __file__, "--ross-only"] + ([] if rpm is None else ["--rpm", repr(rpm)])
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1]
        return json.loads(out)

    ours, theirs = geardyn_frequencies(), ross(None)
    n, worst = _compare(ours, theirs, "standstill")
    if a.json:
        Path(a.json).write_text(
            json.dumps({"geardyn_hz": ours[:n], "ross_hz": theirs[:n], "largest_relative_difference": worst}, indent=1)
        )
    ok = worst < TOL
    if a.rpm is not None:
        ours_g, theirs_g = geardyn_frequencies(a.rpm), ross(a.rpm)
        n_g, worst_g = _compare(ours_g, theirs_g, f"at {a.rpm:g} rpm of the driver, gyroscopic terms on")
        # the speed splits the whirl: the gyroscopic comparison is not the standstill one again
        split = max(abs(g / s - 1) for g, s in zip(ours_g[:n_g], ours[:n_g]))
        print(f"largest change from standstill over those modes: {split:.3e}")
        if a.json_gyro:
            Path(a.json_gyro).write_text(
                json.dumps(
                    {
                        "rpm": a.rpm,
                        "geardyn_hz": ours_g[:n_g],
                        "ross_hz": theirs_g[:n_g],
                        "largest_relative_difference": worst_g,
                        "largest_change_from_standstill": split,
                    },
                    indent=1,
                )
            )
        ok = ok and worst_g < TOL
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
