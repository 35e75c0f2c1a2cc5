"""Coexisting attractors: starts, settling, grouping, and what the averaged solver and sweeps report."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import shakermill as sm
from shakermill.analysis.attractors import (
    FAILED,
    MEASURE_PERIODS,
    POSITION_SPREAD,
    AttractorScan,
    SettledStart,
    group,
    initial_states,
)
from shakermill.analysis.regime import IRREGULAR, NO_IMPACTS, PHASE_TOLERANCE
from shakermill.solvers.attractors import find_attractors, settle
from shakermill.studies.sweeps.sweep import sweep

# A stroke of 23 mm, just above the free gap of 22.65 mm: period-1 and period-2 coexist at every ω of
# 90–130 rad/s, at rtol 1e-3 and at 1e-5 alike. At the default 25 mm and ω = 110 rad/s all starts
# reach one attractor; there the regime's dependence on rtol is the integrator's, not a second basin.
SHORT_STROKE = 0.023


@pytest.fixture(scope="module")
def coexisting():
    params = sm.default_parameters(omega=110.0, amplitude=SHORT_STROKE)
    return params, find_attractors(params)


def test_two_attractors_at_110_rad_s_with_basins_summing_to_one(coexisting):
    params, scan = coexisting
    assert len(scan.attractors) == 2
    assert sum(attractor.basin_fraction for attractor in scan.attractors) == pytest.approx(1.0)
    assert sorted(start for attractor in scan.attractors for start in attractor.starts) == list(
        range(params.attractor_starts)
    )
    assert {attractor.regime for attractor in scan.attractors} == {"period-1", "period-2"}
    first, second = scan.attractors
    assert 0 in first.starts and scan.configured == first
    assert abs(first.heat_power_W - second.heat_power_W) > 0.01 * first.heat_power_W
    assert scan.heat_power_spread_W == pytest.approx(abs(first.heat_power_W - second.heat_power_W))
    for attractor in scan.attractors:
        assert attractor.basin_fraction == len(attractor.starts) / params.attractor_starts


def test_a_periodic_attractor_hits_a_whole_number_of_times_per_cycle(coexisting):
    params, scan = coexisting
    drive_period = 2 * math.pi / params.omega
    for attractor in scan.attractors:
        assert attractor.period is not None
        per_cycle = attractor.impact_rate_hz * attractor.period * drive_period
        assert per_cycle == pytest.approx(round(per_cycle), abs=1e-9) and per_cycle >= 1


@pytest.mark.slow
def test_every_start_reaches_an_attractor_at_the_default_stroke():
    params = sm.default_parameters(omega=110.0)
    scan = find_attractors(params)
    assert sum(attractor.basin_fraction for attractor in scan.attractors) == pytest.approx(1.0)
    assert scan.failed == ()
    assert scan.configured is scan.attractors[0]
    assert scan.as_summary().count == len(scan.attractors)


def test_starts_are_deterministic_inside_the_gap_and_begin_with_the_configured_one():
    params = sm.default_parameters(ball_position=0.004, ball_momentum=0.01)
    states = initial_states(params, 8)
    assert states == initial_states(params, 8)
    assert states[0] == (0.004, 0.01)
    assert initial_states(params, 3) == states[:3]
    half_gap = params.vial_length / 2 - params.ball_radius
    assert all(abs(position) <= POSITION_SPREAD * half_gap for position, _ in states[1:])
    assert len({position for position, _ in states}) == 8
    momenta = [momentum for _, momentum in states[1:]]
    assert 0.0 in momenta and max(momenta) > 0 > min(momenta)


def test_one_start_is_the_configured_start_alone():
    params = sm.default_parameters(omega=110.0, amplitude=SHORT_STROKE, attractor_starts=1)
    scan = find_attractors(params)
    assert len(scan.settled) == 1 and len(scan.attractors) == 1
    assert scan.attractors[0].basin_fraction == 1.0 and scan.heat_power_spread_W == 0.0
    with pytest.raises(sm.ParameterError, match="attractor_starts"):
        params.replace(attractor_starts=0)


def test_settled_heat_power_and_impact_rate_agree_with_a_plain_run():
    params = sm.default_parameters(omega=110.0, amplitude=SHORT_STROKE)
    settled = settle(params)
    run = sm.simulate(params.replace(duration=60.0, record_windows=()))
    late = run.timeseries.sel(time=slice(30.0, 60.0))
    heat, times = late["heat_generated"].to_numpy(), late["time"].to_numpy()
    span = times[-1] - times[0]
    # The plain run's 30 s hold a fraction of a drive period more or less than whole cycles: ~0.2 %.
    assert settled.heat_power_W == pytest.approx((heat[-1] - heat[0]) / span, rel=3e-3)
    impacts = run.impacts["time"].between(times[0], times[-1]).sum()
    assert settled.impact_rate_hz == pytest.approx(impacts / span, rel=3e-3)


# Grouping, on made-up settled motions ----------------------------------------------------------------

OMEGA = 100.0
DRIVE = 2 * math.pi / OMEGA


def _motion(
    pattern: list[tuple[float, str]], every: int, periods: int = MEASURE_PERIODS, jitter: float = 0.0
) -> pd.DataFrame:
    """Impacts at fractions of the drive period, the pattern repeating every ``every`` periods."""
    rng = np.random.default_rng(3)
    times, walls = [], []
    for k in range(0, periods, every):
        for fraction, wall in pattern:
            times.append((k + fraction) * DRIVE + jitter * DRIVE / (2 * math.pi) * rng.uniform(-1, 1))
            walls.append(wall)
    return pd.DataFrame({"time": times, "wall": walls})


def _settled(
    start: int, impacts: pd.DataFrame, regime: str, period: int | None, heat: float = 1.0, stderr: float = 0.0
) -> SettledStart:
    return SettledStart(
        start, 0.0, 0.0, regime, period, len(impacts) / (MEASURE_PERIODS * DRIVE), heat, stderr, impacts
    )


PERIOD_TWO = [(0.2, "left"), (0.7, "right"), (1.3, "left"), (1.75, "right")]


def _mirror(pattern: list[tuple[float, str]]) -> list[tuple[float, str]]:
    return [(fraction + 0.5, "right" if wall == "left" else "left") for fraction, wall in pattern]


def test_a_cycle_entered_later_and_its_mirror_image_are_one_attractor():
    cycle = _settled(0, _motion(PERIOD_TWO, 2), "period-2", 2)
    later = _settled(1, _motion([(f + 1.0, w) for f, w in PERIOD_TWO], 2), "period-2", 2)
    mirrored = _settled(2, _motion(_mirror(PERIOD_TWO), 2), "period-2", 2)
    other = _settled(3, _motion([(0.4, "left"), (0.9, "right")], 1), "period-1", 1, heat=1.2)
    attractors = group((cycle, later, mirrored, other), OMEGA, 0.0)
    assert [attractor.starts for attractor in attractors] == [(0, 1, 2), (3,)]
    assert [attractor.regime for attractor in attractors] == ["period-2", "period-1"]
    assert [attractor.basin_fraction for attractor in attractors] == [0.75, 0.25]


def test_a_start_jittering_on_a_cycle_joins_it_under_the_cycles_name():
    cycle = _settled(0, _motion(PERIOD_TWO, 2), "period-2", 2)
    # Jitter of about the classification's tolerance: called irregular, but on the same cycle.
    jittered = _settled(1, _motion(PERIOD_TWO, 2, jitter=0.9 * PHASE_TOLERANCE), IRREGULAR, None)
    far = _settled(2, _motion(PERIOD_TWO, 2, jitter=20 * PHASE_TOLERANCE), IRREGULAR, None, heat=0.8, stderr=0.001)
    attractors = group((jittered, cycle, far), OMEGA, 0.0)
    assert [(attractor.regime, attractor.starts) for attractor in attractors] == [
        ("period-2", (0, 1)),
        (IRREGULAR, (2,)),
    ]


def test_irregular_motions_split_only_where_their_heat_powers_are_told_apart():
    def irregular(start: int, heat: float, stderr: float) -> SettledStart:
        return _settled(
            start, _motion([(0.1 * start, "left")], 1, jitter=3.0), IRREGULAR, None, heat=heat, stderr=stderr
        )

    # 1.00 and 1.03 differ by 3 %, within 3 combined standard errors of 1 %; 1.30 does not.
    starts = (irregular(0, 1.00, 0.01), irregular(1, 1.30, 0.01), irregular(2, 1.03, 0.01))
    assert [attractor.starts for attractor in group(starts, OMEGA, 0.0)] == [(0, 2), (1,)]
    # Without sampling errors the 1 % floor decides.
    exact = (irregular(0, 1.000, 0.0), irregular(1, 1.005, 0.0), irregular(2, 1.03, 0.0))
    assert [attractor.starts for attractor in group(exact, OMEGA, 0.0)] == [(0, 1), (2,)]


def test_resting_starts_are_one_attractor_and_failed_starts_none():
    resting = [_settled(k, pd.DataFrame({"time": [], "wall": []}), NO_IMPACTS, None, heat=0.0) for k in (0, 2)]
    moving = _settled(1, _motion(PERIOD_TWO, 2), "period-2", 2)
    failed = SettledStart(
        3,
        0.0,
        0.0,
        FAILED,
        None,
        math.nan,
        math.nan,
        math.nan,
        pd.DataFrame(columns=["time", "wall"]),
        "step too small",
    )
    attractors = group((resting[0], moving, resting[1], failed), OMEGA, 0.0)
    assert [(attractor.regime, attractor.starts) for attractor in attractors] == [
        (NO_IMPACTS, (0, 2)),
        ("period-2", (1,)),
    ]
    assert sum(attractor.basin_fraction for attractor in attractors) == 0.75


def test_a_start_that_fails_is_reported_not_grouped(monkeypatch):
    from shakermill.solvers import attractors as module

    real_settle = module.settle

    def third_fails(params, start=0, *budget_and_heartbeat):
        settled = real_settle(params, start, *budget_and_heartbeat)
        if start != 2:
            return settled
        return SettledStart(
            start,
            params.ball_position,
            params.ball_momentum,
            FAILED,
            None,
            math.nan,
            math.nan,
            math.nan,
            {name: values[:0] for name, values in settled.impacts.items()},
            "step size too small",
        )

    monkeypatch.setattr(module, "settle", third_fails)
    scan = find_attractors(sm.default_parameters(omega=110.0, attractor_starts=4))
    assert [start.start for start in scan.failed] == [2]
    assert all(2 not in attractor.starts for attractor in scan.attractors)
    assert sum(attractor.basin_fraction for attractor in scan.attractors) == pytest.approx(0.75)
    assert scan.as_summary().failed_starts == 1
    assert any("start 2" in line and "step size too small" in line for line in scan.warnings())


# The averaged solver and sweeps ----------------------------------------------------------------------


@pytest.mark.slow
def test_averaged_run_follows_the_configured_start_and_warns_of_the_other_attractor(coexisting):
    params, scan = coexisting
    # Three hours outlast three slowest time constants, so the only warning left is the attractor's.
    base = params.replace(solver="averaged", duration=10800.0, record_windows=())
    alone = sm.simulate(base.replace(attractor_starts=1))
    probed = sm.simulate(base)
    assert probed.summary.heat_power_W == alone.summary.heat_power_W
    assert probed.summary.theta_inf_C == alone.summary.theta_inf_C
    assert alone.summary.attractors is None and alone.warnings == []
    assert probed.summary.attractors.count == len(scan.attractors) == 2
    other = scan.attractors[1]
    (warning,) = probed.warnings
    assert f"basin fraction {other.basin_fraction:.2f}" in warning and f"{other.heat_power_W:.4g} W" in warning
    assert probed.summary.warnings == [warning]


@pytest.mark.slow
def test_one_attractor_at_the_default_stroke_and_no_warning():
    result = sm.simulate(sm.default_parameters(solver="averaged", duration=10800.0, omega=110.0, record_windows=()))
    assert result.summary.attractors.count == len(result.attractors.attractors) == 1
    assert result.summary.attractors.heat_power_spread_W == 0.0
    assert result.warnings == []


def test_a_resting_ball_never_reached_is_warned_of_the_moving_starts():
    # A stroke below the free gap: the configured ball at rest is never hit, moving starts are.
    scan = find_attractors(sm.default_parameters(amplitude=0.015))
    assert scan.configured.regime == NO_IMPACTS and scan.configured.heat_power_W == 0.0
    assert len(scan.differing()) == len(scan.attractors) - 1 >= 1
    assert all("with 0 W" in line and "%" not in line for line in scan.warnings())
    assert math.isnan(scan.as_summary().heat_power_spread_relative)


def test_only_a_heat_power_more_than_one_percent_away_is_worth_a_warning():
    def cycle(start: int, fraction: float, heat: float) -> SettledStart:
        return _settled(start, _motion([(fraction, "left"), (fraction + 0.5, "left")], 1), "period-1", 1, heat=heat)

    settled = (cycle(0, 0.1, 1.000), cycle(1, 0.2, 1.005), cycle(2, 0.3, 1.030))
    scan = AttractorScan(settled, group(settled, OMEGA, 0.0))
    assert [attractor.starts for attractor in scan.differing()] == [(2,)]
    (warning,) = scan.warnings()
    assert "1 of 3 starts (basin fraction 0.33)" in warning and "+3.0 %" in warning


@pytest.mark.slow
def test_sweep_rows_count_the_attractors_and_their_heat_spread(tmp_path):
    base = sm.default_parameters(solver="averaged", duration=60.0, omega=110.0)
    points = [{"amplitude": SHORT_STROKE, "solver": "averaged"}, {"amplitude": SHORT_STROKE, "solver": "full"}]
    table = sweep(base, points, tmp_path / "sweep", workers=1)
    expected = find_attractors(base.replace(amplitude=SHORT_STROKE))
    for _, row in table.iterrows():
        assert row["n_attractors"] == len(expected.attractors)
        assert row["heat_power_spread_W"] == pytest.approx(expected.heat_power_spread_W)
        assert row["heat_power_spread_relative"] == pytest.approx(
            expected.heat_power_spread_W / expected.configured.heat_power_W
        )
        assert "coexisting attractor" in row["warnings"]
    assert str(table["n_attractors"].dtype) == "Int64"
