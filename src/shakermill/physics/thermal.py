"""Convection and the three-node thermal network (MODEL.md sections 4–6). SI units."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def sutherland_viscosity(temperature: float, mu_ref: float, t_ref: float, sutherland: float) -> float:
    """μ(θ) = μ_r·(θ/θ_r)^{3/2}·(θ_r + S)/(θ + S) in Pa·s (MODEL.md §4; paper Eq. 14)."""
    ratio = temperature / t_ref
    return mu_ref * ratio * math.sqrt(ratio) * (t_ref + sutherland) / (temperature + sutherland)


@njit(cache=True)
def reynolds_number(radius: float, air_density: float, speed: float, viscosity: float) -> float:
    """Re = 2R·ρ_a·|u|/μ_∞ (MODEL.md §4; paper Eq. 12)."""
    return 2.0 * radius * air_density * abs(speed) / viscosity


@njit(cache=True)
def prandtl_number(cp: float, viscosity: float, conductivity: float) -> float:
    """Pr = c_p,a·μ_∞/k_a (MODEL.md §4; paper Eq. 12)."""
    return cp * viscosity / conductivity


@njit(cache=True)
def whitaker_velocity_term(reynolds: float) -> float:
    """The velocity-dependent part of Whitaker's correlation, 0.4·Re^{1/2} + 0.06·Re^{2/3}."""
    root = math.sqrt(reynolds)
    return 0.4 * root + 0.06 * np.cbrt(reynolds * reynolds)


@njit(cache=True)
def whitaker_nusselt(reynolds: float, prandtl: float, viscosity_ratio: float) -> float:
    """Nu = 2 + (0.4 Re^{1/2} + 0.06 Re^{2/3})·Pr^{0.4}·(μ(θ_b)/μ_r)^{−1/4} (MODEL.md §4; paper Eq. 13).

    ``viscosity_ratio`` is μ(θ_b)/μ_r exactly as the paper prints it.
    """
    return nusselt_from_velocity_term(whitaker_velocity_term(reynolds), prandtl, viscosity_ratio)


@njit(cache=True)
def nusselt_from_velocity_term(velocity_term: float, prandtl: float, viscosity_ratio: float) -> float:
    """Whitaker's Nu from its velocity-dependent part, so that a time average of that part can be used."""
    return 2.0 + velocity_term * prandtl**0.4 / math.sqrt(math.sqrt(viscosity_ratio))


@njit(cache=True)
def heat_transfer_coefficient(nusselt: float, conductivity: float, radius: float) -> float:
    """h = Nu·k_a/(2R) in W/(m²·K) (MODEL.md §4)."""
    return nusselt * conductivity / (2.0 * radius)


@njit(cache=True)
def ball_air_heat_flow(radius: float, beta: float, h: float, t_ball: float, t_air: float) -> float:
    """Q̇_ba = 4πR²·β·h·(θ_b − θ_a) in W, ball to inner air (MODEL.md §4; paper Eq. 15)."""
    return 4.0 * math.pi * radius * radius * beta * h * (t_ball - t_air)


@njit(cache=True)
def newton_cooling(h: float, area: float, t_hot: float, t_cold: float) -> float:
    """Q̇ = h·A·(θ_hot − θ_cold) in W (MODEL.md §5; paper Eqs. 16–17)."""
    return h * area * (t_hot - t_cold)


@njit(cache=True)
def temperature_rates(
    heat_to_ball: float,
    heat_to_vial: float,
    ball_to_air: float,
    vial_to_air: float,
    vial_to_outside: float,
    capacity_ball: float,
    capacity_vial: float,
    capacity_air: float,
) -> tuple[float, float, float]:
    """(θ̇_b, θ̇_v, θ̇_a) in K/s from the energy balances of MODEL.md §6 (paper Eqs. 18–23).

    Capacities are m·c in J/K; heat flows in W.
    """
    rate_ball = (heat_to_ball - ball_to_air) / capacity_ball
    rate_vial = (heat_to_vial - vial_to_air - vial_to_outside) / capacity_vial
    rate_air = (ball_to_air + vial_to_air) / capacity_air
    return rate_ball, rate_vial, rate_air
