"""The run's budget (max_wall_time, max_steps), the compiled loop's pauses, and results that cannot be trusted."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import TIGHTEST_TOLERANCES

import shakermill as sm
from shakermill.engines import budget as budget_module
from shakermill.engines.budget import PACE_JUDGED_AFTER_S, BudgetExceeded, RunBudget
from shakermill.engines.one_d import integrator as integrate
from shakermill.engines.one_d.engine import OneDimensionalEngine, integrator_for
from shakermill.engines.one_d.integrator import WINDOWS_FULL
from shakermill.engines.records import EnergyAudit
from shakermill.engines.status import BUDGET_EXCEEDED
from shakermill.solvers.driver import sample_times
from shakermill.solvers.full import simulate_full
from shakermill.solvers.result import ENERGY_AUDIT_FAILED, ENERGY_AUDIT_TOLERANCE
from shakermill.solvers.simulate import simulate_whole

# A 10-s chunk at the tightest tolerances is ~3·10⁵ steps.
TINY_STEPS = {**TIGHTEST_TOLERANCES, "record_windows": ()}


def test_a_step_budget_stops_the_run_exactly_and_keeps_what_it_computed() -> None:
    result = sm.simulate(sm.default_parameters(duration=20.0, record_windows=((0.0, 1.0),), max_steps=5000))
    assert result.status == BUDGET_EXCEEDED and not result.success
    assert result.summary.steps == 5000
    assert "max_steps = 5000" in result.message and "--set max_steps=10000" in result.message
    assert 1.0 < result.t_end < 20.0
    assert result.history.times[-1] == result.t_end and result.history.times[0] == 0.0
    assert result.impact_count > 100 and len(result.window_history.times) > 100


def test_a_wall_clock_budget_stops_a_long_run_between_chunks() -> None:
    # Normal steps: the chunks (10 simulated s each) end long before any pause, so the clock is read there.
    result = sm.simulate(sm.default_parameters(duration=36000.0, record_windows=(), max_wall_time=0.05))
    assert result.status == BUDGET_EXCEEDED
    assert "max_wall_time = 0.05 s" in result.message and "--set max_wall_time=0.1" in result.message
    assert 0.0 < result.t_end < 36000.0
    assert result.impact_count > 0


def test_a_run_whose_pace_cannot_reach_its_end_within_the_budget_is_stopped_with_the_estimate() -> None:
    budget = RunBudget(max_wall_time=100.0, max_steps=10**9)
    assert not budget.outpaced(t=0.0, end=1000.0)  # starts the clock
    budget.started -= 20.0
    budget.paced_from = (budget.paced_from[0] - 15.0, 0.0)
    # 15 s for 1 s simulated: 4 more seconds need 20 + 60 = 80 s <= 1.5 x 100 s, 99 more ~1505 s.
    assert not budget.outpaced(t=1.0, end=5.0) and budget.reason is None
    assert budget.outpaced(t=1.0, end=100.0)
    assert "would need ~25 min of computing to reach t = 100 s" in budget.reason
    assert f"--set max_wall_time={math.ceil(1.5 * (20.0 + 15.0 * 99.0))}" in budget.reason.replace("\n", "")


def test_the_pace_is_judged_only_after_a_while_past_the_first_call() -> None:
    budget = RunBudget(max_wall_time=1.0, max_steps=10**9)
    budget.paced_from = (budget.started - (PACE_JUDGED_AFTER_S - 1.0), 0.0)
    assert not budget.outpaced(t=1e-3, end=1e6)  # a hopeless pace, but not yet judged


def test_a_3d_run_that_cannot_end_within_its_budget_stops_at_its_pace_not_at_the_budget(monkeypatch) -> None:
    monkeypatch.setattr(budget_module, "PACE_JUDGED_AFTER_S", 0.3)
    params = sm.default_parameters("spex8000m-3d", duration=600.0, solver="full", record_windows=(), max_wall_time=30.0)
    result = sm.simulate(params)
    assert (
        result.status == BUDGET_EXCEEDED
        and "stopped early" in result.message
        and "max_wall_time = 30 s" in result.message
    )
    assert 0.0 < result.t_end < 600.0 and result.summary.wall_time_s < 10.0
    assert result.history.times[-1] == result.t_end


def test_pauses_of_the_compiled_loop_leave_a_run_bit_for_bit_unchanged(monkeypatch) -> None:
    params = sm.default_parameters(duration=3.0, record_windows=((0.0, 0.5), (2.0, 0.3)))
    whole = simulate_full(params, OneDimensionalEngine)
    monkeypatch.setattr(integrate.Integrator, "first_steps_per_call", 7)
    monkeypatch.setattr(integrate.Integrator, "most_steps_per_call", 7)
    reports: list[float] = []
    paused = simulate_full(params, OneDimensionalEngine, progress=lambda t, _duration: reports.append(t))
    assert len(reports) > whole.counters["steps"] // 7 - 1
    assert paused.counters == whole.counters
    for name in ("x", "p", "theta_ball", "theta_vial", "theta_air", "heat_generated"):
        np.testing.assert_array_equal(paused.history[name], whole.history[name])
        np.testing.assert_array_equal(paused.window_history[name], whole.window_history[name])
    np.testing.assert_array_equal(paused.window_history.times, whole.window_history.times)
    for name, values in whole.impact_columns.items():
        np.testing.assert_array_equal(paused.impact_columns[name], values)


def test_tiny_steps_hand_control_back_inside_a_chunk() -> None:
    params = sm.default_parameters(duration=10.0, max_steps=3000, **TINY_STEPS)
    integrator = integrator_for(params, sample_times(params))
    heartbeats: list[float] = []
    status = integrator.advance(10.0, heartbeats.append)
    # The first call takes first_steps_per_call steps, the next the rest of the budget; then it is spent.
    assert status == BUDGET_EXCEEDED
    assert len(heartbeats) == 2 and 0.0 < heartbeats[0] < heartbeats[1] == integrator.t < 1.0
    assert int(integrator.counters[integrate.STEPS]) == 3000
    assert "max_steps = 3000" in integrator.explain(status)


def test_one_budget_covers_the_averaged_solvers_mechanics_phase() -> None:
    result = sm.simulate(sm.default_parameters(solver="averaged", max_steps=3000, record_windows=()))
    assert result.status == BUDGET_EXCEEDED and result.solver == "averaged"
    assert "mechanics phase" in result.message
    assert result.summary.steps == 3000
    assert list(result.history.times) == [0.0, result.t_end] and result.impact_count > 0


def test_a_probe_that_uses_up_the_budget_stops_an_averaged_run_that_finished() -> None:
    base = sm.default_parameters(solver="averaged", duration=600.0, record_windows=())
    mechanics_steps = sm.simulate(base.replace(attractor_starts=1)).summary.steps
    result = sm.simulate(base.replace(attractor_starts=4, max_steps=mechanics_steps + 1000))
    assert result.status == BUDGET_EXCEEDED
    assert "probing attractors (4 of 4 starts not settled); the run itself finished" in result.message
    assert result.t_end == 600.0 and result.summary.attractors.failed_starts == 4
    probe_lines = [line for line in result.warnings if line.startswith("attractor probe")]
    assert len(probe_lines) == 1 and probe_lines[0].startswith("attractor probe: starts 0, 1, 2, 3 did not settle")


def test_scans_and_fits_are_told_of_a_spent_budget_by_an_exception() -> None:
    with pytest.raises(BudgetExceeded, match="max_steps = 2000"):
        simulate_whole(sm.default_parameters(duration=20.0, max_steps=2000, record_windows=()))


def test_full_record_windows_stop_the_run_instead_of_filling_memory(monkeypatch) -> None:
    monkeypatch.setattr(integrate, "MAX_WINDOW_POINTS", 50)
    # The size is checked between calls: short calls make the check as fine as the test needs.
    monkeypatch.setattr(integrate.Integrator, "first_steps_per_call", 10)
    monkeypatch.setattr(integrate.Integrator, "most_steps_per_call", 10)
    result = sm.simulate(sm.default_parameters(duration=20.0, record_windows=((0.0, 5.0),)))
    assert result.status == WINDOWS_FULL
    assert "Shorten record_windows" in result.message and result.t_end < 5.0
    assert 50 <= len(result.window_history.times) <= 70


def test_a_run_whose_energy_audit_does_not_close_is_not_ok() -> None:
    # Without the projection the audit shows the contacts' truncation error: ~9 % at rtol 0.1.
    result = sm.simulate(sm.default_parameters(duration=5.0, rtol=0.1, energy_projection=False, record_windows=()))
    residual = result.energy.relative_residual
    assert residual > ENERGY_AUDIT_TOLERANCE
    assert result.status == ENERGY_AUDIT_FAILED and not result.success
    assert f"{residual:.3g}" in result.message and f"above {ENERGY_AUDIT_TOLERANCE:g}" in result.message
    assert result.t_end == 5.0


@pytest.mark.parametrize(
    "preset, overrides",
    [
        ("spex8000m", {}),
        ("spex8000m-calibrated", {}),
        ("spex8000m", {"solver": "averaged", "attractor_starts": 1}),
        ("spex8000m", {"energy_projection": False}),
    ],
    ids=["default", "calibrated", "averaged", "no projection"],
)
def test_presets_close_their_energy_audit_well_within_the_tolerance(preset: str, overrides: dict) -> None:
    result = sm.simulate(sm.default_parameters(preset, duration=120.0, record_windows=(), **overrides))
    assert result.success, result.message
    assert result.energy.relative_residual < ENERGY_AUDIT_TOLERANCE


def test_an_audit_with_a_non_finite_term_has_no_relative_residual() -> None:
    terms = {**dict.fromkeys(EnergyAudit.__dataclass_fields__, 0.0), "heat_into": {}, "dissipated_by_channel": {}}
    closed = EnergyAudit(**{**terms, "stored": {"balls": 0.0}})
    broken = EnergyAudit(**{**terms, "stored": {"balls": math.nan}})
    assert closed.relative_residual == 0.0
    assert math.isnan(broken.relative_residual)


def test_a_failed_fit_is_said_in_a_warning_where_a_fit_was_to_be_expected() -> None:
    # Started at rest with a stroke shorter than the free gap, the ball is never hit: nothing heats.
    long = sm.simulate(sm.default_parameters(amplitude=1e-3, duration=9000.0, record_windows=()))
    assert long.t_end > long.steady.slowest_time_constant
    assert long.success and not long.ball_fit.success
    assert any(line.startswith("the exponential fit of the ball temperature failed") for line in long.warnings)
    # A run shorter than its slowest time constant expects no exponential: a note says so, no warning (issue 37).
    short = sm.simulate(sm.default_parameters(amplitude=1e-3, duration=5.0, record_windows=()))
    assert not short.ball_fit.success
    assert not any("exponential fit" in line for line in short.warnings)
    assert any("no exponential describes it" in line for line in short.notes)
