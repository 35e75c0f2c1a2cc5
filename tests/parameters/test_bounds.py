"""Bounds with a relative tolerance, printed so that they never contradict the value they refuse (issue 25)."""

from __future__ import annotations

import math

import pytest

from shakermill.parameters.bounds import RELATIVE_TOLERANCE, Bounds, number
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import bounds, build_parameters
from shakermill.parameters.presets import preset_values


def test_a_documented_bound_written_with_a_unit_is_that_bound():
    # 25 um reaches SI as 2.4999999999999998e-05, one rounding step below the bound.
    assert build_parameters(preset_values("spex8000m"), {"ball_radius": "25um"}).ball_radius == 2.5e-05
    assert (
        build_parameters(preset_values("spex8000m"), {"ball_radius": "25 um"}).ball_radius == bounds("ball_radius").low
    )


def test_a_value_beyond_the_tolerance_is_still_refused():
    with pytest.raises(
        ParameterError, match=r"^ball_radius: 2\.4989999999999996e-05 is out of range; allowed \[2\.5e-05"
    ):
        build_parameters(preset_values("spex8000m"), {"ball_radius": "24.99 um"})


def test_only_closed_finite_bounds_attract_values_within_the_tolerance():
    closed = Bounds(0.0, 1.0, low_open=False, high_open=False)
    assert closed.snapped(1.0 + 0.5 * RELATIVE_TOLERANCE) == 1.0
    assert closed.snapped(1.0 + 2 * RELATIVE_TOLERANCE) == 1.0 + 2 * RELATIVE_TOLERANCE
    assert closed.snapped(-1e-300) == -1e-300  # no relative tolerance about zero
    assert Bounds(0.0, 1.0, low_open=False, high_open=True).snapped(1.0 + 1e-12) == 1.0 + 1e-12
    assert Bounds(0.0, math.inf, low_open=False, high_open=True).snapped(1e308) == 1e308


def test_per_ball_values_snap_onto_their_bound_too():
    values = {**preset_values("spex8000m"), "engine": "dem", "n_balls": 2}
    assert build_parameters(values, {"ball_radii": "25um, 3mm"}).ball_radii == (2.5e-05, 0.003)


def test_a_bound_is_printed_in_as_many_digits_as_tell_it_from_the_value():
    assert number(math.pi / 2, 1.5708) == "1.570796"
    assert number(math.pi / 2) == "1.5708"
    assert number(0.1, 0.1) == "0.1"
    assert Bounds(0.0, math.pi / 2, low_open=False, high_open=False).shown(1.5708) == "[0, 1.570796]"
    with pytest.raises(ParameterError, match=r"^yaw_amplitude: 1\.5708 is out of range; allowed \[0, 1\.570796\] rad$"):
        build_parameters(preset_values("spex8000m"), {"yaw_amplitude": 1.5708})
    # A closed bound is printed in as many digits as are accepted as written: 6.28319 lies beyond 2π, 6.283185 inside.
    with pytest.raises(ParameterError, match=r"allowed \[-6\.283185, 6\.283185\] rad$"):
        build_parameters(preset_values("spex8000m"), {"phase": 6.2832})
    with pytest.raises(
        ParameterError, match=r"^phase: 6\.28319 is out of range; allowed \[-6\.283185, 6\.283185\] rad$"
    ):
        build_parameters(preset_values("spex8000m"), {"phase": 6.28319})


@pytest.mark.parametrize("key", ["jar_tilt", "phase", "yaw_amplitude", "contact_step_fraction", "vial_length", "omega"])
def test_every_printed_closed_bound_is_accepted_as_written(key):
    """Issue 35: `keys` printed jar_tilt <= 1.0472, and 1.0472 was refused (the bound is π/3 = 1.047198...)."""
    from shakermill.parameters.keys import bounds

    limits = bounds(key)
    shown = limits.shown()[1:-1].split(", ")
    for text, bound, is_open in zip(shown, (limits.low, limits.high), (limits.low_open, limits.high_open)):
        if not is_open and math.isfinite(bound):
            assert limits.contains(limits.snapped(float(text))), (key, text)
