"""Rolling-element bearings as elements of a system: the physical element, its non-dimensional form, and its
linearisation about the static load (for modes).

A :class:`RollingElementBearing` joins one body's (x, y) translation to ground, or to a second body's (x, y)
(the outer ring's housing), through the Hertzian contacts of :class:`~geardyn.systems.bearings.RollingBearing`:
the force on the first body is ``−K Σ_j max(δ_j, 0)^n (cos ψ_j, sin ψ_j)`` (:func:`~geardyn.systems.bearings.
bearing_forces`) with δ = (x, y) relative, plus linear viscous damping per direction.  The cage turns at
``Ω (1 − d_b cos α/d_m)/2`` for the inner ring at the shaft speed Ω and a stationary outer ring, so the elements
pass the load line at the ball-pass frequency ``Z ω_cage``; its ratio to the base frequency (``ratio``) must be a
fraction for the forcing to stay periodic: the readers round it (an :class:`~geardyn.geometry.Assumption` gives
both values) so the forcing period stays the least common period of the meshes, the orders and the bearings.

Non-dimensional form (:class:`BearingND`, :mod:`geardyn.systems.assemble`): K̃ = K b_c^(n−1)/k_ref, c̃ = c/b_c,
c̃_x = c_x ω_n/k_ref; the element rows are the x and y vectors of the bearing (translations scale with b_c, so
they are the unit vectors, minus the second body's).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .._docfill import attributes
from ..errors import ModelError
from .bearings import RollingBearing, bearing_forces, bearing_stiffness

__all__ = ["BearingND", "RollingElementBearing", "round_ball_pass", "static_bearing_stiffness", "static_deflection"]

#: Largest denominator of a ball-pass ratio read from a system file (as the meshes' ratios are read).
BALL_PASS_DENOMINATOR = 1000


@dataclass(frozen=True)
@attributes
class RollingElementBearing:
    """A rolling-element bearing between a body's (x, y) and ground or a second body (SI)."""

    #: Unique element name.
    name: str
    #: The body carried by the inner ring (its x and y DOFs).
    body: str
    #: The bearing's geometry, clearance and load–deflection law.
    bearing: RollingBearing
    #: The ball-pass frequency over the base frequency: Z ω_cage/ω_base, a fraction (exact).
    ratio: Fraction
    #: The housing body (its x and y), or None for ground.
    body2: str | None = None
    #: Viscous damping per direction (N·s/m), >= 0.
    cx: float = 0.0
    cy: float = 0.0
    #: Cage angle at θ = 0 (rad).
    phase: float = 0.0

    def __post_init__(self) -> None:
        who = f"bearing {self.name!r}"
        r = Fraction(self.ratio)
        if not r > 0:
            raise ModelError(f"{who}: ratio: the ball-pass frequency ratio must be > 0, got {self.ratio}")
        object.__setattr__(self, "ratio", r)
        for key in ("cx", "cy", "phase"):
            v = float(getattr(self, key))
            if not math.isfinite(v) or (key != "phase" and v < 0):
                raise ModelError(f"{who}: {key}: must be finite{' and >= 0' if key != 'phase' else ''}, got {v!r}")
            object.__setattr__(self, key, v)
        if self.body2 == self.body:
            raise ModelError(f"{who}: body2: the housing must be another body than {self.body!r}")

    @property
    def dofs(self) -> tuple[tuple[str, str], ...]:
        """The DOFs it acts on: (body, x), (body, y), and the housing's."""
        out = ((self.body, "x"), (self.body, "y"))
        return out + (((self.body2, "x"), (self.body2, "y")) if self.body2 else ())

    def vectors(self, index: dict) -> np.ndarray:
        """Its x and y vectors over the DOFs (2, n) (SI; unit entries, minus the housing's)."""
        n = len(index)
        V = np.zeros((2, n))
        for k, d in enumerate(("x", "y")):
            V[k, index[(self.body, d)]] += 1.0
            if self.body2:
                V[k, index[(self.body2, d)]] -= 1.0
        return V


@dataclass(frozen=True)
@attributes
class BearingND:
    """A rolling bearing in a non-dimensional system (see the module docstring)."""

    #: Element name (its rows are ``<name>.x`` and ``<name>.y``).
    name: str
    #: ``"ball"`` or ``"roller"``.
    kind: str
    #: Z, rolling elements.
    elements: int
    #: K̃ = K b_c^(n−1)/k_ref.
    K: float
    #: The load–deflection exponent n.
    exponent: float
    #: c̃ = c/b_c.
    clearance: float
    #: Damping c ω_n/k_ref per direction.
    cx: float
    cy: float
    #: Ball-pass frequency / base frequency (a fraction's value).
    ratio: float
    #: Cage angle at θ = 0 (rad).
    phase: float = 0.0

    def __post_init__(self) -> None:
        for key in ("K", "exponent", "clearance", "cx", "cy", "ratio", "phase"):
            v = float(getattr(self, key))
            if not math.isfinite(v):
                raise ModelError(f"bearing {self.name!r}: {key}: must be finite, got {v!r}")
            object.__setattr__(self, key, v)
        object.__setattr__(self, "elements", int(self.elements))
        if self.K <= 0 or self.ratio <= 0 or self.clearance < 0 or self.elements < 3:
            raise ModelError(f"bearing {self.name!r}: K and ratio must be > 0, clearance >= 0, elements >= 3")

    def row(self) -> list[float]:
        """Its kernel parameter row (:data:`geardyn._kernel_ndof.core.BQ_Z` … ``BQ_PHASE``)."""
        return [
            float(self.elements),
            self.K,
            self.exponent,
            self.clearance,
            self.cx,
            self.cy,
            self.ratio / self.elements,
            self.phase,
        ]


def round_ball_pass(exact: float, denominator: int = BALL_PASS_DENOMINATOR) -> Fraction:
    """The ball-pass ratio as the nearest fraction of denominator at most ``denominator`` (never 0).

    Parameters
    ----------
    exact : float
        Z ω_cage over the base frequency, from the geometry.
    denominator : int
        The largest denominator.

    Examples
    --------
    >>> round_ball_pass(0.15)
    Fraction(3, 20)
    """
    f = Fraction(exact).limit_denominator(denominator)
    return f if f > 0 else Fraction(1, denominator)


def static_deflection(K: np.ndarray, F: np.ndarray, items, iterations: int = 100) -> tuple[np.ndarray, list]:
    """The static deflection q of ``K q + Σ_b V_bᵀ F_b(V_b q) = F`` and each bearing's tangent stiffness there.

    Newton's method from the bearings as linear springs (their stiffness at twice the clearance), the
    least-squares step where rigid-body rotations leave the matrix singular, with backtracking.  Any consistent
    units (SI, or a system's non-dimensional ones).

    Parameters
    ----------
    K : ndarray (n, n)
        The linear stiffness.
    F : ndarray (n,)
        The loads.
    items : sequence of (V, Z, K_b, n, c, cage)
        Each bearing: its x and y rows V (2, n), elements, load–deflection constant, exponent, clearance and cage
        angle.
    iterations : int
        The most Newton steps.

    Returns
    -------
    q : ndarray (n,)
    mats : list of ndarray (n, n)
        Each bearing's tangent stiffness Vᵀ k₂ V at q.

    Raises
    ------
    ModelError
        If Newton's method does not converge (a bearing carries no load and nothing else holds its body).
    """
    K = np.asarray(K, dtype=float)
    F = np.asarray(F, dtype=float)

    def parts(q):
        f = np.zeros_like(q)
        Kt = K.copy()
        mats = []
        for V, Z, Kb, n, c, cage in items:
            dx, dy = V @ q
            fx, fy = bearing_forces(dx, dy, cage, Z, Kb, n, c)
            f -= V.T @ np.array([float(fx), float(fy)])
            kb = V.T @ bearing_stiffness(dx, dy, cage, Z, Kb, n, c) @ V
            mats.append(kb)
            Kt = Kt + kb
        return f, Kt, mats

    K0 = K.copy()
    for V, Z, Kb, n, c, _cage in items:
        d = 2.0 * c + 1e-6 * max(c, 1e-12) if c > 0 else 1e-3
        K0 = K0 + Kb * n * Z / 2.0 * d ** (n - 1.0) * V.T @ V
    q0 = np.linalg.lstsq(K0, F, rcond=None)[0]
    scale = max(float(np.max(np.abs(F), initial=0.0)), 1e-300)
    for _attempt in range(2):  # the second from a start pushed out of the clearances
        q = q0
        for _ in range(iterations):
            f, Kt, mats = parts(q)
            r = K @ q + f - F
            n0 = float(np.linalg.norm(r))
            if float(np.max(np.abs(r))) <= 1e-10 * scale:
                return q, mats
            dq = np.linalg.lstsq(Kt, -r, rcond=None)[0]
            lam = 1.0
            for _ls in range(40):  # backtracking keeps the step inside the region it improves
                f2, _, _ = parts(q + lam * dq)
                if np.linalg.norm(K @ (q + lam * dq) + f2 - F) < n0:
                    break
                lam *= 0.5
            q = q + lam * dq
        for V, _Z, _Kb, _n, c, _cage in items:  # a start inside a clearance has no stiffness there: out to 2c
            d = V @ q0
            rad = float(np.hypot(d[0], d[1]))
            if 0.0 < rad < 2.0 * c:
                q0 = q0 + np.linalg.lstsq(V, (2.0 * c / rad - 1.0) * d, rcond=None)[0]
    raise ModelError(
        "bearing: the static deflection under the mean loads did not converge (a rolling bearing without load "
        "has no stiffness); load the bearings or use linear bearings"
    )


def static_bearing_stiffness(desc, linear_stiffness: np.ndarray, iterations: int = 100) -> list[np.ndarray]:
    """The tangent stiffness (n × n, SI) of every rolling bearing of ``desc`` at the static deflection under
    the mean loads, cage at its θ = 0 angle (:func:`static_deflection`).

    Parameters
    ----------
    desc : SystemDescription
        The system (its ``rolling_bearings``, loads and DOFs).
    linear_stiffness : ndarray (n, n)
        The linear part K (bearings, shafts, meshes at mean stiffness).
    iterations : int
        The most Newton steps.

    Returns
    -------
    list of ndarray (n, n)
        One matrix per rolling bearing, in order.
    """
    idx = desc.index()
    items = [
        (b.vectors(idx), b.bearing.elements, b.bearing.stiffness, b.bearing.exponent, b.bearing.clearance, b.phase)
        for b in desc.rolling_bearings
    ]
    return static_deflection(linear_stiffness, desc.load_vector(), items, iterations)[1]


_LOAD_DEFLECTION = re.compile(
    r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*\*?\s*([A-Za-zµ]+)\s*/\s*([A-Za-zµ]+)\s*(?:\^|\*\*)\s*"
    r"\(?\s*(\d+(?:\.\d+)?(?:\s*/\s*\d+)?)\s*\)?\s*$"
)


def parse_load_deflection(raw, exponent: float) -> float:
    """A Hertzian load–deflection constant written with its unit, ``"8e9 N/m^1.5"`` (or ``N/mm^1.5``,
    ``"2e9 N/m^(10/9)"``), in N/m^n; the unit's exponent must be the bearing's n.

    Parameters
    ----------
    raw : str
        The value and its unit.
    exponent : float
        The bearing's n.

    Raises
    ------
    ValueError
        With the problem, for a value that is not of this form, another exponent, or not > 0.

    Examples
    --------
    >>> parse_load_deflection("8e5 N/mm^1.5", 1.5)
    25298221281.347034
    """
    from .._config_values import quantity

    if not isinstance(raw, str):
        raise ValueError(f'expected a string with its unit, e.g. "8e9 N/m^1.5", got {raw!r}')
    m = _LOAD_DEFLECTION.match(raw)
    if m is None:
        raise ValueError(f'cannot read {raw!r} as a load-deflection constant; write e.g. "8e9 N/m^1.5"')
    value, fu, lu, ex = m.groups()
    try:
        e = float(Fraction(ex.replace(" ", "")))
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"cannot read the exponent {ex!r} of {raw!r}") from None
    if abs(e - exponent) > 1e-6 * exponent:
        raise ValueError(f"the unit's exponent {ex} is not the bearing's exponent n = {exponent:.6g}")
    try:
        ff = float(quantity(f"1 {fu}").to("N").magnitude)
        lf = float(quantity(f"1 {lu}").to("m").magnitude)
    except Exception:
        raise ValueError(f"cannot read the units of {raw!r}: a force over a length, e.g. N/m^1.5") from None
    x = float(value) * ff / lf**exponent
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"must be > 0, got {raw!r}")
    return x


#: Keys of a rolling bearing's table (both file formats; a gearbox adds shaft and position, a system file body).
ROLLING_KEYS = {
    "name": "text",
    "type": "text",
    "elements": "int",
    "pitch_diameter": "length",
    "element_diameter": "length",
    "contact_angle": "angle",
    "radial_clearance": "length",
    "load_deflection": "any",
    "exponent": "number",
    "cx": "damping",
    "cy": "damping",
    "phase": "phase",
}
#: The largest radial clearance, as a fraction of the element diameter (real clearances are below 1 %).
MAX_CLEARANCE_FRACTION = 0.1


def read_rolling(blk, body: str, body2: str | None, speed: Fraction, round_to) -> RollingElementBearing:
    """A rolling bearing's table (``type = "ball"`` or ``"roller"``) read by a file reader's block.

    Parameters
    ----------
    blk
        The reader's block of the table (values with units; errors placed on its lines).
    body, body2 : str
        The inner ring's body (its x, y) and the housing's body (None: ground).
    speed : Fraction
        The inner ring's (the shaft's) speed over the base frequency.
    round_to : callable
        Fraction of the exact ball-pass ratio (a float): how the format keeps the forcing periodic.
    """
    typ = blk.get("type")
    if typ not in ("ball", "roller"):
        raise blk.cerr("type", f"must be 'ball' or 'roller' for a rolling bearing, got {typ!r}")
    missing = [
        k
        for k in ("elements", "pitch_diameter", "element_diameter", "radial_clearance", "load_deflection")
        if not blk.has(k)
    ]
    if missing:
        raise blk.cerr(None, f"a {typ} bearing needs {', '.join(missing)}")
    n = blk.get("exponent")
    try:
        n_ = float(n) if n is not None else (1.5 if typ == "ball" else 10.0 / 9.0)
        raw = blk.data["load_deflection"]
        src = raw.get("assumed") if isinstance(raw, dict) else None
        if isinstance(raw, dict) and (set(raw) - {"value", "assumed"} or "value" not in raw):
            raise blk.cerr("load_deflection", "an inline table must have the keys 'value' and optionally 'assumed'")
        raw = raw.get("value") if isinstance(raw, dict) else raw
        K = parse_load_deflection(raw, n_)
    except ValueError as e:
        raise blk.merr("load_deflection", str(e)) from None
    if src:
        blk.ctx.assume(f"{blk.element}.load_deflection", K, f"N/m^{n_:.6g}", str(src))
    db = blk.get("element_diameter")
    c = blk.get("radial_clearance")
    if db > 0 and c > MAX_CLEARANCE_FRACTION * db:
        raise blk.merr(
            "radial_clearance",
            f"{c * 1e6:.6g} um is above {MAX_CLEARANCE_FRACTION:g} x element_diameter ({db * 1e3:.6g} mm): no "
            "rolling bearing has such a clearance (write it in um)",
        )
    try:
        br = RollingBearing(
            typ,
            blk.get("elements"),
            blk.get("pitch_diameter"),
            db,
            blk.get("contact_angle", default=0.0),
            c,
            K,
            n,
        )
    except ModelError as e:  # RollingBearing names its fields; the file names its keys
        msg = str(e)
        keys = {"clearance": "radial_clearance", "stiffness": "load_deflection", "type": "type"}
        field = next((k for k in (*ROLLING_KEYS, *keys) if msg.startswith(f"bearing {k}:")), None)
        key = keys.get(field, field)
        raise blk.merr(key, msg.split(": ", 1)[-1] if key else msg) from None
    exact = float(br.ball_pass_ratio * Fraction(speed))
    ratio = round_to(exact)
    if abs(float(ratio) - exact) > 1e-12 * exact:
        blk.ctx.assume(
            f"{blk.element}.ball_pass_ratio",
            str(ratio),
            "",
            f"the geometry's ball-pass frequency {exact:.12g} of the base frequency, as the fraction "
            f"{ratio} (relative change {float(ratio) / exact - 1:+.2e}) so that the forcing stays periodic",
        )
    try:
        return RollingElementBearing(
            blk.element,
            body,
            br,
            ratio,
            body2,
            blk.get("cx", default=0.0),
            blk.get("cy", default=0.0),
            blk.get("phase", default=0.0),
        )
    except ModelError as e:
        raise blk.merr(None, str(e).split(": ", 1)[-1]) from None
