"""Timoshenko shaft elements against the closed-form frequency equations of a uniform shaft.

The references are solved here independently of the elements: the Timoshenko dispersion relation for a
simply supported shaft (each mode n has the wavenumber nπ/L exactly), the 4×4 boundary determinant of the
exact solution (cosh, sinh, cos, sin) for a free–free shaft, and the wave solutions of torsion, each
root found with scipy's brentq.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import brentq

from geardyn.gearbox.shaft import (
    Material,
    Section,
    ShaftMesh,
    element_matrices,
    shaft_matrices,
    shear_coefficient,
)

MAT = Material(E=2.1e11, nu=0.3, rho=7850.0)
L = 1.0
SEC = Section(outer=0.12, inner=0.06)  # stocky and hollow: shear and rotary inertia matter (L/d ≈ 8)


def _uniform(n_el: int, sec: Section = SEC, length: float = L) -> ShaftMesh:
    return ShaftMesh(tuple(np.linspace(0.0, length, n_el + 1)), (sec,) * n_el)


def _plane_a(n_el: int, sec=SEC, mat=MAT):
    K, M, _ = shaft_matrices(_uniform(n_el, sec), mat)
    keep = [6 * i + d for i in range(n_el + 1) for d in (0, 4)]  # x and ry of every node
    return K[np.ix_(keep, keep)], M[np.ix_(keep, keep)]


def _fe_frequencies(K, M, drop=()):
    keep = [i for i in range(K.shape[0]) if i not in set(drop)]
    w2 = scipy.linalg.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], eigvals_only=True)
    return np.sqrt(np.clip(np.sort(w2), 0.0, None))


def _constants(sec=SEC, mat=MAT):
    kappa = shear_coefficient(mat.nu, sec.outer, sec.inner)
    return mat.E, mat.G, mat.rho, kappa, sec.area, sec.I


def _ss_exact(n: int, sec=SEC, mat=MAT) -> float:
    """Lower root of the Timoshenko dispersion relation at k = nπ/L (simply supported, exact)."""
    E, G, rho, kappa, A, I = _constants(sec, mat)  # noqa: E741
    k = n * math.pi / L

    def f(w):
        return (
            E * I * k**4
            - rho * A * w**2
            - rho * I * (1 + E / (kappa * G)) * k**2 * w**2
            + rho**2 * I / (kappa * G) * w**4
        )

    w_eb = k**2 * math.sqrt(E * I / (rho * A))
    return brentq(f, 1e-9, w_eb, xtol=1e-14, rtol=1e-15)


def _free_free_det(w: float, sec=SEC, mat=MAT) -> float:
    E, G, rho, kappa, A, I = _constants(sec, mat)  # noqa: E741
    kGA = kappa * G * A
    a = kGA * E * I
    b = w**2 * (kGA * rho * I + rho * A * E * I)
    c = rho * A * w**2 * (rho * I * w**2 - kGA)
    disc = math.sqrt(b * b - 4 * a * c)
    al = math.sqrt((-b + disc) / (2 * a))
    be = math.sqrt((b + disc) / (2 * a))
    q = rho * w**2 / (kappa * G)
    pa, pb = (al**2 + q) / al, (q - be**2) / be

    def rows(z):
        ch, sh, co, si = math.cosh(al * z), math.sinh(al * z), math.cos(be * z), math.sin(be * z)
        # columns: cosh, sinh, cos, sin; w, psi and their derivatives
        w_d = [al * sh, al * ch, -be * si, be * co]
        psi = [pa * sh, pa * ch, pb * si, -pb * co]
        psi_d = [pa * al * ch, pa * al * sh, pb * be * co, pb * be * si]
        return [psi_d, [wd - p for wd, p in zip(w_d, psi)]]

    Mx = np.array(rows(0.0) + rows(L))
    Mx /= np.abs(Mx).max(axis=0)
    return float(np.linalg.det(Mx))


def _free_free_exact(count: int) -> list[float]:
    grid = np.linspace(1.0, 3.0e4, 30001)
    vals = [_free_free_det(w) for w in grid]
    roots = []
    for w0, w1, v0, v1 in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if v0 == 0 or v0 * v1 < 0:
            roots.append(brentq(_free_free_det, w0, w1, xtol=1e-13, rtol=1e-15))
            if len(roots) == count:
                break
    return roots


def _rates(errs):
    """Error ratios between successive halvings of the element length."""
    return errs[:-1] / errs[1:]


# The element's shear strain w' − ψ is constant along it, so the frequencies converge as h² (error ratio 4
# per halving); 256 elements bring the first four modes within 1e-4.
COUNTS = (16, 32, 64, 128, 256)


def test_simply_supported_converges_to_the_timoshenko_closed_form():
    exact = np.array([_ss_exact(n) for n in (1, 2, 3, 4)])
    errs = []
    for n_el in COUNTS:
        K, M = _plane_a(n_el)
        fe = _fe_frequencies(K, M, drop=(0, 2 * n_el))  # x = 0 at both ends; the section rotations free
        errs.append(fe[:4] / exact - 1.0)
    errs = np.array(errs)
    assert np.all(errs > 0)  # a Rayleigh-Ritz upper bound
    assert np.all(errs[-1] < 1e-4), errs[-1]
    assert np.all(np.abs(_rates(errs[:, :3]) - 4.0) < 0.1), _rates(errs)
    # shear and rotary inertia matter here: Euler-Bernoulli is off by more than 3 % at mode 3
    E, _, rho, _, A, I = _constants()  # noqa: E741
    assert (3 * math.pi / L) ** 2 * math.sqrt(E * I / (rho * A)) / exact[2] - 1 > 0.03


def test_free_free_converges_to_the_timoshenko_closed_form():
    exact = np.array(_free_free_exact(4))
    assert len(exact) == 4
    errs = []
    for n_el in COUNTS:
        K, M = _plane_a(n_el)
        fe = _fe_frequencies(K, M)
        assert np.all(fe[:2] < 1e-3 * fe[2])  # two rigid-body modes
        errs.append(fe[2:6] / exact - 1.0)
    errs = np.array(errs)
    assert np.all(errs > 0)
    assert np.all(errs[-1] < 1e-4), errs[-1]
    assert np.all(np.abs(_rates(errs[:, :3]) - 4.0) < 0.1), _rates(errs)


def test_both_planes_alike_and_the_euler_bernoulli_limit():
    K, M, _ = shaft_matrices(_uniform(8), MAT)
    a = [6 * i + d for i in range(9) for d in (0, 4)]
    b = [6 * i + d for i in range(9) for d in (1, 3)]
    fa = _fe_frequencies(K[np.ix_(a, a)], M[np.ix_(a, a)])
    fb = _fe_frequencies(K[np.ix_(b, b)], M[np.ix_(b, b)])
    assert np.allclose(fa, fb, rtol=1e-12, atol=1e-6)
    # without shear and rotary inertia: the classical element, whose SS frequencies converge to (nπ/L)²√(EI/ρA)
    sec = Section(0.02)
    Kt, Mt = np.zeros((2 * 65, 2 * 65)), np.zeros((2 * 65, 2 * 65))
    for e in range(64):
        k, m, _ = element_matrices(L / 64, sec, MAT, shear=False, rotary=False)
        sl = [0, 4, 6, 10]
        ii = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3]
        Kt[np.ix_(ii, ii)] += k[np.ix_(sl, sl)]
        Mt[np.ix_(ii, ii)] += m[np.ix_(sl, sl)]
    fe = _fe_frequencies(Kt, Mt, drop=(0, 128))
    eb = np.array([(n * math.pi / L) ** 2 * math.sqrt(MAT.E * sec.I / (MAT.rho * sec.area)) for n in (1, 2, 3)])
    assert np.all(np.abs(fe[:3] / eb - 1) < 1e-6)


def _torsion(n_el: int, length=L):
    K, M, _ = shaft_matrices(_uniform(n_el, length=length), MAT)
    t = [6 * i + 5 for i in range(n_el + 1)]
    return K[np.ix_(t, t)], M[np.ix_(t, t)]


def test_torsion_free_free_converges_to_the_wave_solution():
    c = math.sqrt(MAT.G / MAT.rho)
    exact = np.array([n * math.pi * c / L for n in (1, 2, 3)])
    errs = []
    for n_el in (16, 32, 64, 128, 256):
        fe = _fe_frequencies(*_torsion(n_el))
        assert fe[0] < 1e-5 * fe[1]  # the rigid rotation (round-off)
        errs.append(np.abs(fe[1:4] / exact - 1))
    errs = np.array(errs)
    # linear elements with consistent mass: error ∝ h², ratio 4 per halving
    assert np.all(errs[-1] < 1e-4)
    rates = errs[:-1, 0] / errs[1:, 0]
    assert np.all(np.abs(rates - 4.0) < 0.05), rates


def test_torsion_with_end_inertias_exact():
    """A shaft with disks J1, J2 at its ends: the exact frequency equation, and the massless two-inertia limit."""
    J1, J2 = 0.8, 0.3
    c = math.sqrt(MAT.G / MAT.rho)
    GJ = MAT.G * SEC.J

    def det(w):
        k = w / c
        # θ = A cos kz + B sin kz; GJ θ'(0) = −J1 ω² θ(0); GJ θ'(L) = J2 ω² θ(L)
        row0 = [J1 * w**2, GJ * k]
        rowL = [
            -GJ * k * math.sin(k * L) - J2 * w**2 * math.cos(k * L),
            GJ * k * math.cos(k * L) - J2 * w**2 * math.sin(k * L),
        ]
        return row0[0] * rowL[1] - row0[1] * rowL[0]

    w_lumped = math.sqrt(GJ / L * (1 / J1 + 1 / J2))
    exact = brentq(det, 0.5 * w_lumped, 0.999 * w_lumped, xtol=1e-12, rtol=1e-15)
    prev = None
    for n_el in (4, 16, 64):
        K, M = _torsion(n_el)
        M = M.copy()
        M[0, 0] += J1
        M[-1, -1] += J2
        f = _fe_frequencies(K, M)[1]
        err = abs(f / exact - 1)
        if prev is not None:
            assert err < prev / 10
        prev = err
    assert prev < 1e-5
    # a nearly massless shaft between the two inertias: ω² = k (1/J1 + 1/J2), k = GJ/L, with one element
    K, M = _torsion(1)
    M = M * 1e-9
    M[0, 0] += J1
    M[1, 1] += J2
    f = _fe_frequencies(K, M)[1]
    assert abs(f / w_lumped - 1) < 1e-9


def test_axial_free_free_wave_solution():
    K, M, _ = shaft_matrices(_uniform(128), MAT)
    z = [6 * i + 2 for i in range(129)]
    fe = _fe_frequencies(K[np.ix_(z, z)], M[np.ix_(z, z)])
    assert abs(fe[1] / (math.pi * math.sqrt(MAT.E / MAT.rho) / L) - 1) < 1e-4


def test_gyroscopic_matrix_is_skew_and_holds_the_polar_inertia_of_a_rigid_tilt():
    Le = 0.3
    _, _, G = element_matrices(Le, SEC, MAT)
    assert np.allclose(G, -G.T, atol=1e-15 * np.abs(G).max())
    # rigid tilts: about y (x = z b, ry = b) and about x (y = −z a, rx = a); uᵀ_x G u_y = ρ J L
    uy = np.zeros(12)
    ux = np.zeros(12)
    for k, z in enumerate((0.0, Le)):
        uy[6 * k + 0], uy[6 * k + 4] = z, 1.0
        ux[6 * k + 1], ux[6 * k + 3] = -z, 1.0
    assert ux @ G @ uy == pytest.approx(MAT.rho * SEC.J * Le, rel=1e-12)


def test_cowper_shear_coefficient_values():
    assert shear_coefficient(0.3, 1.0) == pytest.approx(6 * 1.3 / (7 + 1.8), rel=1e-15)
    # thin-walled tube limit (m → 1): 2(1+ν)/(4+3ν)
    assert shear_coefficient(0.3, 1.0, 0.999999) == pytest.approx(2 * 1.3 / (4 + 0.9), rel=1e-6)
