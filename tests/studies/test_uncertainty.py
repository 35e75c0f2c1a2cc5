"""90 % intervals of the headline temperatures (studies/calibration/intervals.py): the delta method against what the
network says analytically, and its scaling with the covariance."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm

import shakermill as sm
from shakermill.studies.calibration.intervals import HEADLINE, Uncertainty, intervals
from shakermill.studies.inference.posterior import Posterior

Z90 = norm.ppf(0.95)


@pytest.fixture(scope="module", name="full_run")
def full_run_fixture():
    return sm.simulate(sm.default_parameters(record_windows=(), duration=600.0))


@pytest.mark.slow
def test_intervals_hold_the_run_and_scale_with_the_covariance(full_run):
    covariance = np.array([[0.01, 0.002], [0.002, 0.04]])
    one = intervals(full_run, Uncertainty(("beta", "vial_mass"), covariance))
    four = intervals(full_run, Uncertainty(("beta", "vial_mass"), 4.0 * covariance))
    # The steady vial is its rise over its only way out (h_outer, the next test): neither beta nor vial_mass moves it,
    # and the steady state, Newton's root on the network's own Jacobian, says so exactly.
    assert one.bounds("vial_steady_C") == (full_run.summary.value("vial_steady_C"),) * 2
    for key in (key for key in HEADLINE if key != "vial_steady_C"):
        low, high = one.bounds(key)
        assert low < full_run.summary.value(key) < high
        assert high - full_run.summary.value(key) == pytest.approx(
            full_run.summary.value(key) - low, rel=1e-9
        )  # linear: symmetric
        # A full run has no averaging error: the spread is the calibration's alone, linear in its standard deviations.
        assert four.high[key] - four.low[key] == pytest.approx(2.0 * (high - low), rel=1e-9)
    assert one.as_summary().ball_C_high == one.bounds("ball_C")[1]
    assert intervals(full_run, Uncertainty(("beta",))) is None  # nothing uncertain


@pytest.mark.slow
def test_the_steady_vials_error_is_its_rise_times_the_error_of_its_only_way_out(full_run):
    # At steady state all the heat P leaves through h_outer·outer_area: Δθ_vial = P/(h_o·A_o), so d Δθ/d ln h_o = −Δθ.
    found = intervals(full_run, Uncertainty(("h_outer",), np.array([[0.01]])))
    rise = full_run.summary.vial_steady_C - (full_run.params.ambient_temperature - 273.15)
    low, high = found.bounds("vial_steady_C")
    assert (high - low) / 2 == pytest.approx(Z90 * 0.1 * rise, rel=2e-3)


@pytest.mark.slow
def test_the_averaging_error_of_the_heat_widens_the_intervals_in_proportion():
    result = sm.simulate(sm.default_parameters(record_windows=(), solver="averaged"))
    found = intervals(result, Uncertainty(()))
    relative = result.averages.heat_power_stderr / result.averages.heat_power
    rise = result.summary.vial_steady_C - (result.params.ambient_temperature - 273.15)
    # The network is linear in the heat but for Sutherland's factor, which the vial does not see.
    low, high = found.bounds("vial_steady_C")
    assert (high - low) / 2 == pytest.approx(Z90 * relative * rise, rel=2e-3)
    assert found.sources == ("the averaging error of the heat",)


def test_posterior_samples_give_percentile_intervals(full_run):
    # Samples of ln h_outer spread evenly over ±0.2: the steady vial's rise P/(h_o·A_o) spans exp(∓0.2) of its own.
    base = np.log(full_run.params.h_outer)
    samples = base + np.linspace(-0.2, 0.2, 100)[:, None]
    found = intervals(full_run, Uncertainty(("h_outer",), posterior=Posterior.of_logarithms(("h_outer",), samples)))
    rise = full_run.summary.vial_steady_C - (full_run.params.ambient_temperature - 273.15)
    low, high = found.bounds("vial_steady_C")
    ambient = full_run.params.ambient_temperature - 273.15
    assert low - ambient == pytest.approx(rise * np.exp(-np.percentile(samples[:, 0] - base, 95)), rel=2e-3)
    assert high - ambient == pytest.approx(rise * np.exp(-np.percentile(samples[:, 0] - base, 5)), rel=2e-3)
    assert found.sources == ("the calibration's posterior (emcee)",)
