"""Harmonic balance of multi-DOF systems (``geardyn.analysis.hb.system*``, ``geardyn hb --system``).

References: the 1-DOF harmonic balance (the paper's torsional pair is exactly the 1-DOF model), the
closed-form frequency-domain solution of a linear system, and the systems' shooting (periodic orbits
and their monodromy matrices by RK4 in the accurate mode).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.analysis.hb import hb_continuation, hb_solve
from geardyn.analysis.hb.equations import HBEquations
from geardyn.analysis.periodic import shoot
from geardyn.cli import app
from geardyn.geometry.scales import Scales
from geardyn.model import GearModel
from geardyn.status import Status
from geardyn.systems import SystemModel, load_system
from geardyn.systems.assemble import MeshND

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
TORSIONAL = EX / "paper_torsional.toml"


def _conj_close(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two multiplier sets (Hausdorff), the smaller of b and its conjugate set."""

    def haus(x, y):
        d = np.abs(x[:, None] - y[None, :])
        return float(max(d.min(axis=0).max(), d.min(axis=1).max()))

    return min(haus(a, b), haus(a, np.conj(b)))


def _four_dof(omega, D=0.5, kappa=(0.2,), xi=(0.02,), eps=(0.3,), clearance=True, fp=(0.0, 0.15, 0.0, -0.1)):
    """Two bodies (a translation and a rotation each) on bearings, one mesh and one clearance: 4 DOFs."""
    Mi = np.linalg.inv(np.diag([1.0, 0.7, 1.3, 0.9]))
    Kb = np.diag([2.0, 0.0, 1.5, 0.0]) + 0.1 * np.eye(4)
    mesh = MeshND("m0", 1.0, 0.05, tuple(xi), (), tuple(kappa), (), tuple(eps), (), D, 1.0)
    extra = (
        dict(clearance_names=("gap",), Vc=np.array([[1.0, 0.0, -1.0, 0.0]]), kc=(0.5,), cc=(0.01,), Dc=(0.4,))
        if clearance
        else {}
    )
    return SystemModel(
        labels=tuple(f"b{i}.x" for i in range(4)),
        Mi=Mi,
        Kb=Kb,
        Cb=0.02 * Kb,
        V=np.array([[0.3, 1.0, -0.2, -1.0]]),
        meshes=(mesh,),
        F=np.array(fp),
        omega=omega,
        scaling=Scales.of_reference_mesh("m0", 1.0, 1.0, 1.0, (1.0,) * 4, None),
        **extra,
    )


@pytest.fixture(scope="module")
def torsional():
    return load_system(TORSIONAL)


# ---------------------------------------------------------------------------- the 1-DOF reduction
@pytest.fixture(scope="module")
def torsional_branch(torsional):
    return hb_continuation(torsional, "omega", 0.5, 0.8, harmonics=16, floquet="hill")


def test_torsional_branch_reproduces_the_1dof_hb(torsional_branch, torsional):
    """Every point of the system's branch against the 1-DOF HB solved at the same ω (same H, same N), and the
    located events against the 1-DOF continuation.

    The branch points are on the branch to the corrector's tolerance (1e-10), which near a fold moves the
    multipliers by up to 1e-7 (they have an infinite ω-derivative there): the multipliers are compared after
    both solutions are refined by Newton at the point's ω to 1e-13.
    """
    res = torsional_branch
    assert res.converged and res.rigid == 1 and res.multipliers.shape[1] == 2
    eq = HBEquations(res.model, res.harmonics, res.period, param="omega")
    assert eq.N == res.samples
    worst = {"u": 0.0, "mu": 0.0}
    for w, x, lo, hi, st in zip(res.values, res.coefficients, res.u_min, res.u_max, res.status):
        sysw = hb_solve(
            torsional.with_param("omega", w), res.harmonics, guess=x.reshape(2, -1), tol=1e-13, floquet="hill"
        )
        d = eq.deflection(sysw.unknowns, eq.reference, w)  # the mesh's u, a guess for the 1-DOF HB
        one = hb_solve(
            GearModel().with_param("omega", w), res.harmonics, guess=d, samples=res.samples, tol=1e-13, floquet="hill"
        )
        assert one.converged and sysw.converged
        worst["u"] = max(worst["u"], abs(one.u_min - lo), abs(one.u_max - hi), abs(one.amplitude - 0.5 * (hi - lo)))
        assert int(one.hill.status) == int(st) == int(sysw.hill.status)
        # the multipliers of a real system are a conjugate-closed set; Hill's choice may take the conjugate
        # copies (they differ by the truncation error, about 1e-6 at H = 16): compared up to conjugation
        worst["mu"] = max(worst["mu"], _conj_close(sysw.multipliers, one.multipliers))
    assert worst["u"] < 1e-8 and worst["mu"] < 1e-8, worst
    ref = hb_continuation(GearModel(), "omega", 0.5, 0.8, harmonics=16, floquet="hill")
    got = sorted((b.type, b.value) for b in res.bifurcations)
    want = sorted((b.type, b.value) for b in ref.bifurcations)
    assert [t for t, _ in got] == [t for t, _ in want] == ["fold", "fold", "grazing", "period-doubling"]
    for (_, a), (_, b) in zip(got, want):
        assert a == pytest.approx(b, abs=1e-8)


def test_torsional_monodromy_multipliers_are_the_1dof_ones(torsional):
    """The monodromy of the system (its rigid mode left out) against the 1-DOF monodromy at the same solution:
    the same equation integrated with different steps (the rates differ), so equal to RK4's error, below 1e-7
    each (docs/hb.md); and both within Hill's truncation (1e-3 at H = 16) of Hill's multipliers."""
    for w in (0.55, 0.7, 0.9):
        sysw = hb_solve(torsional.with_param("omega", w), 16)
        eq = sysw.equations
        one = hb_solve(
            GearModel().with_param("omega", w),
            16,
            guess=eq.deflection(sysw.unknowns, eq.reference),
            samples=eq.N,
            tol=1e-13,
        )
        assert sysw.hill.status is Status.OK and one.hill.status is Status.OK
        assert _conj_close(sysw.multipliers, one.multipliers) < 1e-6
        hill = hb_solve(GearModel().with_param("omega", w), 16, guess=one.coefficients, floquet="hill")
        assert _conj_close(one.multipliers, hill.multipliers) < 1e-3


def test_rigid_mode_gauge_and_note(torsional_branch, torsional):
    res = torsional_branch
    R = np.array([1.0, 1.0]) / math.sqrt(2.0)  # the pair's rigid rotation (V = (1, −1))
    a0 = res.coefficients.reshape(res.values.size, 2, -1)[:, :, 0]
    np.testing.assert_allclose(a0 @ R, 0.0, atol=1e-12)
    j = res.to_json()
    assert j["rigid_body_modes"] == 1 and "rigid-body" in j["notes"][0]
    assert all(len(p["multipliers"]) == 2 for p in j["branch"])


# ---------------------------------------------------------------------------- exact linear theory
def _frequency_domain(model, omega):
    """(K̄ a_0 = F + k D V; (K − ω²M + iωC) Q = V (k + iωc) ε): the permanently meshing response to E = ε cos θ."""
    M = np.linalg.inv(model.Mi)
    v, mesh = model.V[0], model.meshes[0]
    k, c, eps = mesh.k, 2 * mesh.xi0, mesh.eps[0]
    K, C = model.Kb + k * np.outer(v, v), model.Cb + c * np.outer(v, v)
    q0 = np.linalg.lstsq(K, model.F + k * mesh.D * v, rcond=None)[0]
    Q = np.linalg.solve(K - omega**2 * M + 1j * omega * C, v * (k + 1j * omega * c) * eps)
    A = np.block([[np.zeros_like(K), np.eye(len(v))], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    mu = np.exp(np.linalg.eigvals(A) * 2 * math.pi / omega)
    return q0, Q, mu


@pytest.mark.parametrize("floquet, mu_tol", [("hill", 1e-10), ("monodromy", 1e-7)])  # monodromy: RK4's error
@pytest.mark.parametrize("case", ["4dof", "4dof_preloaded", "torsional_rigid"])
def test_in_contact_constant_stiffness_h1_is_the_frequency_domain_solution(case, torsional, floquet, mu_tol):
    omega = 1.3
    if case == "torsional_rigid":
        model = torsional.with_param("omega", omega).with_param("mesh.kappa1", 0.0).with_param("mesh.xi1", 0.0)
        model = model.with_param("mesh.D", 0.0)
    else:
        D, fp = (0.0, (0.0, 0.15, 0.0, -0.1)) if case == "4dof" else (0.5, (0.0, 3.0, 0.0, -2.0))
        model = _four_dof(omega, D=D, kappa=(), xi=(), clearance=False, fp=fp)
    sol = hb_solve(model, 1, guess="linear", floquet=floquet)
    assert sol.converged
    q0, Q, mu = _frequency_domain(model, omega)
    if case == "4dof_preloaded":
        assert sol.u_min > model.meshes[0].D  # no separation: the linear theory applies
    a = sol.coefficients
    np.testing.assert_allclose(a[:, 0], q0, atol=1e-10)
    np.testing.assert_allclose(a[:, 1], Q.real, atol=1e-10)
    np.testing.assert_allclose(a[:, 2], -Q.imag, atol=1e-10)
    r = sol.rigid
    assert r == (1 if case == "torsional_rigid" else 0)
    exact = mu if r == 0 else mu[np.argsort(np.abs(mu - 1.0))[2 * r :]]  # the rigid mode's two multipliers 1 out
    assert sol.hill.status is Status.OK and sol.multipliers.size == exact.size
    assert _conj_close(sol.multipliers, exact) < mu_tol


# ---------------------------------------------------------------------------- nonlinear: against shooting
def test_nonlinear_4dof_orbit_agrees_with_shooting():
    """Contact loss of the mesh (D = 0.5) at ω = 0.9: HB at H = 16 and 32 against shooting (accurate mode).

    Shooting's own error is far below the tolerances: halving Δτ from 0.002 to 0.001 changes its extremes
    by 4e-13 and its multipliers by 3e-12 (measured).  HB's error is the truncation of the series, algebraic
    because of the kink of the dead zone (docs/hb.md: about H⁻³): measured 2.6e-6 (H = 16) and 8.7e-8
    (H = 32) in δ_min, 1.8e-5 and 2.0e-6 in Hill's multipliers.  Asserted: 1e-6 and 1e-5 at H = 32, and that
    both errors fall from H = 16 to H = 32; the monodromy's multipliers within 1e-6 at both H.
    """
    model = _four_dof(0.9)
    # Newton from 30 settling periods (not the default 400): the same orbit to 1.4e-12 (measured), 8x cheaper
    orb = shoot(model, 1, accurate=True, dtau=0.002, transient=30)
    assert orb.converged
    mu_ref, r = orb.elastic
    assert r == 0
    ref = orb.extra["meshes"][0]
    assert ref["u_min"] < model.meshes[0].D < ref["u_max"]  # the mesh loses contact: a nonlinear orbit
    errs, mono = [], []
    for H in (16, 32):
        sol = hb_solve(model, H, floquet="hill")
        assert sol.converged and sol.hill.status is Status.OK
        np.testing.assert_allclose(sol.state()[:4] - orb.state[:4], 0.0, atol=1e-3)
        errs.append(
            (
                max(
                    abs(sol.u_min - ref["u_min"]), abs(sol.u_max - ref["u_max"]), abs(sol.amplitude - ref["amplitude"])
                ),
                _conj_close(sol.multipliers, mu_ref),
            )
        )
        m = hb_solve(model, H, guess=sol.coefficients)  # the monodromy (default)
        assert m.hill.status is Status.OK
        mono.append(_conj_close(m.multipliers, mu_ref))
    (u16, m16), (u32, m32) = errs
    assert u32 < 1e-6 and m32 < 1e-5, errs
    assert u32 < u16 and m32 < m16, errs
    # the monodromy of the period started on the Newton-corrected HB state: RK4's error at either H (measured
    # 1.0e-7 at H = 16 and 32), not the series' truncation
    assert max(mono) < 1e-6, mono


# ---------------------------------------------------------------------------- the analytic derivatives
def test_jacobian_and_domega_match_central_differences():
    model = _four_dof(0.9)
    eq = HBEquations(model, 8, param="omega")
    sol = hb_solve(model, 8)
    x = sol.unknowns + 1e-3 * np.random.default_rng(1).standard_normal(sol.unknowns.size)
    R, J = eq.residual(x, 0.9)
    h = 1e-6
    Jfd = np.array(
        [
            (eq.residual(x + h * e, 0.9, False)[0] - eq.residual(x - h * e, 0.9, False)[0]) / (2 * h)
            for e in np.eye(x.size)
        ]
    ).T
    np.testing.assert_allclose(J, Jfd, atol=1e-6 * max(1.0, np.abs(J).max()))
    dfd = (eq.residual(x, 0.9 + h, False)[0] - eq.residual(x, 0.9 - h, False)[0]) / (2 * h)
    np.testing.assert_allclose(eq.dR_dp(x, 0.9), dfd, atol=1e-7)


# ---------------------------------------------------------------------------- command line
SMALL = ["--param", "omega", "--start", "0.55", "--stop", "0.65", "--harmonics", "8"]


def test_cli_system_json_and_files(tmp_path):
    r = CliRunner().invoke(app, ["hb", "--system", str(TORSIONAL), *SMALL, "--json", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    one = json.loads(CliRunner().invoke(app, ["hb", *SMALL, "--json"]).stdout)
    assert set(one) - {"physical"} <= set(s)
    assert {"branch", "bifurcations", "harmonics", "converged", "meshes"} <= set(s)
    lib = hb_continuation(load_system(TORSIONAL), "omega", 0.55, 0.65, harmonics=8)
    assert len(s["branch"]) == lib.values.size and s["converged"] is True
    for p, v, lo, hi in zip(s["branch"], lib.values, lib.u_min, lib.u_max):
        assert {"omega", "amplitude", "u_min", "u_max", "stable", "multipliers"} <= set(p)
        assert p["omega"] == v and p["u_min"] == lo and p["u_max"] == hi
    (m,) = s["meshes"]
    phys = {"u_min_um", "u_max_um", "amplitude_um"}  # the physical values beside the non-dimensional ones
    assert set(m) - phys == {"name", "u_min", "u_max", "amplitude", "impact", "dynamic_factor"} and m["name"] == "mesh"
    assert m["u_min"] == [p["u_min"] for p in s["branch"]]
    assert m["impact"][0] == "no impact" and len(m["dynamic_factor"]) == len(s["branch"])
    assert sorted(b["type"] for b in s["bifurcations"]) == sorted(b["type"] for b in one["bifurcations"])
    files = [Path(f) for f in s["files"]]
    assert [f.suffix for f in files] == [".nc", ".png"] and all(f.stat().st_size > 0 for f in files)


def test_cli_system_refuses_one_line():
    r = CliRunner().invoke(app, ["hb", "--system", str(TORSIONAL), *SMALL, "--fp", "0.3"])
    assert r.exit_code == 2 and "fp" in r.output
    r = CliRunner().invoke(
        app, ["hb", "--system", str(TORSIONAL), "--param", "mesh.zeta", "--start", "0.1", "--stop", "0.2"]
    )
    assert r.exit_code == 2 and "zeta" in r.output


def test_cli_system_compare_shooting_overlay_is_stored_and_redrawn(tmp_path):
    """--compare-shooting --system: the shooting branch (an independent method: the period map) is stored in hb.nc
    under ``shooting``, drawn at the reference mesh under the HB branch, and ``geardyn plot hb.nc`` redraws it."""
    import matplotlib

    matplotlib.use("Agg")
    from geardyn.io import attached, read_netcdf
    from geardyn.plot.hb import SHOOTING_STYLE, hb_figure

    out = tmp_path / "run"
    r = CliRunner().invoke(
        app,
        ["hb", "--system", str(TORSIONAL), *SMALL, "--compare-shooting", "--default-mode", "--json", "--out", str(out)],
    )
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    ds = read_netcdf(out / "hb.nc")
    sh = attached(ds, "shooting")
    assert sh is not None and sh.attrs["geardyn_kind"] == "continuation" and sh.sizes["point"] > 10
    # the two methods agree on the folds (shooting brackets them to one step of its branch: within 1e-3)
    hb_f = sorted(b["omega"] for b in s["bifurcations"] if b["type"] == "fold")
    sh_f = sorted(b["omega"] for b in s["shooting"]["bifurcations"] if b["type"] == "fold")
    assert len(hb_f) == len(sh_f) == 2 and np.allclose(hb_f, sh_f, atol=1e-3)
    # the grey branch is shooting's reference-mesh extremes against its ω (the one continuation Dataset)
    art = hb_figure(ds)
    drawn = [ln for ln in art.axes[1].get_lines() if ln.get_color() == SHOOTING_STYLE["color"]]
    x = np.concatenate([ln.get_xdata() for ln in drawn])
    y = np.concatenate([ln.get_ydata() for ln in drawn])
    assert set(np.round(x, 12)) == set(np.round(sh["omega"].values, 12))
    want = np.concatenate([sh["u_min"].values, sh["u_max"].values])  # the reference mesh's extremes
    assert set(np.round(y, 12)) == set(np.round(want, 12))
    assert "over the shooting branch" in art.axes[0].get_title()
    re = tmp_path / "re"
    r = CliRunner().invoke(app, ["plot", str(out / "hb.nc"), "--out", str(re), "--json"])
    assert r.exit_code == 0, r.output
    assert {p.name for p in re.iterdir() if p.suffix == ".png"} == {"hb.png"}


def test_response_method_hb_of_the_torsional_system_is_the_1dof_response():
    """``geardyn response --method hb --system``: the torsional pair is exactly the 1-DOF model, so its response (the
    reference mesh's δ) is the 1-DOF HB response — same grid values, motion, jumps at the same folds, same
    hysteresis (to the continuation's corrector tolerance)."""
    from geardyn.analysis.hb import hb_response

    args = (0.5, 0.65, 31)
    sysr = hb_response(load_system(TORSIONAL), *args)
    one = hb_response(GearModel(), *args)
    assert sysr.attrs["geardyn_kind"] == "response" and sysr.attrs["method"] == "hb"
    for k in ("amplitude", "rms", "mean", "u_min", "u_max", "poincare_u", "poincare_v"):
        a, b = sysr[k].values, one[k].values
        assert np.array_equal(np.isnan(a), np.isnan(b)), k
        np.testing.assert_allclose(a[~np.isnan(a)], b[~np.isnan(b)], atol=1e-7, err_msg=k)
    for k in ("motion", "impact", "period", "status"):
        assert np.array_equal(sysr[k].values, one[k].values), k
    js, jo = json.loads(sysr.attrs["jumps"]), json.loads(one.attrs["jumps"])
    assert len(js) == len(jo) == 2
    for a, b in zip(js, jo):
        assert (a["sweep"], a["direction"]) == (b["sweep"], b["direction"])
        assert a["omega"] == pytest.approx(b["omega"], abs=1e-7) and a["size"] == pytest.approx(b["size"], abs=1e-7)
    np.testing.assert_allclose(json.loads(sysr.attrs["hysteresis"]), json.loads(one.attrs["hysteresis"]), atol=1e-7)
    r = CliRunner().invoke(
        app,
        [
            "response",
            "--system",
            str(TORSIONAL),
            "--method",
            "hb",
            "--omega-start",
            "0.5",
            "--omega-stop",
            "0.65",
            "--num",
            "31",
            "--json",
        ],
    )
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    # the command's jumps are those of the Dataset, with the pair's physical keys (rpm, µm) beside them
    assert [{k: j[k] for k in js[0]} for j in s["jumps"]] == js and s["up"]["amplitude"] == [
        None if np.isnan(v) else v for v in sysr["amplitude"].sel(sweep="up").values
    ]
