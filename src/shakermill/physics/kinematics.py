"""Prescribed vial motion (MODEL.md section 1). SI units: m, s, rad."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def vial_position(t: float, amplitude: float, omega: float, phase: float) -> float:
    """Vial centre x_v(t) = X_v·sin(ωt + φ) in m (MODEL.md §1; paper Eq. 1)."""
    return amplitude * math.sin(omega * t + phase)


@njit(cache=True)
def vial_velocity(t: float, amplitude: float, omega: float, phase: float) -> float:
    """Vial velocity ẋ_v(t) = ω·X_v·cos(ωt + φ) in m/s (MODEL.md §1; paper Eq. 6)."""
    return omega * amplitude * math.cos(omega * t + phase)


@njit(cache=True)
def left_face(vial_centre: float, vial_length: float) -> float:
    """Left end face x_L = x_v − l_v/2 in m (MODEL.md §1: the paper's Eq. 1 omits the offset)."""
    return vial_centre - 0.5 * vial_length


@njit(cache=True)
def right_face(vial_centre: float, vial_length: float) -> float:
    """Right end face x_R = x_v + l_v/2 in m (MODEL.md §1)."""
    return vial_centre + 0.5 * vial_length
