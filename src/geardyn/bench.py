"""Timing of the integrator kernel on the three standard workloads.

The workloads (paper defaults ξ0 = 0.1, ξ1 = 0.05, κ1 = 0.2, f_p = 0.2, ε1 = 0.5, D = 1, phases 0,
start u = u' = 0; classic RK4 with h = T/ceil(T/0.01)):

- **W1 bifurcation**: ω = numpy.linspace(0.5, 1.5, 200); per ω 300 transient + 200 recorded
  periods, the 200 Poincaré points kept (69,152,500 RK4 steps).
- **W2 trajectory**: ω = 1.2, 10,000 periods, Poincaré points kept (5,240,000 steps).
- **W3 Lyapunov**: ω = numpy.linspace(0.5, 1.5, 50); 300 transient + 2000 periods with both
  tangent vectors and Gram–Schmidt each period; both exponents (79,782,400 steps).

Each workload is timed in-process after a warm-up run (JIT compilation or cache load excluded);
the reported wall time is the minimum over ``repeats`` runs of one ``integrate_batch`` call (the
parameter points are built once beforehand; packing them is timed) plus, for W3, the exponents.
These are the workloads of the C reference in ``benchmarks/``; compare the two only within one run (see
``docs/performance.md``).
"""

from __future__ import annotations

import itertools
import os
import platform
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ._docfill import attributes
from .model import GearModel, IntegrationOptions, ModelError
from .pairpack import steps_per_period

__all__ = ["WORKLOADS", "DEFAULT_REPEATS", "Workload", "workload", "time_workload", "run_benchmarks", "machine_info"]

#: Runs timed per workload; the minimum is reported.
DEFAULT_REPEATS = 5
#: The step Δτ of every workload.
BENCH_DTAU = 0.01


@dataclass(frozen=True)
@attributes
class Workload:
    """One standard workload: its parameter points, options and what is computed."""

    #: ``W1``, ``W2`` or ``W3`` (a key of :data:`WORKLOADS`).
    name: str
    #: One line saying what is integrated.
    description: str
    #: The forcing frequencies ω of the batch (the other parameters are the paper's defaults).
    omegas: tuple[float, ...]
    #: Step, transient and recorded periods.
    options: IntegrationOptions
    #: Propagate the tangent vectors and compute both Lyapunov exponents.
    lyapunov: bool = False
    #: Keep the Poincaré points.
    record_poincare: bool = True

    def models(self) -> list[GearModel]:
        """One :class:`~geardyn.model.GearModel` per ω of the workload."""
        return [GearModel(omega=float(w)) for w in self.omegas]

    @property
    def steps(self) -> int:
        """RK4 steps of one run (transient included)."""
        n = steps_per_period(np.asarray(self.omegas), self.options.dtau)
        return int(np.sum(n)) * (self.options.transient + self.options.periods)

    def run(self, models: Sequence[GearModel] | None = None) -> dict[str, np.ndarray]:
        """Integrate the workload once; returns its result arrays (the exponents for W3).

        Parameters
        ----------
        models : sequence of GearModel, optional
            The points from :meth:`models`, built once beforehand: the timing then covers the
            integration call only, as a user who builds a grid once and integrates it would see.

        Returns
        -------
        dict
            ``poincare`` and ``status`` arrays, plus ``exponents`` for a Lyapunov workload.
        """
        from .integrate import integrate_batch

        res = integrate_batch(
            self.models() if models is None else models,
            options=self.options,
            lyapunov=self.lyapunov,
            record_poincare=self.record_poincare,
        )
        out = {"poincare": res.poincare, "status": res.status}
        if self.lyapunov:
            T = 2.0 * np.pi / np.asarray(self.omegas)
            out["exponents"] = res.lyapunov_log.sum(axis=1) / (self.options.periods * T)[:, None]
        return out


#: The standard workloads by name.
WORKLOADS: dict[str, Callable[[], Workload]] = {
    "W1": lambda: Workload(
        "W1",
        "bifurcation: 200 ω in [0.5, 1.5], 300 + 200 periods, Poincaré points",
        tuple(np.linspace(0.5, 1.5, 200)),
        IntegrationOptions(dtau=BENCH_DTAU, transient=300, periods=200),
    ),
    "W2": lambda: Workload(
        "W2",
        "trajectory: ω = 1.2, 10,000 periods, Poincaré points",
        (1.2,),
        IntegrationOptions(dtau=BENCH_DTAU, transient=0, periods=10_000),
    ),
    "W3": lambda: Workload(
        "W3",
        "Lyapunov: 50 ω in [0.5, 1.5], 300 + 2000 periods, tangent vectors, both exponents",
        tuple(np.linspace(0.5, 1.5, 50)),
        IntegrationOptions(dtau=BENCH_DTAU, transient=300, periods=2000),
        lyapunov=True,
        record_poincare=False,
    ),
}


def workload(name: str) -> Workload:
    """The workload ``name`` (W1, W2 or W3, case-insensitive).

    Parameters
    ----------
    name : str
        A key of :data:`WORKLOADS`, in any case.

    Returns
    -------
    Workload

    Raises
    ------
    ModelError
        For an unknown name.
    """
    key = str(name).upper()
    if key not in WORKLOADS:
        raise ModelError(f"workload: unknown {name!r}; allowed: {', '.join(WORKLOADS)} or all")
    return WORKLOADS[key]()


def time_workload(
    w: Workload, repeats: int = DEFAULT_REPEATS, warmup: bool = True, ran: Callable[[], None] | None = None
) -> dict[str, float | int]:
    """Time one workload in-process (minimum wall time over the repeats).

    Parameters
    ----------
    w : Workload
        The workload.
    repeats : int
        Timed runs (default :data:`DEFAULT_REPEATS`); the minimum is reported.
    warmup : bool
        Run once untimed first (JIT compilation or cache load excluded).
    ran : callable, optional
        Called with no argument after each run (the warm-up included), outside the timed span.

    Returns
    -------
    dict
        ``wall_s`` (minimum), ``steps`` (RK4 steps of one run), ``ns_per_step``, ``median_s`` and
        ``repeats``.

    Raises
    ------
    ModelError
        If ``repeats`` < 1.
    """
    if repeats < 1:
        raise ModelError(f"repeats: must be >= 1, got {repeats}")
    models = w.models()
    times = []
    for _ in range(int(warmup) + repeats):  # the warm-up's time is dropped below
        t0 = time.perf_counter()
        w.run(models)
        times.append(time.perf_counter() - t0)
        if ran is not None:
            ran()
    times = times[int(warmup) :]
    wall = min(times)
    steps = w.steps
    return {
        "wall_s": wall,
        "steps": steps,
        "ns_per_step": 1e9 * wall / steps,
        "median_s": float(np.median(times)),
        "repeats": repeats,
    }


def machine_info() -> dict[str, object]:
    """CPU, core count, load and library versions, for the record of a benchmark."""
    import numba

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    info: dict[str, object] = {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "llvm_cpu": _llvm_cpu(),
    }
    try:
        info["load_average"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        pass
    return info


def _llvm_cpu() -> str:
    try:
        import llvmlite.binding as llvm

        return str(llvm.get_host_cpu_name())
    except Exception:  # pragma: no cover - informational only
        return "unknown"


def run_benchmarks(
    names: Sequence[str] = ("W1", "W2", "W3"),
    threads: int | None = None,
    repeats: int = DEFAULT_REPEATS,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, object]:
    """Time the named workloads with ``threads`` kernel threads.

    numba's thread count is restored afterwards.

    Parameters
    ----------
    names : sequence of str
        Workload names (keys of :data:`WORKLOADS`); default all three.
    threads : int, optional
        Kernel threads; None keeps the current setting.
    repeats : int
        Timed runs per workload (default :data:`DEFAULT_REPEATS`).
    progress : callable, optional
        Called as ``progress(done, total)`` in runs (each workload's warm-up and timed runs) after each run,
        outside the timed spans.

    Returns
    -------
    dict
        ``{"workloads": {name: {"wall_s", "steps", "ns_per_step", ...}}, "threads", "repeats",
        "machine"}`` (the per-workload entries of :func:`time_workload`, ``machine`` from
        :func:`machine_info`).

    Raises
    ------
    ModelError
        For an unknown workload name or ``threads`` < 1.
    """
    import numba

    from .integrate import using_threads

    with using_threads(threads):  # numba's setting is restored afterwards
        ws = [workload(n) for n in names]
        used = numba.get_num_threads()
        done, total = itertools.count(1), len(ws) * (repeats + 1)
        ran = None if progress is None else lambda: progress(next(done), total)
        results = {w.name: time_workload(w, repeats, ran=ran) for w in ws}
    return {"workloads": results, "threads": used, "repeats": repeats, "machine": machine_info()}
