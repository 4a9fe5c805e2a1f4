"""geardyn's tooth stiffness against an independent potential-energy implementation, ISO 6336-1 and a 2-D
finite-element model, on three standard spur pairs; writes the tables into docs/excitation.md and the figures.

    pip install -e ".[validate]"          # scikit-fem
    PYTHONPATH=src python benchmarks/tooth_fe.py [--quick] [--no-docs]

The pairs are the tooth-pair files examples/tooth_19_48.toml, tooth_23_47.toml and tooth_30_30.toml (steel,
20°, ISO 53 profile A, bore radius 0.25 × pitch radius).  The independent models are in
``benchmarks/tooth_fe_model.py`` (their own outline in closed form; nothing of geardyn).  Printed and written:

1. mean mesh stiffness per face width: geardyn, the quadrature reference, ISO 6336-1 c_γα; curve shape RMS;
2. tooth compliance (bending + shear + axial + foundation) at seven points along each gear's contact path:
   geardyn against FE (plane stress, the section displacement along the force), with mesh convergence;
3. the stiffness reduction of a root crack of 25 % and 50 % on the pinion against FE, the slit's tip refined:
   geardyn, and for comparison the strip's factors alone (without the fillet's notch), the section law and the
   limiting-line section laws (to the tooth's tip, to the load point); where the crack starts in both models;
   the crack's FE convergence and its compliance and reduction against depth (19/48);
4. how the bore radius and a thin rim move the mean stiffness (geardyn, FE at the pitch point, ISO's C_R).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from tooth_fe_model import Gear, build_mesh, crack_depth_of, fe_compliance, pair_stiffness  # noqa: E402

from geardyn.tooth.config import load_case  # noqa: E402
from geardyn.tooth.energy import (  # noqa: E402
    cantilever_compliance,
    crack_compliance,
    fillet_compliance,
    hertz_compliance,
    load_point,
    tooth_compliance,
)
from geardyn.tooth.faults import Crack  # noqa: E402
from geardyn.tooth.geometry import pair_geometry  # noqa: E402
from geardyn.tooth.mesh import mesh_stiffness  # noqa: E402
from geardyn.tooth.result import iso_beside  # noqa: E402

PAIRS = ("tooth_19_48", "tooth_23_47", "tooth_30_30")
BEGIN, END = "<!-- tooth_fe:begin -->", "<!-- tooth_fe:end -->"
N_LOAD = 7
#: Halvings of the cells at the FE slit's tip in the crack runs (converged: the crack convergence table).
TIP = 4


def _gears(geo):
    return [
        Gear(int(g.teeth), geo.m_n, x=g.x, bore=g.bore_radius, E=g.E, nu=g.nu, h_f=geo.h_f, h_a=geo.h_a)
        for g in geo.gears
    ]


def pe_reference(geo, points=64):
    """Mean stiffness per width and the normalised curves: geardyn, the quadrature reference (both u_f)."""
    ms = mesh_stiffness(geo, 100.0, points=points)
    kg = ms.stiffness / geo.face_width
    g1, g2 = _gears(geo)
    _, kr = pair_stiffness(g1, g2, points=points, u_f="contact")
    _, kf = pair_stiffness(g1, g2, points=points, u_f="force")
    iso = iso_beside(ms)
    return {
        "geardyn": float(kg.mean()),
        "reference": float(kr.mean()),
        "reference_force_lever": float(kf.mean()),
        "shape_rms": float(np.sqrt(np.mean((kg / kg.mean() - kr / kr.mean()) ** 2))),
        "c_gamma_iso": float(iso["c_gamma_iso"]) * 1e9 if iso.get("c_gamma_iso") else float("nan"),
        "curves": (kg, kr),
    }


def load_radii(geo, gear):
    s = np.linspace(geo.s_A, geo.s_E, N_LOAD)
    return geo.contact_radius(gear, s), s


def geardyn_compliance(geo, gear, radii, crack=None):
    return tooth_compliance(geo, gear, radii, crack_depth=crack).total  # bending + shear + axial + fillet (+ crack)


def strip_compliance(geo, gear, radii, crack):
    """geardyn's cracked tooth with the strip's factors alone (no notch): the crack model before the notch."""
    sec = geo.sections[gear]
    i = sec.crack_start
    d, h_l, a1 = load_point(sec, radii)
    t = tooth_compliance(geo, gear, radii)
    return t.total + crack_compliance(crack, float(sec.y[i]), float(sec.h[i]), d, h_l, a1, geo.gears[gear].E)


def limiting_compliance(geo, gear, radii, crack, to="tip"):
    """geardyn's tooth with a section law of the limiting line instead of the fracture term: the band between the
    loaded flank and a straight line from the crack's tip (h_q = (1 − crack) h_c at y_c) to the loaded flank at
    the tooth's tip (``to="tip"``, the limiting line of Mohammed, Rantatalo & Aidanpää 2013) or at the load point
    (``to="load"``) carries no load in every section above the crack; the foundation unchanged."""
    sec = geo.sections[gear]
    blank = geo.gears[gear]
    d, h_l, a1 = load_point(sec, radii)
    i = sec.crack_start
    y_c, h_q = float(sec.y[i]), (1.0 - crack) * float(sec.h[i])
    out = np.empty(len(d))
    for k in range(len(d)):
        y1, x1 = (float(sec.y[-1]), float(sec.h[-1])) if to == "tip" else (float(d[k]), float(h_l[k]))
        line = h_q + (x1 - h_q) * (sec.y - y_c) / (y1 - y_c)
        lost = np.where((sec.y >= y_c) & (sec.y <= y1), np.clip(sec.h - line, 0.0, None), 0.0)
        pt = slice(k, k + 1)
        kb, ks, ka = cantilever_compliance(sec.y, 2 * sec.h - lost, d[pt], h_l[pt], a1[pt], blank.E, blank.nu)
        kf = fillet_compliance(a1[pt], d[pt] - sec.r_f, sec.r_f, sec.theta_f, blank.bore_radius, blank.E)
        out[k] = (kb + ks + ka + kf)[0]
    return out


#: The crack models compared with the FE slit (the pinion's compliance with a crack of depth d).
CRACK_MODELS = {
    "geardyn": lambda geo, r, d: geardyn_compliance(geo, 0, r, crack=d),
    "strip alone": lambda geo, r, d: strip_compliance(geo, 0, r, d),
    "section law": lambda geo, r, d: tooth_compliance(geo, 0, r, crack_depth=d, crack_model="section").total,
    "limiting line, tip": lambda geo, r, d: limiting_compliance(geo, 0, r, d, "tip"),
    "limiting line, load point": lambda geo, r, d: limiting_compliance(geo, 0, r, d, "load"),
}


def crack_models(geo, radii, depth):
    return {k: f(geo, radii, depth) for k, f in CRACK_MODELS.items()}


def pair_reduction(c1, c0, w, ch):
    """The single-pair stiffness reduction of a tooth compliance c0 → c1 with the mating tooth w and Hertz ch,
    averaged over the load points."""
    return float(np.mean(1 - (c0 + w + ch) / (c1 + w + ch)))


def crack_start(geo):
    """Where the crack starts on the pinion: (radius, half thickness) of the FE slit's row (the fillet point
    whose tangent makes 30° with the centre line, in closed form) and of geardyn's crack section (m)."""
    _, X, Y = _gears(geo)[0].critical()
    sec = geo.sections[0]
    i = sec.crack_start
    return math.hypot(X, Y), X, math.hypot(float(sec.y[i]), float(sec.h[i])), float(sec.h[i])


def fe_run(geo, gear, level, crack=0.0, tip=0):
    fg_gear = _gears(geo)[gear]
    radii, _ = load_radii(geo, gear)
    fg = build_mesh(fg_gear, radii, level=level, crack=crack, tip=tip)
    t0 = time.perf_counter()
    c = fe_compliance(fg, radii)
    depth = crack_depth_of(fg, crack) if crack else 0.0
    return c, depth, fg.p.shape[1], time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one FE level, no convergence study")
    ap.add_argument("--no-docs", action="store_true", help="print only")
    a = ap.parse_args()
    levels = (1.0,) if a.quick else (0.5, 1.0, 2.0)
    rows_pe, fe_tab, conv_tab, crack_tab, sens_tab = [], [], [], [], []
    data = {}
    for name in PAIRS:
        case = load_case(ROOT / "examples" / f"{name}.toml")
        geo = case.geometry
        z = [g.teeth for g in geo.gears]
        pe = pe_reference(geo)
        rows_pe.append((name, z, geo.m_n, pe))
        data[f"{name}_geardyn"] = pe["curves"][0]
        data[f"{name}_reference"] = pe["curves"][1]
        print(
            f"{name}: mean k/b geardyn {pe['geardyn'] / 1e9:.3f}, reference {pe['reference'] / 1e9:.3f} "
            f"N/(mm um) ratio {pe['geardyn'] / pe['reference']:.6f}, shape RMS {pe['shape_rms'] * 100:.2f} %, "
            f"ISO c_ga {pe['c_gamma_iso'] / 1e9:.3f} ratio {pe['geardyn'] / pe['c_gamma_iso']:.3f}",
            flush=True,
        )
        for gear in (0, 1):
            radii, s = load_radii(geo, gear)
            cg = geardyn_compliance(geo, gear, radii)
            res = {lv: fe_run(geo, gear, lv) for lv in levels}
            c_fe = res[1.0][0]
            fe_tab.append((name, gear, z[gear], radii, cg, c_fe))
            data[f"{name}_g{gear}_radius"] = radii
            data[f"{name}_g{gear}_geardyn"] = cg
            data[f"{name}_g{gear}_fe"] = c_fe
            for lv in levels:
                conv_tab.append((name, gear, lv, res[lv][2], res[lv][0], res[lv][3]))
            print(
                f"  gear {gear} (z = {z[gear]}): geardyn / FE = {np.round(cg / c_fe, 3)}",
                flush=True,
            )
        # the crack on the pinion
        radii, s = load_radii(geo, 0)
        c0 = geardyn_compliance(geo, 0, radii)
        fe0 = fe_tab[-2][5]
        w_r = geardyn_compliance(geo, 1, geo.contact_radius(1, s))
        w_fe = fe_tab[-1][5]
        ch = hertz_compliance(geo.gears[0].E, geo.gears[0].nu, geo.gears[1].E, geo.gears[1].nu)
        start = crack_start(geo)
        for depth in (0.25, 0.5):
            fe_c, d_fe, _, _ = fe_run(geo, 0, 1.0, crack=depth, tip=TIP)
            models = crack_models(geo, radii, d_fe)
            # single-pair stiffness along the path, healthy and cracked, each model with its own wheel tooth
            red = {k: pair_reduction(c, c0, w_r, ch) for k, c in models.items()}
            red_fe = pair_reduction(fe_c, fe0, w_fe, ch)
            ms_h = mesh_stiffness(geo, 100.0, cycles=z[0], points=32)
            ms_c = mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, d_fe)], cycles=z[0], points=32)
            cg = models["geardyn"]
            crack_tab.append(
                (name, depth, d_fe, cg / c0, fe_c / fe0, red, red_fe, ms_c.mean_stiffness / ms_h.mean_stiffness, start)
            )
            data[f"{name}_crack{int(depth * 100)}_geardyn"] = cg / c0
            data[f"{name}_crack{int(depth * 100)}_fe"] = fe_c / fe0
            print(
                f"  crack {d_fe:.3f}: compliance ratio geardyn {np.round(cg / c0, 3)}, FE {np.round(fe_c / fe0, 3)}; "
                f"pair stiffness reduction (mean over the path) FE {red_fe * 100:.2f} %, over the FE's: "
                + ", ".join(f"{k} {v / red_fe:.3f}" for k, v in red.items()),
                flush=True,
            )
    crack_conv, release = ([], []) if a.quick else crack_studies()
    # bore and rim of the 19/48 pair
    case = load_case(ROOT / "examples" / "tooth_19_48.toml")
    g0 = case.geometry
    kw = dict(face_width=g0.face_width)
    r1, r2 = g0.r
    variants = [
        ("bore 0.25 r", dict(bore1=0.25 * r1, bore2=0.25 * r2)),
        ("bore 0.50 r", dict(bore1=0.5 * r1, bore2=0.5 * r2)),
        ("bore 0.75 r", dict(bore1=0.75 * r1, bore2=0.75 * r2)),
        ("rim 3.5 m_n", dict(rim1=3.5 * g0.m_n, rim2=3.5 * g0.m_n)),
        ("rim 2 m_n", dict(rim1=2.0 * g0.m_n, rim2=2.0 * g0.m_n)),
        ("rim 1.2 m_n", dict(rim1=1.2 * g0.m_n, rim2=1.2 * g0.m_n)),
    ]
    k_ref = None
    for label, v in variants:
        geo = pair_geometry(19, 48, g0.m_n, **kw, **v)
        k = mesh_stiffness(geo, 100.0, points=64).mean_stiffness / geo.face_width
        k_ref = k if k_ref is None else k_ref
        rad = geo.contact_radius(0, np.array([geo.s_pitch]))
        cg = float(geardyn_compliance(geo, 0, rad)[0])
        gfe = _gears(geo)[0]
        fg = build_mesh(gfe, rad, level=1.0)
        cf = float(fe_compliance(fg, rad)[0])
        s_R = geo.r_f[0] - geo.gears[0].bore_radius
        c_r = 1.0 + math.log(0.5) / (5.0 * math.exp(s_R / (5.0 * geo.m_n)))
        sens_tab.append((label, s_R / geo.m_n, k, k / k_ref, cg, cf, c_r))
        print(
            f"  {label}: k/b {k / 1e9:.3f} ({k / k_ref:.3f}); pinion pitch compliance geardyn {cg * 1e12:.2f}, "
            f"FE {cf * 1e12:.2f}",
            flush=True,
        )

    # ---- the Dataset (figures through the registry) and the docs
    ds = _dataset(fe_tab, crack_tab, conv_tab, rows_pe)
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out / "tooth_fe.nc")
    from geardyn.plot.registry import save_figures

    figs = save_figures(ds, ROOT / "docs" / "figures" / "tooth_fe")
    print("figures:", ", ".join(str(Path(f).relative_to(ROOT)) for f in figs))
    text = _markdown(rows_pe, fe_tab, conv_tab, crack_tab, sens_tab, levels, crack_conv, release)
    print(text)
    if not a.no_docs:
        doc = ROOT / "docs" / "excitation.md"
        d = doc.read_text()
        i, j = d.index(BEGIN) + len(BEGIN), d.index(END)
        doc.write_text(d[:i] + "\n" + text + "\n" + d[j:])
        print(f"wrote {doc.relative_to(ROOT)}")


def crack_studies():
    """On the 19/48 pinion: the FE crack increment's convergence with the tip's refinement and the level, and the
    crack increment against depth (FE, geardyn, the strip alone) at the lowest and the highest load point."""
    case = load_case(ROOT / "examples" / "tooth_19_48.toml")
    geo = case.geometry
    radii, _ = load_radii(geo, 0)
    conv = []
    healthy = {lv: fe_run(geo, 0, lv)[0] for lv in (1.0, 2.0)}
    for depth in (0.25, 0.5):
        for level, tip in ((1.0, 0), (1.0, 2), (1.0, 4), (1.0, 6), (2.0, 4)):
            c0 = healthy[level]
            c1, d_fe, nodes, _ = fe_run(geo, 0, level, crack=depth, tip=tip)
            conv.append((depth, d_fe, level, tip, nodes, c1 - c0))
            print(f"  crack {d_fe:.3f} level {level:g} tip {tip}: FE increment {np.round((c1 - c0) * 1e12, 3)}")
    c0 = healthy[1.0]
    g0 = geardyn_compliance(geo, 0, radii)
    _, s = load_radii(geo, 0)
    w_r = geardyn_compliance(geo, 1, geo.contact_radius(1, s))
    w_fe = fe_run(geo, 1, 1.0)[0]
    ch = hertz_compliance(geo.gears[0].E, geo.gears[0].nu, geo.gears[1].E, geo.gears[1].nu)
    release = []
    for j in range(1, 7):
        c1, d_fe, _, _ = fe_run(geo, 0, 1.0, crack=j / 8, tip=TIP)
        models = crack_models(geo, radii, d_fe)
        red_fe = pair_reduction(c1, c0, w_fe, ch)
        ratio = {k: pair_reduction(c, g0, w_r, ch) / red_fe for k, c in models.items()}
        release.append(
            (
                d_fe,
                c1 - c0,
                models["geardyn"] - g0,
                models["strip alone"] - g0,
                models["limiting line, tip"] - g0,
                ratio,
            )
        )
    return conv, release


def _dataset(fe_tab, crack_tab, conv_tab, rows_pe) -> xr.Dataset:
    names = [f"{n} {'pinion' if g == 0 else 'wheel'} (z = {z})" for n, g, z, *_ in fe_tab]
    ds = xr.Dataset(
        {
            "radius": (("tooth", "point"), np.array([r for *_, r, _, _ in fe_tab]) * 1e3, {"units": "mm"}),
            "compliance_geardyn": (
                ("tooth", "point"),
                np.array([c for *_, c, _ in fe_tab]) * 1e12,
                {"units": "1e-12 m^2/N", "long_name": "geardyn bending + shear + axial + foundation"},
            ),
            "compliance_fe": (
                ("tooth", "point"),
                np.array([c for *_, c in fe_tab]) * 1e12,
                {"units": "1e-12 m^2/N", "long_name": "finite elements, plane stress"},
            ),
        },
        coords={"tooth": names, "point": np.arange(N_LOAD)},
    )
    levels = sorted({c[2] for c in conv_tab})
    conv = np.array(
        [
            [next(c[4] for c in conv_tab if c[0] == n and c[1] == g and c[2] == lv) for lv in levels]
            for n, g, *_ in fe_tab
        ]
    )
    nodes = np.array(
        [
            [next(c[3] for c in conv_tab if c[0] == n and c[1] == g and c[2] == lv) for lv in levels]
            for n, g, *_ in fe_tab
        ]
    )
    ds["compliance_fe_level"] = (("tooth", "level", "point"), conv * 1e12, {"units": "1e-12 m^2/N"})
    ds["nodes"] = (("tooth", "level"), nodes)
    ds = ds.assign_coords(level=("level", np.array(levels)))
    ck = [f"{n} {int(d * 100)} %" for n, d, *_ in crack_tab]
    ds["crack_ratio_geardyn"] = (("crack", "point"), np.array([c[3] for c in crack_tab]))
    ds["crack_ratio_fe"] = (("crack", "point"), np.array([c[4] for c in crack_tab]))
    ds = ds.assign_coords(crack=ck)
    ds.attrs.update(
        geardyn_kind="tooth_fe",
        summary=json.dumps(
            {
                "pairs": [
                    {
                        "name": n,
                        "z": list(map(int, z)),
                        "mean_geardyn": pe["geardyn"],
                        "mean_reference": pe["reference"],
                    }
                    for n, z, _, pe in rows_pe
                ]
            }
        ),
    )
    return ds


def _tooth(name: str, gear: int) -> str:
    return f"{name.split('_', 1)[1].replace('_', '/')} {'pinion' if gear == 0 else 'wheel'}"


def _markdown(rows_pe, fe_tab, conv_tab, crack_tab, sens_tab, levels, crack_conv=(), release=()) -> str:
    out = ["Written by `PYTHONPATH=src python benchmarks/tooth_fe.py` (do not edit by hand).", ""]
    out += [
        "**Mean mesh stiffness per face width** (N/(mm·µm); steel, 20°, profile A, bore radius 0.25 r; 64 phases "
        "per mesh cycle):",
        "",
        "| pair | geardyn | reference (quadrature) | geardyn / reference | shape RMS "
        "| reference, u_f to the force line | ISO 6336-1 c_γα | geardyn / c_γα |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for _name, z, m, pe in rows_pe:
        out.append(
            f"| {z[0]}/{z[1]} m {m * 1e3:g} | {pe['geardyn'] / 1e9:.3f} | {pe['reference'] / 1e9:.3f} | "
            f"{pe['geardyn'] / pe['reference']:.5f} | {pe['shape_rms'] * 100:.3f} % | "
            f"{pe['reference_force_lever'] / 1e9:.3f} | {pe['c_gamma_iso'] / 1e9:.3f} | "
            f"{pe['geardyn'] / pe['c_gamma_iso']:.3f} |"
        )
    out += [
        "",
        "**Tooth compliance against finite elements** (bending + shear + axial + foundation, 10⁻¹² m²/N, at "
        f"{N_LOAD} points from the start to the end of that gear's contact; FE level 1):",
        "",
        "| tooth | " + " | ".join(f"point {i + 1}" for i in range(N_LOAD)) + " | worst |",
        "|---|" + "---|" * (N_LOAD + 1),
    ]
    for name, g, z, _r, cg, cf in fe_tab:
        cells = " | ".join(f"{a * 1e12:.2f} / {b * 1e12:.2f}" for a, b in zip(cg, cf))
        worst = np.max(np.abs(cg / cf - 1))
        out.append(f"| {_tooth(name, g)} (z = {z}) | {cells} | {worst * 100:.1f} % |")
    out += ["", "(cells: geardyn / FE.)", "", "**FE mesh convergence** (compliance at the seven points; nodes):", ""]
    out += [
        "| tooth | level | nodes | " + " | ".join(f"point {i + 1}" for i in range(N_LOAD)) + " |",
        "|---|---|---|" + "---|" * N_LOAD,
    ]
    for name, g, lv, n, c, _ in conv_tab:
        out.append(f"| {_tooth(name, g)} | {lv:g} | {n} | " + " | ".join(f"{x * 1e12:.3f}" for x in c) + " |")
    out += [
        "",
        "**Root crack on the pinion** (slit at the fillet's 30° point; depth as a share of that section's half "
        f"thickness, the FE node nearest to 25 % and 50 %; FE level 1 with {TIP} halvings at the slit's tip): where "
        "the crack starts (radius and half thickness of the FE slit's row and of geardyn's crack section), and the "
        "tooth compliance ratio cracked / healthy at the seven points:",
        "",
        "| pair | depth | start, FE: radius / h_c (mm) | start, geardyn | geardyn ratio | FE ratio "
        "| mesh mean, cracked / healthy (geardyn) |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, _d, dfe, rg, rf, _red, _redf, mm, st in crack_tab:
        out.append(
            f"| {name.split('_', 1)[1].replace('_', '/')} | {dfe * 100:.1f} % | "
            f"{st[0] * 1e3:.3f} / {st[1] * 1e3:.3f} | {st[2] * 1e3:.3f} / {st[3] * 1e3:.3f} | "
            f"{' '.join(f'{x:.3f}' for x in rg)} | "
            f"{' '.join(f'{x:.3f}' for x in rf)} | {mm:.4f} |"
        )
    keys = list(CRACK_MODELS)
    out += [
        "",
        "**The crack's single-pair stiffness reduction** (averaged over the path; each model with its own healthy "
        "tooth and wheel tooth) and, in brackets, its ratio to the FE's: geardyn (the fracture term with the "
        "fillet's notch); the strip's factors alone (without the notch); the section law (`crack_model=\"section\"`, "
        "Wu, Zuo & Parey 2008, Chen & Shao 2011); the limiting line from the crack's tip to the loaded flank at the "
        "tooth's tip (Mohammed, Rantatalo & Aidanpää 2013) and to the load point (the last three: sections above "
        "the crack lose the band between the flank and that line, no fracture term):",
        "",
        "| pair | depth | FE | " + " | ".join(keys) + " |",
        "|---|---|---|" + "---|" * len(keys),
    ]
    for name, _d, dfe, _rg, _rf, red, redf, *_ in crack_tab:
        out.append(
            f"| {name.split('_', 1)[1].replace('_', '/')} | {dfe * 100:.1f} % | {redf * 100:.2f} % | "
            + " | ".join(f"{red[k] * 100:.2f} % ({red[k] / redf:.2f})" for k in keys)
            + " |"
        )
    if crack_conv:
        out += [
            "",
            "**FE convergence of the crack** (19/48 pinion; the compliance the slit adds, 10⁻¹² m²/N, at the seven "
            "points; tip: halvings of the cells at the slit's tip across and along the tooth):",
            "",
            "| depth | level | tip | nodes | " + " | ".join(f"point {i + 1}" for i in range(N_LOAD)) + " |",
            "|---|---|---|---|" + "---|" * N_LOAD,
        ]
        for _d, dfe, lv, tip, n, dc in crack_conv:
            out.append(
                f"| {dfe * 100:.1f} % | {lv:g} | {tip} | {n} | " + " | ".join(f"{x * 1e12:.3f}" for x in dc) + " |"
            )
    if release:
        out += [
            "",
            "**The crack's compliance against its depth** (19/48 pinion, 10⁻¹² m²/N, at the lowest and the highest "
            "load point: FE / geardyn / the strip alone / the limiting line to the tip), the rate of growth between "
            "successive depths, d(ΔC)/da ∝ K², of geardyn and of the strip alone over the FE's, and each model's "
            "single-pair stiffness reduction over the FE's (the order of the table above):",
            "",
            "| depth | point 1: FE / geardyn / strip / limiting | point 7: FE / geardyn / strip / limiting "
            "| rate point 1: geardyn, strip | rate point 7: geardyn, strip | reduction over the FE's |",
            "|---|---|---|---|---|---|",
        ]
        prev = (0.0, np.zeros(N_LOAD), np.zeros(N_LOAD), np.zeros(N_LOAD))
        for dfe, f, g, st, lim, ratio in release:
            rate = [
                (x[i] - p[i]) / (f[i] - prev[1][i]) for i in (0, N_LOAD - 1) for x, p in ((g, prev[2]), (st, prev[3]))
            ]
            cells = [" / ".join(f"{x[i] * 1e12:.3f}" for x in (f, g, st, lim)) for i in (0, N_LOAD - 1)]
            out.append(
                f"| {dfe * 100:.1f} % | {cells[0]} | {cells[1]} | {rate[0]:.2f}, {rate[1]:.2f} | "
                f"{rate[2]:.2f}, {rate[3]:.2f} | {' / '.join(f'{v:.2f}' for v in ratio.values())} |"
            )
            prev = (dfe, f, g, st)
    out += [
        "",
        "**Bore and rim** (19/48 m 3.2; mean stiffness per width; pinion tooth compliance at the pitch point, "
        "geardyn and FE; ISO 6336-1's C_R for a web of b_s/b = 0.5 with that rim, for comparison — ISO has no "
        "rim effect on a solid gear):",
        "",
        "| body | s_R / m_n | k/b (N/(mm·µm)) | against bore 0.25 r | pitch compliance geardyn | FE "
        "| ISO C_R (b_s/b = 0.5) |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, sr, k, rel, cg, cf, c_r in sens_tab:
        out.append(
            f"| {label} | {sr:.2f} | {k / 1e9:.3f} | {rel:.3f} | {cg * 1e12:.2f} | {cf * 1e12:.2f} | {c_r:.3f} |"
        )
    return "\n".join(out)


if __name__ == "__main__":
    main()
