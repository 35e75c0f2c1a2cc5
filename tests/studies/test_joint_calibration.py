"""Calibration over every uncertain input (issue 36 point 4): the emulated posterior against a problem whose posterior
is known by hand, predictions that carry inputs the fit left free, and the inputs a run frees."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shakermill.parameters.assumed import AssumedInput
from shakermill.parameters.presets import PRESETS, default_parameters
from shakermill.studies.calibration import joint as joint_calibration
from shakermill.studies.calibration.emulators import emulate, predict
from shakermill.studies.calibration.joint import fit_inputs, prior_sample, sample_posterior
from shakermill.studies.calibration.observables import Measured, Observable
from shakermill.studies.calibration.training import Training

A = AssumedInput("friction", 0.0, 1.0, "uniform", "a test's range")
B = AssumedInput("restitution", 0.0, 1.0, "uniform", "a test's range")
Y, Z = Observable("ball", 3600.0), Observable("vial", 3600.0)


def linear_training(inputs, slopes, points=48):
    """Rises that are exactly linear in the inputs' unit coordinates: ``slopes`` (observables × inputs), K."""
    unit = np.random.default_rng(3).random((points, len(inputs)))
    rises = unit @ np.asarray(slopes, dtype=float).T
    observables = (Y, Z)[: len(slopes)]
    return Training(tuple(inputs), observables, unit, rises, np.arange(points))


@pytest.fixture(name="short_chain")
def short_chain_fixture(monkeypatch):
    # A posterior of one or two inputs mixes within a few hundred steps.
    monkeypatch.setattr(joint_calibration, "STEPS", 2000)


def test_the_posterior_of_a_linear_model_is_the_hand_computed_gaussian(short_chain):
    # y = 10 a K measured as 4 K with σ = 0.5 K and a uniform prior on [0, 1]: a ~ N(0.4, 0.05²), far from the edges.
    emulator = emulate(linear_training([A], [[10.0]]))
    assert emulator.q2[Y.name] > 0.99
    posterior = sample_posterior([(emulator, [Measured(Y, 4.0, 0.5)])])
    low, median, high = posterior.quantiles()["friction"]
    assert median == pytest.approx(0.4, abs=0.01)
    assert high - low == pytest.approx(2 * 1.645 * 0.05, rel=0.15)
    assert 0.2 < posterior.acceptance < 0.9


def test_a_prediction_carries_the_fit_and_draws_what_the_fit_left_free_from_its_prior(short_chain):
    fitted = emulate(linear_training([A], [[10.0]]))
    # The other configuration reads b too, which the fit knows nothing of: its vial rise is 20 a + 6 b.
    other = emulate(linear_training([A, B], [[20.0, 0.0], [20.0, 6.0]]))
    posterior = sample_posterior([(fitted, [Measured(Y, 4.0, 0.5)])])
    ball, vial = predict(other, posterior, [Measured(Y, 8.0), Measured(Z, 30.0)])
    assert ball.quantiles[1] == pytest.approx(8.0, abs=0.2)
    assert ball.quantiles[2] - ball.quantiles[0] == pytest.approx(2 * 1.645 * 20 * 0.05, rel=0.2)
    assert ball.inside is True
    # 20 a + 6 b with b uniform: the interval is about 6·0.9 = 5.4 K wider than the ball's alone, around 8 + 3 K.
    assert vial.quantiles[1] == pytest.approx(11.0, abs=0.5)
    assert vial.quantiles[2] - vial.quantiles[0] > 5.0
    assert vial.inside is False and vial.measured_K == 30.0
    # Before any measurement the prior alone spreads the ball's rise over most of 0-20 K.
    prior_ball = predict(other, prior_sample(other.inputs))[0]
    assert prior_ball.quantiles[0] < 2.0 and prior_ball.quantiles[2] > 18.0


def test_two_configurations_fit_together_constrain_their_shared_input_more_than_either(short_chain):
    one = emulate(linear_training([A], [[10.0]]))
    two = emulate(linear_training([A, B], [[10.0, 0.0]]))
    alone = sample_posterior([(one, [Measured(Y, 4.0, 0.5)])])
    both = sample_posterior([(one, [Measured(Y, 4.0, 0.5)]), (two, [Measured(Y, 4.0, 0.5)])])
    assert both.keys == ("friction", "restitution")
    width = {
        name: found.quantiles()["friction"][2] - found.quantiles()["friction"][0]
        for name, found in (("alone", alone), ("both", both))
    }
    # Two independent measurements of the same quantity: the spread shrinks by √2.
    assert width["both"] == pytest.approx(width["alone"] / math.sqrt(2), rel=0.2)
    # b is in no likelihood: its posterior is its prior.
    low, _, high = both.quantiles()["restitution"]
    assert low < 0.1 and high > 0.9


def test_an_emulator_checked_on_runs_it_did_not_see_reports_a_poor_q2_for_noise():
    training = linear_training([A], [[10.0]])
    training.rises = np.random.default_rng(5).standard_normal(training.rises.shape)
    assert emulate(training).q2[Y.name] < 0.5


def test_a_run_of_one_ball_frees_no_pair_key_and_the_network_keys_over_their_defensible_ranges():
    preset = PRESETS["spex8000m-3d-mill-head"]
    free = ("drive_heat", "clamp_heat_capacity", "clamp_loss")
    one = {item.key: item for item in fit_inputs(preset, default_parameters(preset.name, n_balls=1), free)}
    five = {item.key: item for item in fit_inputs(preset, default_parameters(preset.name, n_balls=5), free)}
    assert not [key for key in one if key.startswith("pair_")]
    assert {"pair_friction", "pair_restitution"} <= set(five)
    assert {"friction", "restitution", "lam", "lateral_amplitude", "yaw_amplitude"} <= set(one)
    for key in free:
        assert one[key].distribution == "log-uniform" and one[key].reason.startswith("fitted: ")
        assert one[key].low < getattr(default_parameters(preset.name), key) < one[key].high


@pytest.mark.slow
def test_calibrate_with_assumed_writes_a_preset_of_posterior_medians_whose_mechanical_keys_a_run_does_not_carry(
    tmp_path, monkeypatch
):
    import json

    from typer.testing import CliRunner

    from shakermill import cli
    from shakermill.parameters.config import config_preset, load_config
    from shakermill.studies.calibration.intervals import uncertainty_of

    monkeypatch.setattr(joint_calibration, "STEPS", 600)

    def fit(out, problems):
        # Eight runs cannot make a reliable emulator of nine inputs; whether a fit is reliable is decided here, so
        # that both outcomes are seen (the second fit reuses the first one's runs).
        monkeypatch.setattr(joint_calibration, "reliability_problems", lambda emulators, posterior: problems)
        arguments = ["calibrate", "--preset", "spex8000m-3d-mill-head", "--with-assumed", "--members", "8", "--json"]
        return CliRunner().invoke(cli.app, [*arguments, "--out", str(out), "--runs", str(tmp_path / "runs")])

    # Issue 49, point 9: an unreliable fit says why and writes nothing.
    unreliable = fit(tmp_path / "unreliable.toml", ["a test's reason"])
    assert unreliable.exit_code == 1 and not (tmp_path / "unreliable.toml").exists()
    assert json.loads(unreliable.stdout)["output"] is None
    assert "unreliable (nothing written to" in unreliable.stderr and "a test's reason" in unreliable.stderr
    out = tmp_path / "fitted.toml"
    outcome = fit(out, [])
    assert outcome.exit_code == 0, outcome.output
    payload = json.loads(outcome.stdout)
    inputs = payload["posterior"]["inputs"]
    assert {"friction", "restitution", "lam", "lateral_amplitude", "drive_heat", "clamp_loss"} <= set(inputs)
    assert not [key for key in inputs if key.startswith("pair_")]
    for item in inputs.values():
        assert item["low"] <= item["p5"] <= item["p50"] <= item["p95"] <= item["high"]
    # The experiment's curve enters at six times; each point is held against its posterior-predictive interval.
    assert len(payload["fitted_points"]) == joint_calibration.CURVE_POINTS
    for point in payload["fitted_points"]:
        assert point["inside_90"] == (point["p5"] <= point["measured_K"] <= point["p95"])
    assert {item["observable"] for item in payload["predictions"]} == {"ball@3600s", "vial@3600s"}
    assert payload["status"] == "sampled" and "unreliable" not in payload["message"]
    assert payload["output"] == str(out)
    config = load_config(out)
    preset = config_preset(config)
    assert set(preset.fitted) == set(inputs) and not set(preset.assumed) & set(inputs)
    assert config.params.friction == pytest.approx(inputs["friction"]["p50"])
    carried = uncertainty_of(preset)
    assert set(carried.fitted) == {"drive_heat", "clamp_heat_capacity", "clamp_loss", "emissivity", "clamp_conductance"}
    assert "friction" in carried.left_out and carried.posterior.samples.shape[1] == len(carried.fitted)


def test_a_users_configuration_narrows_an_assumed_range_and_a_wrong_table_is_refused_in_one_line(tmp_path):
    from shakermill.parameters.config import config_preset, load_config
    from shakermill.parameters.errors import ParameterError

    narrowed = tmp_path / "mine.toml"
    narrowed.write_text(
        'preset = "spex8000m-3d"\n[assumed.friction]\nlow = 0.25\nhigh = 0.35\n'
        'distribution = "uniform"\nreason = "measured on our vial, ±0.05"\n',
        encoding="utf-8",
    )
    assumed = config_preset(load_config(narrowed)).assumed
    assert (assumed["friction"].low, assumed["friction"].high) == (0.25, 0.35)
    assert assumed["friction"].reason == "measured on our vial, ±0.05"
    assert assumed["restitution"] == PRESETS["spex8000m-3d"].assumed["restitution"]
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(
        'preset = "spex8000m-3d"\n[assumed.friction]\nlow = 0.5\nhigh = 0.4\n'
        'distribution = "uniform"\nreason = "typo"\n',
        encoding="utf-8",
    )
    with pytest.raises(ParameterError, match=r"wrong.toml: \[assumed.friction\]: low and high"):
        load_config(wrong)


def test_a_free_key_the_run_does_not_read_or_that_moves_the_mechanics_is_refused_before_any_run():
    from shakermill.parameters.errors import ParameterError
    from shakermill.studies.calibration.joint import calibrate_jointly

    preset = PRESETS["spex8000m-3d-mill-head"]
    params = default_parameters(preset.name)
    started = []
    for free, refused in (
        (("h_outer",), r"^free: h_outer: fitted, but the 'mill-head' network does not read it"),
        (("friction",), r"^free: friction would change the dem engine's mechanics.*--with-assumed"),
    ):
        with pytest.raises(ParameterError, match=refused):
            calibrate_jointly(preset, params, free, [], 8, on_start=lambda: started.append(True))
    assert started == []
