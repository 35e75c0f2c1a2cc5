"""Steady state and time constants of the thermal network (MODEL.md section 11)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.analysis.steady import SETTLED_TIME_CONSTANTS, run_length_note, settled_rates, steady_state
from shakermill.engines.registry import engine_named
from shakermill.views.notebook import answer_sentences


def _steady(params, heat, term):
    """The steady state of ``params``' engine's network with ``heat`` (W) from the impacts and the velocity term."""
    engine = engine_named(params.engine)(params, None, np.zeros(1), 0.0)
    return steady_state(engine.network, engine.load(np.array([heat]), np.array([term])))


@pytest.mark.slow
def test_steady_state_of_a_ball_at_rest_matches_the_hand_solution():
    # Re = 0 makes Nu = 2 whatever Sutherland's factor, so the network is linear and explicit:
    # all heat leaves through h_o·A_o, and the ball's share crosses ball → air → vial.
    params = sm.default_parameters()
    heat = 0.5  # W
    h_ball = 2.0 * params.air_conductivity / (2.0 * params.ball_radius)
    vial = params.ambient_temperature + heat / (params.h_outer * params.outer_area)
    air = vial + params.lam * heat / (params.h_inner * params.inner_area)
    ball = air + params.lam * heat / (4 * math.pi * params.ball_radius**2 * params.beta * h_ball)
    steady = _steady(params, heat, 0.0)
    assert steady.solved
    assert (steady.ball, steady.vial, steady.air) == pytest.approx((ball, vial, air), abs=1e-9)


def test_time_constants_are_those_of_the_hand_built_linear_network():
    params = sm.default_parameters()
    h_ball = 2.0 * params.air_conductivity / (2.0 * params.ball_radius)
    g_ball = 4 * math.pi * params.ball_radius**2 * params.beta * h_ball
    g_inner = params.h_inner * params.inner_area
    g_outer = params.h_outer * params.outer_area
    capacities = np.array(
        [
            params.ball_mass * params.ball_heat_capacity,
            params.vial_mass * params.vial_heat_capacity,
            params.air_mass * params.air_heat_capacity,
        ]
    )
    conductances = np.array(
        [
            [-g_ball, 0.0, g_ball],
            [0.0, -g_inner - g_outer, g_inner],
            [g_ball, g_inner, -g_ball - g_inner],
        ]
    )
    expected = sorted(-1.0 / np.linalg.eigvals(conductances / capacities[:, None]).real, reverse=True)
    steady = _steady(params, 0.5, 0.0)
    assert steady.time_constants == pytest.approx(expected, rel=1e-6)


def test_steady_state_with_moving_ball_is_a_root_of_the_nonlinear_network():
    from shakermill.engines.one_d import model

    params = sm.default_parameters()
    steady = _steady(params, 1.2, 30.0)
    rates = model.thermal_network(steady.ball, steady.vial, steady.air, 1.2, 30.0, model.constants_from(params))
    assert np.max(np.abs(rates[:3])) < 1e-10
    # Every watt leaves through the outer surface.
    assert params.h_outer * params.outer_area * (steady.vial - params.ambient_temperature) == pytest.approx(
        1.2, rel=1e-9
    )


def test_ball_only_model_has_vial_and_air_at_ambient():
    params = sm.default_parameters(model="ball_only")
    steady = _steady(params, 0.5, 0.0)
    h_ball = 2.0 * params.air_conductivity / (2.0 * params.ball_radius)
    expected_ball = params.ambient_temperature + params.lam * 0.5 / (
        4 * math.pi * params.ball_radius**2 * params.beta * h_ball
    )
    assert steady.vial == steady.air == params.ambient_temperature
    assert steady.ball == pytest.approx(expected_ball, abs=1e-9)
    assert len(steady.time_constants) == 1


def test_no_outer_cooling_has_no_steady_state():
    steady = _steady(sm.default_parameters(h_outer=0.0), 1.0, 30.0)
    assert not steady.solved
    assert "h_outer = 0" in steady.message
    assert math.isinf(steady.ball)


def test_settled_rates_use_the_second_half_of_the_run():
    times = np.linspace(0.0, 10.0, 11)
    heat = np.where(times < 3.0, 0.0, 2.0 * (times - 3.0))  # 2 W once settled after 3 s
    term = 5.0 * times
    assert float(settled_rates(times, heat)) == pytest.approx(2.0)
    assert settled_rates(times, np.column_stack([heat, term])) == pytest.approx([2.0, 5.0])


@pytest.mark.slow
def test_steady_state_is_where_a_ten_hour_averaged_run_ends():
    params = sm.default_parameters("spex8000m-calibrated", solver="averaged", duration=36000.0, record_windows=())
    result = sm.simulate(params)
    assert result.success, result.message
    last = result.timeseries.isel(time=-1)
    for node in ("ball", "vial", "air"):
        assert float(last[f"theta_{node}"]) - 273.15 == pytest.approx(result.summary.value(f"{node}_steady_C"), abs=0.5)
    # Ten hours are more than three slowest time constants, so no note about the run's length.
    assert not any("slowest time constants" in line for line in result.notes)


@pytest.mark.slow
def test_steady_state_is_where_a_long_full_resolution_run_ends():
    # The default preset's slowest time constant is ~20 min: three hours are nine of them.
    result = sm.simulate(sm.default_parameters(duration=3 * 3600.0, record_windows=()))
    assert result.success, result.message
    last = result.timeseries.isel(time=-1)
    for node in ("ball", "vial", "air"):
        assert float(last[f"theta_{node}"]) - 273.15 == pytest.approx(result.summary.value(f"{node}_steady_C"), abs=0.5)


def test_an_hour_of_the_calibrated_preset_notes_that_its_fit_is_not_the_steady_state():
    result = sm.simulate(sm.default_parameters("spex8000m-calibrated", solver="averaged", record_windows=()))
    slowest = result.summary.slowest_time_constant_min
    assert 60.0 < SETTLED_TIME_CONSTANTS * slowest
    # Advice, not a problem: the steady state is reported beside it, so it is a note of the answer, not a warning.
    lines = [line for line in result.notes if "slowest time constants" in line]
    assert len(lines) == 1
    assert f"{SETTLED_TIME_CONSTANTS:g} x {slowest:.3g} min" in lines[0]
    assert not any("slowest time constants" in line for line in result.warnings)
    assert result.summary.notes == result.notes
    assert lines[0] in answer_sentences(result.summary)


def test_run_length_note_only_for_short_runs():
    steady = _steady(sm.default_parameters(), 1.0, 30.0)
    slowest = steady.slowest_time_constant
    assert run_length_note(2.9 * slowest, steady) is not None
    assert run_length_note(3.1 * slowest, steady) is None


def test_a_charge_of_hundreds_of_balls_is_solved_in_few_evaluations_and_at_minpacks_root(monkeypatch):
    from scipy.optimize import root

    from shakermill.engines.dem.engine import DemEngine
    from shakermill.engines.thermal import kernel
    from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork

    bowl = {"vial_diameter": 0.1, "vial_length": 0.0637, "outer_diameter": 0.12, "outer_length": 0.08}
    params = sm.default_parameters("pulverisette7", n_balls=300, ball_radius=2.5e-3, powder_mass=5e-3, **bowl)
    network = DemEngine.network_for(params)
    rng = np.random.default_rng(3)
    drives = rng.uniform(0.05, 3.0, kernel.drive_count(network.n_balls))
    balls = network.n_balls
    heat = np.zeros(len(network.nodes))
    heat[:balls] = rng.uniform(0.0, 0.05, balls)
    load = NetworkLoad(heat, drives[:balls], float(heat.sum()), float(drives[:balls].mean()), drives[balls:])
    evaluations = []
    rates = ThermalNetwork.rates
    monkeypatch.setattr(ThermalNetwork, "rates", lambda self, *args: evaluations.append(1) or rates(self, *args))
    steady = steady_state(network, load)
    # MINPACK's differences took one evaluation per node and iteration: thousands for 300 balls.
    assert steady.solved and len(evaluations) <= 20
    free = network.free
    minpack = root(
        lambda theta: rates(network, network.with_free(theta), load.heat, drives)[0][free],
        np.full(free.size, network.ambient + 10.0),
        method="hybr",
        tol=1e-12,
    )
    assert minpack.success
    assert np.array(steady.balls) == pytest.approx(minpack.x[: network.n_balls], abs=1e-7)
    assert steady.vial == pytest.approx(minpack.x[network.vial], abs=1e-7)
