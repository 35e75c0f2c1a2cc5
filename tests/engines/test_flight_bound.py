"""The 'dem' engine's flight step (engines/dem/stepper.py, MODEL.md §12.6): the longest step in which no contact can
begin. A pair's gap closes at most at its rate along the line of centres and the relative acceleration (the
distance is at least its projection on the present line), so balls moving past each other do not shorten it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.dem.contacts import measure_wall_gaps
from shakermill.engines.dem.engine import DemEngine
from shakermill.engines.dem.stepper import _flight_step, _time_to_close, vial_frame


@pytest.mark.parametrize(
    ("gap", "speed", "acceleration", "expected"),
    [
        (1e-6, 0.1, 0.0, 1e-5),  # gap / speed
        (1e-6, -0.1, 0.0, math.inf),  # opening, nothing pushes
        (1e-6, 0.0, 1000.0, math.sqrt(2e-6 / 1000.0)),  # from rest: ½·a·t² = gap
        (1e-6, 0.1, 1000.0, (math.sqrt(0.01 + 2e-3) - 0.1) / 1000.0),
        (1e-6, -0.1, 1000.0, (math.sqrt(0.01 + 2e-3) + 0.1) / 1000.0),  # opening first, then pushed back
        (-1e-9, 1.0, 0.0, 0.0),  # already touching
    ],
)
def test_time_to_close_by_hand(gap, speed, acceleration, expected):
    assert _time_to_close(gap, speed, acceleration) == pytest.approx(expected, rel=1e-12)


def test_no_pair_touches_within_its_bound_whatever_pushes_it():
    """Sampled pairs of Ø10-mm balls a micrometre or less apart, moving at up to 1 m/s in any direction, each pushed
    within the bound by a constant acceleration aimed to close the gap soonest (along the line of centres, towards
    each other) or at random: the gap stays open up to the bound."""
    rng = np.random.default_rng(7)
    radius_sum = 0.01
    for _ in range(2000):
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        gap = 10 ** rng.uniform(-9, -6)
        centres = (radius_sum + gap) * direction
        velocity = rng.uniform(-1.0, 1.0, size=3)
        bound_on_push = 10 ** rng.uniform(0, 4)
        closing = -float(np.dot(direction, velocity))
        bound = _time_to_close(gap, closing, bound_on_push)
        for push in (-bound_on_push * direction, bound_on_push * rng.uniform(-1, 1, size=3) / math.sqrt(3)):
            times = np.linspace(0.0, min(bound, 1.0), 200)
            separation = centres + np.outer(times, velocity) + 0.5 * np.outer(times**2, push)
            assert np.all(np.linalg.norm(separation, axis=1) - radius_sum >= -1e-15 * radius_sum)


def test_balls_rolling_past_each_other_do_not_shorten_the_flight_step():
    """Two balls 0.1 µm apart moving across their line of centres at 0.3 m/s (as in a planetary pack): the former
    bound, the gap over their relative speed, would allow 0.33 µs; nothing closes the gap along the line, so the
    step is the walls' or the longest flight step."""
    params = sm.default_parameters("spex8000m-3d", n_balls=2, gravity=False, record_windows=())
    engine = DemEngine(params)
    k, s, w = engine.constants, engine.state, engine.scratch
    vial_frame(0.0, k, w)
    centre = w.coordinates[:3]
    gap = 1e-7
    s.position[0] = centre + np.array([0.0, -(k.radius[0] + gap / 2), 0.0])
    s.position[1] = centre + np.array([0.0, k.radius[1] + gap / 2, 0.0])
    s.velocity[0] = w.rates[:3] + np.array([0.15, 0.0, 0.0])
    s.velocity[1] = w.rates[:3] - np.array([0.15, 0.0, 0.0])
    s.force[:] = 0.0
    measure_wall_gaps(k, s, w)  # the stepping keeps them from each step's contacts
    assert not s.contacts.active.any()
    step = _flight_step(math.inf, k, s, w)
    assert step > 100 * gap / 0.3
    # The same pair approaching along its line at 0.3 m/s: the gap over the closing speed, to the contact step.
    s.velocity[0] = w.rates[:3] + np.array([0.0, 0.15, 0.0])
    s.velocity[1] = w.rates[:3] - np.array([0.0, 0.15, 0.0])
    assert _flight_step(math.inf, k, s, w) == pytest.approx(max(gap / 0.3, k.contact_step), rel=1e-9)
