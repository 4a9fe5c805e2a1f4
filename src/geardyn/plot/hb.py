"""Figure of a harmonic-balance branch (``geardyn hb``): amplitude and extremes of u against the continued
parameter, stable solid and unstable dashed, with the located bifurcations and, when the Dataset carries it,
the shooting branch of the same parameter overlaid.  Datasets in, figures out; no numerics here."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..io import attached
from .common import bifurcation_marker, branch_lines, json_attr, json_list, label, model_of, of_mesh, plot_function

__all__ = ["HB_STYLE", "SHOOTING_CONTEXT", "SHOOTING_STYLE", "hb_figure"]

#: Name under which an ``hb`` Dataset carries the shooting branch (see :func:`geardyn.io.attach`).
SHOOTING_CONTEXT = "shooting"
#: Line colour of the HB branch and of the shooting branch drawn under it.
HB_STYLE = dict(color="C0")
SHOOTING_STYLE = dict(color="0.55", lw=3.5, alpha=0.45)
#: Marker of each bifurcation type.
EVENT_MARKERS = {
    "fold": ("o", "C3"),
    "period-doubling": ("s", "C2"),
    "neimark-sacker": ("D", "C4"),
    "grazing": ("^", "0.3"),
}


def _events(ax, bifs: list[dict], param: str, names: list[str], seen: set[str]) -> None:
    for b in bifs:
        mk, c = EVENT_MARKERS.get(b["type"], ("P", "k"))
        ys = [0.5 * (b["u_max"] - b["u_min"])] if names == ["amplitude"] else [b[k] for k in names]
        for y in ys:
            bifurcation_marker(ax, b[param], y, mk, c, b["type"], seen)


def _shooting_curves(shooting: xr.Dataset, ds: xr.Dataset, param: str) -> dict[str, np.ndarray]:
    """The shooting branch's parameter, stability, branch index, amplitude and extremes: a 1-DOF ``continuation``
    Dataset as it is, a ``system_continuation`` one (``value``, per-element extremes) at the HB branch's
    reference mesh."""
    keys = ("stable", "branch", "amplitude")
    if param in shooting:
        return {"x": shooting[param].values, **{k: shooting[k].values for k in keys + ("u_min", "u_max")}}
    ref = json_attr(ds, "summary").get("reference_mesh")
    names = [str(v) for v in shooting["element"].values]
    e = names.index(ref) if ref in names else 0
    return {
        "x": shooting["value"].values,
        **{k: shooting[k].values for k in keys},
        "u_min": shooting["element_u_min"].values[:, e],
        "u_max": shooting["element_u_max"].values[:, e],
    }


@plot_function(
    "hb",
    (10, 8),
    n=2,
    subplots={"sharex": True},
    tight=True,
    params="""
               shooting : xarray.Dataset, optional
                   A ``continuation`` result of the same parameter (shooting), or a ``system_continuation`` one for a
                   system's branch (drawn at its reference mesh); default the one attached to ``ds`` under
                   :data:`SHOOTING_CONTEXT`, if any.""",
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of two Axes, optional
                   One Axes: the amplitude panel only; two: amplitude and extremes; omitted: a new figure.""",
)
def hb_figure(ds: xr.Dataset, shooting: xr.Dataset | None = None, ax: Any = None) -> None:
    """An HB branch (stable solid, unstable dashed) with its bifurcations, over the shooting branch when given
    (:meth:`geardyn.analysis.hb.HBContinuation.to_dataset`).  Top: amplitude (u_max − u_min)/2; bottom: u_min and
    u_max with ±D."""
    if shooting is None:
        shooting = attached(ds, SHOOTING_CONTEXT)
    param = str(ds.attrs["param"])
    model = model_of(ds)
    D = float(model.get("D", 0.0))
    x = ds[param].values
    ok = ds["status"].values == 0
    stable = ds["stable"].values.astype(bool) & ok
    bifs = json_list(ds, "bifurcations")
    H, n = int(ds.attrs.get("harmonics", 0)), int(ds.attrs.get("period", 1))
    sc = _shooting_curves(shooting, ds, param) if shooting is not None and shooting.sizes.get("point", 0) else None
    for a, names in zip(ax, (["amplitude"], ["u_min", "u_max"])):
        if a is None:
            continue
        seen: set[str] = set()
        if sc is not None:
            sst = sc["stable"].astype(bool)
            for b in np.unique(sc["branch"]):
                sel = sc["branch"] == b
                branch_lines(
                    a,
                    sc["x"][sel],
                    [sc[k][sel] for k in names],
                    sst[sel],
                    "shooting, ",
                    seen,
                    zorder=2,
                    **SHOOTING_STYLE,
                )
        ys = [ds[k].values for k in names]
        branch_lines(a, x, ys, stable, f"HB (H = {H}), ", seen, zorder=3, **HB_STYLE)
        if np.any(~ok):
            for y in ys:
                a.plot(
                    x[~ok],
                    y[~ok],
                    ls="none",
                    marker="x",
                    color="C1",
                    ms=4,
                    zorder=4,
                    label=None if "unresolved" in seen else "stability unresolved",
                )
                seen.add("unresolved")
        _events(a, bifs, param, names, seen)
        a.grid(alpha=0.3)
    ax[0].set_ylabel(label(ds["amplitude"]))
    if ax[1] is not None:
        if D > 0:
            for s in (D, -D):
                ax[1].axhline(s, color="0.5", lw=0.8, ls=":")
        ax[1].set_ylabel(of_mesh("u_min, u_max", ds) + " (dotted: ±D)")
    [a for a in ax if a is not None][-1].set_xlabel(label(ds[param]))
    ax[0].legend(fontsize=7, ncol=2, loc="best")
    fixed = ", ".join(f"{k} = {model[k]:g}" for k in ("xi0", "fp", "D") if k != param and k in model)
    over = " over the shooting branch" if shooting is not None else ""
    ax[0].set_title(f"Harmonic balance in {param}, period {n} ({fixed}){over}")
