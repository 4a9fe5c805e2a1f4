"""The Campbell diagram of a ``modes`` result (``geardyn modes --out``,
:func:`geardyn.systems.modes_data.modes_dataset`).

One horizontal line per natural frequency up to 1.25 times the highest order line's frequency at the top
speed (a finite-element model's higher modes are left out), labelled at the right edge with its mode numbers (a
degenerate frequency is one line naming its modes), one line per distinct mesh order (meshes of
equal frequency share it), the crossings as dots, and the legend below the axes, off the data.  With gyroscopic
terms each natural frequency is a branch over speed instead of a horizontal line: solid where its mode whirls
forward, dashed where it whirls backward (thin grey without whirl: a torsional or axial mode), labelled with its
frequency at the top speed.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from .common import json_list, plot_function, spread

__all__ = ["campbell", "has_campbell"]

#: Relative tolerance for two natural frequencies to be one line.
SAME_FREQUENCY_RTOL = 1e-6
#: The diagram reaches this multiple of the highest order line's frequency at the top speed, or the highest
#: natural frequency (+8 %) if that is lower; the natural frequencies above are not drawn.
ORDER_REACH = 1.25
#: Smallest vertical distance (points) between two mode labels.
LABEL_GAP_PT = 10.0


def has_campbell(ds: xr.Dataset) -> bool:
    """Whether a ``modes`` result carries a Campbell diagram (a system with meshes).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``modes`` result.

    Returns
    -------
    bool
    """
    return "line_slope" in ds and ds.sizes.get("line", 0) > 0


def frequency_lines(ds: xr.Dataset, values: np.ndarray | None = None) -> list[tuple[float, list[int]]]:
    """The distinct natural frequencies (Hz, ascending; ``values`` instead of ``frequency_Hz`` when given) with the
    numbers of the modes at each."""
    out: list[tuple[float, list[int]]] = []
    vals = ds["frequency_Hz"].values if values is None else values
    for f, m in zip(vals, ds["mode"].values):
        if out and abs(f - out[-1][0]) <= SAME_FREQUENCY_RTOL * max(abs(f), 1e-300):
            out[-1][1].append(int(m))
        else:
            out.append((float(f), [int(m)]))
    return out


@plot_function("modes", (8, 5.6))
def campbell(ds: xr.Dataset, ax: Axes = None) -> None:
    """Campbell diagram: the natural frequencies (labelled with their mode numbers), the mesh-order lines and
    their crossings against pinion speed (or the mesh frequency when the file gives no tooth count)."""
    lo, hi = json_list(ds, "campbell_x_range")
    branches = "branch_frequency_Hz" in ds
    groups = frequency_lines(ds, ds["branch_frequency_Hz"].values[-1] if branches else None)
    fmax = max(f for f, _ in groups)
    top = 1.08 * fmax if fmax > 0 else 1.0
    # natural frequencies far above every order line (a finite-element model's) are left out of the drawing
    reach = ORDER_REACH * float(np.max(ds["line_slope"].values)) * hi
    if reach < top:
        top = reach
        groups = [(f, m) for f, m in groups if f <= top]
    if branches:
        _branches(ax, ds, top)
    else:
        for f, _ in groups:
            if f > 0:
                ax.axhline(f, color="0.6", lw=0.8, zorder=1)
    for j, (slope, text) in enumerate(zip(ds["line_slope"].values, ds["line_label"].values)):
        x1 = min(hi, top / slope)
        ax.plot([lo, x1], [slope * lo, slope * x1], color=f"C{j}", lw=1.4, zorder=2, label=str(text))
    if ds.sizes.get("crossing", 0):
        ax.plot(
            ds["crossing_x"].values,
            ds["crossing_frequency_Hz"].values,
            "o",
            ms=4,
            color="k",
            zorder=3,
            label="crossing",
        )
    ax.set_xlim(lo, hi)
    ax.set_ylim(0.0, top)
    ax.set_xlabel(ds.attrs.get("campbell_x_label", "pinion speed [rpm]"))
    ax.set_ylabel("frequency [Hz]")
    title = ds.attrs.get("title") or ""
    ax.set_title(f"Campbell diagram\n{title}" if title else "Campbell diagram", fontsize=10)
    # mode labels in a column right of the axes, spread so that they do not overlap
    height_pt = ax.get_window_extent().height * 72.0 / ax.figure.dpi
    ys = np.array([f / top for f, _ in groups])
    placed = spread(ys, LABEL_GAP_PT / max(height_pt, 1.0), 1.0)
    for (f, modes), y in zip(groups, placed):
        num = ", ".join(map(str, modes))
        text = f"{'mode' if len(modes) == 1 else 'modes'} {num}: " + (f"{f:.5g} Hz" if f > 0 else "rigid body")
        ax.annotate(
            text,
            xy=(1.0, f),
            xycoords=("axes fraction", "data"),
            xytext=(1.03, y),
            textcoords="axes fraction",
            va="center",
            ha="left",
            fontsize=7,
            annotation_clip=False,
            arrowprops=dict(arrowstyle="-", lw=0.5, color="0.5", shrinkA=0, shrinkB=1),
        )
    ax.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, -0.12),
        ncol=min(4, ds.sizes["line"] + 1 + 2 * branches),
        fontsize=8,
        frameon=False,
    )


#: |whirl measure| below this draws a branch segment without whirl.
WHIRL_NONE = 1e-3


def _branches(ax: Axes, ds: xr.Dataset, top: float) -> None:
    """The natural frequencies over speed, solid where forward, dashed where backward (the module docstring)."""
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    x = ds["speed"].values
    F = ds["branch_frequency_Hz"].values
    W = ds["branch_whirl"].values
    styles = {1: ("0.1", "solid", 1.0), -1: ("0.1", (0, (4, 2)), 1.0), 0: ("0.6", "solid", 0.7)}
    segs: dict[int, list] = {k: [] for k in styles}
    for j in range(F.shape[1]):
        if F[0, j] <= 0 or np.min(F[:, j]) > top:
            continue
        for i in range(len(x) - 1):
            w = 0.5 * (W[i, j] + W[i + 1, j])
            segs[1 if w > WHIRL_NONE else -1 if w < -WHIRL_NONE else 0].append(
                [(x[i], F[i, j]), (x[i + 1], F[i + 1, j])]
            )
    for k, (color, ls, lw) in styles.items():
        if segs[k]:
            ax.add_collection(LineCollection(segs[k], colors=color, linestyles=ls, linewidths=lw, zorder=1))
    for k, text in ((1, "forward whirl"), (-1, "backward whirl")):
        color, ls, lw = styles[k]
        ax.add_line(Line2D([], [], color=color, ls=ls, lw=lw, label=text))
