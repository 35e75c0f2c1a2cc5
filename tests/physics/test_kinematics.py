"""Prescribed vial motion against MODEL.md §1, with hand-computed values."""

from __future__ import annotations

import math

import pytest

from shakermill.physics import kinematics as drive

# SPEX 8000M drive of MODEL.md §9: X_v = 25 mm, ω = 111 rad/s, l_v = 58 mm.
AMPLITUDE = 25e-3
OMEGA = 111.0
LENGTH = 58e-3


def test_vial_starts_at_centre_with_zero_phase() -> None:
    assert drive.vial_position(0.0, AMPLITUDE, OMEGA, 0.0) == pytest.approx(0.0, abs=1e-18)


def test_vial_position_at_quarter_period_is_the_amplitude() -> None:
    quarter_period = math.pi / (2.0 * OMEGA)  # ωt = π/2, sin = 1
    assert drive.vial_position(quarter_period, AMPLITUDE, OMEGA, 0.0) == pytest.approx(AMPLITUDE, rel=1e-12)
    # half a period later it is at the other extreme
    assert drive.vial_position(3.0 * quarter_period, AMPLITUDE, OMEGA, 0.0) == pytest.approx(-AMPLITUDE, rel=1e-12)


def test_vial_position_hand_value_with_phase() -> None:
    # t = 0.01 s, φ = 0.3 rad: ωt + φ = 1.41 rad, sin(1.41) = 0.98710 (hand, table value 0.987100)
    value = drive.vial_position(0.01, AMPLITUDE, OMEGA, 0.3)
    assert value == pytest.approx(AMPLITUDE * 0.9871001, rel=1e-6)
    assert value == pytest.approx(AMPLITUDE * math.sin(OMEGA * 0.01 + 0.3), rel=1e-13)


def test_phase_shifts_the_motion() -> None:
    # φ = π/2 puts the vial at +X_v at t = 0 and at rest there
    assert drive.vial_position(0.0, AMPLITUDE, OMEGA, math.pi / 2) == pytest.approx(AMPLITUDE, rel=1e-12)
    assert drive.vial_velocity(0.0, AMPLITUDE, OMEGA, math.pi / 2) == pytest.approx(0.0, abs=1e-12)


def test_peak_vial_velocity_is_omega_times_amplitude() -> None:
    # ω X_v = 111 · 0.025 = 2.775 m/s at t = 0 with φ = 0
    assert drive.vial_velocity(0.0, AMPLITUDE, OMEGA, 0.0) == pytest.approx(2.775, rel=1e-12)
    half_period = math.pi / OMEGA
    assert drive.vial_velocity(half_period, AMPLITUDE, OMEGA, 0.0) == pytest.approx(-2.775, rel=1e-12)


@pytest.mark.parametrize("t", [0.0, 0.0123, 0.05, 1.7])
@pytest.mark.parametrize("phase", [0.0, 0.9, -2.0])
def test_vial_velocity_is_the_derivative_of_position(t: float, phase: float) -> None:
    h = 1e-7
    numeric = (
        drive.vial_position(t + h, AMPLITUDE, OMEGA, phase) - drive.vial_position(t - h, AMPLITUDE, OMEGA, phase)
    ) / (2.0 * h)
    assert drive.vial_velocity(t, AMPLITUDE, OMEGA, phase) == pytest.approx(numeric, rel=1e-6, abs=1e-8)


def test_end_faces_are_offset_by_half_the_vial_length() -> None:
    # x_v = 10 mm: x_L = 10 − 29 = −19 mm, x_R = 10 + 29 = 39 mm
    assert drive.left_face(0.010, LENGTH) == pytest.approx(-0.019, rel=1e-12)
    assert drive.right_face(0.010, LENGTH) == pytest.approx(0.039, rel=1e-12)


@pytest.mark.parametrize("centre", [-0.025, 0.0, 0.0137])
def test_faces_are_one_vial_length_apart_and_symmetric(centre: float) -> None:
    left = drive.left_face(centre, LENGTH)
    right = drive.right_face(centre, LENGTH)
    assert right - left == pytest.approx(LENGTH, rel=1e-12)
    assert 0.5 * (left + right) == pytest.approx(centre, abs=1e-15)
