"""Prescribed vial motion (MODEL.md sections 1 and 12.2). SI units: m, s, rad."""

from __future__ import annotations

import math

import numpy as np
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


# A rigid vial moving in three dimensions (MODEL.md section 12.2): each of its six coordinates, the
# translations x, y, z of its centre (m) and the angles roll, pitch, yaw about the lab's x, y and z axes
# (rad), is a Fourier series in the drive's phase θ = ωt + φ, plus a steady turn for the angles of a mill
# that rotates (a planetary mill's sun wheel and jar): q = a₀ + s·θ + Σ_k≥1 (a_k cos kθ + b_k sin kθ).
# The coefficients are an array ``harmonics[coordinate, k] = (cos, sin)`` whose k = 0 sine slot, which a
# Fourier series leaves empty (sin 0θ = 0), holds the steady rate s (rad per radian of θ); so every
# kinematic model, rotating or not, is data, not a code path.


@njit(cache=True)
def fourier_coordinates(
    t: float, omega: float, phase: float, harmonics: np.ndarray, values: np.ndarray, rates: np.ndarray
) -> None:
    """Write each coordinate q = a₀ + s·θ + Σ_k≥1 (a_k cos kθ + b_k sin kθ), θ = ωt + φ, s = ``harmonics[., 0, 1]``
    (the steady rate), into ``values`` and dq/dt into ``rates``."""
    angle = omega * t + phase
    for coordinate in range(harmonics.shape[0]):
        steady = harmonics[coordinate, 0, 1]
        value = harmonics[coordinate, 0, 0] + steady * angle
        rate = steady * omega
        for k in range(1, harmonics.shape[1]):
            a, b = harmonics[coordinate, k, 0], harmonics[coordinate, k, 1]
            if a == 0.0 and b == 0.0:
                continue  # most coefficients of a mill's motion are zero; their sines cost the most here
            cosine, sine = math.cos(k * angle), math.sin(k * angle)
            value += a * cosine + b * sine
            rate += k * omega * (b * cosine - a * sine)
        values[coordinate] = value
        rates[coordinate] = rate


@njit(cache=True)
def rotation_matrix(roll: float, pitch: float, yaw: float, out: np.ndarray) -> None:
    """Q = R_z(yaw)·R_y(pitch)·R_x(roll) into ``out`` (3×3): vial frame to lab frame."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    out[0, 0], out[0, 1], out[0, 2] = cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr
    out[1, 0], out[1, 1], out[1, 2] = sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr
    out[2, 0], out[2, 1], out[2, 2] = -sp, cp * sr, cp * cr


@njit(cache=True)
def angular_velocity(
    pitch: float, yaw: float, roll_rate: float, pitch_rate: float, yaw_rate: float, out: np.ndarray
) -> None:
    """Ω (rad/s, lab frame) of R_z(yaw)·R_y(pitch)·R_x(roll): ψ̇ ẑ + θ̇ R_z ŷ + φ̇ R_z R_y x̂, into ``out``."""
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    out[0] = -sy * pitch_rate + cy * cp * roll_rate
    out[1] = cy * pitch_rate + sy * cp * roll_rate
    out[2] = yaw_rate - sp * roll_rate
