"""Gyroscopic terms of the gearbox (``[gearbox] gyroscopic = true``) against closed forms.

1. A rigid rotor on two isotropic bearings (a very stiff shaft carrying a gear at each bearing): in the complex
   coordinates r = x + i y of its centre of mass and φ = ry − i rx of its tilt, with the bearings at distances a and
   b from the centre of mass, whirl r, φ ∝ e^{iωt} (ω > 0 forward, ω < 0 backward) obeys

       det [[2k − m ω², k (b − a)], [k (b − a), k (a² + b²) − I_t ω² + I_p Ω ω]] = 0,

   a quartic in ω (the rigid rotor on flexible isotropic supports, Friswell et al., *Dynamics of Rotating
   Machines*, Cambridge University Press, 2010, ch. 3; Genta, *Dynamics of Rotating Systems*, Springer, 2005).
   m, I_t (about the centre of mass) and I_p are the rotor's, summed here by hand from the shaft (ρA L, ρ I L and
   ρ J L) and the gears.  A symmetric rotor (a = b) has a bounce mode 2k = m ω² that the speed leaves alone and a
   conical mode that splits; an offset rotor couples both.  The shaft is 10⁶ times as stiff as the bearings, so
   the rigid-rotor closed form holds to about 10⁻⁷.
2. A uniform simply supported spinning Timoshenko shaft: with r = R sin(kz), φ = Φ cos(kz), k = nπ/L,

       (κGA k² − ρA ω²)(EI k² + κGA − ρI ω² + 2ρI Ω ω) − (κGA k)² = 0

   (Timoshenko's equations with the gyroscopic moment ρJ Ω = 2ρI Ω per length), whose roots the finite elements
   approach as the element count grows (the h² rate of the element; below 1e-5 at 256 elements).
3. The system at a speed carries Ω G in its damping, moving with ω; without the option nothing changes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from geardyn.gearbox.shaft import Material, Section, ShaftMesh, shaft_matrices, shear_coefficient
from geardyn.systems import assemble, load_description
from geardyn.systems.modes import campbell, gyroscopic_eigen, modal_analysis, modes_report

RHO, D, L = 7850.0, 0.1, 0.4
KB = 1e8

ROTOR = """
title = "rigid rotor on isotropic bearings, a light second shaft on a very soft mesh"

[system]
characteristic_length = "1 um"

[gearbox]
{gyro}

[[shaft]]
name = "rotor"
material = {{ E = "2.1e17 Pa", nu = 0.3, rho = "7850 kg/m^3" }}
segments = [{{ length = "400 mm", outer = "100 mm" }}]
elements_per_segment = 1
rayleigh_beta = "0 s"

[[shaft]]
name = "other"
segments = [{{ length = "100 mm", outer = "30 mm" }}]
elements_per_segment = 1
rayleigh_beta = "0 s"

[[gear]]
name = "disc1"
shaft = "rotor"
position = "0 mm"
teeth = 40
module = "5 mm"
face_width = "40 mm"
mass = "{m1} kg"
inertia = "{ip1} kg*m^2"
diametral_inertia = "{id1} kg*m^2"

[[gear]]
name = "disc2"
shaft = "rotor"
position = "400 mm"
teeth = 40
module = "5 mm"
face_width = "40 mm"
mass = "{m2} kg"
inertia = "{ip2} kg*m^2"
diametral_inertia = "{id2} kg*m^2"

[[gear]]
name = "wheel"
shaft = "other"
position = "50 mm"
teeth = 20
module = "5 mm"
face_width = "40 mm"

[[mesh]]
name = "m"
pinion = "disc1"
gear = "wheel"
stiffness = "1e-3 N/m"
xi0 = 0.0

[[bearing]]
name = "A"
shaft = "rotor"
position = "0 mm"
kx = "1e8 N/m"
ky = "1e8 N/m"
kz = "1e8 N/m"

[[bearing]]
name = "B"
shaft = "rotor"
position = "400 mm"
kx = "1e8 N/m"
ky = "1e8 N/m"

[[bearing]]
name = "C"
shaft = "other"
position = "0 mm"
kx = "1e9 N/m"
ky = "1e9 N/m"
kz = "1e9 N/m"
krx = "1e7 N*m/rad"
kry = "1e7 N*m/rad"

[[bearing]]
name = "D"
shaft = "other"
position = "100 mm"
kx = "1e9 N/m"
ky = "1e9 N/m"
"""

OFFSET = {"m1": 20.0, "ip1": 0.5, "id1": 0.3, "m2": 5.0, "ip2": 0.2, "id2": 0.1}
CENTRED = {"m1": 10.0, "ip1": 0.4, "id1": 0.25, "m2": 10.0, "ip2": 0.4, "id2": 0.25}


def _file(tmp_path, discs, gyro="gyroscopic = true", name="rotor.toml"):
    p = tmp_path / name
    p.write_text(ROTOR.format(gyro=gyro, **discs))
    return p


def _closed_form(discs, rpm):
    """(forward, backward) whirl frequencies (Hz, ascending) of the rigid rotor (module docstring)."""
    A, I = math.pi * D**2 / 4, math.pi * D**4 / 64  # noqa: E741
    ms = RHO * A * L
    m = ms + discs["m1"] + discs["m2"]
    zg = (ms * L / 2 + discs["m2"] * L) / m
    It = ms * L**2 / 12 + RHO * I * L + ms * (L / 2 - zg) ** 2
    It += discs["id1"] + discs["m1"] * zg**2 + discs["id2"] + discs["m2"] * (L - zg) ** 2
    Ip = RHO * 2 * I * L + discs["ip1"] + discs["ip2"]
    Om = 2 * math.pi * rpm / 60
    a, b = zg, L - zg
    poly = np.poly1d([-m, 0, 2 * KB]) * np.poly1d([-It, Ip * Om, KB * (a * a + b * b)]) - KB**2 * (b - a) ** 2
    w = np.sort(poly.r.real) / (2 * math.pi)
    return np.sort(w[w > 0]), np.sort(-w[w < 0])


def _rotor_modes(desc, res):
    """Indices of the rigid rotor's whirl modes: on the rotor shaft, with lateral motion, below 2 kHz."""
    rot = [i for i, lab in enumerate(desc.labels) if lab.split(".")[0] in desc.shafts[0].nodes]
    M = desc.mass_matrix()
    out = []
    for i, f in enumerate(res.frequencies_hz):
        v = res.shapes[:, i]
        share = float(np.real(np.conj(v[rot]) @ M[np.ix_(rot, rot)] @ v[rot]))
        if 0 < f < 2000 and share > 0.99 and abs(res.whirl[i]) > 0.5:  # the stiff shaft bends far above
            out.append(i)
    return out


@pytest.mark.parametrize("rpm", [0.0, 3000.0, 20000.0])
def test_offset_rigid_rotor_whirl_frequencies_match_the_closed_form(tmp_path, rpm):
    desc = load_description(_file(tmp_path, OFFSET))
    res = modal_analysis(desc, rpm=rpm)
    fwd, bwd = _closed_form(OFFSET, rpm)
    if rpm == 0:  # standstill: each frequency twice (the two planes), no whirl direction
        f = res.frequencies_hz
        for x in fwd:
            near = f[np.abs(f / x - 1) < 1e-6]
            assert len(near) == 2, (x, near)
        return
    idx = _rotor_modes(desc, res)
    assert len(idx) == 4
    f, w = res.frequencies_hz[idx], res.whirl[idx]
    assert np.max(np.abs(np.sort(f[w > 0]) / fwd - 1)) < 1e-6
    assert np.max(np.abs(np.sort(f[w < 0]) / bwd - 1)) < 1e-6
    assert np.all(np.abs(np.abs(w) - 1) < 1e-6)  # circular orbits
    # gyroscopic stiffening: both forward modes above both standstill values, both backward below
    f0 = _closed_form(OFFSET, 0.0)[0]
    assert np.all(fwd > f0 * (1 + 1e-3)) and np.all(bwd < f0 * (1 - 1e-3))


def test_centred_rotor_bounce_mode_does_not_move_and_the_conical_mode_splits(tmp_path):
    desc = load_description(_file(tmp_path, CENTRED))
    m = RHO * math.pi * D**2 / 4 * L + 20.0
    bounce = math.sqrt(2 * KB / m) / (2 * math.pi)  # no coupling to the tilt: independent of the speed
    axial = math.sqrt(KB / m) / (2 * math.pi)
    rot = [i for i, lab in enumerate(desc.labels) if lab.split(".")[0] in desc.shafts[0].nodes]
    for rpm in (5000.0, 30000.0):
        res = modal_analysis(desc, rpm=rpm)
        f = res.frequencies_hz
        on_rotor = [
            i
            for i in range(len(f))
            if 0 < f[i] < 2000
            and np.sum(np.abs(res.shapes[rot, i]) ** 2) > 0.99 * np.sum(np.abs(res.shapes[:, i]) ** 2)
        ]
        fr = f[on_rotor]
        assert np.sum(np.abs(fr / axial - 1) < 1e-6) == 1
        assert np.sum(np.abs(fr / bounce - 1) < 1e-6) == 2  # forward and backward bounce, both at 2k = m ω²
        fwd, bwd = _closed_form(CENTRED, rpm)
        assert np.min(np.abs(fwd / bounce - 1)) < 1e-9 and np.min(np.abs(bwd / bounce - 1)) < 1e-9
        cf, cb = fwd[np.abs(fwd / bounce - 1) > 1e-3], bwd[np.abs(bwd / bounce - 1) > 1e-3]
        conical = [i for i in on_rotor if abs(f[i] / bounce - 1) > 1e-3 and abs(f[i] / axial - 1) > 1e-3]
        assert len(conical) == 2 and cf[0] / cb[0] - 1 > 0.01
        for i in conical:
            ref = cf[0] if res.whirl[i] > 0 else cb[0]
            assert abs(f[i] / ref - 1) < 1e-6 and abs(abs(res.whirl[i]) - 1) < 1e-6


def test_campbell_branches_and_crossings_follow_the_closed_form(tmp_path):
    desc = load_description(_file(tmp_path, OFFSET))
    c = campbell(desc, rpm_range=(0.0, 20000.0), orders=(1,), speeds=21)
    assert c["gyroscopic"] is True
    br = c["branches"]
    assert len(br["rpm"]) == 21 and len(br["frequencies_hz"][0]) == desc.n
    # each branch point: the closed form's four whirl frequencies are among the branches at that speed
    for rpm, f, w in zip(br["rpm"][1:], br["frequencies_hz"][1:], br["whirl"][1:]):
        f, w = np.array(f), np.array(w)
        fwd, bwd = _closed_form(OFFSET, rpm)
        for x in fwd:
            j = np.argmin(np.abs(f - x))
            assert abs(f[j] / x - 1) < 1e-6 and w[j] > 0.99
        for x in bwd:
            j = np.argmin(np.abs(f - x))
            assert abs(f[j] / x - 1) < 1e-6 and w[j] < -0.99
    # order 1 of the mesh (40 teeth): f = 40 n/60 meets each whirl branch where the closed form says
    hits = [x for x in c["crossings"] if x["whirl"] != "none" and x["frequency_hz"] < 600]
    assert len(hits) == 4
    for x in hits:
        fwd, bwd = _closed_form(OFFSET, x["rpm"])
        ref = fwd if x["whirl"] == "forward" else bwd
        assert np.min(np.abs(ref / x["frequency_hz"] - 1)) < 1e-6
        assert x["frequency_hz"] == pytest.approx(40 * x["rpm"] / 60, rel=1e-12)


# ---------------------------------------------------------------------------- the spinning Timoshenko shaft
MAT = Material(E=2.1e11, nu=0.3, rho=7850.0)
SEC = Section(outer=0.12, inner=0.06)
LS = 1.0
SPIN = 2 * math.pi * 12000 / 60  # 12000 rpm


def _ss_closed_form(n, spin):
    """(backward, forward) lower whirl frequencies (rad/s) of mode n (module docstring)."""
    E, G, rho = MAT.E, MAT.G, MAT.rho
    kappa = shear_coefficient(MAT.nu, SEC.outer, SEC.inner)
    A, I = SEC.area, SEC.I  # noqa: E741
    k = n * math.pi / LS
    kGA = kappa * G * A
    poly = np.poly1d([-rho * A, 0, kGA * k**2]) * np.poly1d([-rho * I, 2 * rho * I * spin, E * I * k**2 + kGA])
    poly = poly - (kGA * k) ** 2
    r = np.sort(poly.r.real)
    return float(np.min(-r[r < 0])), float(np.min(r[r > 0]))


def _ss_fe(n_el, spin, count):
    K, M, G = shaft_matrices(ShaftMesh(tuple(np.linspace(0.0, LS, n_el + 1)), (SEC,) * n_el), MAT)
    keep = [6 * i + d for i in range(n_el + 1) for d in (0, 1, 3, 4)]  # bending in both planes
    keep = [i for i in keep if i not in (0, 1, 6 * n_el, 6 * n_el + 1)]  # x = y = 0 at both ends
    K, M, G = (X[np.ix_(keep, keep)] for X in (K, M, G))
    w2, phi = scipy.linalg.eigh(K, M)
    w, _ = gyroscopic_eigen(w2, phi, G, spin, vectors=False)
    return w[:count]


def test_spinning_simply_supported_timoshenko_shaft_converges_to_the_closed_form():
    exact = np.array([x for n in (1, 2) for x in _ss_closed_form(n, SPIN)])
    assert exact[1] / exact[0] - 1 > 0.005  # the speed splits the whirl noticeably
    errs = np.array([_ss_fe(n_el, SPIN, 4) / exact - 1 for n_el in (32, 64, 128, 256)])
    assert np.all(errs > 0)  # from above, as at standstill
    assert np.all(errs[-1] < 1e-5), errs[-1]  # measured 2.7e-7 to 3.8e-6
    assert np.all(np.abs(errs[:-1, :] / errs[1:, :] - 4.0) < 0.15), errs[:-1] / errs[1:]


def test_spinning_shaft_whirl_direction_of_the_finite_elements():
    n_el = 32
    K, M, G = shaft_matrices(ShaftMesh(tuple(np.linspace(0.0, LS, n_el + 1)), (SEC,) * n_el), MAT)
    keep = [6 * i + d for i in range(n_el + 1) for d in (0, 1, 3, 4)]
    keep = [i for i in keep if i not in (0, 1, 6 * n_el, 6 * n_el + 1)]
    K, M, G = (X[np.ix_(keep, keep)] for X in (K, M, G))
    w2, phi = scipy.linalg.eigh(K, M)
    w, v = gyroscopic_eigen(w2, phi, G, SPIN)
    mid = keep.index(6 * (n_el // 2))  # x at mid-span; y follows it
    for i in (0, 1):
        a, b = v[mid, i], v[mid + 1, i]
        turn = 2 * np.imag(a * np.conj(b)) / (abs(a) ** 2 + abs(b) ** 2)  # +1 counterclockwise = with the spin
        assert turn == pytest.approx(-1.0 if i == 0 else 1.0, abs=1e-9)  # the lower one is backward


# ---------------------------------------------------------------------------- the system at a speed
def test_system_damping_takes_omega_g_and_follows_the_speed(tmp_path):
    desc = load_description(_file(tmp_path, OFFSET))
    s = assemble(desc, omega=None)
    assert s.gyro is not None and np.allclose(s.gyro, -s.gyro.T, rtol=0, atol=1e-15 * np.abs(s.gyro).max())
    assert np.array_equal(s.Cb, s.damping_static + s.omega * s.gyro)
    s2 = s.with_param("omega", 2.5 * s.omega)
    assert np.array_equal(s2.Cb, s.damping_static + 2.5 * s.omega * s.gyro)
    assert np.array_equal(s2.arrays().Cb, s2.Cb)
    back = type(s).from_attrs(s2.to_attrs())
    assert np.array_equal(back.Cb, s2.Cb) and np.array_equal(back.gyro, s2.gyro)
    # the non-dimensional linear system at a speed has the SI modes at that speed (no damping in this file)
    rpm = 12000.0
    sr = s.with_param("omega", s.scaling.omega_from_rpm(rpm))
    Kt = sr.Kb + sum(m.k * np.outer(sr.V[i], sr.V[i]) for i, m in enumerate(sr.meshes))
    n = sr.n
    Asys = np.block([[np.zeros((n, n)), np.eye(n)], [-sr.Mi @ Kt, -sr.Mi @ sr.Cb]])
    lam = scipy.linalg.eigvals(Asys)
    f_nd = np.sort(lam.imag[lam.imag > 1e-6]) * sr.scaling.omega_n_rad_s / (2 * math.pi)
    res = modal_analysis(desc, rpm=rpm)
    for i in _rotor_modes(desc, res):
        x = res.frequencies_hz[i]
        assert np.min(np.abs(f_nd / x - 1)) < 1e-7


def test_without_the_option_nothing_changes(tmp_path):
    on = load_description(_file(tmp_path, OFFSET))
    off = load_description(_file(tmp_path, OFFSET, gyro="gyroscopic = false", name="off.toml"))
    absent = load_description(_file(tmp_path, OFFSET, gyro="", name="absent.toml"))
    assert off.gyroscopic_matrix() is None and absent.gyroscopic_matrix() is None
    s_off, s_abs, s_on = assemble(off), assemble(absent), assemble(on)
    assert s_off.gyro is None and s_off.damping_static is None
    for k in ("Mi", "Kb", "Cb", "V", "F", "coef"):
        assert np.array_equal(getattr(s_off.arrays(), k), getattr(s_abs.arrays(), k))
    assert "gyro" not in s_off.to_attrs()
    assert np.array_equal(s_on.damping_static, s_off.Cb)  # the option adds Ω G and nothing else
    for k in ("Mi", "Kb", "V", "F"):
        assert np.array_equal(getattr(s_on, k), getattr(s_off, k))
    r_off = modal_analysis(off, rpm=5000.0)  # the speed is ignored without the option
    r_abs = modal_analysis(absent)
    assert r_off.rpm is None and r_off.whirl is None
    assert np.array_equal(r_off.frequencies_hz, r_abs.frequencies_hz)
    rep = modes_report(off, (0.0, 5000.0))
    assert "gyroscopic" not in rep and "branches" not in rep["campbell"]


# ---------------------------------------------------------------------------- the command line
def test_modes_command_writes_the_branches_and_plot_redraws_them(tmp_path):
    import json

    from typer.testing import CliRunner

    from geardyn.cli import app
    from geardyn.io import read_netcdf

    path = _file(tmp_path, OFFSET)
    out = tmp_path / "out"
    run = CliRunner().invoke(
        app, ["modes", "--system", str(path), "--rpm-max", "20000", "--orders", "1", "--json", "--out", str(out)]
    )
    assert run.exit_code == 0, run.output
    r = json.loads(run.stdout)
    assert r["gyroscopic"] is True and r["campbell"]["gyroscopic"] is True
    ds = read_netcdf(out / "modes.nc")
    np.testing.assert_array_equal(ds["branch_frequency_Hz"].values, r["campbell"]["branches"]["frequencies_hz"])
    assert ds["branch_frequency_Hz"].dims == ("speed", "mode") and ds["speed"].values[-1] == 20000.0
    codes = {"forward": 1, "backward": -1, "none": 0}
    assert list(ds["crossing_whirl"].values) == [codes[c["whirl"]] for c in r["campbell"]["crossings"]]
    again = tmp_path / "again"
    p = CliRunner().invoke(app, ["plot", str(out / "modes.nc"), "--out", str(again), "--json"])
    assert p.exit_code == 0 and (again / "campbell.png").stat().st_size > 10_000
    text = CliRunner().invoke(app, ["modes", "--system", str(path), "--rpm-max", "20000", "--orders", "1"]).stdout
    assert "gyroscopic terms on" in text and "forward" in text and "backward" in text


def test_a_gyroscopic_value_that_is_not_a_boolean_is_refused_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from geardyn.cli import app

    path = _file(tmp_path, OFFSET, gyro='gyroscopic = "yes"')
    run = CliRunner().invoke(app, ["modes", "--system", str(path), "--json"])
    assert run.exit_code == 2
    lines = [ln for ln in run.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "gyroscopic" in lines[0] and "true or false" in lines[0], run.output


def test_each_shaft_at_its_own_speed_and_sense_with_its_gears_polar_inertia(tmp_path):
    from geardyn.gearbox.shaft import element_matrices

    desc = load_description(_file(tmp_path, OFFSET))
    G, idx = desc.gyroscopic_matrix(), desc.index()
    rotor, other = desc.shafts
    # the wheel (20 teeth) turns twice as fast as the 40-tooth disc, the other way round
    ii = [idx[(n, d)] for n in other.nodes for d in ("x", "y", "z", "rx", "ry", "theta")]
    np.testing.assert_array_equal(G[np.ix_(ii, ii)], -2.0 * other.G)
    # the disc's own term I_p on its tilts, beside the shaft element's
    mat = Material(E=2.1e17, nu=0.3, rho=7850.0)
    ge = element_matrices(L, Section(outer=D), mat)[2]
    a, b = idx[("disc1", "rx")], idx[("disc1", "ry")]
    assert G[a, b] - ge[3, 4] == pytest.approx(OFFSET["ip1"], rel=1e-12)
    assert G[b, a] == -G[a, b]
    a, b = idx[("disc2", "rx")], idx[("disc2", "ry")]
    assert G[a, b] - ge[9, 10] == pytest.approx(OFFSET["ip2"], rel=1e-12)
