"""geardyn Python API tutorial: from the non-dimensional model to rpm, µm and newtons.

Run it as a script (``python examples/tutorial.py [OUTPUT_DIR]``); ``tests/test_docs.py`` runs it on
every test run, so every line here works.  The runs are kept short (few transient periods, small
grids) so that it finishes in seconds; real studies use the defaults (300 transient periods, 200
recorded) or more.

Sections:

1. the non-dimensional model and one steady response;
2. the paper's gear pair from its configuration, an operating point in rpm and N·m;
3. physical outputs: dynamic transmission error, mesh force, dynamic factor, Hz;
4. a gear pair built in Python;
5. Lyapunov exponents and a periodic orbit with its Floquet multipliers;
6. a frequency sweep against pinion speed, saved to NetCDF and drawn from the file.
"""

from __future__ import annotations

import sys
import tempfile
from math import radians
from pathlib import Path

import numpy as np

import geardyn
from geardyn import GearModel, IntegrationOptions, PhysicalScales, SpiralBevelGearPair, load_config, simulate

#: Short runs for the tutorial (real studies: IntegrationOptions() = 300 transient, 200 recorded periods).
QUICK = IntegrationOptions(transient=100, periods=32)


def main(out_dir: Path) -> dict:
    results = {}

    # ------------------------------------------------------------------ 1. non-dimensional model
    # The paper's Table 1 values are the defaults: ξ0 = 0.1, ξ1 = 0.05, κ1 = 0.2, f_p = 0.2,
    # ε1 = 0.5 (its "f_e = 0.5 ω² cos θ"), D = 1.  Only ω has to be chosen.
    model = GearModel(omega=0.8)
    res = simulate(model, QUICK)
    s = res.summary
    print(f"1. ω = {model.omega}: {s['motion']}, {s['impact']}, amplitude {s['amplitude']:.4f} (units of b_c)")
    print(f"   Poincaré points: {np.round(res.poincare[-2:], 4).tolist()}")
    results["nondimensional"] = s

    # Any parameter can be set by name, including higher harmonics (each with its phase):
    model2 = model.with_param("kappa2", 0.05).with_param("phi_k2", 0.5)
    print(f"   with a second stiffness harmonic: κ = {model2.kappa}, φ_k = {model2.phi_k}")

    # ------------------------------------------------------------------ 2. the paper's pair
    # load_config() without a file gives the paper's Table 1 pair; its mean mesh stiffness is not
    # in the paper and is assumed: k0 = face width 100 mm × c_γ 20 N/(mm·µm) = 2000 N/µm.
    cfg = load_config()
    print(
        f"2. {cfg.title}: R1 = {cfg.pair.R1 * 1e3:.3f} mm, m_e = {cfg.pair.m_e:.3f} kg, "
        f"k0 = {cfg.pair.k0_mean * 1e-6:.0f} N/µm, f_n = {cfg.pair.omega_n / 2 / np.pi:.1f} Hz"
    )
    print(f"   assumed inputs: {', '.join(cfg.assumed)}")
    at = cfg.at(rpm=2400, torque=1500)  # pinion speed (rpm) and pinion torque (N·m, balanced)
    print(f"   2400 rpm, 1500 N·m → ω = {at.model.omega:.5f}, f_p = {at.model.fp:.5f}")
    scales = PhysicalScales.from_config(cfg)
    print(
        f"   and back: ω = 1 is {scales.rpm_from_omega(1.0):.1f} rpm; f_p = 0.2 is {scales.torque_from_fp(0.2):.1f} N·m"
    )

    # ------------------------------------------------------------------ 3. physical outputs
    res = simulate(at.model, QUICK)
    ds = geardyn.add_physical(res.to_dataset(), scales)  # adds rpm, µm, N, Hz variables
    p = geardyn.simulate_physical(ds)
    print(
        f"3. at {p['rpm']:.0f} rpm: dynamic factor {p['dynamic_factor']:.3f}, max mesh force "
        f"{p['mesh_force_max_N'] / 1e3:.2f} kN (static {p['static_force_N'] / 1e3:.2f} kN), "
        f"DTE RMS {p['dte_rms_um']:.2f} µm"
    )
    for peak in p["spectrum_peaks"][:3]:
        print(
            f"   spectral line: order {peak['order']:g} = {peak['frequency_Hz']:.1f} Hz, {peak['amplitude_um']:.2f} µm"
        )
    # The mesh force time history, F_n/(k0 b_c) = 2ξ(θ) u' + K(θ) f(u; D), in newtons:
    F = ds["mesh_force_N"]
    print(f"   mesh force samples: {F.size}, units {F.attrs['units']}, over {ds['time_s'].values[-1] * 1e3:.2f} ms")
    results["physical"] = p

    # ------------------------------------------------------------------ 4. a pair built in Python
    pair = SpiralBevelGearPair(
        z1=11,
        z2=41,
        m_mn=3.68e-3,
        beta_m=radians(35),
        alpha_n=radians(20),
        j_n=0.1e-3,
        I1=8e-4,
        I2=0.05,
        face_width=34e-3,
    )
    m_car = pair.gear_model(rpm=2500, torque=300)
    print(
        f"4. car-axle sized pair: δ1 = {np.degrees(pair.delta1):.2f}°, R1 = {pair.R1 * 1e3:.2f} mm, "
        f"2500 rpm → ω = {m_car.omega:.4f}, 300 N·m → f_p = {m_car.fp:.4f}"
    )

    # ------------------------------------------------------------------ 5. exponents and an orbit
    ly = geardyn.lyapunov_spectrum(GearModel(omega=0.8), IntegrationOptions(transient=100, periods=200))
    lam = ly.exponents
    print(
        f"5. Lyapunov exponents at ω = 0.8: {lam[0]:+.4f}, {lam[1]:+.4f} per unit τ "
        f"(sum {lam.sum():+.4f}, −2ξ0 = {-2 * 0.1:+.4f})"
    )
    orb = geardyn.shoot(GearModel(omega=0.8), 2)  # Newton on the 2-period map
    fl = orb.floquet
    print(
        f"   period-2 orbit: converged {orb.converged}, state {np.round(orb.state, 6).tolist()}, "
        f"|μ| = {np.round(np.abs(fl.multipliers), 4).tolist()}, stable {fl.stable}"
    )
    # a stable orbit's largest exponent is ln|μ_max| / (n T):
    print(f"   ln|μ_max|/(2T) = {np.log(np.abs(fl.multipliers).max()) / (2 * orb.model.period):+.4f}")
    results["lyapunov"] = lam.tolist()

    # ------------------------------------------------------------------ 6. sweep, save, plot
    rpm = np.linspace(1500, 2100, 7)
    omegas = scales.omega_from_rpm(rpm)
    sweep = geardyn.bifurcation(
        cfg.model,
        "omega",
        omegas,
        mode="continue",
        sweep="both",
        options=IntegrationOptions(transient=60, periods=16),
        settle_periods=0,
    )
    sweep = geardyn.add_physical(sweep, scales)  # adds the rpm coordinate and amplitudes in µm
    for r, up, down in zip(
        sweep["rpm"].values,
        sweep["amplitude_um"].sel(sweep="up").values,
        sweep["amplitude_um"].sel(sweep="down").values,
    ):
        print(f"6. {r:6.0f} rpm: half peak-to-peak DTE up {up:6.2f} µm, down {down:6.2f} µm")
    path = geardyn.write_netcdf(sweep, out_dir / "sweep.nc")
    again = geardyn.read_netcdf(path)
    figures = again.geardyn.plot(out_dir)  # the same figures as `geardyn plot sweep.nc`
    print(f"   wrote {path.name} and {', '.join(f.name for f in figures)} into {out_dir}")
    results["figures"] = [str(f) for f in figures]
    return results


if __name__ == "__main__":
    if len(sys.argv) > 1:
        target = Path(sys.argv[1])
        target.mkdir(parents=True, exist_ok=True)
        main(target)
    else:  # without a directory the files go to a temporary one, removed at the end (say so)
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp))
            print(
                "(the files were written into a temporary directory, removed now; give a directory to keep them: "
                "python examples/tutorial.py OUT)"
            )
