"""What an impact is (MODEL.md §14.4, analysis/impacts.py): records of one pair merged within twice the Hertz duration
of their approach, touches slower than the touch speed, lasting contacts over 1 ms, each counted by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.analysis.impacts import contacts_of
from shakermill.engines.dem.engine import DemEngine, hertz_scales
from shakermill.engines.records import HERTZ_SCALE
from shakermill.physics import contact

# A Hertz duration of 50 µs at 1 m/s: at the touch speed 0.1 m/s it is 50·0.1^(-1/5) = 79.2 µs, twice that 158.5 µs.
SCALE = 50e-6
REACH_AT_TOUCH = 2 * SCALE * 0.1**-0.2


def records(*rows: tuple[float, float, int, str, int, float]) -> dict[str, np.ndarray]:
    """Records (start s, duration s, ball, target, other ball, approach m/s), each dissipating 1 mJ normally."""
    time, duration, ball, target, other, speed = (np.array(column) for column in zip(*rows, strict=True))
    size = time.size
    return {
        "time": time,
        "duration": duration,
        "ball": ball,
        "target": target,
        "other_ball": other,
        "impact_speed": speed,
        "dissipated_energy": np.full(size, 1e-3),
        "dissipated_normal": np.full(size, 1e-3),
        "peak_force": np.arange(1.0, size + 1.0),
        HERTZ_SCALE: np.full(size, SCALE),
    }


def test_a_pair_that_parts_and_touches_again_within_twice_the_hertz_duration_is_one_lasting_contact():
    """Ball 0 on the side wall: chatter 100 µs after a 0.05-m/s touch (within 158.5 µs) merges, 200 µs after does not;
    ball 1 touching the same wall at the same moment is another pair."""
    gap, late = 100e-6, 200e-6
    chatter = records(
        (0.0, 20e-6, 0, "side", -1, 0.05),
        (20e-6 + gap, 20e-6, 0, "side", -1, 0.01),
        (40e-6 + gap + late, 30e-6, 0, "side", -1, 0.02),
        (30e-6, 20e-6, 1, "side", -1, 0.3),
    )
    assert gap < REACH_AT_TOUCH < late
    contacts = contacts_of(chatter, touch_speed=0.1, chatter_factor=2.0)
    assert list(contacts.records) == [2, 1, 1]  # in time order: ball 0's merged pair, ball 1's, ball 0's third
    merged = contacts.columns
    assert merged["duration"][0] == pytest.approx(40e-6 + gap)
    assert merged["dissipated_energy"][0] == pytest.approx(2e-3) and merged["peak_force"][0] == 2.0
    assert merged["impact_speed"][0] == 0.05  # its approach is its first record's
    assert list(contacts.touch) == [True, False, True] and contacts.impact_count == 1 and contacts.record_count == 4


def test_a_fast_approach_merges_only_within_its_own_shorter_hertz_duration():
    """At 5 m/s the Hertz duration is 50·5^(-1/5) = 36.2 µs: a record 100 µs after is a new impact (a rebound and a
    second hit), which the touch speed's longer reach would have merged."""
    fast = records((0.0, 30e-6, 0, "left", -1, 5.0), (130e-6, 30e-6, 0, "left", -1, 2.0))
    assert 2 * SCALE * 5.0**-0.2 < 100e-6 < REACH_AT_TOUCH
    contacts = contacts_of(fast, touch_speed=0.1, chatter_factor=2.0)
    assert list(contacts.records) == [1, 1] and contacts.impact_count == 2


def test_two_balls_and_a_ball_and_the_wall_are_different_pairs():
    """Ball 0 on ball 1, then ball 0 on the wall and ball 1 on ball 0 again, each within reach of the one before."""
    pairs = records(
        (0.0, 10e-6, 0, "ball", 1, 1.0),
        (20e-6, 10e-6, 0, "left", -1, 1.0),
        (40e-6, 10e-6, 0, "ball", 1, 0.5),
        (60e-6, 10e-6, 0, "right", -1, 1.0),
    )
    contacts = contacts_of(pairs, touch_speed=0.1, chatter_factor=2.0)
    assert list(contacts.records) == [2, 1, 1]
    assert list(contacts.columns["target"]) == ["ball", "left", "right"]


def test_a_contact_that_lasts_over_a_millisecond_is_lasting_and_an_impact_if_it_began_fast():
    """A ball thrown onto the wall at 2 m/s that then rolls on it for 5 ms was an impact, and lasts; a ball that
    settles at 0.02 m/s and rests 5 ms is a lasting touch."""
    rolling = records((0.0, 5e-3, 0, "side", -1, 2.0), (0.0, 5e-3, 1, "side", -1, 0.02))
    contacts = contacts_of(rolling, touch_speed=0.1, chatter_factor=2.0)
    assert list(contacts.lasting) == [True, True] and list(contacts.touch) == [False, True]
    assert contacts.impact_count == 1


def test_without_a_chatter_factor_or_a_touch_speed_every_record_is_an_impact():
    """The 1-D engine's rules (solvers/result.py, counting_rules): its records are its impacts."""
    chatter = records((0.0, 20e-6, 0, "side", -1, 0.05), (30e-6, 20e-6, 0, "side", -1, 0.01))
    contacts = contacts_of(chatter)
    assert contacts.impact_count == 2 and list(contacts.records) == [1, 1]
    without_hertz = {name: values for name, values in chatter.items() if name != HERTZ_SCALE}
    assert contacts_of(without_hertz, touch_speed=0.1, chatter_factor=2.0).touch_count == 2


def test_the_engines_hertz_duration_of_each_pair_is_the_hertz_contact_time_at_one_metre_a_second():
    """Ball–ball (m*, R* of the pair), ball on an end face (R) and on the bore (the concave R*), by MODEL.md §12.3."""
    params = sm.default_parameters("pulverisette7", engine="dem", n_balls=2, record_windows=())
    k = DemEngine(params).constants
    scales = hertz_scales(np.array([0, 0, 1]), np.array([1, -1, -1]), np.array(["ball", "left", "side"]), k)
    mass, radius, youngs, poisson = k.mass[0], k.radius[0], k.youngs_modulus[0], k.poisson_ratio[0]
    pair_modulus = contact.effective_modulus(youngs, poisson, youngs, poisson)
    bore = contact.concave_radius(radius, k.bore_radius)
    expected = [
        contact.hertz_contact_time(mass / 2, radius / 2, pair_modulus, 1.0),
        contact.hertz_contact_time(mass, radius, k.wall_modulus[0], 1.0),
        contact.hertz_contact_time(mass, bore, k.wall_modulus[1], 1.0),
    ]
    np.testing.assert_allclose(scales, expected, rtol=1e-12)
    assert scales[0] != pytest.approx(scales[1], rel=1e-3) and math.isfinite(scales[2])
