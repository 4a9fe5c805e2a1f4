"""An independent tooth: its rack-cut outline in closed form, a potential-energy reference by adaptive
quadrature, and a 2-D finite-element model of the gear (scikit-fem), for ``benchmarks/tooth_fe.py`` and the
slow tests.  Nothing here imports geardyn.

Outline.  The root fillet is the closed-form trochoid of the rack's tip rounding (Litvin & Fuentes, *Gear
Geometry and Applied Theory*, 2004; the parametrisation of Ma et al., Mech. Mach. Theory 2014-2015, with the
profile shift in the depth of the rounding's centre): with a1 = (h_fP − x) m − ρ the depth of the centre
below the rolling line and b1 = π m/4 + (h_fP m − ρ) tan α + ρ / cos α its distance from the tooth's centre
line along it, the point cut while the rounding's normal makes the angle γ ∈ [α, π/2] with the rolling line is

    φ = (a1 / tan γ + b1) / r,   X = r sin φ − (a1 / sin γ + ρ) cos(γ − φ),   Y = r cos φ − (a1 / sin γ + ρ) sin(γ − φ)

(Y along the tooth's centre line, X its half thickness).  Above it the involute.  An undercut tooth is not
handled (the three pairs have none).

Potential energy.  Bending, shear and axial compliances as integrals over the fillet (in γ) and the involute
(in the roll angle), by ``scipy.integrate.quad``; the fillet foundation of Sainsot, Velex & Duverger (2004)
with θ_f the fillet's half angle on the root circle, S_f = 2 r_f θ_f, and u_f either the distance from the
root circle to where the force line crosses the centre line (``u_f="force"``, the lever of the root moment)
or to the contact point's height (``u_f="contact"``, Ma et al.); Hertz as Yang & Sun; the mesh stiffness from
the exact contact positions of every pair along the line of action.

Finite elements.  The whole gear in plane stress (unit thickness; ``plane="strain"`` for plane strain),
E and ν, the bore clamped.  A structured mapped mesh of bi-quadratic quadrilaterals: an annulus from the bore
to the root circle, and above it each tooth in (profile parameter, angle) coordinates, the rows arcs of
constant radius.  A unit force along the line of action at a flank node; the tooth's compliance is the mean,
over the row (the section) through the load point, of the displacement along the force (a section
displacement, free of the point load's logarithmic local term, which the Hertzian term carries).  A root crack
is a slit along the row through the fillet point whose tangent makes 30° with the centre line, from the flank
inwards by ``depth`` of that section's half thickness (its nodes doubled).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

E_STEEL, NU_STEEL = 206e9, 0.3


def inv(a: float) -> float:
    return math.tan(a) - a


@dataclass
class Gear:
    z: int
    m: float
    x: float = 0.0
    alpha: float = math.radians(20.0)
    h_a: float = 1.0
    h_f: float = 1.25
    rho: float = 0.38
    bore: float | None = None  # bore radius (m)
    E: float = E_STEEL
    nu: float = NU_STEEL

    def __post_init__(self):
        m = self.m
        self.r = 0.5 * self.z * m
        self.r_b = self.r * math.cos(self.alpha)
        self.r_a = self.r + (self.h_a + self.x) * m
        self.r_f = self.r - (self.h_f - self.x) * m
        self.rho_m = self.rho * m
        self.a1 = (self.h_f - self.x) * m - self.rho_m
        self.b1 = (
            math.pi * m / 4 + (self.h_f * m - self.rho_m) * math.tan(self.alpha) + self.rho_m / math.cos(self.alpha)
        )
        self.theta_b = math.pi / (2 * self.z) + 2 * self.x * math.tan(self.alpha) / self.z + inv(self.alpha)
        self.bore = 0.25 * self.r if self.bore is None else self.bore
        X0, Y0 = self.fillet(math.pi / 2)
        self.theta_f = math.atan2(X0, Y0)
        Xl, Yl = self.fillet(self.alpha)
        self.r_L = math.hypot(Xl, Yl)

    # --- outline -------------------------------------------------------------------------------------------
    def fillet(self, g: float) -> tuple[float, float]:
        phi = (self.a1 / math.tan(g) + self.b1) / self.r
        L = self.a1 / math.sin(g) + self.rho_m
        return self.r * math.sin(phi) - L * math.cos(g - phi), self.r * math.cos(phi) - L * math.sin(g - phi)

    def dfillet(self, g: float, eps: float = 1e-7) -> tuple[float, float]:
        a, b = self.fillet(g + eps), self.fillet(g - eps)
        return (a[0] - b[0]) / (2 * eps), (a[1] - b[1]) / (2 * eps)

    def involute_at(self, rho: float) -> tuple[float, float]:
        """(X, Y) of the involute at radius rho."""
        a = math.acos(self.r_b / rho)
        psi = self.theta_b - inv(a)
        return rho * math.sin(psi), rho * math.cos(psi)

    def psi_at(self, rho: float) -> float:
        if rho >= self.r_L:
            return self.theta_b - inv(math.acos(self.r_b / rho))
        from scipy.optimize import brentq

        g = brentq(lambda g: math.hypot(*self.fillet(g)) - rho, self.alpha, math.pi / 2)
        X, Y = self.fillet(g)
        return math.atan2(X, Y)

    def critical(self) -> tuple[float, float, float]:
        """(γ, X, Y) of the fillet point whose tangent makes 30° with the centre line."""
        from scipy.optimize import brentq

        def f(g):
            dX, dY = self.dfillet(g)
            return abs(dX / dY) - math.tan(math.radians(30.0))

        g = brentq(f, self.alpha + 1e-6, math.pi / 2 - 1e-6)
        return (g, *self.fillet(g))


# --- potential energy -------------------------------------------------------------------------------------
def compliance(gear: Gear, rho_c: float, u_f: str = "force") -> dict[str, float]:
    """Bending, shear, axial and foundation compliances per unit width of a tooth loaded at radius rho_c."""
    a_c = math.acos(gear.r_b / rho_c)
    psi_c = gear.theta_b - inv(a_c)
    d, hl = rho_c * math.cos(psi_c), rho_c * math.sin(psi_c)
    a1 = a_c - psi_c
    c, s = math.cos(a1), math.sin(a1)
    E, G = gear.E, gear.E / (2 * (1 + gear.nu))
    # the fillet: X(γ), Y(γ), dY/dγ; γ from π/2 (root) down to α (start of the involute)

    def fil(fun):
        def f(g):
            X, Y = gear.fillet(g)
            dY = gear.dfillet(g)[1]
            return fun(X, Y) * (-dY)  # γ decreasing as Y increases

        return quad(f, gear.alpha, math.pi / 2, epsabs=0, epsrel=1e-10, limit=200)[0]

    def invo(fun):
        def f(p):
            X, Y = gear.involute_at(p)
            eps = 1e-9 * p
            dY = (gear.involute_at(p + eps)[1] - gear.involute_at(p - eps)[1]) / (2 * eps)
            return fun(X, Y) * dY

        return quad(f, gear.r_L, rho_c, epsabs=0, epsrel=1e-10, limit=200)[0]

    def both(fun):
        return fil(fun) + invo(fun)

    kb = both(lambda X, Y: (c * (d - Y) - s * hl) ** 2 / (E * (2 * X) ** 3 / 12))
    ks = both(lambda X, Y: 1.2 * c * c / (G * 2 * X))
    ka = both(lambda X, Y: s * s / (E * 2 * X))
    th = gear.theta_f
    hh = gear.r_f / gear.bore
    coef = np.array(
        [
            [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],
            [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],
            [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],
            [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],
        ]
    ) @ np.array([1 / th**2, hh * hh, hh / th, 1 / th, hh, 1.0])
    L, M, P, Q = coef
    u = (d - hl * math.tan(a1) if u_f == "force" else d) - gear.r_f
    S = 2 * gear.r_f * th
    kf = c * c / E * (L * (u / S) ** 2 + M * (u / S) + P * (1 + Q * math.tan(a1) ** 2))
    return {"bending": kb, "shear": ks, "axial": ka, "fillet": kf}


def pair_stiffness(g1: Gear, g2: Gear, points: int = 64, u_f: str = "force") -> tuple[np.ndarray, np.ndarray]:
    """Mesh stiffness per unit width (N/m/m) over one mesh cycle, phases 0 … 1 (start of contact of a pair)."""
    alpha = g1.alpha
    inv_w = inv(alpha) + 2 * math.tan(alpha) * (g1.x + g2.x) / (g1.z + g2.z)
    from scipy.optimize import brentq

    a_w = brentq(lambda a: inv(a) - inv_w, 1e-6, 1.4)
    aw = (g1.r + g2.r) * math.cos(alpha) / math.cos(a_w)
    T = aw * math.sin(a_w)
    sE = math.sqrt(g1.r_a**2 - g1.r_b**2)
    sA = T - math.sqrt(g2.r_a**2 - g2.r_b**2)
    pb = math.pi * g1.m * math.cos(alpha)
    ch = 2 / math.pi * ((1 - g1.nu**2) / g1.E + (1 - g2.nu**2) / g2.E)
    cache: dict[float, float] = {}

    def k_pair(s):
        key = round(s, 15)
        if key not in cache:
            c1 = sum(compliance(g1, math.hypot(g1.r_b, s), u_f).values())
            c2 = sum(compliance(g2, math.hypot(g2.r_b, T - s), u_f).values())
            cache[key] = 1.0 / (c1 + c2 + ch)
        return cache[key]

    theta = np.arange(points) / points
    k = np.zeros(points)
    for i, t in enumerate(theta):
        for j in range(4):
            s = sA + (t + j) * pb
            if sA - 1e-12 <= s <= sE + 1e-12:
                k[i] += k_pair(s)
    return theta, k


# --- finite elements --------------------------------------------------------------------------------------
def _grid_profile(gear: Gear, n_fillet: int, n_inv: int, load_radii) -> np.ndarray:
    """Radii of the tooth's rows: the fillet graded towards the root, the involute through every load radius."""
    gam = np.linspace(math.pi / 2, gear.alpha, n_fillet + 1)
    rf = np.array([math.hypot(*gear.fillet(g)) for g in gam])
    knots = np.unique(np.concatenate([[gear.r_L, gear.r_a], np.asarray(load_radii, float)]))
    seg = []
    span = gear.r_a - gear.r_L
    for a, b in zip(knots[:-1], knots[1:]):
        n = max(1, int(round(n_inv * (b - a) / span)))
        seg.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate([rf, np.concatenate(seg)])


@dataclass
class FEGear:
    gear: Gear
    p: np.ndarray  # nodes (2, N)
    t: np.ndarray  # quads (4, K)
    tooth_rows: list  # per row of the loaded tooth: node indices across (from −ψ to +ψ)
    rows_rho: np.ndarray
    bore_nodes: np.ndarray
    crack_row: int
    frac: np.ndarray = None  # the loaded tooth's columns as fractions of its half angle (−1 … 1)
    j_tip: int = -1  # the column of the slit's tip


def _graded(x: np.ndarray, i: int, halvings: int) -> tuple[np.ndarray, int]:
    """``x`` with nodes added at x[i] ± (its neighbouring cell) / 2, / 4, … (``halvings`` on each side); the new
    index of x[i]."""
    if halvings <= 0:
        return x, i
    extra = []
    for nb in (i - 1, i + 1):
        if 0 <= nb < x.size:
            extra += [x[i] + (x[nb] - x[i]) / 2**k for k in range(1, halvings + 1)]
    out = np.unique(np.concatenate([x, extra]))
    return out, int(np.argmin(np.abs(out - x[i])))


def build_mesh(gear: Gear, load_radii, *, level: float = 1.0, crack: float = 0.0, tip: int = 0) -> FEGear:
    """The mapped mesh of the whole gear; the loaded tooth is tooth 0 (centred on +Y), it and its two neighbours
    on each side finely meshed; ``crack`` the slit depth (fraction of the critical section's half thickness);
    ``tip`` halvings of the cells at the slit's tip, across the tooth and along it (a geometric grading towards
    the tip)."""
    z = gear.z
    n_s = 4 * max(1, int(round(2 * level)))  # cells across a half tooth (a multiple of 4: 25 % steps)
    n_fil = max(6, int(round(16 * level)))
    n_inv = max(8, int(round(24 * level)))
    n_gap = max(2, int(round(5 * level)))
    n_rim = max(6, int(round(14 * level)))
    rows = _grid_profile(gear, n_fil, n_inv, load_radii)
    crack_row = -1
    if crack > 0:
        _, Xc, Yc = gear.critical()
        rho_c = math.hypot(Xc, Yc)
        crack_row = int(np.argmin(np.abs(rows[1:-1] - rho_c))) + 1
        rows[crack_row] = rho_c
        rows, crack_row = _graded(rows, crack_row, tip)
    frac0 = np.linspace(-1.0, 1.0, 2 * n_s + 1)  # the loaded tooth's columns, as fractions of its half angle
    j_tip = -1
    if crack > 0:
        frac0, j_tip = _graded(frac0, 2 * n_s - int(round(crack * n_s)), tip)
    th_f = gear.theta_f
    pitch = 2 * math.pi / z

    def near(k):
        return min(k, z - k) <= 2

    coarse_rows = np.concatenate([rows[: n_fil + 1 : 4], rows[n_fil + 1 :: 6], [rows[-1]]])
    coarse_rows = np.unique(coarse_rows)
    ang, starts, fracs = [], [], []
    count = 0
    for k in range(z):
        c = k * pitch
        nk, gk = (n_s, n_gap) if near(k) else (2, 2)
        fk = frac0 if k == 0 else np.linspace(-1.0, 1.0, 2 * nk + 1)
        starts.append(count)
        fracs.append(fk)
        ang.append(c + th_f * fk[:-1])
        ang.append(c + np.linspace(th_f, pitch - th_f, gk + 1)[:-1])
        count += fk.size - 1 + gk
    ang = np.concatenate(ang)
    na = ang.size
    q = np.linspace(0, 1, n_rim + 1)
    rr = gear.bore + (gear.r_f - gear.bore) * (1 - (1 - q) ** 1.6)
    P = [np.vstack([np.outer(rr, np.sin(ang)).ravel(), np.outer(rr, np.cos(ang)).ravel()])]
    rim_id = np.arange(rr.size * na).reshape(rr.size, na)
    T = []
    for i in range(n_rim):
        for j in range(na):
            jn = (j + 1) % na
            T.append([rim_id[i, j], rim_id[i, jn], rim_id[i + 1, jn], rim_id[i + 1, j]])
    n0 = rr.size * na
    top = rim_id[-1]
    tooth_rows = []
    for k in range(z):
        c = k * pitch
        fk = fracs[k]
        idx = (starts[k] + np.arange(fk.size)) % na
        prev = top[idx]
        if k == 0:
            tooth_rows.append(prev)
        for rho in (rows if near(k) else coarse_rows)[1:]:
            psi = gear.psi_at(min(rho, gear.r_a))
            a = c + psi * fk
            ids = n0 + np.arange(a.size)
            n0 += a.size
            P.append(np.vstack([rho * np.sin(a), rho * np.cos(a)]))
            for j in range(fk.size - 1):
                T.append([prev[j], prev[j + 1], ids[j + 1], ids[j]])
            if k == 0:
                tooth_rows.append(ids)
            prev = ids
    p = np.hstack(P)
    t = np.array(T).T
    if crack > 0:
        # slit along the row from the +X flank inwards: its nodes doubled, the cells above take the copies
        ids = tooth_rows[crack_row]
        dup = {n: p.shape[1] + i for i, n in enumerate(ids[j_tip + 1 :])}
        p = np.hstack([p, p[:, list(dup)]])
        above = set(tooth_rows[crack_row + 1].tolist())
        for e in range(t.shape[1]):
            if any(int(n) in above for n in t[:, e]):
                t[:, e] = [dup.get(int(n), int(n)) for n in t[:, e]]
    return FEGear(gear, p, t, tooth_rows, rows, rim_id[0], crack_row, frac0, j_tip)


def crack_depth_of(fg: FEGear, crack: float) -> float:
    """The slit's depth as a fraction of its section's half thickness (the node grid's nearest to ``crack``)."""
    psi = fg.gear.psi_at(fg.rows_rho[fg.crack_row])
    return float(1.0 - math.sin(psi * fg.frac[fg.j_tip]) / math.sin(psi))


def fe_compliance(fg: FEGear, load_radii, plane: str = "stress") -> np.ndarray:
    """Compliance per unit width (m²/N) of the loaded tooth at each radius in ``load_radii``."""
    from scipy.sparse.linalg import splu
    from skfem import Basis, ElementQuad2, ElementVector, MeshQuad, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    g = fg.gear
    mesh = MeshQuad(fg.p, fg.t)
    basis = Basis(mesh, ElementVector(ElementQuad2()))
    lam, mu = lame_parameters(g.E, g.nu)
    if plane == "stress":
        lam = 2 * lam * mu / (lam + 2 * mu)
    K = asm(linear_elasticity(lam, mu), basis)
    nodal = basis.nodal_dofs  # (2, Nnodes) for the vertices
    r_in = g.bore * (1 + 1e-9)
    fixed = basis.get_dofs(lambda x: np.hypot(x[0], x[1]) < r_in).all()
    free = np.setdiff1d(np.arange(basis.N), fixed)
    Kc = K[free][:, free].tocsc()
    lu = splu(Kc)
    out = []
    for rho_c in load_radii:
        row = int(np.argmin(np.abs(fg.rows_rho - rho_c)))
        assert abs(fg.rows_rho[row] - rho_c) < 1e-9 * rho_c, "load radius not on a row"
        ids = fg.tooth_rows[row]
        node = ids[-1]  # the +X flank
        a_c = math.acos(g.r_b / rho_c)
        psi_c = g.theta_b - inv(a_c)
        a1 = a_c - psi_c
        f_dir = np.array([-math.cos(a1), -math.sin(a1)])
        F = np.zeros(basis.N)
        F[nodal[0, node]] = f_dir[0]
        F[nodal[1, node]] = f_dir[1]
        u = np.zeros(basis.N)
        u[free] = lu.solve(F[free])
        ux, uy = u[nodal[0, ids]], u[nodal[1, ids]]
        d = ux * f_dir[0] + uy * f_dir[1]
        f = fg.frac  # trapezoidal weights over the section (its arc)
        w = np.diff(np.concatenate([[f[0]], 0.5 * (f[1:] + f[:-1]), [f[-1]]]))
        out.append(float(np.sum(w * d) / np.sum(w)))
    return np.array(out)
