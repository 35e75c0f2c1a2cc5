"""Keys of the 'dem' engine (MODEL.md section 12): per-ball values, the vial's motion as data, placement."""

from __future__ import annotations

import numpy as np
import pytest

import shakermill as sm
from shakermill.parameters.config import load_config, write_config_toml
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.packing import placement

FIVE = {"engine": "dem", "n_balls": 5, "vial_diameter": "38 mm"}


def test_the_one_dimensional_engine_stays_the_default():
    params = sm.default_parameters()
    assert (params.engine, params.n_balls, params.kinematics) == ("1d", 1, "axial")
    assert not params.relative_convection  # the paper's lab-frame Re for one ball on the axis
    assert sm.default_parameters(engine="dem").relative_convection  # MODEL.md §12.5: air moves with the vial


def test_per_ball_values_come_from_lists_or_the_scalar_key():
    params = sm.default_parameters(**FIVE, ball_radii="6 mm, 5 mm, 5 mm, 4 mm, 3 mm")
    assert params.ball_values("ball_radius") == pytest.approx((6e-3, 5e-3, 5e-3, 4e-3, 3e-3))
    assert params.ball_values("ball_density") == (7800.0,) * 5
    toml_list = sm.default_parameters(**FIVE, ball_densities=[7800, 7800, 6000, 6000, 3900])
    assert toml_list.ball_values("ball_density") == (7800.0, 7800.0, 6000.0, 6000.0, 3900.0)


def test_the_air_makes_room_for_every_ball():
    params = sm.default_parameters(**FIVE)
    vial = np.pi / 4 * 0.038**2 * 0.058
    balls = 5 * 4 / 3 * np.pi * params.ball_radius**3
    assert params.air_mass == pytest.approx(params.air_density * (vial - balls), rel=1e-12)


def test_motion_terms_from_the_command_line_carry_units():
    params = sm.default_parameters(engine="dem", kinematics="fourier", motion="x:1:0:25 mm, yaw:2:5 deg:0")
    assert params.motion == (("x", 1, 0.0, 0.025), ("yaw", 2, pytest.approx(np.radians(5.0)), 0.0))


def test_a_configuration_with_lists_and_motion_round_trips(tmp_path):
    params = sm.default_parameters(
        engine="dem",
        n_balls=2,
        vial_diameter="38 mm",
        ball_radii="6 mm, 4 mm",
        kinematics="fourier",
        motion="x:1:0:25 mm, pitch:2:0.05:0",
    )
    path = tmp_path / "config.toml"
    write_config_toml(params, path, preset="spex8000m")
    assert load_config(path).params == params


@pytest.mark.parametrize(
    "overrides, fragments",
    [
        ({"n_balls": 2}, ("n_balls:", "engine = 'dem'")),
        ({"engine": "dem", "n_balls": 2, "vial_diameter": "38 mm", "ball_radii": "6 mm"}, ("ball_radii:", "exactly 2")),
        ({"engine": "dem", "ball_radii": "9.5 mm"}, ("ball_radii:", "vial_diameter/2")),
        ({"engine": "dem", "kinematics": "fourier", "motion": "roll:1:4:0"}, ("motion:", "at most 3.14159 rad")),
        ({"engine": "dem", "n_balls": 40, "vial_diameter": "38 mm"}, ("n_balls:", "do not fit")),
    ],
)
def test_bad_several_ball_input_is_refused_in_one_line(overrides, fragments):
    with pytest.raises(ParameterError) as caught:
        sm.default_parameters(**overrides)
    message = str(caught.value)
    assert "\n" not in message
    assert all(fragment in message for fragment in fragments), message


@pytest.mark.slow
@pytest.mark.parametrize("count, radius, diameter", [(5, 6.35e-3, 38e-3), (20, 4e-3, 38e-3), (12, 3e-3, 19e-3)])
def test_placed_balls_lie_inside_the_vial_and_apart(count, radius, diameter):
    radii = np.full(count, radius)
    centres = placement(radii, 58e-3, diameter)
    assert centres is not None
    assert np.all(np.abs(centres[:, 0]) < 29e-3 - radius)
    assert np.all(np.hypot(centres[:, 1], centres[:, 2]) < diameter / 2 - radius)
    distance = np.linalg.norm(centres[:, None] - centres[None], axis=2) + np.eye(count)
    assert distance.min() > 2 * radius
    # Bottom layer first: the lowest balls rest near the bore's bottom line.
    assert centres[0, 2] == pytest.approx(centres[:, 2].min())
    assert np.array_equal(centres, placement(radii, 58e-3, diameter))


def test_five_half_inch_balls_do_not_fit_the_papers_bore_side_by_side():
    assert placement(np.full(5, 6.35e-3), 58e-3, 19e-3) is None
