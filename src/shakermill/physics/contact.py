"""Ball–wall contact: Hertz elastic force with Tsuji damping (MODEL.md section 2).

Pure functions, SI units. The damping pairing c ∝ ζ^{1/4} with the Hertz
spring makes the restitution of one impact equal the input e at every speed,
which is why the total force is not clipped by default.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

# Rayleigh-wave speed factor of Eq. 40 (paper): t_R = πR/(0.1631ν + 0.8766)·√(ρ/G)
_RAYLEIGH_A = 0.1631
_RAYLEIGH_B = 0.8766
# Duration of an undamped Hertz impact divided by ζ_max/v: 2·Γ(7/5)·√π/Γ(9/10) ≈ 2.9433
# (Johnson, Contact Mechanics, §11.4)
HERTZ_DURATION_FACTOR = 2.0 * math.gamma(1.4) * math.sqrt(math.pi) / math.gamma(0.9)


@njit(cache=True)
def effective_modulus(e_ball: float, nu_ball: float, e_vial: float, nu_vial: float) -> float:
    """E* from 1/E* = (1−ν_b²)/E_b + (1−ν_v²)/E_v, in Pa (MODEL.md §2; paper Eq. 8)."""
    return 1.0 / ((1.0 - nu_ball * nu_ball) / e_ball + (1.0 - nu_vial * nu_vial) / e_vial)


@njit(cache=True)
def overlap_left(x: float, x_left: float, radius: float) -> float:
    """ζ_L = max(0, R − (x − x_L)) in m (MODEL.md §2; paper Eq. 4)."""
    return max(0.0, radius - (x - x_left))


@njit(cache=True)
def overlap_right(x: float, x_right: float, radius: float) -> float:
    """ζ_R = max(0, R − (x_R − x)) in m (MODEL.md §2; paper Eq. 4)."""
    return max(0.0, radius - (x_right - x))


@njit(cache=True)
def hertz_force(overlap: float, e_star: float, radius: float) -> float:
    """Elastic force F_e = (4/3)·E*·√R·ζ^{3/2} in N (MODEL.md §2).

    The paper's Eq. 7 prints the square root over the whole product; the
    standard Hertz law, used here, is MODEL.md difference 1.
    """
    return 4.0 / 3.0 * e_star * math.sqrt(radius) * overlap * math.sqrt(overlap)


@njit(cache=True)
def elastic_energy(overlap: float, e_star: float, radius: float) -> float:
    """Hertz potential V = (8/15)·E*·√R·ζ^{5/2} in J, so that dV/dζ = F_e (energy audit)."""
    return 8.0 / 15.0 * e_star * math.sqrt(radius) * overlap**2.5


@njit(cache=True)
def damping_ratio(restitution: float) -> float:
    """β_e = ln e / √(ln² e + π²) (MODEL.md §2; the paper drops the square root: difference 2)."""
    log_e = math.log(restitution)
    return log_e / math.sqrt(log_e * log_e + math.pi * math.pi)


@njit(cache=True)
def damping_coefficient(overlap: float, mass: float, radius: float, e_star: float, beta_e: float) -> float:
    """c(ζ) = −√(20/3)·β_e·(m²·R·E*²·ζ)^{1/4} in N·s/m, ≥ 0 for e ≤ 1 (MODEL.md §2)."""
    return -math.sqrt(20.0 / 3.0) * beta_e * math.sqrt(math.sqrt(mass * mass * radius * e_star * e_star * overlap))


@njit(cache=True)
def contact_force(elastic: float, damping: float, overlap_rate: float, no_tension: bool) -> float:
    """Magnitude of the normal force F_e + c·ζ̇ in N, clipped at 0 only with ``no_tension`` (MODEL.md §2)."""
    total = elastic + damping * overlap_rate
    if no_tension and total < 0.0:
        return 0.0
    return total


@njit(cache=True)
def dissipated_power(force: float, elastic: float, overlap_rate: float) -> float:
    """P_d = (f − F_e)·ζ̇ in W: the work rate of the non-elastic part of the applied force.

    Equals c·ζ̇² when the force is not clipped (MODEL.md §3); with clipping it
    uses the force actually applied, as MODEL.md §2 requires.
    """
    return (force - elastic) * overlap_rate


@njit(cache=True)
def rayleigh_time(radius: float, density: float, youngs_modulus: float, poisson_ratio: float) -> float:
    """t_R = πR/(0.1631ν + 0.8766)·√(ρ/G), G = E/(2(1+ν)), in s (MODEL.md §7; paper Eq. 40)."""
    shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson_ratio))
    return math.pi * radius / (_RAYLEIGH_A * poisson_ratio + _RAYLEIGH_B) * math.sqrt(density / shear_modulus)


@njit(cache=True)
def hertz_max_overlap(mass: float, radius: float, e_star: float, speed: float) -> float:
    """Largest overlap of an undamped Hertz impact, ζ_max = (15 m v² / (16 E* √R))^{2/5}, in m."""
    return (15.0 * mass * speed**2 / (16.0 * e_star * math.sqrt(radius))) ** 0.4


@njit(cache=True)
def hertz_contact_time(mass: float, radius: float, e_star: float, speed: float) -> float:
    """Duration of an undamped Hertz impact, 2.9433·ζ_max/v, in s (Johnson 1985, §11.4)."""
    return HERTZ_DURATION_FACTOR * hertz_max_overlap(mass, radius, e_star, speed) / speed


def hertz_duration_at_unit_speed(mass: ArrayLike, radius: ArrayLike, e_star: ArrayLike) -> np.ndarray:
    """:func:`hertz_contact_time` at 1 m/s, over arrays (NumPy, not compiled: a run's many contacts at once; a
    compiled ufunc would cost every import half a second). At speed v the duration is this times v^(-1/5)."""
    overlap_at_unit_speed = (15.0 * np.asarray(mass) / (16.0 * np.asarray(e_star) * np.sqrt(radius))) ** 0.4
    return np.asarray(HERTZ_DURATION_FACTOR * overlap_at_unit_speed)


# Tangential contact and rolling (MODEL.md section 12.3): the Hertz–Mindlin model of DEM codes.


@njit(cache=True)
def effective_shear_modulus(e_1: float, nu_1: float, e_2: float, nu_2: float) -> float:
    """G* from 1/G* = 2(2−ν₁)(1+ν₁)/E₁ + 2(2−ν₂)(1+ν₂)/E₂, in Pa (MODEL.md §12.3)."""
    return 1.0 / (2.0 * (2.0 - nu_1) * (1.0 + nu_1) / e_1 + 2.0 * (2.0 - nu_2) * (1.0 + nu_2) / e_2)


@njit(cache=True)
def concave_radius(radius: float, bore_radius: float) -> float:
    """R* of a ball inside a cylinder of radius R_c: R·R_c/(R_c − R), in m (MODEL.md §12.3)."""
    return radius * bore_radius / (bore_radius - radius)


@njit(cache=True)
def tangential_stiffness(shear_modulus: float, radius: float, overlap: float) -> float:
    """Mindlin's no-slip stiffness k_t = 8·G*·√(R*·ζ), in N/m (MODEL.md §12.3)."""
    return 8.0 * shear_modulus * math.sqrt(radius * overlap)


@njit(cache=True)
def tangential_damping(beta_e: float, stiffness: float, mass: float) -> float:
    """c_t = −2·√(5/6)·β_e·√(k_t·m*), in N·s/m, ≥ 0 for e ≤ 1 (MODEL.md §12.3)."""
    return -2.0 * math.sqrt(5.0 / 6.0) * beta_e * math.sqrt(stiffness * mass)


@njit(cache=True)
def contact_period(mass: float, radius: float, e_star: float, g_star: float, overlap: float, speed: float) -> float:
    """Shortest oscillation period of a Hertz–Mindlin contact (s), for the step inside it (MODEL.md §12.6).

    Its stiffnesses are taken at ζ_e = max(ζ, ζ_max(|ζ̇|)), the overlap now or the peak an approach at the
    normal speed now would reach, whichever is larger, so that an impact's period is known from its first step:
    k_n = 2E*√(R*ζ_e) with the mass m*, and k_t = 8G*√(R*ζ_e) with the contact point's tangential mass 2m*/7
    (a ball's spin, I = 2/5 mR², adds 5/(2m) to each 1/m). The tangential one is the shorter for ν < ~0.9.
    """
    effective = overlap
    reach = 15.0 * mass * speed * speed / (16.0 * e_star * math.sqrt(radius))  # ζ_max^{5/2}
    if reach > overlap * overlap * math.sqrt(overlap):  # the power only where it matters: it is slow
        effective = reach**0.4
    root = math.sqrt(radius * effective)
    normal = mass / (2.0 * e_star * root)
    tangential = 2.0 / 7.0 * mass / (8.0 * g_star * root)
    return 2.0 * math.pi * math.sqrt(min(normal, tangential))
