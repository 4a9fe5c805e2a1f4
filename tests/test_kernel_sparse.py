"""The N-DOF kernel's sparse form and the leading exponents of a classification.

The sparse arrays must hold exactly the dense matrices (every nonzero, nothing else); the state's arithmetic is the
dense kernel's bit for bit (the recorded numbers of ``tests/test_system_pins.py`` and ``benchmarks/ndof_scaling.py``'s
checksums check it against the dense code).  The leading exponents are those of the motion modulo the rigid-body
modes: for the torsional pair (one free rotation, d = 4) the two of them are the elastic pair of the full spectrum,
whose sum is the mean trace of the Jacobian (−2ξ0 = −0.2 for the paper's pair: Liouville's formula, exact).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn.model import IntegrationOptions
from geardyn.systems import SystemModel, load_system

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples" / "systems"
sys.path.insert(0, str(ROOT / "benchmarks"))


def _dense_from(ptr, idx, vals, rows, cols):
    out = np.zeros((rows, cols))
    for r in range(rows):
        for k in range(ptr[r], ptr[r + 1]):
            out[r, idx[k]] = vals[k]
    return out


@pytest.mark.parametrize("path", ["paper_bevel_8dof.toml", "spur_bending_torsional.toml", "chain"])
def test_sparse_arrays_hold_the_dense_matrices(path, tmp_path):
    from geardyn import _kernel_ndof as K

    if path == "chain":
        from ndof_scaling import chain_toml

        s = load_system(chain_toml(3, tmp_path / "chain.toml"))
    else:
        s = load_system(EX / path)
    a = SystemModel.pack([s, s.with_param("omega", 0.7)])
    A, B, W, g, Wc = K.derived(a)
    sp, jt, blk = K.sparse_arrays(a)
    abp, abj, Av, Bv, ep, ej, Ev, wp, wi, Wv, gs = sp
    n = s.n
    E_V = np.concatenate([a.V, a.Vc], axis=1)
    E_W = np.concatenate([W, Wc], axis=1)
    for p in range(2):
        np.testing.assert_array_equal(_dense_from(abp, abj, Av[p], n, n), A[p])
        np.testing.assert_array_equal(_dense_from(abp, abj, Bv[p], n, n), B[p])
        np.testing.assert_array_equal(_dense_from(ep, ej, Ev[p], E_V.shape[1], n), E_V[p])
        np.testing.assert_array_equal(_dense_from(wp, wi, Wv[p], E_W.shape[1], n), E_W[p])
        np.testing.assert_array_equal(gs[p], g[p])
    # the blocks of the plain step: their diagonals hold A and B, every nonzero once, and nothing else
    bcp, bcj, ATs, BTs = blk[0], blk[1], blk[2], blk[3]
    L = K.LANE_BLOCK
    for p in range(2):
        Ab = np.zeros((n, n))
        Bb = np.zeros((n, n))
        for b in range(len(bcp) - 1):
            assert np.all(np.diff(bcj[bcp[b] : bcp[b + 1]]) > 0)  # ascending: each row meets its columns in order
            for k in range(bcp[b], bcp[b + 1]):
                for r in range(L):
                    i, j = b * L + r, b * L + r + bcj[k]
                    if 0 <= i < n and 0 <= j < n:
                        Ab[i, j] += ATs[p, k, r]
                        Bb[i, j] += BTs[p, k, r]
                    else:
                        assert ATs[p, k, r] == 0.0 and BTs[p, k, r] == 0.0
        np.testing.assert_array_equal(Ab, A[p])
        np.testing.assert_array_equal(Bb, B[p])
    assert blk[10] >= np.max(np.abs(bcj), initial=0) and blk[10] % L == 0  # the state's margin
    # the element groups: lane l of group G is element G·L + l, its terms in order (padding: value 0)
    EI, EVs = blk[8], blk[9]
    for p in range(2):
        for e in range(E_V.shape[1]):
            k = np.arange(ep[e], ep[e + 1])
            np.testing.assert_array_equal(EI[e // L, : k.size, e % L], ej[k])
            np.testing.assert_array_equal(EVs[p, e // L, : k.size, e % L], Ev[p, k])
            assert np.all(EVs[p, e // L, k.size :, e % L] == 0.0)
    # the Jacobian's pattern covers A + Σ W Vᵀ
    G = np.abs(A[0]) + np.abs(E_W[0]).T @ np.abs(E_V[0])
    pat = _dense_from(jt[0], jt[1], np.ones(jt[1].size), n, n)
    assert np.all(pat[G != 0] == 1)


def test_leading_exponents_are_the_elastic_ones():
    from geardyn.analysis.lyapunov import lyapunov_spectrum, spectrum_from_log
    from geardyn.integrate import integrate_batch

    t = load_system(EX / "paper_torsional.toml").with_param("omega", 0.8)
    opts = IntegrationOptions(transient=50, periods=200)
    full = lyapunov_spectrum(t, opts).exponents  # [~0, ~0 (the free rotation), λ_a, λ_b]
    r = integrate_batch([t], None, opts, lyapunov=True, tangents=2)
    lam, _err = spectrum_from_log(r.lyapunov_log, np.array([t.sampling_period]))
    assert r.lyapunov_log.shape[2] == 2
    assert lam[0].sum() == pytest.approx(t.mean_trace(), abs=1e-9)  # Liouville: the trace of the quotient
    assert t.mean_trace() == pytest.approx(-0.2, abs=1e-12)
    np.testing.assert_allclose(lam[0], full[2:], atol=2e-3)


def test_lyapunov_of_a_system_prints_the_cost_of_its_full_spectrum():
    from cli_run import run_cli

    code, out, err = run_cli(
        [
            "lyapunov",
            "--system",
            EX / "paper_torsional.toml",
            "--omega",
            "0.8",
            "--transient",
            "5",
            "--periods",
            "40",
            "--blocks",
            "4",
        ]
    )  # the cost line is printed where progress is (not with --json, whose stderr stays empty)
    assert code == 0, err
    assert "the full spectrum integrates 4 tangent vectors" in err and "x the work of a plain run" in err


def test_work_of_the_leading_vectors_is_a_small_multiple_of_a_plain_run(tmp_path):
    from ndof_scaling import chain_toml

    from geardyn.backend import tangent_work

    s = load_system(chain_toml(4, tmp_path / "c.toml"))
    assert 1.0 < tangent_work([s], 2) < 4.0
    assert tangent_work([s]) > 10 * tangent_work([s], 2)


def _chain_with_bearing_and_order(tmp_path):
    """A 2-stage chain (12 DOF: the grouped sparse step) with a ball bearing on the first pinion and a torque order
    at the mesh order on its drive."""
    from ndof_scaling import chain_toml

    f = chain_toml(2, tmp_path / "chain.toml", fp_torque=100.0)  # the pinion's bearing deflection beyond 5 µm
    text = f.read_text().replace(
        'body = "p1"\ntorque = "100.0 N*m"\n',
        'body = "p1"\ntorque = "100.0 N*m"\norders = [{ order = 32, amplitude = "30 N*m", phase = "10 deg" }]\n',
    )
    assert "orders" in text
    text += """
[[bearing]]
name = "brg"
type = "ball"
body = "p1"
elements = 8
pitch_diameter = "40 mm"
element_diameter = "10 mm"
contact_angle = "0 deg"
radial_clearance = "5 um"
load_deflection = { value = "8e9 N/m^1.5", assumed = "a small deep-groove ball bearing" }
cx = "200 N*s/m"
cy = "200 N*s/m"
"""
    f.write_text(text)
    return f


@pytest.mark.parametrize("which", ["chain", "bearing_order"])
def test_grouped_plain_step_is_the_row_by_row_step_bit_for_bit(which, tmp_path):
    """The plain step (diagonal blocks, element groups) against the step of the full spectrum, which sums row by row
    and element by element (``core.field``): the same trajectory and statistics, bit for bit."""
    from ndof_scaling import chain_toml

    from geardyn.integrate import integrate_batch

    if which == "chain":
        s = load_system(chain_toml(3, tmp_path / "chain.toml", fp_torque=2.0, eps_um=40.0))  # 18 DOF
    else:
        s = load_system(_chain_with_bearing_and_order(tmp_path))
    assert s.n > 8  # the sparse step (one block of rows takes the dense one)
    ms = [s.with_param("omega", w) for w in (0.7, 1.1)]
    opts = IntegrationOptions(transient=0, periods=3)
    plain = integrate_batch(ms, None, opts, threads=1)
    full = integrate_batch(ms, None, opts, threads=1, lyapunov=True)  # all 2n tangents: the row-by-row step
    assert np.asarray(plain.poincare).tobytes() == np.asarray(full.poincare).tobytes()
    for e in range(len(s.elements)):
        np.testing.assert_array_equal(plain.element_u_max(e), full.element_u_max(e))
        np.testing.assert_array_equal(plain.element_u_min(e), full.element_u_min(e))
