"""The explicit-SIMD lanes (``geardyn._kernel.simd``) give the same bits as the compiler-vectorised
lanes and as the scalar path, lane by lane, in every kernel mode.

The same batch is run through ``run_batch`` at each register width (512, 256 and 0, the
compiler-vectorised loops of the template, i.e. the kernel before the explicit vectors) and
through the scalar worker (one point at a time, state in registers: another implementation of the
same arithmetic); every output array must agree bit for bit.  The batches cover both
first-harmonic kinds (cosine terms only, sine terms), the general kind (any number of harmonics,
which always runs the template), points with and without backlash, different steps per period
(lanes reaching their period ends at different steps), a diverging point, a batch size that
leaves partial blocks once the queue is empty (1 to 4 vectors per step), one and two threads,
and the modes: plain transient, statistics, Lyapunov tangents, monodromy, adaptive transient and
the accurate mode (scalar in every width).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numba
import numpy as np
import pytest

from geardyn import _kernel as K
from geardyn._kernel import lanes
from geardyn._kernel.scalar import _scalar_worker
from geardyn._kernel.simd import BLOCKS
from geardyn.model import GearModel
from geardyn.pairpack import steps_per_period

WIDTHS = (512, 256, 0)


def _batch(kind: str, P: int = 37):
    """Arrays of a batch of P points of one chunk kind, with varied ω, backlash and start states."""
    rng = np.random.default_rng({"cos": 1, "sin": 2, "gen": 3}[kind])
    omegas = np.linspace(0.5, 1.6, P)
    models = []
    for i, w in enumerate(omegas):
        kw = dict(omega=float(w), D=(0.0 if i % 9 == 4 else (0.5 if i % 7 == 3 else 1.0)))
        if kind == "sin":
            kw.update(phi_c=(0.3,), phi_k=(-0.7,), phi_e=(1.1,))
        elif kind == "gen":
            kw.update(xi=(0.05, 0.02), kappa=(0.2, 0.05), eps=(0.5, 0.1))
        if i == 11:
            kw.update(xi0=-0.4)  # negative damping: diverges
        models.append(GearModel(**kw))
    coef = np.ascontiguousarray(np.stack([m.coefficients() for m in models]))
    D = np.array([m.D for m in models])
    omega = np.array([m.omega for m in models])
    nsteps = np.asarray(steps_per_period(omega, 0.02), dtype=np.int64)
    state0 = rng.uniform(-1.5, 1.5, size=(P, 2))
    return coef, D, omega, nsteps, state0


def _outputs(P, n_record, hist_len=0):
    return dict(
        poincare=np.zeros((P, n_record, 2)),
        end_state=np.zeros((P, 2)),
        stats=np.zeros((P, K.NSTAT)),
        tan_log=np.zeros((P, n_record, 2)),
        tan_out=np.zeros((P, 2, 2)),
        status=np.zeros(P, dtype=np.int64),
        hist=np.zeros((P, hist_len, 2)),
    )


def _run(width, batch, n_transient, n_record, tangent, accurate=False, adapt=False, threads=1):
    coef, D, omega, nsteps, state0 = batch
    out = _outputs(coef.shape[0], n_record)
    old_w = lanes._set_simd_width(width)
    old_t = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        K.run_batch(
            coef,
            D,
            omega,
            nsteps,
            state0,
            n_transient,
            n_record,
            tangent,
            accurate,
            out["poincare"],
            out["end_state"],
            out["stats"],
            out["tan_log"],
            out["tan_out"],
            out["status"],
            out["hist"],
            1e-10 if adapt else 0.0,
            8 if adapt else 0,
        )
    finally:
        numba.set_num_threads(old_t)
        lanes._set_simd_width(old_w)
    return out


def _run_scalar(batch, n_transient, n_record, tangent):
    """The scalar worker on the whole batch (one point at a time)."""
    coef, D, omega, nsteps, state0 = batch
    out = _outputs(coef.shape[0], n_record)
    order = K._queue_order(nsteps)
    _scalar_worker(
        order,
        np.zeros(1, dtype=np.int64),
        coef,
        D,
        omega,
        nsteps,
        state0,
        n_transient,
        n_record,
        tangent,
        out["poincare"],
        out["end_state"],
        out["stats"],
        out["tan_log"],
        out["tan_out"],
        out["status"],
        out["hist"],
        0.0,
        0,
    )
    return out


def _bits(out):
    """Every output value as an integer: the bit pattern of the floats, the status codes."""
    return [int(x) for a in out.values() for x in (a.ravel().view(np.uint64) if a.dtype == np.float64 else a.ravel())]


def _assert_same_bits(a, b, what):
    for name in a:
        x, y = a[name], b[name]
        assert x.shape == y.shape
        same = x.view(np.uint64) == y.view(np.uint64) if x.dtype == np.float64 else x == y
        bad = np.argwhere(~same)
        first = tuple(bad[0]) if bad.size else ()
        assert bad.size == 0, f"{what}: {name} differs at {bad[:5].tolist()} ({x[first]!r} vs {y[first]!r})"


MODES = {  # (n_transient, n_record, tangent, adaptive)
    "plain": (7, 0, K.TAN_NONE, False),
    "statistics": (6, 5, K.TAN_NONE, False),
    "tangents": (5, 6, K.TAN_LYAPUNOV, False),
    "monodromy": (4, 3, K.TAN_MONODROMY, False),
    "adaptive": (60, 4, K.TAN_NONE, True),
}


@pytest.fixture(scope="module", params=["cos", "sin", "gen"])
def batch(request):
    return request.param, _batch(request.param)


def test_batch_kinds_are_those_named(batch):
    kind, (coef, D, omega, nsteps, state0) = batch
    order = K._queue_order(nsteps)
    assert lanes._lanes_kind(coef, order) == {"cos": K.KIND_COS, "sin": K.KIND_SIN, "gen": K.KIND_GEN}[kind]
    assert len(set(nsteps.tolist())) > 10  # the lanes end their periods at different steps


@pytest.mark.parametrize("mode", list(MODES))
def test_widths_give_the_same_bits_lane_by_lane(batch, mode):
    kind, arrays = batch
    n_tr, n_rec, tangent, adapt = MODES[mode]
    ref = _run(0, arrays, n_tr, n_rec, tangent, adapt=adapt)
    assert ref["status"][11] == K.ST_DIVERGED and np.sum(ref["status"] == K.ST_OK) == len(ref["status"]) - 1
    assert np.all(np.isfinite(ref["poincare"][ref["status"] == K.ST_OK]))
    for width in (512, 256):
        _assert_same_bits(ref, _run(width, arrays, n_tr, n_rec, tangent, adapt=adapt), f"{kind} {mode} width {width}")
    _assert_same_bits(
        ref,
        _run(lanes.native_simd_width(), arrays, n_tr, n_rec, tangent, adapt=adapt, threads=2),
        f"{kind} {mode} native width, 2 threads",
    )
    if not adapt:
        _assert_same_bits(ref, _run_scalar(arrays, n_tr, n_rec, tangent), f"{kind} {mode} scalar worker")


def test_accurate_mode_is_the_same_in_every_width():
    arrays = _batch("cos", P=6)
    ref = _run(0, arrays, 3, 3, K.TAN_LYAPUNOV, accurate=True)
    assert np.all(ref["status"][np.arange(6) != 11] == K.ST_OK)
    for width in (512, 256):
        _assert_same_bits(ref, _run(width, arrays, 3, 3, K.TAN_LYAPUNOV, accurate=True), f"accurate width {width}")


def test_partial_blocks_give_the_same_bits():
    """Small batches: once the queue is empty the lanes in use run as fewer vectors per step."""
    for P in (3, 5, 9, 17, 21):
        arrays = _batch("cos", P=P)
        ref = _run(0, arrays, 3, 4, K.TAN_LYAPUNOV)
        for width in (512, 256):
            _assert_same_bits(ref, _run(width, arrays, 3, 4, K.TAN_LYAPUNOV), f"P={P} width {width}")


def _asm(width, mode=lanes.MODE_TAN):
    f = BLOCKS[(False, mode, width)]
    if not f.signatures:
        f.compile((numba.float64[::1], numba.int64, numba.int64))
    return f.inspect_asm(f.signatures[0])


@pytest.mark.skipif(lanes.native_simd_width() != 512, reason="the CPU has no AVX-512")
def test_512_bit_blocks_use_zmm_registers_and_256_bit_ones_do_not():
    wide = _asm(512)
    assert "zmm" in wide and "vfmadd" in wide
    narrow = _asm(256)
    assert "zmm" not in narrow and "ymm" in narrow and "vfmadd" in narrow


def test_width_from_the_environment():
    code = (
        "from geardyn._kernel import lanes, simd_width; import sys; "
        "sys.stdout.write(str(simd_width()) + ' ' + str(lanes.native_simd_width()))"
    )
    env = dict(os.environ)
    for value, expect in (("256", "256"), ("0", "0"), ("512", "512")):
        env[lanes.SIMD_ENV] = value
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
        assert out.split()[0] == expect
    env.pop(lanes.SIMD_ENV)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert out.split()[0] == out.split()[1] in ("256", "512")
    env[lanes.SIMD_ENV] = "128"
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert r.returncode != 0 and lanes.SIMD_ENV in r.stderr


def test_avx2_machine_code_gives_the_same_bits():
    """The kernel compiled for a CPU without AVX-512 (``NUMBA_CPU_NAME=haswell``: 256-bit lanes
    chosen as the native width) gives the bits of this process's lanes, statistics and tangents."""
    arrays = _batch("sin", P=21)
    ref = _run(0, arrays, 3, 4, K.TAN_LYAPUNOV)
    code = (
        "import sys, numpy as np\n"
        f"sys.path.insert(0, {os.path.dirname(__file__)!r})\n"
        "import test_simd as T\n"
        "from geardyn._kernel import simd_width\n"
        "assert simd_width() == 256, simd_width()\n"
        "out = T._run(256, T._batch('sin', P=21), 3, 4, T.K.TAN_LYAPUNOV)\n"
        "sys.stdout.write(' '.join(str(x) for x in T._bits(out)))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != lanes.SIMD_ENV}
    env.update(NUMBA_CPU_NAME="haswell", NUMBA_CPU_FEATURES="+avx,+avx2,+fma,+sse4.2,+popcnt")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert [int(x) for x in out.split()] == _bits(ref)
