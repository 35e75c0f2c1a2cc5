"""The heat paths of a real mill (physics/heat_paths.py) against values worked out by hand."""

from __future__ import annotations

import math

import pytest

from shakermill.physics import heat_paths


def test_forced_convection_of_the_side_and_the_ends():
    # 0.664 · √1e4 · 0.7^(1/3) = 66.4 · 0.887904 = 58.957
    assert heat_paths.flat_plate_nusselt(1e4, 0.7) == pytest.approx(58.957, rel=1e-4)
    # 1.05 · √1e4 · 0.7^0.36 = 105 · exp(0.36 · ln 0.7) = 105 · 0.879537 = 92.351
    assert heat_paths.disk_nusselt(1e4, 0.7) == pytest.approx(92.351, rel=1e-4)


def test_forced_convection_of_a_cylinder_across_the_flow():
    # 0.62 · √1e4 · 0.71^(1/3) = 62 · 0.892112 = 55.311; [1 + (0.4/0.71)^(2/3)]^(1/4) = 1.682131^0.25 = 1.138846;
    # [1 + (1e4/282000)^(5/8)]^(4/5) = 1.124049^0.8 = 1.098066; 0.3 + 55.311/1.138846 · 1.098066 = 53.630
    assert heat_paths.churchill_bernstein_nusselt(1e4, 0.71) == pytest.approx(53.630, rel=1e-4)


def test_natural_convection_of_a_horizontal_cylinder():
    # Ra = g·ΔT/θ_f·L³/(ν·α) = 9.80665 · 20/303.15 · 0.05³ / (1.5e-5 · 2.07297e-5) = 260 088
    rayleigh = heat_paths.rayleigh_number(0.05, 20.0, 303.15, 1.8e-5, 1.2, 0.025, 1005.0)
    assert rayleigh == pytest.approx(260_088, rel=1e-5)
    # {0.6 + 0.387 · 1e5^(1/6) / [1 + (0.559/0.7)^(9/16)]^(8/27)}² = (0.6 + 2.63660/1.20591)² = 2.78640² = 7.7640
    assert heat_paths.churchill_chu_cylinder_nusselt(1e5, 0.7) == pytest.approx(7.7640, rel=1e-4)


def test_mixed_convection_keeps_the_larger_where_the_other_is_small():
    assert heat_paths.mixed_convection_coefficient(3.0, 4.0) == pytest.approx(91.0 ** (1 / 3))
    assert heat_paths.mixed_convection_coefficient(25.0, 5.0) == pytest.approx(25.0, rel=3e-3)


def test_radiation_coefficient_is_four_sigma_theta_cubed_at_equal_temperatures():
    assert heat_paths.radiation_coefficient(1.0, 300.0, 300.0) == pytest.approx(4 * 5.670374419e-8 * 300.0**3)
    # ε·σ·(θ_s² + θ_∞²)(θ_s + θ_∞)·(θ_s − θ_∞) is ε·σ·(θ_s⁴ − θ_∞⁴)
    h = heat_paths.radiation_coefficient(0.2, 350.0, 293.15)
    assert h * (350.0 - 293.15) == pytest.approx(0.2 * 5.670374419e-8 * (350.0**4 - 293.15**4))


def test_contact_conduction_of_an_impact_and_of_a_lasting_contact():
    # a = √(R*·δ) = √(0.01 · 1e-6) = 1e-4 m
    assert heat_paths.hertz_contact_radius(0.01, 1e-6) == pytest.approx(1e-4)
    # 0.87·π·a²·√t_c/(1/e₁ + 1/e₂) = 0.87π · 1e-8 · 1e-2 / 2e-4 = 1.36659e-6 J/K
    assert heat_paths.impact_conduction(1e-4, 1e-4, 1e4, 1e4) == pytest.approx(0.87 * math.pi * 5e-7)
    # Equal conductivities: 2ka = 2 · 50 · 1e-4 = 0.01 W/K
    assert heat_paths.constriction_conductance(1e-4, 50.0, 50.0) == pytest.approx(0.01)
    short = heat_paths.contact_conduction(1e-4, 1e-5, 1e4, 1e4, 50.0, 50.0)
    lasting = heat_paths.contact_conduction(1e-4, 1.0, 1e4, 1e4, 50.0, 50.0)
    assert short == pytest.approx(heat_paths.impact_conduction(1e-4, 1e-5, 1e4, 1e4))
    assert lasting == pytest.approx(0.01 * 1.0)
