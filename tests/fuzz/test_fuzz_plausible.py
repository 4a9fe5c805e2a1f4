"""Property-based fuzzing of the physical plausibility rules, with metamorphic properties.

Generated: bevel pair geometries over ranges far wider than gears (API); excitation tables of any magnitude
(files read back); system files whose bevel mesh geometry is replaced (the ``modes`` command); simulate
results with their drawn variables retyped or reshaped (``plot``); parameter points of the damped 1-DOF model
(the classifier).  Properties:

* accepted means plausible: a geometry or table the rules accept lies within every named bound, a refused
  one raises the package's error naming its key;
* metamorphic: scaling every length of a pair by s (inertias kept) scales f_n by s^(3/2) (k0 = b c_γ ∝ s,
  m_e ∝ s⁻²); the hand of spiral does not change the torsional model; scaling an STE table by c scales the
  model's STE harmonics by c; a table whose values lie out of range is refused however it is spelled;
* the classifier never labels a point of the damped 1-DOF model quasi-periodic (its period map contracts
  area, det = exp(−4πξ0/ω)).

The default profile (``derandomize``, a few dozen cases) takes well under a minute; ``-m slow`` runs the long
profile.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from fuzz_helpers import EXAMPLES, check_contract, run
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from geardyn import plausible
from geardyn.errors import ConfigError, ModelError
from geardyn.geometry import SpiralBevelGearPair

FAST = settings(
    max_examples=40, deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck)
)
FAST_FILES = settings(FAST, max_examples=8)
LONG = settings(max_examples=400, deadline=None, database=None, suppress_health_check=list(HealthCheck))
DEG = math.pi / 180
KEYS = ("alpha_n", "beta_m", "m_mn", "j_n", "r1", "r2", "face_width", "z1", "z2", "Sigma", "I1", "I2")


def log_uniform(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


@st.composite
def geometries(draw) -> dict:
    """Half of the pairs drawn near gears that are made (most accepted), half anywhere (most refused)."""
    made = draw(st.booleans())
    z1 = draw(st.integers(5, 60) if made else st.integers(1, 200))
    z2 = draw(st.integers(z1, 5 * z1) if made else st.integers(1, 400))
    m = draw(log_uniform(1e-3, 2e-2) if made else log_uniform(1e-6, 10.0))
    beta = draw(st.floats(0.0, 45.0) if made else st.floats(0.0, 89.0)) * DEG
    kw = dict(
        z1=z1,
        z2=z2,
        m_mn=m,
        beta_m=beta,
        alpha_n=draw(st.floats(14.5, 30.0) if made else st.floats(0.5, 89.9)) * DEG,
        j_n=draw(st.one_of(st.just(0.0), log_uniform(1e-6, 0.1 * m) if made else log_uniform(1e-7, 10.0))),
        I1=draw(log_uniform(1e-6, 1e3)),
        I2=draw(log_uniform(1e-6, 1e3)),
    )
    if draw(st.booleans()):  # radii given: about the pitch radii, or anything
        spread = (0.97, 1.03) if made else (0.2, 3.0)
        f1, f2 = draw(st.floats(*spread)), draw(st.floats(*spread))
        kw["r1"] = f1 * m * z1 / (2 * math.cos(beta))
        kw["r2"] = f2 * m * z2 / (2 * math.cos(beta))
    if draw(st.booleans()):
        kw["face_width"] = draw(st.floats(3.0, 10.0).map(lambda k: k * m) if made else log_uniform(1e-5, 100.0))
    return kw


def within_bounds(p: SpiralBevelGearPair) -> None:
    """Every named bound holds for an accepted pair."""
    lo, hi = plausible.ALPHA_N_DEG
    assert lo <= math.degrees(p.alpha_n) <= hi
    assert math.degrees(p.beta_m) <= plausible.BETA_M_MAX_DEG
    assert plausible.MODULE_M[0] <= p.m_mn <= plausible.MODULE_M[1]
    assert p.j_n <= plausible.BACKLASH_MAX_MODULES * p.m_mn
    if p.r1 is not None and p.r2 is not None:
        q = (p.r2 / p.r1) / (p.z2 / p.z1)
        assert math.cos(p.beta_m) * (1 - plausible.RADIUS_RATIO_TOL) <= q <= 1 + plausible.RADIUS_RATIO_TOL
    if p.face_width is not None:
        r_m = p.resolved.r1 / math.sin(p.delta1)
        assert p.face_width <= plausible.FACE_WIDTH_MAX_CONE * (r_m + 0.5 * p.face_width)
    assert math.isfinite(p.m_e) and p.m_e > 0 and math.isfinite(p.omega_n) and p.omega_n > 0


def geometry_case(kw: dict, s: float) -> None:
    try:
        p = SpiralBevelGearPair(**kw)
    except ModelError as e:
        msg = str(e)
        assert "\n" not in msg and msg.split(":", 1)[0] in KEYS + ("xi0/c0", "assumed"), msg
        return
    within_bounds(p)
    # metamorphic: the hand of spiral changes no torsional quantity
    q = SpiralBevelGearPair(**kw, hand="right")
    assert q.m_e == pytest.approx(p.m_e, rel=1e-12) and q.omega_n == pytest.approx(p.omega_n, rel=1e-12)
    # metamorphic: every length × s, inertias kept: k0 ∝ s (b c_γ), m_e ∝ s⁻² (R_l ∝ s), f_n ∝ s^(3/2)
    scaled = {k: (v * s if k in ("m_mn", "j_n", "r1", "r2", "face_width") else v) for k, v in kw.items()}
    try:
        ps = SpiralBevelGearPair(**scaled)
    except ModelError as e:  # the scaled pair may leave the module's range, never another bound
        assert str(e).startswith("m_mn:"), str(e)
        return
    assert ps.k0_mean == pytest.approx(s * p.k0_mean, rel=1e-12)
    assert ps.m_e == pytest.approx(p.m_e / s**2, rel=1e-12)
    assert ps.omega_n == pytest.approx(p.omega_n * s**1.5, rel=1e-12)


@FAST
@given(geometries(), st.floats(0.25, 4.0))
def test_bevel_geometry(kw, s):
    geometry_case(kw, s)


@pytest.mark.slow
@LONG
@given(geometries(), st.floats(0.25, 4.0))
def test_bevel_geometry_long(kw, s):
    geometry_case(kw, s)


# ---------------------------------------------------------------- excitation tables
MAGNITUDES = st.one_of(
    log_uniform(1e-3, 1e15),
    st.sampled_from([1e300, 1e-300, 5e-324, 1e30, 1e-30, 999.0, 1e12, 1.0000001e12]),
)


def table_case(data, tmp_path: Path) -> None:
    from geardyn.model import GearModel
    from geardyn.tooth.excitation import excitation_model
    from geardyn.tooth.table import read_table

    n = data.draw(st.integers(4, 24), label="phases")
    k_mean = data.draw(MAGNITUDES, label="stiffness")
    e_amp = data.draw(st.one_of(log_uniform(1e-9, 1e-2), st.sampled_from([0.0, 1e300, 2e-3])), label="ste")
    th = 2 * np.pi * np.arange(n) / n
    k = k_mean * (1 + 0.2 * np.cos(th))
    e = e_amp * np.cos(th + 0.3)
    spelled = data.draw(st.sampled_from(["csv", "json"]), label="format")
    f = tmp_path / f"t.{spelled}"
    if spelled == "csv":
        f.write_text(
            "phase_cycles,stiffness_N_per_m,ste_m\n"
            + "".join(f"{i / n!r},{float(k[i])!r},{float(e[i])!r}\n" for i in range(n))
        )
    else:
        import json

        f.write_text(json.dumps({"cycles": 1, "stiffness_N_per_m": list(k), "ste_m": list(e)}))
    lo, hi = plausible.STIFFNESS_N_PER_M
    inside = lo <= k.min() and k.max() <= hi and np.max(np.abs(e)) <= plausible.STE_MAX_M
    try:
        exc = read_table(f)
    except ConfigError as err:
        assert not inside, str(err)
        assert "\n" not in str(err) and str(f) in str(err)
        return
    assert inside
    np.testing.assert_allclose(exc.stiffness, k, rtol=1e-15)
    # metamorphic: the model's STE harmonics are linear in the table (c·e gives c·ε)
    c = data.draw(st.floats(0.1, 0.9), label="scale")
    base = GearModel(omega=0.8, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=())
    a = excitation_model(base, exc, b_c=1e-5)
    b = excitation_model(base, type(exc)(exc.stiffness, c * exc.ste, exc.cycles), b_c=1e-5)
    ea, eb = np.asarray(a.eps), np.asarray(b.eps)
    np.testing.assert_allclose(eb, c * ea, rtol=1e-9, atol=1e-12 * float(np.max(np.abs(ea), initial=0.0)) + 1e-300)


@FAST_FILES
@given(data=st.data())
def test_excitation_tables(data, tmp_path_factory):
    table_case(data, tmp_path_factory.mktemp("tab"))


@pytest.mark.slow
@LONG
@given(data=st.data())
def test_excitation_tables_long(data, tmp_path_factory):
    table_case(data, tmp_path_factory.mktemp("tab"))


# ---------------------------------------------------------------- system files
SYSTEM = (EXAMPLES / "systems" / "paper_torsional.toml").read_text()
SYSTEM_VALUES = {
    "alpha_n": ('alpha_n = "20 deg"', st.floats(0.5, 89.9).map(lambda x: f'alpha_n = "{x:.6g} deg"')),
    "beta_m": ('beta_m = "35 deg"', st.floats(0.0, 89.0).map(lambda x: f'beta_m = "{x:.6g} deg"')),
    "r2": ('r2 = "256 mm"', log_uniform(1.0, 1e4).map(lambda x: f'r2 = "{x:.6g} mm"')),
    "m_mn": ('m_mn = "7.28 mm"', log_uniform(1e-3, 1e4).map(lambda x: f'm_mn = "{x:.6g} mm"')),
    "backlash": ('backlash = "0.1 mm"', log_uniform(1e-4, 1e4).map(lambda x: f'backlash = "{x:.6g} mm"')),
}


def system_case(data, tmp_path: Path) -> None:
    key = data.draw(st.sampled_from(sorted(SYSTEM_VALUES)), label="key")
    old, values = SYSTEM_VALUES[key]
    new = data.draw(values, label="value")
    assert old in SYSTEM
    f = tmp_path / "s.toml"
    f.write_text(SYSTEM.replace(old, new))
    args = ["modes", "--system", f, "--json"]
    code, out, err = run(args)
    check_contract(code, out, err, json_mode=True, args=args)
    if code == 2:  # refused: one line naming the file and the key (a backlash is the mesh's j_n)
        assert len(err.strip().splitlines()) == 1 and "s.toml" in err, err
        assert key in err or (key == "backlash" and "j_n" in err) or "m_mn" in err or "r1" in err, err


@FAST_FILES
@given(data=st.data())
def test_system_files(data, tmp_path_factory):
    system_case(data, tmp_path_factory.mktemp("sys"))


@pytest.mark.slow
@LONG
@given(data=st.data())
def test_system_files_long(data, tmp_path_factory):
    system_case(data, tmp_path_factory.mktemp("sys"))


# ---------------------------------------------------------------- result files
@pytest.fixture(scope="module")
def simulate_result(tmp_path_factory) -> xr.Dataset:
    d = tmp_path_factory.mktemp("sim")
    code, _, err = run(["simulate", "--omega", "0.8", "--transient", "20", "--periods", "8", "--out", d, "--json"])
    assert code == 0, err
    with xr.open_dataset(d / "simulate.nc", engine="h5netcdf") as ds:
        return ds.load()


def result_case(data, ds: xr.Dataset, tmp_path: Path) -> None:
    name = data.draw(st.sampled_from(["u", "v", "poincare_u", "poincare_v", "spectrum", "tau"]), label="variable")
    how = data.draw(st.sampled_from(["text", "reshape"]), label="mutation")
    ds = ds.copy()
    if how == "text":
        ds[name] = ds[name].astype(str)
    elif name in ds.coords:  # a dimension coordinate keeps its shape: stretched to another length instead
        return
    else:
        v = ds[name]
        ds = ds.drop_vars(name)
        ds[name] = ((*v.dims, "extra"), np.stack([v.values] * 2, axis=-1))
    f = tmp_path / "bad.nc"
    try:
        ds.to_netcdf(f, engine="h5netcdf")
    except (ValueError, TypeError):
        return
    args = ["plot", f, "--out", tmp_path / "fig", "--json"]
    code, out, err = run(args)
    check_contract(code, out, err, json_mode=True, args=args)
    assert code == 2, f"a {how} {name} was drawn: {err}"  # refused, never drawn
    assert len(err.strip().splitlines()) == 1


@FAST_FILES
@given(data=st.data())
def test_result_files_of_another_type_or_shape(data, simulate_result, tmp_path_factory):
    result_case(data, simulate_result, tmp_path_factory.mktemp("nc"))


# ---------------------------------------------------------------- the classifier and the model's structure
@settings(FAST, max_examples=3)
@given(st.lists(st.tuples(st.floats(0.5, 1.5), st.floats(0.02, 0.3)), min_size=4, max_size=4))
def test_the_damped_pair_is_never_labelled_quasi_periodic(points):
    from geardyn.analysis.classify import MOTION_QUASIPERIODIC
    from geardyn.analysis.steady import classify_batch
    from geardyn.integrate import integrate_batch
    from geardyn.model import GearModel, IntegrationOptions

    models = [GearModel(omega=w, xi0=x) for w, x in points]
    res = integrate_batch(models, None, IntegrationOptions(transient=100, periods=100))
    out = classify_batch(res, settle_periods=200)
    assert not np.any(out["motion"] == MOTION_QUASIPERIODIC), points
