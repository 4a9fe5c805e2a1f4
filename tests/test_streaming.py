"""Sweeps without a model per point and without per-chunk copies: packed points, batch
classification and streamed rows give bit for bit what the per-model path gives."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.analysis.bifurcation import fixed_chunk, grid_chunk
from geardyn.analysis.classify import detect_period, detect_periods, impact_state, impact_states
from geardyn.analysis.maps import MAP_VARIABLES, parameter_map
from geardyn.analysis.points import RowSink, concat_rows
from geardyn.grid import Grid, build_models
from geardyn.integrate import integrate_batch
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.pairpack import PointModels, pack_models, pack_points
from geardyn.sweep import Chunk, run_chunks

SHORT = IntegrationOptions(transient=5, periods=12)


def square(x: np.ndarray) -> dict[str, np.ndarray]:
    """A chunk function: rows x and x² (in process)."""
    return {"x": x, "x2": np.column_stack([x, x * x])}


def _same(a, b) -> None:
    assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize(
    "names",
    [
        ["omega", "xi0"],
        ["omega", "phi_e1", "kappa1"],
        ["eps2", "phi_c3", "fp", "D"],
        ["phi_k2"],
        ["fe", "backlash", "xi1"],
        ["omega", "omega"],
    ],
)
def test_pack_points_is_pack_models_of_the_models(names):
    rng = np.random.default_rng(len(names))
    pts = rng.uniform(0.05, 0.3, (300, len(names)))
    pts[::7] = np.round(pts[::7], 2)  # repeated values
    if "omega" not in names:
        pts[3] = 0.0
        pts[5, 0] = -0.0  # a signed zero keeps its sign through sin
    for a, b in zip(pack_models(build_models(GearModel(), names, pts)), pack_points(GearModel(), names, pts)):
        _same(a, b)


@pytest.mark.parametrize(
    "base, names, pts",
    [
        (GearModel(), ["omega", "xi0"], [[0.5, 0.1], [-1.0, 0.1]]),
        (GearModel(), ["omega", "xi0"], [[0.5, np.nan]]),
        (GearModel(), ["kappa1"], [[0.3], [1.2]]),
        (GearModel(), ["D"], [[0.3], [-1.0]]),
        (GearModel(kappa=(0.2, 0.7)), ["kappa1", "kappa2"], [[0.5, 0.1]]),  # refused on the way, as with_param does
        (GearModel(), ["omega", "omega"], [[-1.0, 0.5]]),
    ],
)
def test_pack_points_refuses_what_the_model_refuses(base, names, pts):
    with pytest.raises(ModelError) as want:
        build_models(base, names, np.array(pts))
    with pytest.raises(ModelError) as got:
        pack_points(base, names, np.array(pts))
    assert str(got.value) == str(want.value)
    with pytest.raises(ModelError):
        PointModels(base, names, np.array(pts))


def test_point_models_integrate_and_index_like_models():
    pts = np.column_stack([np.linspace(0.5, 1.5, 40), np.linspace(0.05, 0.3, 40)])
    models = build_models(GearModel(), ["omega", "xi0"], pts)
    pm = PointModels(GearModel(), ["omega", "xi0"], pts)
    assert len(pm) == 40 and pm[3] == models[3] and pm[-1] == models[-1]
    assert list(pm[5:8]) == models[5:8]
    for lyap in (False, True):
        a = integrate_batch(models, (0.1, 0.0), SHORT, lyapunov=lyap)
        b = integrate_batch(pm, (0.1, 0.0), SHORT, lyapunov=lyap)
        for k in ("poincare", "end_state", "stats", "status", "nsteps"):
            _same(getattr(a, k), getattr(b, k))
    ra = fixed_chunk(models, (0.0, 0.0), SHORT, False, 50)
    rb = grid_chunk(GearModel(), ["omega", "xi0"], pts, (0.0, 0.0), SHORT, False, 50)
    assert ra.keys() == rb.keys()
    for k in ra:
        _same(ra[k], rb[k])


def test_batch_period_and_impact_equal_the_scalar_ones():
    rng = np.random.default_rng(3)
    P, m = 400, 24
    pts = rng.normal(size=(P, m, 2))
    for i in range(0, P, 3):  # period n cycles, some with noise around the tolerance
        n = 1 + i % 9
        pts[i] = np.tile(pts[i, :n], (m // n + 1, 1))[:m] + rng.normal(scale=10.0 ** rng.uniform(-9, -5), size=(m, 2))
    pts[7, 4] = np.nan
    pts[11, 0, 1] = np.inf
    _same(detect_periods(pts), np.array([detect_period(p) for p in pts], dtype=np.int64))
    for short in (pts[:, :0], pts[:, :1], pts[:, :3]):
        _same(detect_periods(short), np.array([detect_period(p) for p in short], dtype=np.int64))
    u = np.concatenate([rng.uniform(-3, 3, 200), [np.nan, np.inf, 1.0, -1.0, 0.0]])
    D = np.concatenate([rng.choice([0.0, 0.5, 1.0], 200), [1.0, 1.0, 1.0, 1.0, 0.0]])
    _same(impact_states(u, D), np.array([impact_state(a, b) for a, b in zip(u, D)], dtype=np.int64))


def test_row_sink_equals_concatenated_rows_in_any_order():
    rng = np.random.default_rng(0)
    chunks = [{"a": rng.normal(size=n), "b": rng.integers(0, 9, (n, 3, 2))} for n in (5, 1, 7, 3)]
    sink = RowSink([0, 5, 6, 13], 16)
    for k in (2, 0, 3, 1):
        sink(k, chunks[k])
    want = concat_rows(chunks)
    for k in want:
        _same(sink.result()[k], want[k])
    with pytest.raises(Exception, match="rows"):
        RowSink([0, 5], 9).result()


def test_run_chunks_sink_and_resume_deliver_every_chunk_once(tmp_path):
    chunks = [Chunk(i, square, (np.arange(i * 4, i * 4 + 4, dtype=float),)) for i in range(6)]
    ref = concat_rows(run_chunks(chunks))
    ck = tmp_path / "ck"
    run_chunks(chunks[:3] + chunks[3:], checkpoint=ck)  # all chunks finished and saved
    seen: list[int] = []
    sink = RowSink([4 * i for i in range(6)], 24)

    def record(pos, r):
        seen.append(pos)
        sink(pos, r)

    assert run_chunks(chunks, checkpoint=ck, resume=True, sink=record) is None
    assert sorted(seen) == list(range(6))
    for k in ref:
        _same(sink.result()[k], ref[k])


def test_grid_lazy_models_and_omegas():
    g = Grid("product", ["xi0", "omega"], [np.array([0.1, 0.2]), np.array([0.5, 0.7, 0.9])])
    lazy = g.lazy_models(GearModel())
    assert len(lazy) == 6 and list(lazy) == g.models(GearModel()) and lazy[-1] == g.models(GearModel())[-1]
    _same(g.omegas(GearModel()), np.array([m.omega for m in g.models(GearModel())]))
    with pytest.raises(ModelError, match="D"):
        Grid.range("D", [0.5, -1.0]).lazy_models(GearModel())


def test_map_streamed_equals_map_in_one_chunk_and_two_workers():
    kw = dict(options=SHORT, settle_periods=40)
    args = (GearModel(), "omega", np.linspace(0.6, 1.4, 9), "xi0", np.linspace(0.05, 0.2, 4))
    one = parameter_map(*args, chunk_points=36, **kw)
    small = parameter_map(*args, chunk_points=5, **kw)
    assert set(MAP_VARIABLES) <= set(one.data_vars)
    assert one.identical(small)
    two = parameter_map(*args, chunk_points=7, workers=2, **kw)
    assert one.identical(two)


@pytest.mark.parametrize("m", [0, 5, 8, 10, 17, 40, 200])
def test_batch_settling_ratio_equals_the_scalar_one(m):
    from geardyn.analysis.classify import settling_ratio, settling_ratios

    rng = np.random.default_rng(m)
    pts = rng.normal(size=(30, m, 2))
    pts[::4] *= (0.5 ** np.arange(m))[None, :, None]  # contracting sequences
    if m:
        pts[3, 1, 0] = np.nan
        pts[5] = 1.0  # repeating exactly: NaN
    _same(settling_ratios(pts), np.array([settling_ratio(p) for p in pts]))
