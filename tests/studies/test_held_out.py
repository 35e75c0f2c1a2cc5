"""The held-out five-ball prediction and the one-ball comparison of the engines (studies/validation/held_out.py)."""

from __future__ import annotations

import math

import pytest

from shakermill.parameters.presets import PRESETS
from shakermill.studies.validation.held_out import (
    ENGINE_CASES,
    FIVE_BALLS,
    HELD_OUT_PRESET,
    engine_comparison,
    five_ball_parameters,
    five_ball_prediction,
    five_ball_rows,
)

# A few drive periods at full resolution: what the study is made of, not its numbers (validate gives those).
QUICK = {"solver": "full", "duration": 0.3}


def test_the_rises_and_their_errors_are_read_from_the_summary(default_run_20s):
    summary = default_run_20s.summary.updated(initial_temperature_C=20.0, ball_C=89.0, vial_C=41.0, vial_ball_ratio=0.3)
    rows = five_ball_rows(summary)
    ball, vial, ratio = rows
    assert (ball.experiment, vial.experiment, ratio.experiment) == (46.0, 21.0, 0.46)
    assert ball.predicted == 69.0 and ball.relative_error == pytest.approx(0.5)
    assert vial.predicted == 21.0 and vial.relative_error == 0.0
    assert ratio.relative_error == pytest.approx(0.3 / 0.46 - 1.0)


def test_the_held_out_preset_was_fitted_to_one_ball_and_runs_five_unrefitted():
    preset = PRESETS[HELD_OUT_PRESET]
    assert preset.values["n_balls"].value == 1 and preset.fitted
    params = five_ball_parameters()
    assert params.n_balls == FIVE_BALLS and params.duration == 3600.0 and params.solver == "averaged"
    for key in preset.fitted:
        assert getattr(params, key) == preset.values[key].value  # nothing refitted


@pytest.mark.slow
def test_the_prediction_says_what_was_fitted_and_that_the_rest_is_predicted():
    prediction = five_ball_prediction(QUICK)
    assert prediction.summary.charge.n_balls == FIVE_BALLS
    assert all(math.isfinite(row.predicted) for row in prediction.rows)
    assert prediction.rows[0].predicted == pytest.approx(prediction.summary.ball_C - 20.0)
    assert "nothing was refitted" in prediction.statement
    assert all(key in prediction.statement for key in PRESETS[HELD_OUT_PRESET].fitted)


def test_the_engines_agree_in_their_overlap_and_differ_beyond_it():
    comparison = engine_comparison(ENGINE_CASES[:2], overrides={**QUICK, "duration": 1.0})
    one_d, limit = comparison.values
    # The 3-D engine with one ball on the axis, no gravity and no friction is the 1-D model (MODEL.md §12).
    assert comparison.change("heat_power_W", 1) == pytest.approx(0.0, abs=0.02)
    assert limit["hit_rate_hz"] == pytest.approx(one_d["hit_rate_hz"], rel=0.05)
    assert limit["mean_hit_speed_m_s"] == pytest.approx(one_d["mean_hit_speed_m_s"], rel=0.02)
