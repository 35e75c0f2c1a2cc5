"""The 'dem' engine's two solvers against each other, and the averaged one's refusals (MODEL.md §§11-12)."""

from __future__ import annotations

import numpy as np
import pytest

import shakermill as sm
from shakermill.solvers.result import BALL_TEMPERATURES

# Five balls knock each other off the vial's bottom: far fewer contact steps a second than one or two
# resting there (benchmarks/README.md), so the fastest several-ball case to test with.
BALLS = {"engine": "dem", "n_balls": 5, "vial_diameter": "38 mm", "record_windows": ()}


@pytest.fixture(name="pair", scope="module")
def pair_fixture():
    """The same 20 s of five balls, at full resolution and averaged (mechanics until ±2 % per ball, in batches of
    8 periods so that the least mechanics, 40 batches, fit in the run)."""
    full = sm.simulate(sm.default_parameters(**BALLS, duration=20.0))
    averaged = sm.simulate(
        sm.default_parameters(
            **BALLS, duration=20.0, solver="averaged", dem_averaging_rel_error=0.02, averaging_batch_periods=8
        )
    )
    return full, averaged


@pytest.mark.slow
def test_the_averaged_solver_heats_as_the_full_one(pair):
    full, averaged = pair
    assert full.success and averaged.success and averaged.solver == "averaged"
    assert averaged.averages.converged
    rise = lambda result, name: result.history[name][-1] - result.params.initial_temperature  # noqa: E731
    for name in ("theta_ball", "theta_vial", "theta_air"):
        assert rise(averaged, name) == pytest.approx(rise(full, name), rel=0.05), name
    assert averaged.summary.heat_power_W == pytest.approx(full.summary.heat_power_W, rel=0.05)
    # The averaged run splits its heat by channel as the contacts of its averaging window did.
    for channel in ("normal", "sliding"):
        key = f"heat_{channel}_W"
        assert averaged.summary.value(key) == pytest.approx(full.summary.value(key), rel=0.15), key


@pytest.mark.slow
def test_both_solvers_give_each_ball_its_own_temperature_and_a_steady_state(pair):
    for result in pair:
        temperatures = result.history[BALL_TEMPERATURES]
        assert temperatures.shape == (result.history.times.size, 5)
        assert np.allclose(temperatures.mean(axis=1), result.history["theta_ball"])
        assert len(result.summary.steady.each_ball_C) == 5
        assert result.steady.solved and len(result.steady.time_constants) == 7  # five balls, vial, air
        assert result.summary.ball_steady_C == pytest.approx(np.mean(result.summary.steady.each_ball_C))


@pytest.mark.slow
def test_the_averaged_solver_falls_back_when_the_means_do_not_converge():
    # Batches of one period make the least mechanics (8 periods, 0.45 s) shorter than the run, so averaging is tried.
    params = sm.default_parameters(
        **BALLS,
        duration=3.0,
        solver="averaged",
        dem_averaging_rel_error=1e-6,
        averaging_max_time=2.0,
        averaging_batch_periods=1,
        averaging_min_batches=4,
    )
    result = sm.simulate(params)
    assert result.success
    assert result.solver == "full" and result.t_end == 3.0
    fell_back = "Averaging is not valid (the averages did not converge"
    assert result.message.startswith(fell_back)
    assert "(dem_averaging_rel_error)" in result.message and "averaging_max_time = 2 s" in result.message
    # A fall-back is a warning, said once.
    assert [line for line in result.warnings if line.startswith(fell_back)] == [result.warnings[0]]
    failed = sm.simulate(params.replace(averaging_fallback="fail"))
    assert not failed.success and "averaging_fallback" in failed.message
