"""Named motions of the vial (MODEL.md §12.2; parameters/motions/, found by parameters/kinematic_models.py) and the
presets that use them."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.dem.model import harmonics_of
from shakermill.parameters import kinematic_models as models
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import choices_of, unit_slip_warnings
from shakermill.parameters.motions import MAX_MOTION_HARMONIC, MOTION_COORDINATES
from shakermill.parameters.motions.mixer_mill_arc import MAX_SWING_ANGLE, arc_terms
from shakermill.parameters.presets import PRESETS
from shakermill.physics import kinematics as drive

THETAS = np.linspace(0.0, 2.0 * math.pi, 37)


def _coordinates(harmonics: np.ndarray, t: float, omega: float, phase: float) -> tuple[np.ndarray, np.ndarray]:
    values, rates = np.zeros(6), np.zeros(6)
    drive.fourier_coordinates(t, omega, phase, harmonics, values, rates)
    return values, rates


def test_every_named_motion_is_a_choice_of_the_kinematics_key():
    assert set(choices_of("kinematics")) == set(models.KINEMATIC_MODELS)
    assert {"axial", "fourier", "spex8000m", "mixer-mill-arc", "planetary"} <= set(models.KINEMATIC_MODELS)
    with pytest.raises(ParameterError, match="^kinematics: input should be 'axial' or 'fourier' or "):
        sm.default_parameters(engine="dem", kinematics="orbital")


@pytest.mark.parametrize("t", [0.0, 0.0123, 0.5, 7.77])
def test_the_spex_stroke_is_the_one_dimensional_drive(t):
    params = sm.default_parameters("spex8000m-3d", phase=0.3)
    values, rates = _coordinates(harmonics_of(params), t, params.omega, params.phase)
    assert values[0] == drive.vial_position(t, params.amplitude, params.omega, params.phase)
    assert rates[0] == pytest.approx(drive.vial_velocity(t, params.amplitude, params.omega, params.phase), rel=1e-14)
    # The lateral motion at twice the frequency, the yaw at the drive's, in phase with the stroke.
    theta = params.omega * t + params.phase
    assert values[1] == pytest.approx(params.lateral_amplitude * math.sin(2 * theta), rel=1e-12, abs=1e-18)
    assert values[5] == pytest.approx(params.yaw_amplitude * math.sin(theta), rel=1e-12, abs=1e-18)
    assert values[2:5] == pytest.approx(np.zeros(3), abs=0)


def test_the_spex_motion_without_lateral_motion_and_yaw_is_axial():
    axial = sm.default_parameters(engine="dem")
    figure_of_eight = axial.replace(kinematics="spex8000m", lateral_amplitude=0.0, yaw_amplitude=0.0)
    assert np.array_equal(harmonics_of(figure_of_eight), harmonics_of(axial))


@pytest.mark.parametrize("alpha", [1e-3, 0.1, 0.5, MAX_SWING_ANGLE])
def test_the_arcs_fourier_series_is_its_closed_form(alpha):
    radius = 0.1
    terms = arc_terms(alpha * radius, radius)
    assert max(k for _, k, _, _ in terms) <= MAX_MOTION_HARMONIC
    harmonics = np.zeros((6, MAX_MOTION_HARMONIC + 1, 2))
    for coordinate, k, cosine, sine in terms:
        harmonics[MOTION_COORDINATES.index(coordinate), k] += (cosine, sine)
    for theta in THETAS:
        values, _ = _coordinates(harmonics, theta, 1.0, 0.0)
        swing = alpha * math.sin(theta)
        assert abs(values[0] - radius * math.sin(swing)) <= 1e-12 * radius
        assert abs(values[1] - radius * (1.0 - math.cos(swing))) <= 1e-12 * radius
        assert values[5] == pytest.approx(swing, rel=1e-14, abs=1e-18)


@pytest.mark.parametrize("t", [0.0, 0.004, 0.0123])
def test_the_arc_turns_the_jar_about_a_pivot_at_rest(t):
    """The pivot (0, R, 0) is a point of the rigid jar that does not move: ṙ_v + Ω × (P − r_v) = 0."""
    params = sm.default_parameters("mm400")
    values, rates = _coordinates(harmonics_of(params), t, params.omega, params.phase)
    pivot = np.array([0.0, params.swing_radius, 0.0])
    spin = np.array([0.0, 0.0, rates[5]])
    # The series is truncated at 1e-12 R a term; the rates weigh term k by kω (~2 m/s here).
    assert rates[:3] + np.cross(spin, pivot - values[:3]) == pytest.approx(np.zeros(3), abs=1e-9)
    assert np.linalg.norm(pivot - values[:3]) == pytest.approx(params.swing_radius, rel=1e-12)


def test_the_three_dimensional_spex_preset_is_the_real_vial():
    params = sm.default_parameters("spex8000m-3d")
    assert (params.engine, params.kinematics, params.n_balls) == ("dem", "spex8000m", 1)
    assert (params.vial_diameter, params.vial_length, params.amplitude) == (0.038, 0.058, 0.025)
    bore, length = params.vial_diameter, params.vial_length
    assert params.inner_area == pytest.approx(math.pi * bore * length + math.pi * bore**2 / 2, rel=1e-12)
    steel = math.pi / 4 * (0.050**2 * 0.070 - bore**2 * length)
    assert params.vial_mass == pytest.approx(params.vial_density * steel, rel=1e-12)
    assert sm.default_parameters("spex8000m-3d", n_balls=5).n_balls == 5


def test_the_mixer_mill_preset_shakes_at_30_hz_and_accepts_3_hz():
    params = sm.default_parameters("mm400")
    assert params.omega == pytest.approx(2 * math.pi * 30.0, rel=1e-12)
    assert (params.engine, params.kinematics) == ("dem", "mixer-mill-arc")
    assert unit_slip_warnings(params.replace(omega="3 Hz")) == []


@pytest.mark.parametrize("name", ["spex8000m-3d", "mm400"])
def test_every_value_a_preset_sets_names_its_source(name):
    preset = PRESETS[name]
    base = PRESETS["spex8000m"].values
    for key, cited in preset.values.items():
        if cited != base[key]:
            assert not cited.source.startswith("set in"), key


@pytest.mark.parametrize(
    "overrides, fragments",
    [
        ({"kinematics": "spex8000m", "lateral_amplitude": "-1 mm"}, ("lateral_amplitude:", "allowed [0, 0.5] m")),
        ({"kinematics": "spex8000m", "yaw_amplitude": "100 deg"}, ("yaw_amplitude:", "allowed [0, 1.570796] rad")),
        ({"kinematics": "mixer-mill-arc", "swing_radius": 0}, ("swing_radius:", "allowed [0.001, 1] m")),
        ({"kinematics": "mixer-mill-arc", "swing_radius": "10 mm"}, ("amplitude:", "swing_radius·π/2 = 0.01571 m")),
        ({"kinematics": "figure8"}, ("kinematics:", "'mixer-mill-arc', 'planetary', 'spex8000m'")),
        ({"engine": "1d", "kinematics": "spex8000m"}, ("kinematics:", "allowed 'axial' with engine = '1d'")),
    ],
)
def test_bad_kinematic_values_are_refused_in_one_line(overrides, fragments):
    with pytest.raises(ParameterError) as caught:
        sm.default_parameters(**{"engine": "dem", **overrides})
    message = str(caught.value)
    assert "\n" not in message
    assert all(fragment in message for fragment in fragments), message
