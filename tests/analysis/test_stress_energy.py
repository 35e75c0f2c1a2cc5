"""The stress-energy spectrum (analysis/stress_energy.py) against values counted by hand, and against the energy a
run dissipates."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shakermill as sm
from shakermill.analysis.impacts import contacts_of
from shakermill.analysis.stress_energy import stress_spectrum

# Five impacts of the 'dem' engine over 2 s: on the side, between balls, on an end face.
DEM_IMPACTS = {
    "target": np.array(["side", "ball", "left", "ball", "right"]),
    "dissipated_normal": np.array([1e-3, 4e-3, 0.0, 2e-2, 5e-3]),
    "dissipated_tangential": np.array([0.0, 1e-3, 1e-4, 0.0, 0.0]),
    "dissipated_sliding": np.array([0.0, 2e-3, 0.0, 0.0, 5e-3]),
    "dissipated_rolling": np.array([0.0, 0.0, 0.0, 0.0, 0.0]),
    "dissipated_energy": np.array([1e-3, 7e-3, 1e-4, 2e-2, 1e-2]),
    "duration": np.array([5e-5, 6e-5, 4e-5, 8e-5, 7e-5]),
}


def test_the_spectrum_of_five_impacts_counted_by_hand():
    spectrum = stress_spectrum(contacts_of(DEM_IMPACTS), 2.0, (0.01, 0.005))
    # Totals sorted: 0.1, 1, 7, 10, 20 mJ; the median is the third, the 90th percentile 10 + 0.6·(20 − 10) mJ.
    assert spectrum.percentile(50) == pytest.approx(7e-3)
    assert spectrum.percentile(90) == pytest.approx(1.6e-2)
    # Tangential parts 0, 3, 0.1, 0, 5 mJ: median 0.1 mJ; normal parts 1, 4, 0, 20, 5 mJ: median 4 mJ.
    assert spectrum.percentile(50, "tangential") == pytest.approx(1e-4)
    assert spectrum.percentile(50, "normal") == pytest.approx(4e-3)
    # Between balls: 7 and 20 mJ; on the vial: 0.1, 1 and 10 mJ.
    assert spectrum.percentile(50, target="ball") == pytest.approx(1.35e-2)
    assert spectrum.percentile(50, target="wall") == pytest.approx(1e-3)
    # At or above 10 mJ: 10 and 20 mJ, two events in 2 s carrying 30 mJ; at or above 5 mJ three, 37 mJ.
    assert spectrum.events_per_second(0.01) == pytest.approx(1.0)
    assert spectrum.power(0.01) == pytest.approx(0.015)
    summary = spectrum.as_summary()
    assert summary.stress_power_above_W["0.005J"] == pytest.approx(0.0185)
    assert summary.stress_events_above_hz["0.005J"] == pytest.approx(1.5)
    assert summary.stress_energy_ball_p90_J == pytest.approx(7e-3 + 0.9 * 13e-3)
    assert summary.stress_window_s == 2.0


def test_one_ball_on_the_axis_stresses_head_on_and_hits_no_ball():
    impacts = {
        "wall": np.array(["left", "right"]),
        "dissipated_energy": np.array([2e-3, 4e-3]),
        "duration": np.full(2, 5e-5),
    }
    summary = stress_spectrum(contacts_of(impacts), 1.0).as_summary()
    assert summary.stress_energy_normal_median_J == summary.stress_energy_median_J == pytest.approx(3e-3)
    assert summary.stress_energy_tangential_p90_J == 0.0
    assert math.isnan(summary.stress_energy_ball_median_J)
    assert summary.stress_energy_wall_median_J == pytest.approx(3e-3)


def test_a_lasting_contact_is_no_stress_event_but_the_power_of_steady_grinding():
    """A ball that slid on the wall for 0.4 s dissipated 0.5 J: counted apart, not in the spectrum's tail."""
    impacts = {
        **DEM_IMPACTS,
        "dissipated_energy": np.append(DEM_IMPACTS["dissipated_energy"], 0.5),
        "duration": np.append(DEM_IMPACTS["duration"], 0.4),
        "target": np.append(DEM_IMPACTS["target"], "side"),
        **{
            name: np.append(DEM_IMPACTS[name], value)
            for name, value in (
                ("dissipated_normal", 0.0),
                ("dissipated_tangential", 0.0),
                ("dissipated_sliding", 0.5),
                ("dissipated_rolling", 0.0),
            )
        },
    }
    with_lasting, without = stress_spectrum(contacts_of(impacts), 2.0), stress_spectrum(contacts_of(DEM_IMPACTS), 2.0)
    assert with_lasting.percentile(90) == without.percentile(90)
    assert with_lasting.power() == without.power()
    summary = with_lasting.as_summary()
    assert summary.stress_lasting_power_W == pytest.approx(0.25)
    assert summary.stress_lasting_contacts_hz == pytest.approx(0.5)
    # Given all the contacts dissipated (a contact still running is in no record), the lasting contacts have the rest:
    # 0.4 W less the impacts' 38.1 mJ over 2 s.
    assert stress_spectrum(contacts_of(impacts), 2.0, dissipated_power=0.4).lasting_power() == pytest.approx(
        0.4 - 0.01905
    )


def test_no_impacts_give_no_energies_and_no_power():
    empty = {name: values[:0] for name, values in DEM_IMPACTS.items()}
    spectrum = stress_spectrum(contacts_of(empty), 5.0, (1e-3,))
    assert math.isnan(spectrum.percentile(50))
    assert spectrum.power(1e-3) == 0.0


@pytest.mark.slow
def test_the_stress_power_of_a_run_is_the_power_its_impacts_dissipate():
    """All of a full 1-D run's dissipation happens in its recorded impacts: the spectrum's power above zero and that
    of the lasting contacts (none here: the ball flies from end to end) is the summary's dissipated power (but for the
    impact still running at the end)."""
    result = sm.simulate(sm.default_parameters(duration=30.0))
    spectrum = stress_spectrum(result.contacts(), result.t_end)
    assert spectrum.lasting_power() == 0.0
    assert result.summary.stress_lasting_power_W == pytest.approx(0.0, abs=1e-3 * result.summary.dissipated_power_W)
    assert spectrum.power() == pytest.approx(result.summary.dissipated_power_W, rel=1e-3)
    assert spectrum.events_per_second() == pytest.approx(result.summary.impacts.rate_hz, rel=1e-12)


def test_distinct_thresholds_get_distinct_summary_keys():
    """Issue 35: two thresholds that agreed to six digits shared one summary key, and one result was overwritten."""
    from shakermill.analysis.stress_energy import threshold_name

    assert threshold_name(1e-3) == "0.001J" and threshold_name(1e-2) == "0.01J" and threshold_name(1000.0) == "1000J"
    assert threshold_name(0.0010000001) == "0.0010000001J" != threshold_name(0.001)
    spectrum = stress_spectrum(
        contacts_of({"dissipated_energy": np.array([2e-3]), "duration": np.array([1e-5])}), 1.0, (0.001, 0.0010000001)
    )
    assert list(spectrum.as_summary().stress_events_above_hz) == ["0.001J", "0.0010000001J"]


def test_a_threshold_given_twice_is_refused():
    with pytest.raises(
        sm.ParameterError, match=r"^stress_energy_thresholds: 0\.001 J is given 2 times; allowed distinct"
    ):
        sm.default_parameters("spex8000m-3d", stress_energy_thresholds=(0.001, 1e-3))


def test_kwades_stress_energy_is_the_pairs_relative_kinetic_energy_at_first_touch_counted_by_hand():
    """½·m*·v_n²: balls of 1 and 3 kg closing at 2 m/s bring 0.5·0.75·4 = 1.5 J; the 1-kg ball on the vial at 2 m/s
    brings 2 J; the 3-kg ball on the vial at 1 m/s 1.5 J."""
    from shakermill.analysis.stress_energy import collision_energy

    impacts = {
        "impact_speed": np.array([2.0, 2.0, 1.0]),
        "ball": np.array([0, 0, 1]),
        "other_ball": np.array([1, -1, -1]),
        "dissipated_energy": np.array([0.5, 1.0, 0.2]),
        "duration": np.full(3, 1e-4),
    }
    np.testing.assert_allclose(collision_energy(impacts, (1.0, 3.0)), [1.5, 2.0, 1.5], rtol=1e-15)
    summary = stress_spectrum(contacts_of(impacts), 1.0, masses=(1.0, 3.0), dissipated_power=2.0).as_summary()
    assert summary.stress_energy_kinetic_median_J == pytest.approx(1.5)
    # One ball on the axis (the 1-D engine's columns have no ball index): its own mass.
    np.testing.assert_allclose(collision_energy({"impact_speed": np.array([3.0])}, (0.5,)), [2.25])
    # Of the 2 W dissipated, the impacts' 1.7 J in 1 s leave 0.3 W, 15 %, to lasting contacts.
    assert summary.stress_lasting_share == pytest.approx(0.15)


@pytest.mark.slow
def test_a_head_on_impact_dissipates_one_minus_e_squared_of_kwades_stress_energy():
    """One ball dropped head-on on the end face of a resting vial: the energy it brought, ½·m·v_n², and what the
    contact dissipated, (1 − e²) of it, for the engine's own restitution."""
    from shakermill.solvers.impact import single_impact

    params = sm.default_parameters("spex8000m-3d")
    outcome = single_impact(params, 2.0)
    impacts = {
        "impact_speed": np.array([outcome.normal_speed_in]),
        "dissipated_energy": np.array([outcome.dissipated_J]),
        "duration": np.array([outcome.contact_time_s]),
    }
    kinetic = stress_spectrum(contacts_of(impacts), 1.0, masses=params.ball_masses()).percentile(50, "kinetic")
    assert kinetic == pytest.approx(0.5 * params.ball_mass * 2.0**2, rel=1e-12)
    assert outcome.dissipated_J == pytest.approx((1 - outcome.normal_restitution**2) * kinetic, rel=1e-3)
