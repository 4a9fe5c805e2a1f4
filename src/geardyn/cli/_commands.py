"""The commands of ``geardyn`` and the modules that define them, listed without importing those modules.

``geardyn --help`` lists the commands from :data:`COMMANDS`, and a command's module is imported when the
command is run (or its own ``--help`` is asked for), so that a short command imports only what it runs.
:data:`COMMANDS` is written by ``python docs/gen_cli.py`` from the commands themselves
(:func:`geardyn.cli._listing.write`); ``tests/test_startup.py`` fails while it differs from them.
"""

from __future__ import annotations

__all__ = ["COMMANDS", "MODULES"]

#: The modules that define commands, in the order their commands are registered (and listed).
MODULES = ("point", "sweeps", "tools", "engineering", "hb", "systems", "diagnostics", "rattle")

#: name -> (module in :mod:`geardyn.cli`, help text), in the order of ``geardyn --help``.
COMMANDS: dict[str, tuple[str, str]] = {
    # generated: begin
    "simulate": (
        "point",
        (
            "Integrate one operating point and report its steady response (Poincaré points, period, impact, "
            "amplitudes),\n"
            "with physical values for the configured gear pair: pinion speed, dynamic transmission error (µm), dynamic "
            "mesh\n"
            "force (N), dynamic factor, spectrum peaks in Hz and mesh orders."
        ),
    ),
    "lyapunov": (
        "point",
        (
            "Both Lyapunov exponents (per unit τ) by the Benettin method with Gram–Schmidt each period, with their\n"
            "uncertainty from block statistics, and the motion class."
        ),
    ),
    "orbit": (
        "point",
        (
            "Find a period-n orbit by shooting (Newton on the n-period map, Jacobian = monodromy matrix) and report "
            "its\n"
            "section points, Floquet multipliers, stability, extremes and impact state."
        ),
    ),
    "continuation": (
        "point",
        (
            "Pseudo-arclength continuation of periodic orbits in any parameter: stable and unstable branches, folds,\n"
            "period doublings (with branch switching), Neimark–Sacker points and grazing; with --out the figure shows "
            "the\n"
            "branches over the brute-force up/down sweep."
        ),
    ),
    "bifurcation": (
        "sweeps",
        (
            "Bifurcation diagram over any parameter: Poincaré points, period, motion class, impact state and "
            "amplitudes\n"
            "per point (and the largest Lyapunov exponent with --lyapunov); fixed initial state or continuation, "
            "up/down/both."
        ),
    ),
    "response": (
        "sweeps",
        (
            "Amplitude-frequency response swept up and down with state continuation: jumps (ω, direction, size, "
            "sweep)\n"
            "and hysteresis intervals where the sweeps end on different attractors (or, with --method hb, from one\n"
            "harmonic-balance branch: jumps at its folds)."
        ),
    ),
    "map": (
        "sweeps",
        ("2-D parameter map (e.g. ω × ξ0, ω × D) of motion class, impact state, amplitude and largest exponent."),
    ),
    "basins": (
        "sweeps",
        (
            "Basins of attraction: a grid of initial states (u0, v0) at θ = 0, each labelled by the attractor it "
            "reaches\n"
            "(attractors identified by their Poincaré cycles)."
        ),
    ),
    "geometry": (
        "tools",
        (
            "Gear pair geometry: pitch cones, directional radii, equivalent mass, k0, ω_n, static mesh force "
            "(assumed\n"
            "values marked)."
        ),
    ),
    "plot": (
        "tools",
        (
            "Redraw the figures of a saved result from its NetCDF file, chosen by its kind (simulate, bifurcation,\n"
            "response, map, basins, orbit, continuation, ...)."
        ),
    ),
    "reproduce": (
        "tools",
        ("Run every study of the paper on its Table 1 pair and write a report judging each claim."),
    ),
    "bench": (
        "tools",
        ("Time the integrator on the standard workloads (in-process, after JIT warm-up, minimum of the runs)."),
    ),
    "te": (
        "engineering",
        (
            "Measured transmission error: mesh-order harmonics with phases, shaft-order sidebands, hunting period, and "
            "a\n"
            "[mesh] section (mesh orders only) the other commands accept."
        ),
    ),
    "runup": (
        "engineering",
        (
            "Run-up / run-down through a linear speed ramp: order-tracked DTE, amplitude and dynamic factor against\n"
            "speed, beside the quasi-static (steady) response swept up and down; with --system those of the "
            "reference\n"
            "mesh of any system file."
        ),
    ),
    "hb": (
        "hb",
        (
            "Harmonic balance (AFT, exact dead-zone switches) with Floquet stability (monodromy or Hill): a branch "
            "of\n"
            "period-n responses continued in any parameter through its folds, with folds, period doublings, "
            "Neimark–Sacker\n"
            "points and grazing located; with --out the figure shows it stable solid and unstable dashed (over the "
            "shooting\n"
            "branch with --compare-shooting).  With --system the branch is the system's (every DOF's harmonics, the "
            "elastic\n"
            "multipliers; --param takes its parameter names).  Without damping the multipliers lie on the unit circle: "
            "folds\n"
            "and period doublings are located by det(I - M) and det(I + M) and stable means neutrally stable; a branch "
            "whose\n"
            "first solution does not converge exits with code 1 and writes nothing."
        ),
    ),
    "modes": (
        "systems",
        (
            "Natural frequencies (Hz, ascending; modes numbered from 1, rigid-body modes 0 Hz), M-orthonormal mode\n"
            "shapes and modal strain-energy fractions per element at mean mesh stiffness, and the Campbell diagram "
            "with\n"
            "the crossings of the mesh orders (against pinion speed, or against the mesh frequency when the "
            "reference\n"
            "mesh gives no teeth); --out writes modes.nc and the Campbell figure."
        ),
    ),
    "stiffness": (
        "diagnostics",
        (
            "Mesh stiffness and static transmission error of a spur or helical pair by the potential-energy method,\n"
            "healthy or with tooth faults, over the mesh cycle or the hunting period: table, Fourier harmonics, and\n"
            "ISO 6336-1 c′ and c_γ beside it."
        ),
    ),
    "signature": (
        "diagnostics",
        (
            "Vibration signature of a pair: the acceleration along the line of action sampled with a "
            "once-per-revolution\n"
            "tachometer, order spectrum, TSA per shaft, regular/residual/difference signals and the condition "
            "indicators;\n"
            "healthy beside faulty with two files; indicators against crack depth with --sweep-depths. With --system: "
            "the\n"
            "same for a bearing sensor (a translational DOF) of a multi-DOF system."
        ),
    ),
    "rattle": (
        "rattle",
        (
            "Gear rattle of an unloaded (loose) gear pair driven by torque orders (--torque-order, [model] "
            "torque_orders,\n"
            "or orders on a load of a --system file of two gears): impacts per cycle on the drive and back flanks, "
            "impact\n"
            "velocities, and the rattle index (impact kinetic-energy loss per cycle); with --map-points a rattle map "
            "over\n"
            "speed × torque-order amplitude."
        ),
    ),
    # generated: end
}
