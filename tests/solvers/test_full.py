"""The whole run: energy audit, thermal relaxation, interruption, determinism (MODEL.md §§3, 6, 8)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import shakermill as sm
from shakermill.engines.one_d import model
from shakermill.engines.registry import engine_named
from shakermill.solvers.result import INTERRUPTED, conclude

RESTING_WALL_AMPLITUDE = 1e-12


def test_energy_audit_of_default_run_closes(default_run_20s: sm.Result) -> None:
    audit = default_run_20s.energy
    assert default_run_20s.success
    assert audit.relative_residual < 1e-6
    # The heat bookkeeping closes by construction of the quadratures: check it independently of the mechanics.
    assert abs(audit.thermal_residual) < 1e-9 * audit.heat_generated
    assert audit.heat_generated == pytest.approx(0.9 * audit.dissipated, rel=1e-12)
    assert audit.heat_into["balls"] == pytest.approx(0.368 * audit.heat_generated, rel=1e-12)
    assert set(audit.stored) == {"balls", "vial", "air"}
    assert sum(audit.stored.values()) + audit.heat_lost_to_surroundings == pytest.approx(audit.heat_generated, rel=1e-9)
    # The projection that closes the mechanical part removes the contact truncation error, a few
    # percent of the dissipated energy at ode23's default rtol 1e-3; it must stay that small.
    assert 0.0 < audit.projection_correction < 0.05 * audit.dissipated
    # Impact records add up to the dissipated energy of the run (a contact open at the end is not recorded).
    recorded = default_run_20s.impacts["dissipated_energy"].sum()
    assert recorded == pytest.approx(audit.dissipated, rel=1e-3)


def test_summary_is_consistent_with_the_records(default_run_20s: sm.Result) -> None:
    summary = default_run_20s.summary
    impacts = default_run_20s.impacts
    assert summary.impacts.count == len(impacts)
    assert summary.impacts.rate_hz == pytest.approx(len(impacts) / 20.0)
    assert summary.heat_power_W == pytest.approx(default_run_20s.energy.heat_generated / 20.0)
    assert summary.impacts.mean_speed_m_s == pytest.approx(impacts["impact_speed"].mean())
    assert set(impacts["wall"]) == {"left", "right"}
    assert (impacts["rebound_speed"] > 0).all() and (impacts["duration"] > 0).all()
    last = default_run_20s.timeseries.isel(time=-1)
    assert summary.ball_C == pytest.approx(float(last["theta_ball"]) - 273.15)
    assert summary.ball_C > summary.vial_C > 20.0


def test_time_series_is_sampled_on_the_output_grid(default_run_20s: sm.Result) -> None:
    times = default_run_20s.timeseries["time"].values
    np.testing.assert_allclose(times, np.arange(21.0))
    assert default_run_20s.timeseries["theta_ball"].attrs["units"] == "K"
    # The cumulative heat is non-decreasing and the dense output respects it.
    assert np.all(np.diff(default_run_20s.timeseries["heat_generated"].values) >= 0)


def test_default_tolerance_finds_the_converged_motion_at_90_rad_s() -> None:
    # From rest at the centre, ode23's default rtol once settled here on a motion with 29 impacts/s
    # where the converged one has 42: the contacts were barely error-controlled.
    base = sm.default_parameters(omega=90.0, duration=20.0, record_windows=())
    default = sm.simulate(base).summary
    converged = sm.simulate(base.replace(rtol=1e-6, atol_position=1e-9, atol_momentum=1e-9)).summary
    assert default.impacts.rate_hz == pytest.approx(converged.impacts.rate_hz, rel=0.03)
    assert default.heat_power_W == pytest.approx(converged.heat_power_W, rel=0.01)


def test_runs_are_deterministic() -> None:
    params = sm.default_parameters(duration=3.0, record_windows=((0.0, 0.5),))
    first, second = sm.simulate(params), sm.simulate(params)
    np.testing.assert_array_equal(first.timeseries["theta_ball"].values, second.timeseries["theta_ball"].values)
    np.testing.assert_array_equal(first.windows["x"].values, second.windows["x"].values)
    assert first.impacts.equals(second.impacts)


@pytest.mark.slow
def test_without_motion_the_temperatures_relax_to_ambient() -> None:
    params = sm.default_parameters(
        amplitude=RESTING_WALL_AMPLITUDE,
        initial_temperature=350.0,
        duration=24 * 3600.0,
        output_interval=60.0,
        rtol=1e-5,
        record_windows=(),
    )
    result = sm.simulate(params)
    assert result.success
    assert len(result.impacts) == 0
    final = result.timeseries.isel(time=-1)
    for name in ("theta_ball", "theta_vial", "theta_air"):
        assert float(final[name]) == pytest.approx(params.ambient_temperature, abs=1e-3)
    # Compare the transient with SciPy's stiff solver on the same network (Nu = 2 for a ball at rest).
    k = model.constants_from(params)

    def network(t: float, theta: np.ndarray) -> list[float]:
        rates = model.thermal_network(theta[0], theta[1], theta[2], 0.0, 0.0, k)
        return list(rates[:3])

    reference = solve_ivp(network, (0.0, 1800.0), [350.0] * 3, method="Radau", rtol=1e-10, atol=1e-10)
    at_half_hour = result.timeseries.sel(time=1800.0)
    for index, name in enumerate(("theta_ball", "theta_vial", "theta_air")):
        assert float(at_half_hour[name]) == pytest.approx(reference.y[index, -1], abs=2e-3)


def test_thermal_network_reaches_the_analytic_steady_state() -> None:
    # With a constant heat input Q and the ball at rest (Re = 0, so Nu = 2 whatever Sutherland's factor,
    # and h = k_a/R) the steady state is explicit:
    # all heat leaves through the vial's outer face, and the ball's share crosses ball→air→vial.
    params = sm.default_parameters()
    k = model.constants_from(params)
    heat = 0.5  # W
    h_ball = 2.0 * params.air_conductivity / (2.0 * params.ball_radius)
    vial = params.ambient_temperature + heat / (params.h_outer * params.outer_area)
    air = vial + params.lam * heat / (params.h_inner * params.inner_area)
    ball = air + params.lam * heat / (4 * np.pi * params.ball_radius**2 * params.beta * h_ball)

    def network(t: float, theta: np.ndarray) -> list[float]:
        return list(model.thermal_network(theta[0], theta[1], theta[2], heat, 0.0, k)[:3])

    solution = solve_ivp(network, (0.0, 5e5), [params.initial_temperature] * 3, method="Radau", rtol=1e-10, atol=1e-10)
    theta_ball, theta_vial, theta_air = solution.y[:, -1]
    assert theta_vial == pytest.approx(vial, abs=1e-6)
    assert theta_air == pytest.approx(air, abs=1e-6)
    assert theta_ball == pytest.approx(ball, abs=1e-6)


def test_interrupted_run_keeps_what_was_computed() -> None:
    params = sm.default_parameters(duration=60.0, record_windows=())

    def interrupt_after_twenty_seconds(t: float, duration: float) -> None:
        if t >= 20.0:
            raise KeyboardInterrupt

    result = sm.simulate(params, progress=interrupt_after_twenty_seconds)
    assert result.status == INTERRUPTED and not result.success
    assert "Interrupted" in result.message
    assert result.t_end == pytest.approx(20.0)
    assert result.timeseries["time"].values[-1] == pytest.approx(20.0)
    assert len(result.impacts) > 500
    assert result.energy.relative_residual < 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("solver", ["full", "averaged"])
def test_ball_only_model_holds_air_and_vial_at_ambient(solver: str) -> None:
    params = sm.default_parameters(model="ball_only", solver=solver, duration=1200.0, record_windows=())
    result = sm.simulate(params)
    assert result.success
    np.testing.assert_allclose(result.timeseries["theta_air"].values, params.ambient_temperature, rtol=0, atol=1e-9)
    np.testing.assert_allclose(result.timeseries["theta_vial"].values, params.ambient_temperature, rtol=0, atol=1e-9)
    assert result.summary.ball_C > 30.0
    # Everything the ball does not keep leaves the system.
    audit = result.energy
    assert audit.stored["vial"] == pytest.approx(0.0, abs=1e-9) and audit.stored["air"] == pytest.approx(0.0, abs=1e-9)
    assert audit.relative_residual < 1e-6
    three_node = sm.simulate(params.replace(model="three_node"))
    assert three_node.summary.ball_C > result.summary.ball_C


def test_each_warning_and_note_is_kept_once_however_often_a_run_is_concluded() -> None:
    # 1060 bare is 1060 rad/s, far outside the plausible drive frequencies: a unit-slip warning the run keeps; two
    # seconds are far shorter than the network's time constants: a note.
    result = sm.simulate(sm.default_parameters(duration=2.0, omega=1060.0, record_windows=()))
    assert any("1060" in line for line in result.warnings) and len(result.notes) == 1
    warnings, notes = list(result.warnings), list(result.notes)
    conclude(result, engine_named(result.params.engine).network_for(result.params), result.load)
    assert result.warnings == warnings and result.notes == notes
    assert result.summary.warnings == warnings and result.summary.notes == notes
