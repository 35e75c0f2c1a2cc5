"""Convection correlations and the thermal network (MODEL.md §§4–6) against hand-computed values.

Air of the paper's Table 3: μ_r = 1.716e-5 Pa·s at θ_r = 273.15 K, S = 111 K, k_a = 0.0241 W/(m·K),
c_p,a = 1003.5 J/(kg·K), ρ_a = 1.225 kg/m³. Ball radius R = 6.35 mm.
"""

from __future__ import annotations

import math

import pytest

from shakermill.physics import thermal

MU_REF = 1.716e-5
T_REF = 273.15
SUTHERLAND = 111.0
CONDUCTIVITY = 0.0241
CP = 1003.5
AIR_DENSITY = 1.225
RADIUS = 6.35e-3
# μ(293.15 K), by hand: (293.15/273.15)^{3/2} = 1.0732198^{1.5} = 1.111816;
# (273.15 + 111)/(293.15 + 111) = 384.15/404.15 = 0.9505134; μ = 1.716e-5 · 1.111816 · 0.9505134 = 1.81346e-5
MU_20C = 1.81346e-5


# --- Sutherland -----------------------------------------------------------------------------------


def test_sutherland_equals_reference_at_reference_temperature() -> None:
    assert thermal.sutherland_viscosity(T_REF, MU_REF, T_REF, SUTHERLAND) == pytest.approx(MU_REF, rel=1e-14)


def test_sutherland_at_20_celsius_hand_value() -> None:
    assert thermal.sutherland_viscosity(293.15, MU_REF, T_REF, SUTHERLAND) == pytest.approx(MU_20C, rel=1e-5)


def test_sutherland_formula_at_another_temperature() -> None:
    theta = 350.0
    expected = MU_REF * (theta / T_REF) ** 1.5 * (T_REF + SUTHERLAND) / (theta + SUTHERLAND)
    assert thermal.sutherland_viscosity(theta, MU_REF, T_REF, SUTHERLAND) == pytest.approx(expected, rel=1e-13)
    # gas viscosity grows with temperature
    assert thermal.sutherland_viscosity(theta, MU_REF, T_REF, SUTHERLAND) > MU_20C


# --- dimensionless groups -------------------------------------------------------------------------


def test_reynolds_number_hand_value() -> None:
    # Re = 2 · 6.35e-3 · 1.225 · 2 / 1.81346e-5 = 0.031115 / 1.81346e-5 = 1715.78
    assert thermal.reynolds_number(RADIUS, AIR_DENSITY, 2.0, MU_20C) == pytest.approx(1715.78, rel=1e-5)


def test_reynolds_number_uses_the_speed_magnitude() -> None:
    forward = thermal.reynolds_number(RADIUS, AIR_DENSITY, 2.0, MU_20C)
    assert thermal.reynolds_number(RADIUS, AIR_DENSITY, -2.0, MU_20C) == pytest.approx(forward, rel=1e-15)
    assert thermal.reynolds_number(RADIUS, AIR_DENSITY, 0.0, MU_20C) == 0.0


def test_prandtl_number_with_table_3_air_at_20_celsius() -> None:
    # Pr = 1003.5 · 1.81346e-5 / 0.0241 = 0.0181981 / 0.0241 = 0.75511
    # (with μ_r at 0 °C instead it would be 1003.5 · 1.716e-5 / 0.0241 = 0.71453)
    assert thermal.prandtl_number(CP, MU_20C, CONDUCTIVITY) == pytest.approx(0.75511, rel=1e-4)
    assert thermal.prandtl_number(CP, MU_REF, CONDUCTIVITY) == pytest.approx(0.71453, rel=1e-4)


# --- Whitaker -------------------------------------------------------------------------------------


def test_whitaker_velocity_term_hand_values() -> None:
    # Re = 1000: 0.4 · 31.6227766 + 0.06 · 100 = 12.6491106 + 6 = 18.6491106
    assert thermal.whitaker_velocity_term(1000.0) == pytest.approx(18.6491106, rel=1e-8)
    # Re = 8: 0.4 · 2.8284271 + 0.06 · 4 = 1.1313708 + 0.24 = 1.3713708
    assert thermal.whitaker_velocity_term(8.0) == pytest.approx(1.3713708, rel=1e-7)
    assert thermal.whitaker_velocity_term(0.0) == 0.0


def test_whitaker_nusselt_is_two_for_still_air() -> None:
    assert thermal.whitaker_nusselt(0.0, 0.75, 1.06) == pytest.approx(2.0, rel=1e-15)


def test_whitaker_nusselt_hand_value() -> None:
    # Nu = 2 + 18.6491106 · 0.7^{0.4} · 1.1^{−1/4} = 2 + 18.6491106 · 0.8670402 · 0.9764541 = 17.788802
    assert thermal.whitaker_nusselt(1000.0, 0.7, 1.1) == pytest.approx(17.788802, rel=1e-6)


def test_whitaker_nusselt_decreases_with_ball_temperature() -> None:
    # (μ(θ_b)/μ_r)^{−1/4}: a hotter ball (larger μ ratio) gives a smaller Nu, as the paper prints it
    cold = thermal.whitaker_nusselt(500.0, 0.75, 1.0)
    hot = thermal.whitaker_nusselt(500.0, 0.75, 1.2)
    assert (hot - 2.0) / (cold - 2.0) == pytest.approx(1.2**-0.25, rel=1e-12)


def test_nusselt_from_velocity_term_matches_whitaker_nusselt() -> None:
    term = 0.4 * math.sqrt(1715.78) + 0.06 * 1715.78 ** (2.0 / 3.0)
    assert thermal.nusselt_from_velocity_term(term, 0.75511, 1.05) == pytest.approx(
        thermal.whitaker_nusselt(1715.78, 0.75511, 1.05), rel=1e-12
    )


# --- heat flows -----------------------------------------------------------------------------------


def test_heat_transfer_coefficient_hand_value() -> None:
    # h = Nu · k_a/(2R) = 10 · 0.0241 / 0.0127 = 18.976378 W/(m²·K)
    assert thermal.heat_transfer_coefficient(10.0, CONDUCTIVITY, RADIUS) == pytest.approx(18.976378, rel=1e-7)


def test_ball_air_heat_flow_hand_value() -> None:
    # 4πR² = 4π · 4.032250e-5 = 5.067075e-4 m²; · β 0.3 · h 20 · Δθ 15 = 5.067075e-4 · 90 = 0.0456037 W
    assert thermal.ball_air_heat_flow(RADIUS, 0.3, 20.0, 320.0, 305.0) == pytest.approx(0.0456037, rel=1e-5)


def test_ball_air_heat_flow_sign() -> None:
    assert thermal.ball_air_heat_flow(RADIUS, 0.3, 20.0, 300.0, 305.0) < 0.0
    assert thermal.ball_air_heat_flow(RADIUS, 0.3, 20.0, 305.0, 305.0) == 0.0


def test_newton_cooling_hand_value() -> None:
    # h_i A (θ_v − θ_a) = 200 · 5.6706e-4 · (300 − 305) = −0.56706 W
    assert thermal.newton_cooling(200.0, 5.6706e-4, 300.0, 305.0) == pytest.approx(-0.56706, rel=1e-12)
    # h_o A (θ_v − θ_amb) = 45 · 5.6706e-4 · 6.85 = 0.174796 W
    assert thermal.newton_cooling(45.0, 5.6706e-4, 300.0, 293.15) == pytest.approx(0.1747962, rel=1e-6)


# --- energy balances ------------------------------------------------------------------------------


def test_temperature_rates_hand_values() -> None:
    # ball: (0.3 − 0.05)/3.0 = 0.0833333; vial: (0.5 − 0.2 − 0.1)/20 = 0.01; air: (0.05 + 0.2)/0.0135 = 18.518519
    rates = thermal.temperature_rates(0.3, 0.5, 0.05, 0.2, 0.1, 3.0, 20.0, 0.0135)
    assert rates[0] == pytest.approx(0.0833333333, rel=1e-9)
    assert rates[1] == pytest.approx(0.01, rel=1e-9)
    assert rates[2] == pytest.approx(18.518518519, rel=1e-9)


def test_temperature_rates_conserve_energy() -> None:
    heat_ball, heat_vial = 0.37, 0.63
    ball_air, vial_air, vial_out = 0.021, -0.4, 0.8
    capacities = (3.857, 23.05, 0.01349)
    rates = thermal.temperature_rates(heat_ball, heat_vial, ball_air, vial_air, vial_out, *capacities)
    stored = sum(c * r for c, r in zip(capacities, rates))
    # Σ C·θ̇ = heat in − heat lost to the outside: 0.37 + 0.63 − 0.8 = 0.2 W
    assert stored == pytest.approx(0.2, rel=1e-12)
