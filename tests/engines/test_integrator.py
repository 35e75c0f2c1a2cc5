"""The compiled integrator against analytic cases (MODEL.md §§2, 7)."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import shakermill as sm
from shakermill.engines.one_d import model
from shakermill.engines.one_d.integrator import BOGACKI_SHAMPINE, ButcherTableau
from shakermill.engines.status import OVERLAP_TOO_LARGE
from shakermill.physics import contact

# Restitution is reproduced to ~5e-5 at rtol 1e-5, to ~3e-4 at rtol 1e-4 and to ~2e-3 at ode23's
# default rtol 1e-3 (benchmarks/README.md has the table).
RESTITUTION_RTOL = 1e-5
DEFAULT_RTOL = sm.default_parameters().rtol


def test_bogacki_shampine_tableau_matches_scipy_rk23() -> None:
    from scipy.integrate._ivp.rk import RK23

    a, b, error, c = BOGACKI_SHAMPINE.arrays()
    np.testing.assert_allclose(a[:3, :3], RK23.A, atol=1e-15)
    np.testing.assert_allclose(b[:3], RK23.B, atol=1e-15)
    np.testing.assert_allclose(c[:3], RK23.C, atol=1e-15)
    # SciPy's E is b_hat - b with the FSAL stage appended; ours is b - b_hat.
    np.testing.assert_allclose(error, -RK23.E, atol=1e-15)


@pytest.mark.parametrize(
    "change, complaint",
    [
        (dict(b=(Fraction(1, 3), Fraction(1, 3), Fraction(1, 3), Fraction(0))), "last row of a"),
        (dict(c=(Fraction(0), Fraction(1, 3), Fraction(3, 4), Fraction(1))), "row 1 of a"),
        (dict(b_hat=(Fraction(7, 24), Fraction(1, 4), Fraction(1, 3), Fraction(1, 4))), "b_hat violates"),
    ],
)
def test_tableau_is_checked_at_construction(change: dict, complaint: str) -> None:
    fields = dict(
        name="broken",
        order=BOGACKI_SHAMPINE.order,
        error_order=BOGACKI_SHAMPINE.error_order,
        a=BOGACKI_SHAMPINE.a,
        b=BOGACKI_SHAMPINE.b,
        b_hat=BOGACKI_SHAMPINE.b_hat,
        c=BOGACKI_SHAMPINE.c,
    )
    fields.update(change)
    with pytest.raises(ValueError, match=complaint):
        ButcherTableau(**fields)


@pytest.mark.parametrize("restitution", [0.5, 0.7, 0.9])
@pytest.mark.parametrize("speed", [0.1, 0.5, 1.0, 2.0, 5.0])
def test_single_impact_restitution_equals_input(speed: float, restitution: float, single_impact) -> None:
    result = sm.simulate(single_impact(speed, restitution, rtol=RESTITUTION_RTOL))
    assert result.success, result.message
    assert len(result.impacts) == 1
    impact = result.impacts.iloc[0]
    # The "resting" wall still moves at ~1e-10 m/s.
    assert impact["impact_speed"] == pytest.approx(speed, abs=1e-9)
    assert impact["rebound_speed"] / impact["impact_speed"] == pytest.approx(restitution, abs=1e-3)


@pytest.mark.parametrize("restitution", [0.5, 0.7, 0.9])
@pytest.mark.parametrize("speed", [0.1, 1.0, 5.0])
def test_default_tolerance_gets_the_heat_and_rebound_of_one_impact(
    speed: float, restitution: float, single_impact
) -> None:
    # The heat is what the model is for: at ode23's default rtol the contact used to lose 1-3 % of its
    # dissipated energy, which the energy projection then passed on to the rebound.
    params = single_impact(speed, restitution, rtol=DEFAULT_RTOL)
    impact = sm.simulate(params).impacts.iloc[0]
    lost = 0.5 * params.ball_mass * speed**2 * (1.0 - restitution**2)
    assert impact["dissipated_energy"] == pytest.approx(lost, rel=0.01)
    assert impact["rebound_speed"] / impact["impact_speed"] == pytest.approx(restitution, abs=3 * DEFAULT_RTOL)


@pytest.mark.parametrize("speed", [0.1, 1.0, 5.0])
def test_contact_accuracy_is_not_capped_by_the_absolute_tolerances(speed: float, single_impact) -> None:
    # Inside a contact the error is measured relative to the impact's own scales, so tightening rtol
    # alone converges; the default atol (1e-6 in SI, 2-25 % of these overlaps) would cap it.
    base = sm.default_parameters()
    params = single_impact(speed, rtol=1e-7, atol_position=base.atol_position, atol_momentum=base.atol_momentum)
    impact = sm.simulate(params).impacts.iloc[0]
    assert impact["rebound_speed"] / impact["impact_speed"] == pytest.approx(params.restitution, abs=1e-5)


@pytest.mark.parametrize("speed", [0.1, 1.0, 5.0])
def test_elastic_contact_duration_matches_hertz(speed: float, single_impact) -> None:
    params = single_impact(speed, restitution=1.0, rtol=RESTITUTION_RTOL)
    result = sm.simulate(params)
    impact = result.impacts.iloc[0]
    k = model.constants_from(params)
    expected_duration = contact.hertz_contact_time(k.ball_mass, k.radius, k.e_star, speed)
    expected_overlap = contact.hertz_max_overlap(k.ball_mass, k.radius, k.e_star, speed)
    assert impact["duration"] == pytest.approx(expected_duration, rel=0.02)
    # The maximum overlap is sampled at step ends, so it can only fall short of the true maximum.
    assert impact["max_overlap"] == pytest.approx(expected_overlap, rel=0.02)
    assert impact["max_overlap"] <= expected_overlap * (1 + 1e-9)
    assert impact["rebound_speed"] == pytest.approx(speed, rel=1e-3)


def test_restitution_does_not_depend_on_speed(single_impact) -> None:
    ratios = []
    for speed in (0.1, 5.0):
        impact = sm.simulate(single_impact(speed, rtol=1e-6)).impacts.iloc[0]
        ratios.append(impact["rebound_speed"] / impact["impact_speed"])
    assert ratios[0] == pytest.approx(ratios[1], abs=1e-4)


def test_elastic_collisions_make_no_heat_and_balance_the_vial_work() -> None:
    # Without projection the balance is a genuine check of the integration, not of the bookkeeping.
    params = sm.default_parameters(
        duration=2.0,
        restitution=1.0,
        rtol=1e-6,
        atol_position=1e-12,
        atol_momentum=1e-12,
        energy_projection=False,
        record_windows=(),
    )
    result = sm.simulate(params)
    audit = result.energy
    assert len(result.impacts) > 50
    assert audit.dissipated == 0.0
    assert audit.heat_generated == 0.0
    assert result.timeseries["theta_ball"].values.max() == pytest.approx(params.initial_temperature, abs=1e-9)
    # Scale: the kinetic energy brought into the impacts, relative to the vial's frame.
    impact_energy = float((0.5 * params.ball_mass * result.impacts["impact_speed"] ** 2).sum())
    assert abs(audit.mechanical_residual) < 1e-4 * impact_energy
    assert audit.work_by_vial == pytest.approx(
        audit.kinetic_energy_change + audit.elastic_energy_change, abs=1e-4 * impact_energy
    )


def test_grazing_contact_is_not_stepped_over() -> None:
    # The right wall sweeps to within 1 µm of overlap of a ball at rest and turns back; the contact lasts
    # ~0.2 ms while flight steps are many milliseconds long.
    amplitude, overlap = 10e-3, 1e-6
    base = sm.default_parameters()
    position = -amplitude + base.vial_length / 2 - base.ball_radius + overlap
    params = base.replace(amplitude=amplitude, ball_position=position, duration=0.06, record_windows=())
    result = sm.simulate(params)
    assert len(result.impacts) >= 1
    first = result.impacts.iloc[0]
    turning_time = 1.5 * math.pi / params.omega
    half_width = math.sqrt(2 * overlap / amplitude) / params.omega
    assert first["wall"] == "right"
    assert turning_time - 1.5 * half_width < first["time"] < turning_time
    assert 0 < first["max_overlap"] <= overlap * 1.01


def test_numerical_fault_stops_with_a_message_and_keeps_results() -> None:
    # A rubber-soft ball overlaps far beyond a few percent of its radius: the run must stop cleanly.
    params = sm.default_parameters(duration=5.0, ball_youngs_modulus=1e5, vial_youngs_modulus=1e5, record_windows=())
    result = sm.simulate(params)
    assert not result.success
    assert result.status == OVERLAP_TOO_LARGE
    assert "overlap" in result.message and "Stopped at t =" in result.message
    assert 0.0 < result.t_end < params.duration
    series = result.timeseries
    assert series["time"].values[-1] == pytest.approx(result.t_end)
    assert np.all(np.isfinite(series["theta_ball"].values))


def test_contact_steps_respect_the_rayleigh_limit() -> None:
    params = sm.default_parameters(duration=1.0, record_windows=((0.0, 1.0),))
    result = sm.simulate(params)
    k = model.constants_from(params)
    window = result.windows
    times = window["time"].values
    limit = 0.9 * contact.rayleigh_time(
        params.ball_radius, params.ball_density, params.ball_youngs_modulus, params.ball_poisson_ratio
    )
    gaps = np.array(
        [
            min(model.gap(t, x, model.LEFT_WALL, k), model.gap(t, x, model.RIGHT_WALL, k))
            for t, x in zip(times, window["x"].values)
        ]
    )
    # A step belongs to a contact when it starts overlapping; the landing step that ends at an onset does not.
    in_contact = gaps[:-1] < 0.0
    steps = np.diff(times)
    assert in_contact.sum() > 100
    assert steps[in_contact].max() <= limit * (1 + 1e-12)


def test_record_windows_span_exactly_the_requested_interval() -> None:
    params = sm.default_parameters(duration=12.0, record_windows=((0.0, 1.0), (10.0, 0.1)))
    times = sm.simulate(params).windows["time"].values
    first = times[times <= 1.0]
    second = times[times >= 10.0]
    assert first[-1] == pytest.approx(1.0, abs=1e-12) and times[0] >= 0.0
    assert second[0] == pytest.approx(10.0, abs=1e-12) and second[-1] == pytest.approx(10.1, abs=1e-12)
    assert np.all(np.diff(times) >= 0)
    assert len(second) > 20  # the contacts inside the window are resolved step by step
