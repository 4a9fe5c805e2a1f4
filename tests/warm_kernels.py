"""Compile geardyn's numba kernels into their cache: ``python tests/warm_kernels.py GROUP`` with GROUP ``pair``
(the pair's scalar, lanes and accurate workers), ``systems`` (the mesh-vector worker, a system's harmonic balance)
or ``hb`` (the pair's harmonic balance).  ``tests/conftest.py`` runs the three at once before a run spread over
several workers, so that each kernel of a fresh checkout is compiled once, in parallel, rather than by every
worker that needs it."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from geardyn.integrate import integrate_batch
from geardyn.model import GearModel, IntegrationOptions

ONE = IntegrationOptions(transient=1, periods=1)


def pair() -> None:
    integrate_batch([GearModel()], None, ONE)  # one point: the scalar worker
    w = np.linspace(0.5, 1.5, 64)
    for kw in ({}, {"phi_k": (0.5,)}, {"kappa": (0.2, 0.1), "phi_k": (0.0, 0.0)}):  # the lanes' three kinds
        integrate_batch([GearModel(omega=x, **kw) for x in w], None, ONE)
    integrate_batch([GearModel()], None, ONE.replace(accurate=True))
    from geardyn.tooth.excitation import Excitation, excitation_model  # a table evaluated as given

    exc = Excitation(np.array([1.25, 1.2, 0.7, 1.15]) * 3e8, np.array([0, 2, 5, -3]) * 1e-7, 1,
                     phase=np.array([0.0, 0.3, 0.55, 0.9]))
    table = excitation_model(GearModel(fp=0.3, D=0.6), exc, b_c=1e-5, evaluation="table", harmonics=3)
    integrate_batch([table], None, ONE.replace(accurate=True))


def systems() -> None:
    from geardyn.analysis.hb import hb_system_solve
    from geardyn.systems import load_system

    s = load_system(Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_torsional.toml")
    integrate_batch([s.with_param("omega", 0.8)], None, ONE)
    hb_system_solve(s.with_param("omega", 0.8), 8)


def hb() -> None:
    from geardyn.analysis.hb import hb_continuation, hb_solve

    hb_solve(GearModel(omega=0.8), 8)
    hb_solve(GearModel(omega=0.8), 8, floquet="hill")
    hb_continuation(GearModel(), "omega", 0.8, 0.81, harmonics=4, max_points=3)


GROUPS = {"pair": pair, "systems": systems, "hb": hb}

if __name__ == "__main__":
    GROUPS[sys.argv[1]]()
