"""Runs that differ in the thermal network alone share the 'dem' engine's mechanics
(solvers.simulate.thermal_variants)."""

from __future__ import annotations

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.dem.engine import DemEngine
from shakermill.parameters.defaults import FAST_IMPACT_SPEED, HIT_SPEED
from shakermill.parameters.errors import ParameterError
from shakermill.solvers.averaged import settle_mechanics, simulate_averaged
from shakermill.solvers.simulate import thermal_variants
from shakermill.studies.calibration.calibrate import calibrate

# Five balls knock each other off the bottom of a wide bore (the cheapest several-ball case) and their means
# settle to ±3 % in a few seconds of mechanics.
BALLS = {
    "engine": "dem",
    "n_balls": 5,
    "vial_diameter": "38 mm",
    "record_windows": (),
    "solver": "averaged",
    "dem_averaging_rel_error": 0.03,
    "duration": 600.0,
}
VARIANT = {"h_outer": 20.0, "vial_mass": 0.3, "beta": 1.5, "outer_area": 0.01}


@pytest.fixture(name="base", scope="module")
def base_fixture():
    return sm.default_parameters(**BALLS)


@pytest.mark.slow
def test_a_thermal_variant_is_the_run_it_would_be_on_its_own(base):
    variant = base.replace(**VARIANT)
    run = thermal_variants(base)
    shared = run(variant)
    alone = sm.simulate(variant)
    assert shared.success and alone.success and shared.averages.converged
    # The mechanics are deterministic, so the reused means are the very numbers a fresh run measures.
    assert shared.summary.heat_power_W == alone.summary.heat_power_W
    for name in ("theta_ball", "theta_vial", "theta_air"):
        np.testing.assert_allclose(shared.history[name], alone.history[name], rtol=1e-12)
    assert shared.summary.vial_C != run(base).summary.vial_C  # the variant did change the network


@pytest.mark.slow
def test_mechanics_measured_for_other_mechanical_keys_are_refused(base):
    mechanics = settle_mechanics(base.replace(averaging_max_time=0.2), DemEngine)
    measured = mechanics.params
    assert mechanics.serves(measured.replace(h_outer=10.0)) and not mechanics.serves(measured.replace(lam=0.5))
    # The room's temperature sets the air's viscosity in the Reynolds number of the measured Whitaker term.
    assert not mechanics.serves(measured.replace(ambient_temperature=measured.ambient_temperature + 10.0))
    with pytest.raises(ValueError, match="thermal-only keys"):
        simulate_averaged(measured.replace(restitution=0.8), DemEngine, None, None, mechanics)


def test_a_dem_calibration_frees_only_thermal_keys(base):
    with pytest.raises(
        ParameterError,
        match=r"^free: lam would change the dem engine's mechanics.*allowed for engine = 'dem': .*h_inner",
    ):
        calibrate(base, ("beta", "lam"))


@pytest.mark.slow
def test_hits_are_the_impacts_at_or_above_the_hit_speed_among_contacts_whose_chatter_is_merged(base):
    """MODEL.md §14.4: the records' chatter merged, touches (slower than touch_speed, 0.1 m/s = HIT_SPEED) left out."""
    result = sm.simulate(base.replace(solver="full", duration=2.0))
    contacts = result.contacts()
    speeds = np.asarray(contacts.columns["impact_speed"])
    hits = speeds[speeds >= HIT_SPEED]
    assert 0 < hits.size < speeds.size  # resting balls touch; flying ones hit
    assert contacts.record_count == result.impact_columns["time"].size > speeds.size  # chatter merged
    impacts = result.summary.impacts
    assert impacts.hit_rate_hz == pytest.approx(hits.size / 2.0) == impacts.rate_hz
    assert impacts.mean_hit_speed_m_s == pytest.approx(hits.mean())
    fast = speeds[speeds >= FAST_IMPACT_SPEED]
    assert 0 < fast.size < hits.size
    assert impacts.fast_rate_hz == pytest.approx(fast.size / 2.0)
    assert impacts.touches_hz == pytest.approx((speeds.size - hits.size) / 2.0)
    assert impacts.records_hz == pytest.approx(contacts.record_count / 2.0)
