"""Prescribed vial motion against MODEL.md §1, with hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

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


# The vial as a rigid body (MODEL.md §12.2): Fourier data for its six coordinates.


def _harmonics(terms: dict[tuple[int, int], tuple[float, float]], highest: int = 2) -> np.ndarray:
    harmonics = np.zeros((6, highest + 1, 2))
    for (coordinate, k), (cosine, sine) in terms.items():
        harmonics[coordinate, k] = (cosine, sine)
    return harmonics


def test_fourier_coordinates_hand_values() -> None:
    # x = 25 mm sin θ; yaw = 0.1 cos 2θ + 0.05 (harmonic 0); θ = ωt + φ = 111·0.01 + 0.3 = 1.41 rad.
    harmonics = _harmonics({(0, 1): (0.0, 25e-3), (5, 2): (0.1, 0.0), (5, 0): (0.05, 0.0)})
    values, rates = np.zeros(6), np.zeros(6)
    drive.fourier_coordinates(0.01, OMEGA, 0.3, harmonics, values, rates)
    theta = 1.41
    assert values[0] == pytest.approx(25e-3 * math.sin(theta), rel=1e-12)
    assert rates[0] == pytest.approx(OMEGA * 25e-3 * math.cos(theta), rel=1e-12)
    assert values[5] == pytest.approx(0.05 + 0.1 * math.cos(2 * theta), rel=1e-12)
    assert rates[5] == pytest.approx(-2 * OMEGA * 0.1 * math.sin(2 * theta), rel=1e-12)
    assert values[1:5] == pytest.approx(np.zeros(4), abs=0) and rates[1:5] == pytest.approx(np.zeros(4), abs=0)


def test_axial_fourier_data_is_the_one_dimensional_drive() -> None:
    harmonics = _harmonics({(0, 1): (0.0, AMPLITUDE)}, highest=1)
    values, rates = np.zeros(6), np.zeros(6)
    for t in (0.0, 0.0123, 0.5):
        drive.fourier_coordinates(t, OMEGA, 0.2, harmonics, values, rates)
        assert values[0] == drive.vial_position(t, AMPLITUDE, OMEGA, 0.2)
        assert rates[0] == pytest.approx(drive.vial_velocity(t, AMPLITUDE, OMEGA, 0.2), rel=1e-14)


@pytest.mark.parametrize("angles", [(0.3, -0.2, 1.1), (0.0, 0.0, 0.7), (-1.0, 0.4, 0.0)])
def test_rotation_matrix_is_extrinsic_x_then_y_then_z(angles) -> None:
    roll, pitch, yaw = angles
    matrix = np.empty((3, 3))
    drive.rotation_matrix(roll, pitch, yaw, matrix)
    expected = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_matrix()  # extrinsic: R_z·R_y·R_x
    assert matrix == pytest.approx(expected, abs=1e-14)
    assert matrix @ matrix.T == pytest.approx(np.eye(3), abs=1e-14)


def test_angular_velocity_is_that_of_the_rotating_matrix() -> None:
    """Ω× = Q̇·Qᵀ, Q̇ by central differences of the angles moving at the given rates."""
    angles = np.array([0.3, -0.2, 1.1])
    rates = np.array([2.0, -1.5, 0.7])
    h = 1e-6
    ahead, behind, now = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3))
    drive.rotation_matrix(*(angles + h * rates), ahead)
    drive.rotation_matrix(*(angles - h * rates), behind)
    drive.rotation_matrix(*angles, now)
    skew = (ahead - behind) / (2 * h) @ now.T
    omega = np.empty(3)
    drive.angular_velocity(angles[1], angles[2], *rates, omega)
    assert omega == pytest.approx([skew[2, 1], skew[0, 2], skew[1, 0]], rel=1e-8)


# Every named motion (parameters/kinematic_models.py): the rates the engine uses are the derivatives of
# the positions and orientations it uses.
NAMED_MOTIONS = {
    "axial": {},
    "fourier": {"motion": "x:1:0:25 mm, y:2:3 mm:1 mm, yaw:1:0.05:0.1, pitch:3:0:0.02, roll:2:0.01:0, z:0:1 mm:0"},
    "spex8000m": {"yaw_amplitude": "10 deg"},
    "mixer-mill-arc": {"amplitude": "10 mm", "swing_radius": "100 mm"},
}


def _pose(harmonics: np.ndarray, t: float, phase: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre, orientation Q and coordinate rates of the vial at ``t``."""
    values, rates, matrix = np.zeros(6), np.zeros(6), np.empty((3, 3))
    drive.fourier_coordinates(t, OMEGA, phase, harmonics, values, rates)
    drive.rotation_matrix(values[3], values[4], values[5], matrix)
    return values, matrix, rates


@pytest.mark.parametrize("kinematics", sorted(NAMED_MOTIONS))
@pytest.mark.parametrize("t", [0.0, 0.0123, 0.05])
def test_each_named_motion_moves_at_the_rates_it_prescribes(kinematics, t):
    """Coordinates' rates against central differences, and Ω against Q̇·Qᵀ = skew(Ω)."""
    import shakermill as sm
    from shakermill.engines.dem.model import harmonics_of

    params = sm.default_parameters(engine="dem", kinematics=kinematics, phase=0.4, **NAMED_MOTIONS[kinematics])
    harmonics = harmonics_of(params)
    h = 1e-7
    ahead, q_ahead, _ = _pose(harmonics, t + h, 0.4)
    behind, q_behind, _ = _pose(harmonics, t - h, 0.4)
    values, q_now, rates = _pose(harmonics, t, 0.4)
    assert rates == pytest.approx((ahead - behind) / (2 * h), rel=1e-6, abs=1e-9)
    skew = (q_ahead - q_behind) / (2 * h) @ q_now.T
    omega = np.empty(3)
    drive.angular_velocity(values[4], values[5], rates[3], rates[4], rates[5], omega)
    assert omega == pytest.approx([skew[2, 1], skew[0, 2], skew[1, 0]], rel=1e-6, abs=1e-9)
    assert skew == pytest.approx(-skew.T, abs=1e-8)
