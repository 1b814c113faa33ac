"""Mindlin's tangential contact: the closed forms fretsim's Coulomb cycle is tested against (Johnson, *Contact
Mechanics*, §7.2–7.4; Hills & Nowell).  Two elastically similar bodies (or the coupling neglected), the normal
load held constant, the tangential force Q (or its amplitude Q*) below μP.

Ball (Cattaneo–Mindlin), Hertz radius a: the stick radius c/a = (1 − Q/μP)^{1/3}; the traction
q = μp₀√(1 − r²/a²) − μp₀(c/a)√(1 − r²/c²) inside the stick zone; the rigid-body displacement
δ(Q) = δ*[1 − (1 − Q/μP)^{2/3}], δ* = 3μP/(16a)·Σ(2 − ν)/G, which is also where gross slip begins.
Unloading and reloading follow Masing's rule (Mindlin–Deresiewicz): from a turning point the curve is the virgin
one doubled in both axes, so the energy dissipated per cycle between ±Q* is
W = 4Q*δ(Q*) − 8∫₀^{Q*}δ dQ = δ*μP[(24/5)(1 − (1 − t)^{5/3}) − 4t(1 + (1 − t)^{2/3})], t = Q*/μP (→ (4/27)t³·δ*μP).

Cylinder (Cattaneo, plane strain), half-width a, load per length P′: c/a = (1 − Q′/μP′)^{1/2}; q likewise with
c; the displacement carries the datum's arbitrary constant, but only in a term linear in Q′, which a closed loop
does not see: W′ = (μ²P′²/(πE*))·[4(1 − t)ln(1 − t) + 2t(2 − t)] per unit length (→ (2/3)t³μ²P′²/(πE*)).
E* here is the plane-strain contact modulus, 1/E* = Σ(1 − ν²)/E.
"""
from __future__ import annotations

import math

import numpy as np


def _t(q_amplitude: float, mu_p: float) -> float:
    t = q_amplitude / mu_p
    if not 0.0 <= t <= 1.0:
        raise ValueError(f"the tangential force must lie within ±μP, got Q/μP = {t:.4g}")
    return t


def compliance_sum(bodies) -> float:
    """Σ (2 − ν)/G over the bodies, given as (E, ν) pairs (MPa)."""
    return sum((2.0 - nu) * 2.0 * (1.0 + nu) / e for e, nu in bodies)


def ball_gross_slip_displacement(mu: float, load: float, radius_a: float, bodies) -> float:
    """δ* = 3μP/(16a)·Σ(2 − ν)/G (mm): where a ball's contact starts to slide as a whole."""
    return 3.0 * mu * load / (16.0 * radius_a) * compliance_sum(bodies)


def ball_stick_radius(q: float, mu: float, load: float) -> float:
    """c/a for a monotonic Q."""
    return (1.0 - _t(q, mu * load)) ** (1.0 / 3.0)


def ball_displacement(q: float, mu: float, load: float, radius_a: float, bodies) -> float:
    """δ(Q) of a monotonic loading from Q = 0."""
    return ball_gross_slip_displacement(mu, load, radius_a, bodies) * (1.0 - (1.0 - _t(q, mu * load)) ** (2 / 3))


def ball_force(delta: float, mu: float, load: float, radius_a: float, bodies) -> float:
    """Q(δ) of a monotonic loading (μP beyond δ*)."""
    d = delta / ball_gross_slip_displacement(mu, load, radius_a, bodies)
    return mu * load * (1.0 - max(0.0, 1.0 - min(d, 1.0)) ** 1.5)


def ball_traction(r: np.ndarray, q: float, mu: float, load: float, radius_a: float) -> np.ndarray:
    """Cattaneo–Mindlin shear traction at radius r for a monotonic Q."""
    p0 = 3.0 * load / (2.0 * math.pi * radius_a ** 2)
    c = ball_stick_radius(q, mu, load) * radius_a
    r = np.asarray(r, dtype=float)
    outer = mu * p0 * np.sqrt(np.clip(1.0 - (r / radius_a) ** 2, 0.0, None))
    inner = mu * p0 * (c / radius_a) * np.sqrt(np.clip(1.0 - (r / c) ** 2, 0.0, None)) if c > 0 else 0.0
    return outer - inner


def ball_loop_energy(q_amplitude: float, mu: float, load: float, radius_a: float, bodies) -> float:
    """Energy dissipated per cycle (N·mm) between ±Q* (Mindlin–Deresiewicz)."""
    t = _t(q_amplitude, mu * load)
    ds = ball_gross_slip_displacement(mu, load, radius_a, bodies)
    return ds * mu * load * (4.8 * (1.0 - (1.0 - t) ** (5 / 3)) - 4.0 * t * (1.0 + (1.0 - t) ** (2 / 3)))


def cylinder_stick_half_width(q: float, mu: float, load_per_length: float) -> float:
    """c/a for a monotonic Q′ (per unit length)."""
    return math.sqrt(1.0 - _t(q, mu * load_per_length))


def cylinder_traction(x: np.ndarray, q: float, mu: float, load_per_length: float, half_width: float) -> np.ndarray:
    """Cattaneo's shear traction across a cylinder's contact for a monotonic Q′."""
    p0 = 2.0 * load_per_length / (math.pi * half_width)
    c = cylinder_stick_half_width(q, mu, load_per_length) * half_width
    x = np.asarray(x, dtype=float)
    outer = mu * p0 * np.sqrt(np.clip(1.0 - (x / half_width) ** 2, 0.0, None))
    inner = mu * p0 * (c / half_width) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None)) if c > 0 else 0.0
    return outer - inner


def cylinder_displacement(q: float, mu: float, load_per_length: float, half_width: float, e_star: float,
                          datum: float) -> float:
    """δ(Q′) of a monotonic loading, the displacement measured from surface points at distance ``datum``: the
    stick zone moves as a whole by (μp₀/E*)·[a(ln(2d/a) + ½) − (c²/a)(ln(2d/c) + ½)] (an elliptic traction
    q₀√(1 − x²/b²) displaces its centre by (q₀b/E*)(ln(2d/b) + ½) against the datum, its curvature terms cancel
    in the stick zone).  The datum enters only as the term (2μP′/πE*)·t·ln d linear in t = Q′/μP′."""
    t = _t(q, mu * load_per_length)
    p0 = 2.0 * load_per_length / (math.pi * half_width)
    c2 = half_width**2 * (1.0 - t)
    inner = c2 / half_width * (math.log(2.0 * datum / math.sqrt(c2)) + 0.5) if c2 > 0 else 0.0
    return mu * p0 / e_star * (half_width * (math.log(2.0 * datum / half_width) + 0.5) - inner)


def cylinder_loop_energy(q_amplitude: float, mu: float, load_per_length: float, e_star: float) -> float:
    """Energy dissipated per cycle per unit length (N·mm/mm) between ±Q′* — independent of the 2D datum."""
    t = _t(q_amplitude, mu * load_per_length)
    log_term = 0.0 if t == 1.0 else 4.0 * (1.0 - t) * math.log(1.0 - t)
    return (mu * load_per_length) ** 2 / (math.pi * e_star) * (log_term + 2.0 * t * (2.0 - t))


def dundurs_beta(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """Dundurs' β = [(1 − 2ν₁)/G₁ − (1 − 2ν₂)/G₂] / [2((1 − ν₁)/G₁ + (1 − ν₂)/G₂)]: the coupling of normal and
    tangential contact (0 for elastically similar bodies)."""
    g1, g2 = e1 / (2 * (1 + nu1)), e2 / (2 * (1 + nu2))
    return ((1 - 2 * nu1) / g1 - (1 - 2 * nu2) / g2) / (2 * ((1 - nu1) / g1 + (1 - nu2) / g2))
