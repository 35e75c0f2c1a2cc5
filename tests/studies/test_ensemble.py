"""The uncertainty ensemble: its design over the assumed inputs, the quantiles and Sobol' indices of its headlines,
its regimes (MODEL.md §§14.1-14.2, issue 36)."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shakermill.analysis.regime import ACTIVE, PACK, charge_regime
from shakermill.parameters.assumed import AssumedInput
from shakermill.parameters.config import config_preset, load_config
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.presets import PRESET_FOLDER, PRESETS, default_parameters
from shakermill.studies.ensembles.ensemble import analyse, check_members, design, ensemble_inputs, fitted_keys_posterior
from shakermill.studies.inference.posterior import Posterior
from shakermill.studies.inference.prior import Prior


def from_unit(inputs, unit):
    return Prior(tuple(inputs)).values(unit)


def to_unit(inputs, values):
    return Prior(tuple(inputs)).unit(values)


def fitted_posterior(keys, samples):
    """A calibration's recorded posterior (samples of the keys' logarithms) as the ensemble carries it."""
    return Posterior.of_logarithms(keys, samples).log_normal()


LINEAR = AssumedInput("friction", 0.0, 1.0, "uniform", "test")
SMALL = AssumedInput("restitution", 0.5, 1.0, "uniform", "test")
LOG = AssumedInput("clamp_loss", 1.0, 100.0, "log-uniform", "test")


def test_the_design_covers_each_range_through_its_distribution_and_is_repeatable():
    points = design([LINEAR, LOG], 64, seed=3)
    assert points == design([LINEAR, LOG], 64, seed=3) and points != design([LINEAR, LOG], 64, seed=4)
    friction = np.array([point["friction"] for point in points])
    loss = np.array([point["clamp_loss"] for point in points])
    assert 0.0 <= friction.min() and friction.max() <= 1.0
    # A balanced Sobol' design: each eighth of the unit interval holds exactly 8 of the 64 members.
    assert np.all(np.histogram(friction, bins=8, range=(0.0, 1.0))[0] == 8)
    # Log-uniform: each decade holds half of the members.
    assert np.count_nonzero(loss < 10.0) == 32


def test_unit_mapping_round_trips():
    unit = np.random.default_rng(1).random((20, 3))
    values = from_unit([LINEAR, SMALL, LOG], unit)
    assert values[:, 2].min() >= 1.0 and values[:, 1].min() >= 0.5
    np.testing.assert_allclose(to_unit([LINEAR, SMALL, LOG], values), unit, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("members", [4, 12, 8192])
def test_members_are_a_power_of_two_within_limits(members):
    with pytest.raises(ParameterError, match=f"^members: {members} is not allowed; a power of two in"):
        check_members(members)


def members_table(points: list[dict[str, float]], heat: np.ndarray, **columns: np.ndarray) -> pd.DataFrame:
    table = pd.DataFrame(points)
    table["error"] = None
    table["heat_power_W"] = heat
    table["initial_temperature_C"] = 20.0
    table["ball_C"] = 20.0 + 5.0 * heat
    for key, values in columns.items():
        table[key] = values
    return table


def test_quantiles_and_sobol_indices_of_a_known_function(tmp_path: Path):
    # heat = 4·f + e' on two uniform inputs (f in [0, 1], e' the restitution scaled to [0, 1]): variances 16/12 and
    # 1/12, so the first and total indices are 16/17 and 1/17; the 5/50/95 % points those of the members.
    points = design([LINEAR, SMALL], 64, seed=5)
    unit = to_unit([LINEAR, SMALL], pd.DataFrame(points)[["friction", "restitution"]].to_numpy())
    heat = 4.0 * unit[:, 0] + unit[:, 1]
    ensemble = analyse(members_table(points, heat), [LINEAR, SMALL], tmp_path)
    spread = ensemble.headline("heat_power_W")
    assert spread.quantiles == pytest.approx(tuple(np.quantile(heat, (0.05, 0.5, 0.95))))
    assert spread.surrogate_q2 > 0.99
    assert spread.total["friction"] == pytest.approx(16 / 17, abs=0.03)
    assert spread.first["restitution"] == pytest.approx(1 / 17, abs=0.03)
    assert spread.deciding == ["friction", "restitution"]
    rise = ensemble.headline("ball_rise_K")
    assert rise.quantiles == pytest.approx(tuple(5.0 * np.quantile(heat, (0.05, 0.5, 0.95))))
    summary = ensemble.as_dict()
    assert summary["headlines"]["heat_power_W"]["deciding"] == ["friction", "restitution"]
    assert summary["members"] == 64 and summary["failed"] == 0


def test_a_headline_the_surrogate_cannot_predict_gets_no_indices(tmp_path: Path):
    points = design([LINEAR, SMALL], 32, seed=6)
    noise = np.random.default_rng(7).normal(size=32)
    spread = analyse(members_table(points, 10.0 + noise), [LINEAR, SMALL], tmp_path).headline("heat_power_W")
    assert spread.surrogate_q2 < 0.5 and spread.total == {} and spread.deciding == []


def test_a_share_zero_to_round_off_does_not_vary_where_a_power_of_that_size_does(tmp_path: Path):
    points = design([LINEAR], 16, seed=9)
    round_off = np.linspace(0.0, 3e-17, 16)
    ensemble = analyse(members_table(points, 1e-16 + round_off, stress_lasting_share=round_off), [LINEAR], tmp_path)
    assert not ensemble.headline("stress_lasting_share").varies
    assert ensemble.headline("heat_power_W").varies


def test_failed_members_are_counted_and_left_out(tmp_path: Path):
    points = design([LINEAR], 8, seed=8)
    table = members_table(points, np.arange(8.0))
    table.loc[3, "error"] = "the mechanics failed"
    table.loc[3, "heat_power_W"] = np.nan
    ensemble = analyse(table, [LINEAR], tmp_path)
    assert ensemble.failed == 1 and len(ensemble.table) == 7


def test_a_charge_is_a_pack_when_lasting_contacts_dissipate_most_and_fast_impacts_are_rare():
    # Ten balls at 13.33 turns/s: fewer than 133.3 impacts a second above 1 m/s is under one a ball and turn.
    assert charge_regime(0.95, 133.0, 10, 13.33) == PACK
    assert charge_regime(0.95, 134.0, 10, 13.33) == ACTIVE
    assert charge_regime(0.49, 0.0, 10, 13.33) == ACTIVE
    assert charge_regime(0.5, 0.0, 10, 13.33) == PACK


def test_regimes_with_their_share_and_medians(tmp_path: Path):
    points = design([LINEAR], 8, seed=9)
    heat = np.linspace(18.0, 26.0, 8)
    table = members_table(
        points,
        heat,
        charge_regime=np.array([PACK] * 4 + [ACTIVE] * 4),
        stress_energy_median_J=np.linspace(1e-4, 1e-3, 8),
    )
    regimes = analyse(table, [LINEAR], tmp_path).regimes
    assert regimes["pack"]["share"] == 0.5 and regimes["active"]["members"] == 4
    assert regimes["pack"]["medians"]["heat_power_W"] == pytest.approx(np.median(heat[:4]))
    assert regimes["active"]["medians"]["stress_energy_median_J"] > regimes["pack"]["medians"]["stress_energy_median_J"]


def test_a_calibrations_posterior_joins_the_design_as_independent_normals(tmp_path: Path):
    rng = np.random.default_rng(10)
    samples = rng.multivariate_normal([np.log(20.0), np.log(3000.0)], [[0.04, 0.03], [0.03, 0.09]], size=400)
    posterior = fitted_posterior(("drive_heat", "clamp_heat_capacity"), samples.tolist())
    assert posterior.names == ("drive_heat (fitted)", "clamp_heat_capacity (fitted)")
    points = design([LINEAR], 256, seed=11, posterior=posterior)
    logs = np.log([[point["drive_heat"], point["clamp_heat_capacity"]] for point in points])
    # The design reproduces the posterior's mean and correlation in the logarithms.
    np.testing.assert_allclose(logs.mean(axis=0), samples.mean(axis=0), atol=0.02)
    assert np.corrcoef(logs.T)[0, 1] == pytest.approx(np.corrcoef(samples.T)[0, 1], abs=0.05)
    unit = posterior.unit(np.exp(logs))
    np.testing.assert_allclose(posterior.values(unit), np.exp(logs), rtol=1e-10)
    # A headline that follows the drive's heat alone is decided by it.
    table = members_table(points[:32], np.exp(logs[:32, 0]))
    ensemble = analyse(table, [LINEAR], tmp_path, posterior)
    assert ensemble.headline("heat_power_W").deciding[0] == "drive_heat (fitted)"
    assert set(ensemble.as_dict()["fitted"]) == {"drive_heat", "clamp_heat_capacity"}
    assert fitted_posterior(("drive_heat",), [[1.0]]) is None


def test_the_interval_is_split_into_its_named_parts(tmp_path: Path):
    # heat = 4·u + 2·ξ-part + noise: the assumed input, the posterior and the members' own noise each take a share.
    rng = np.random.default_rng(12)
    samples = rng.normal([np.log(20.0)], [0.2], size=(300, 1))
    posterior = fitted_posterior(("drive_heat",), samples.tolist())
    points = design([LINEAR], 64, seed=13, posterior=posterior)
    friction = np.array([point["friction"] for point in points])
    drive = np.log([point["drive_heat"] for point in points])
    heat = 4.0 * friction + 2.0 * (drive - np.log(20.0)) / 0.2 * 0.3 + rng.normal(0.0, 0.2, size=64)
    parts = analyse(members_table(points, heat), [LINEAR], tmp_path, posterior).headline("heat_power_W").parts
    # Variances: 16/12 = 1.33 (assumed), 0.6² = 0.36 (posterior), 0.04 (noise): shares 0.77, 0.21, 0.02.
    assert parts["assumed inputs"] == pytest.approx(0.77, abs=0.08)
    assert parts["fitted keys' posterior"] == pytest.approx(0.21, abs=0.06)
    assert 0.0 < parts["unexplained"] < 0.08


FITTED_FILE = PRESET_FOLDER / "spex8000m-3d-calibrated-paper.toml"


def test_a_key_the_user_sets_wins_over_a_fitted_files_posterior_and_the_others_keep_their_marginal(tmp_path: Path):
    mine = tmp_path / "fitted.toml"
    shutil.copy(FITTED_FILE, mine)
    config = load_config(mine, overrides=["beta=5"])
    whole = fitted_keys_posterior(config_preset(load_config(mine)), load_config(mine).params)[0]
    inputs, posterior, notes = ensemble_inputs(config_preset(config), config.params, [], [], config.explicit)
    assert posterior is not None and whole is not None
    assert posterior.keys == ("vial_mass", "h_outer")
    # The marginal of a Gaussian: the same means and covariance of the keys drawn, without beta's.
    whole_covariance = whole.factor @ whole.factor.T
    np.testing.assert_allclose(posterior.mean, whole.mean[1:])
    np.testing.assert_allclose(posterior.factor @ posterior.factor.T, whole_covariance[1:, 1:])
    assert notes == [
        "beta: the run's own value, not drawn from the posterior of fitted's calibration; vial_mass, h_outer drawn "
        "from their marginal posterior"
    ]
    assert all("beta" not in point for point in design(inputs, 8, seed=1, posterior=posterior))


def test_a_calibration_that_recorded_only_its_covariance_is_drawn_about_its_fitted_values():
    preset = PRESETS["spex8000m-calibrated"]
    posterior, notes = fitted_keys_posterior(preset, default_parameters("spex8000m-calibrated"))
    assert posterior is not None and posterior.keys == preset.fitted
    np.testing.assert_allclose(np.exp(posterior.mean), [preset.values[key].value for key in preset.fitted])
    np.testing.assert_allclose(posterior.factor @ posterior.factor.T, preset.covariance)
    assert "covariance_log" in notes[0]
    broken = dataclasses.replace(preset, provenance={**preset.provenance, "covariance_log": [[1.0, 2.0], [2.0, 1.0]]})
    with pytest.raises(ParameterError, match=r"covariance_log: a symmetric 4 x 4 matrix is needed"):
        fitted_keys_posterior(broken, default_parameters("spex8000m-calibrated"))


def test_an_input_the_bore_moves_takes_no_range_of_its_own():
    with pytest.raises(ParameterError, match=r"^inner_area: its value is derived from the bore diameter and length"):
        ensemble_inputs(PRESETS["pm100"], default_parameters("pm100"), ["inner_area=0.005:0.009"], [])
    # Alone, nothing moves it: it is the user's to vary.
    inputs, _, _ = ensemble_inputs(
        PRESETS["pm100"], default_parameters("pm100"), ["inner_area=0.005:0.009"], ["inner_area"]
    )
    assert [item.key for item in inputs] == ["inner_area"]
