"""Explicit membrane-fluid coupling: the stiffness limit predicted for caplab's IB-LBM scheme.

Used by the stability page (stress.py) to draw the predicted boundary on the G, E_b and marker
spacing maps and to give each point its ratio S / S_crit. Everything is in lattice units of the
finest block (h = dt = rho = 1, mu = nu = (tau_f - 1/2)/3).

The scheme (solver/sim/capsule.hpp; thesis fig. 2.4, eq. 2.15-2.19, 2.25): per fine step the
membrane force F(X^n) is spread, the node velocity is interpolated *including the half-force
term* U = sum_x [u* + f/(2 rho)] phi, and X^{n+1} = X^n + U dt (explicit Euler). Lumping one
membrane mode q into a node-fluid oscillator (node stiffness K, fluid mass m the force accelerates
in one step, viscous drag c = 1/M with M the quasi-steady Stokes mobility of the mode):

    x' = (1 - a/2) x + v dt,   v' dt = beta (v dt - a x),   a = K dt^2/m,  beta = m/(m + c dt),

whose eigenvalues lie in the unit disc (Jury) iff

    (i)  K M dt < 2                              (viscous: the brief's  E dt/(mu ds) bounded),
    (ii) K dt^2 < 4 m + 8 m^2/(c dt)              (inertial; only matters at large nu).

Without the half-force term (ii) would read K dt^2 < 4m + 2 c dt; with it, an undamped node is
never stable (|det| = 1 + a/2), so viscosity is what stabilises the explicit coupling and (i) is
the operative bound.

Mode stiffness per node (membrane line of spacing s along x, or a square sheet of spacing s):
    2D Hooke ring, tangential:   K = 4 E sin^2(q s/2) / s          (tension T = E (l/l0 - 1))
    2D bending, normal:          K = 16 E_B sin^4(q s/2) / s^3      (m = E_B kappa, q = dm/dl)
    3D sheet, in-plane:          K = 4 E_L sin^2(q s/2)             (E_L = longitudinal modulus:
                                  NH 4 G_s = 4E/3 with E = 3 G_s; Skalak (1 + C) E with E = 2 G_s)
Mobility and mass of the mode, from the Stokes (resp. impulsive) response of a force sheet
filtered by the kernel (phi^ its Fourier transform) and sampled at the nodes (aliases q + 2 pi j/s):
    mu M(q) = (1/s^d') sum_j |phi^(q_j)|^2 int dk/(2 pi) |phi^(k)|^2 P(q_j, k) / |k|^4
    1/m(q)  = (1/s^d') sum_j |phi^(q_j)|^2 int dk/(2 pi) |phi^(k)|^2 P(q_j, k) / |k|^2
with P the Stokes projector's component along the force (tangential in-line: k_perp^2; normal: q^2),
d' = 1 (2D line) or 2 (3D sheet). Without the kernel, M = 1/(4 mu q s^d'): the Stokes force-sheet
result for both tangential and normal forcing in 2D and 3D.

Written in the capillary number G = mu k a / E (E/mu = k a / G, so E dt/(mu h) = U/G with U the
lattice velocity k a dt/h), criterion (i) becomes

    S = U / (G s)  <  S_crit(s, kernel)                       (tension, 2D and 3D)
    S_b = E_b N_a^2 U / (G s^3)  <  S_b,crit(s, kernel)      (bending, 2D; N_a = a/h)

with S_crit = min_q 2 / (4 sin^2(qs/2) s mu M(q)) (2D) and similarly for the others. The
minimising mode is the kernel-scale one (q h ~ 0.5, wavelength ~ 12 h), not the node sawtooth:
the kernel filters the sawtooth, so S_crit s is almost independent of the marker spacing.

Approximations, stated on the page: straight membrane (curvature a >> h), continuous kernel
transform (no lattice aliasing of the fluid), quasi-steady Stokes mobility for (i), linear
elasticity about the rest state (prestress and large strain ignored), square node lattice for the
triangulated 3D membrane with the node density of the mesh (s = (area per node)^(1/2)).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

_R = np.linspace(-2.5, 2.5, 2001)
_KY_HALF = np.geomspace(1e-4, 30.0, 500)
_KY = np.concatenate([-_KY_HALF[::-1], [0.0], _KY_HALF])  # fine near 0, where long modes peak
_ALIASES = (-2, -1, 0, 1, 2)


def kernel(name: str, r):
    """The regularised delta functions of solver/ibm/kernels.hpp (one dimension, h = 1)."""
    r = np.abs(np.asarray(r, dtype=float))
    if name == "cosine4":
        return np.where(r < 2, 0.25 * (1 + np.cos(np.pi * r / 2)), 0.0)
    if name == "roma3":
        inner = (1 + np.sqrt(np.clip(1 - 3 * r ** 2, 0, None))) / 3
        outer = (5 - 3 * r - np.sqrt(np.clip(1 - 3 * (1 - r) ** 2, 0, None))) / 6
        return np.where(r <= 0.5, inner, np.where(r <= 1.5, outer, 0.0))
    if name == "linear2":
        return np.where(r < 1, 1 - r, 0.0)
    raise ValueError(f"unknown kernel {name!r}; expected cosine4, roma3 or linear2")


def kernel_transform(name: str, k):
    """phi^(k) = int phi(r) cos(k r) dr (the kernels are even); closed form for cosine4:
    phi^(k) = sin(2k) (pi^2/4) / (2 k (pi^2/4 - k^2)), by quadrature for the others."""
    k = np.asarray(k, dtype=float)
    if name == "cosine4":
        a2 = np.pi ** 2 / 4
        kk = np.where(np.abs(k) < 1e-9, 1e-9, k)
        near = np.abs(np.abs(kk) - np.pi / 2) < 1e-7
        kk = np.where(near, kk + 2e-7, kk)  # removable singularity at k = pi/2 (value 1/2)
        return np.sin(2 * kk) * a2 / (2 * kk * (a2 - kk ** 2))
    w = kernel(name, _R)
    return np.trapz(w[None, :] * np.cos(np.outer(k.ravel(), _R)), _R, axis=1).reshape(k.shape)


@lru_cache(maxsize=8)
def _phi2_ky(name: str) -> np.ndarray:
    return kernel_transform(name, _KY) ** 2


def mode_response(name: str, s: float, q: np.ndarray, direction: str = "tangential", dim: int = 2):
    """(mu M(q), 1/m(q)) of the mode q of a line (dim 2) or square sheet (dim 3) of nodes spaced s."""
    q = np.asarray(q, dtype=float)
    ky2 = _KY[None, :] ** 2
    phi_k = _phi2_ky(name)[None, :]
    mob = np.zeros_like(q)
    inv_mass = np.zeros_like(q)
    in_plane = _ALIASES if dim == 3 else (None,)
    for j in _ALIASES:
        qj = q + 2 * np.pi * j / s
        pq = kernel_transform(name, qj) ** 2
        if float(np.max(pq)) < 1e-12:
            continue
        for n in in_plane:
            if n is None:  # 2D: the line along x, k = (q_j, k_y)
                k2 = qj[:, None] ** 2 + ky2
                num = (qj[:, None] ** 2 + 0 * ky2) if direction == "normal" else ky2 + 0 * k2
                weight, area = pq[:, None], s
            else:  # 3D: the sheet z = 0, k = (q_j, 2 pi n/s, k_z), force along x
                kyn = 2 * np.pi * n / s
                k2 = qj[:, None] ** 2 + kyn ** 2 + ky2
                num = kyn ** 2 + ky2 + 0 * k2
                weight, area = pq[:, None] * float(kernel_transform(name, np.array([kyn]))[0]) ** 2, s * s
            mob += np.trapz(weight * phi_k * num / k2 ** 2, _KY, axis=1) / (2 * np.pi) / area
            inv_mass += np.trapz(weight * phi_k * num / k2, _KY, axis=1) / (2 * np.pi) / area
    return mob, inv_mass


def _modes(s: float) -> np.ndarray:
    return np.linspace(0.02, np.pi / s, 100)


@lru_cache(maxsize=256)
def tension_limit(s: float, nu: float, dim: int = 2, kernel_name: str = "cosine4", modulus: float = 1.0) -> dict:
    """Critical S = U/(G s) for in-plane (tension) modes: viscous bound (i), inertial bound (ii),
    their minimum, and the critical mode q (1/h). ``modulus`` = longitudinal modulus over E."""
    q = _modes(s)
    mob, inv_mass = mode_response(kernel_name, s, q, "tangential", dim)
    sin2 = np.sin(q * s / 2) ** 2
    geom = 4 * sin2 / s if dim == 2 else 4 * sin2  # K / E_L per node
    viscous = 2.0 / (modulus * geom * s * mob)
    mass = 1.0 / inv_mass
    inertial = (4 * mass + 8 * mass ** 2 * mob / nu) / (modulus * nu * geom * s)
    i = int(np.argmin(viscous))
    return {"viscous": float(viscous.min()), "inertial": float(inertial.min()),
            "critical": float(min(viscous.min(), inertial.min())), "mode_q": float(q[i]),
            "wavelength_h": float(2 * np.pi / q[i])}


@lru_cache(maxsize=256)
def lattice_inertial_limit(s: float, dim: int = 2, kernel_name: str = "cosine4", modulus: float = 1.0) -> dict:
    """Critical E_lu = nu U / G of the grid-scale modes, bound (ii) in its lattice form: within one
    step the LBM fluid answers a force without the pressure projection (sound needs several steps
    to cross the kernel), and a grid-scale mode is damped within a step (nu k^2 dt ~ 1), so that
    (ii) reduces to K dt^2 < 4 m_u(q) with the unprojected mass 1/m_u = (1/s^d') sum_j |phi^(q_j)|^2
    int |phi^(k)|^2 dk/(2 pi). Returns the critical E_lu (per E of the law) and the critical mode."""
    q = _modes(s)
    phi_k = _phi2_ky(kernel_name)
    line = float(np.trapz(phi_k, _KY)) / (2 * np.pi)
    inv_mass = np.zeros_like(q)
    for j in _ALIASES:
        pq = kernel_transform(kernel_name, q + 2 * np.pi * j / s) ** 2
        if dim == 2:
            inv_mass += pq * line / s
        else:
            for n in _ALIASES:
                pn = float(kernel_transform(kernel_name, np.array([2 * np.pi * n / s]))[0]) ** 2
                inv_mass += pq * pn * line / (s * s)
    sin2 = np.sin(q * s / 2) ** 2
    geom = 4 * sin2 / s if dim == 2 else 4 * sin2
    e_crit = 4.0 / (modulus * geom * inv_mass)
    eb_crit = 4.0 / (16 * sin2 ** 2 / s ** 3 * inv_mass)  # 2D bending: critical E_B in lattice units
    i = int(np.argmin(e_crit))
    return {"E_crit": float(e_crit[i]), "E_B_crit": float(eb_crit.min()), "mode_q": float(q[i]),
            "wavelength_h": float(2 * np.pi / q[i])}


@lru_cache(maxsize=256)
def bending_limit(s: float, kernel_name: str = "cosine4") -> dict:
    """Critical S_b = E_b N_a^2 U / (G s^3) for the normal (bending) modes of a 2D ring, bound (i)."""
    q = _modes(s)
    mob, _ = mode_response(kernel_name, s, q, "normal", 2)
    v = 2.0 / (16 * np.sin(q * s / 2) ** 4 * mob)
    i = int(np.argmin(v))
    return {"viscous": float(v[i]), "critical": float(v[i]), "mode_q": float(q[i]),
            "wavelength_h": float(2 * np.pi / q[i])}


def longitudinal_modulus(law: str, area_dilation: float | None = None) -> float:
    """Small-strain longitudinal (in-plane P-wave) modulus over caplab's E (DESIGN.md section 4)."""
    if law == "hooke":
        return 1.0
    if law in ("neo_hookean", "zero_thickness"):
        return 4.0 / 3.0  # K_s + G_s = 3 G_s + G_s, E = 3 G_s
    if law == "skalak":
        return 1.0 + (area_dilation or 1.0)  # K_s + G_s = G_s (1 + 2C) + G_s, E = 2 G_s
    raise ValueError(f"unknown membrane law {law!r}")


def explicit_numbers(p: dict) -> dict | None:
    """Theory for one point from its resolved parameters (keys of the runner's ``physics``):
    dimension, law, capillary, bending_ratio, lattice_velocity, tau_fine, fine_spacing, diameter,
    nodes (2D) or subdivisions (3D), kernel. None when the point has no membrane."""
    if p.get("capillary") is None or p.get("lattice_velocity") is None or p.get("tau_fine") is None:
        return None
    dim = int(p.get("dimension", 2))
    h = float(p["fine_spacing"])
    a_h = 0.5 * float(p["diameter"]) / h  # N_a = a / h
    u = float(p["lattice_velocity"])
    g = float(p["capillary"])
    nu = (float(p["tau_fine"]) - 0.5) / 3.0
    kern = p.get("kernel", "cosine4")
    if dim == 2:
        nodes = int(p["nodes"])
        s = 2 * math.pi * a_h / nodes  # circle: perimeter 2 pi a
        modulus = 1.0
    else:
        nodes = 4 * 4 ** int(p["subdivisions"]) + 2
        s = math.sqrt(4 * math.pi * a_h ** 2 / nodes)
        modulus = longitudinal_modulus(p.get("law", "neo_hookean"), p.get("area_dilation"))
    lim = tension_limit(round(s, 4), round(nu, 6), dim, kern, modulus)
    out = {"marker_spacing": s, "nu_fine": nu, "S": u / (g * s), "S_crit": lim["critical"],
           "S_crit_viscous": lim["viscous"], "S_crit_inertial": lim["inertial"],
           "critical_wavelength_h": lim["wavelength_h"],
           "G_crit": u / (s * lim["critical"]),
           "E_dt_over_mu_h": u / g, "E_lu": nu * u / g}
    out["ratio_viscous"] = out["S"] / out["S_crit"]
    li = lattice_inertial_limit(round(s, 4), dim, kern, modulus)
    out.update({"E_crit_inertial": li["E_crit"], "ratio_inertial": out["E_lu"] / li["E_crit"],
                "G_crit_inertial": nu * u / li["E_crit"]})
    out["ratio"] = max(out["ratio_viscous"], out["ratio_inertial"])
    eb = p.get("bending_ratio")
    if dim == 2 and eb:
        bl = bending_limit(round(s, 4), kern)
        sb = float(eb) * a_h ** 2 * u / (g * s ** 3)
        eb_lu = float(eb) * a_h ** 2 * out["E_lu"]
        out.update({"S_b": sb, "S_b_crit": bl["critical"], "ratio_bending": sb / bl["critical"],
                    "Eb_crit": bl["critical"] * g * s ** 3 / (a_h ** 2 * u),
                    "E_B_lu": eb_lu, "E_B_crit_inertial": li["E_B_crit"],
                    "ratio_bending_inertial": eb_lu / li["E_B_crit"]})
        out["ratio_viscous"] = max(out["ratio_viscous"], out["ratio_bending"])
        out["ratio_inertial"] = max(out["ratio_inertial"], out["ratio_bending_inertial"])
        out["ratio"] = max(out["ratio_viscous"], out["ratio_inertial"])
    return out
