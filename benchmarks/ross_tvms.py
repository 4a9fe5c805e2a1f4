"""Side by side: geardyn.tooth against ROSS's GearElementTVMS (potential-energy mesh stiffness), term by term.

    pip install -e ".[bench]"        # ross-rotordynamics 2.3.0 and plotly<6
    PYTHONPATH=src python benchmarks/ross_tvms.py [--z 20,40] [--module-mm 3] [--width-mm 20]

Both use the same pair, steel of ROSS (E, ν), the same bore radius (Sainsot's h_f) and the Hertzian term
of Yang & Sun.  Printed: the mesh stiffness over a mesh cycle (mean, min, max) and, for the pinion's
tooth at contact points along the path, the bending, shear, axial and fillet-foundation compliances of
each code and their ratio.  The script is not imported by the package or its tests.
"""

from __future__ import annotations

import argparse
import math
import warnings

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--z", default="20,40")
    ap.add_argument("--module-mm", type=float, default=3.0)
    ap.add_argument("--width-mm", type=float, default=20.0)
    a = ap.parse_args()
    z1, z2 = (int(x) for x in a.z.split(","))
    m, b = a.module_mm * 1e-3, a.width_mm * 1e-3
    warnings.filterwarnings("ignore")
    from ross.gear_element import GearElementTVMS, Mesh
    from ross.materials import steel

    from geardyn.tooth.energy import hertz_compliance, tooth_compliance
    from geardyn.tooth.geometry import pair_geometry
    from geardyn.tooth.mesh import mesh_stiffness

    E, nu = float(steel.E), float(steel.Poisson)
    geo = pair_geometry(z1, z2, m, face_width=b, E=E, nu=nu)
    bores = [0.5 * rf for rf in geo.r_f]
    geo = pair_geometry(z1, z2, m, face_width=b, E=E, nu=nu, bore1=bores[0], bore2=bores[1])
    g1 = GearElementTVMS(
        n=0, material=steel, width=b, bore_diameter=2 * bores[0], module=m, n_teeth=z1, pr_angle=math.radians(20.0)
    )
    g2 = GearElementTVMS(
        n=1, material=steel, width=b, bore_diameter=2 * bores[1], module=m, n_teeth=z2, pr_angle=math.radians(20.0)
    )
    mesh = Mesh(g1, g2)
    ks_ross = np.asarray(mesh.stiffness_range, dtype=float)
    ms = mesh_stiffness(geo, 100.0, points=256)
    print(
        f"pair z = {z1}/{z2}, m = {a.module_mm} mm, b = {a.width_mm} mm, E = {E / 1e9:g} GPa, nu = {nu:.4f}, "
        f"bore radii = {bores[0] * 1e3:.3f}, {bores[1] * 1e3:.3f} mm"
    )
    print(f"contact ratio: ROSS {mesh.contact_ratio:.5f}, geardyn {geo.eps_alpha:.5f}")
    print(
        f"Hertz k_h (N/um): ROSS {mesh.hertzian_stiffness / 1e6:.2f}, geardyn {b / hertz_compliance(E, nu, E, nu) / 1e6:.2f}"
    )
    for name, k in (("ROSS", ks_ross), ("geardyn", ms.stiffness_unmodified)):
        print(
            f"mesh stiffness {name:8s}: mean {k.mean() / 1e6:8.2f}  min {k.min() / 1e6:8.2f}  max {k.max() / 1e6:8.2f} N/um"
        )
    print(f"ratio of means ROSS/geardyn = {ks_ross.mean() / ms.stiffness_unmodified.mean():.3f}")
    print(
        f"root half angle theta_f (rad): ROSS {float(g1.tooth_dict['root_angle']):.4f} (trochoid fillet of the rack "
        f"cutter), geardyn {geo.sections[0].theta_f:.4f} (radial flank below the base circle)"
    )
    print("\npinion tooth, compliance x 1e-12 m/N (whole face width) at contact radii along the path:")
    print(
        f"{'r (mm)':>8} | {'bend R':>8} {'bend g':>8} | {'shear R':>8} {'shear g':>8} | {'axial R':>8} {'axial g':>8}"
        f" | {'fillet R':>8} {'fillet g':>8}"
    )
    for s in np.linspace(geo.s_A, geo.s_E, 5):
        rho = float(geo.contact_radius(0, s))
        alpha = math.acos(geo.r_b[0] / rho)
        beta = g1._to_tau(alpha)
        ross = [float(f(beta)) for f in (g1._inv_kb, g1._inv_ks, g1._inv_ka, g1._inv_kf)]
        c = tooth_compliance(geo, 0, np.array([rho]))
        ours = [float(x[0]) / b for x in (c.bending, c.shear, c.axial, c.fillet)]
        cells = " | ".join(f"{r * 1e12:8.3f} {o * 1e12:8.3f}" for r, o in zip(ross, ours))
        print(f"{rho * 1e3:8.3f} | {cells}")


if __name__ == "__main__":
    main()
