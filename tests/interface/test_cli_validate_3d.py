"""`shakermill validate`'s three-dimensional part: the held-out five-ball prediction, the engines on one ball,
and the sensitivity to the assumed SPEX motion, through the command (short runs stand in for the hour)."""

from __future__ import annotations

import functools
import html
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from shakermill import cli
from shakermill.parameters.assumed import AssumedInput
from shakermill.studies.calibration import joint as joint_calibration
from shakermill.studies.calibration.emulators import emulate
from shakermill.studies.calibration.observables import Observable
from shakermill.studies.calibration.training import Training
from shakermill.studies.validation import cross_prediction, held_out, powder
from shakermill.studies.validation import report as validation_report
from shakermill.studies.validation.matrix import THERMAL_MODEL_PRESETS, load_experiments, validation_matrix
from shakermill.studies.validation.table5 import VALIDATION_PRESETS
from shakermill.views.validation_page import CROSS_TITLE, QUICK_NOTE

runner = CliRunner()
# A few drive periods at full resolution for every run: the command's shape, not its numbers.
QUICK = {"solver": "full", "duration": 0.2}


@pytest.fixture(name="quick_runs")
def quick_runs_fixture(monkeypatch):
    monkeypatch.setattr(held_out, "five_ball_prediction", functools.partial(held_out.five_ball_prediction, QUICK))
    monkeypatch.setattr(held_out, "five_ball_sensitivity", functools.partial(held_out.five_ball_sensitivity, QUICK))
    monkeypatch.setattr(held_out, "engine_comparison", functools.partial(held_out.engine_comparison, overrides=QUICK))
    monkeypatch.setattr(validation_report, "validation_matrix", functools.partial(validation_matrix, overrides=QUICK))
    monkeypatch.setattr(validation_report, "powder_studies", functools.partial(powder.powder_studies, QUICK))
    # Each structure's fit runs the one-ball hour: its study has tests of its own.
    monkeypatch.setattr(validation_report, "structure_study", lambda progress: ())
    # Both directions run 64 averaged hours: emulators of made-up rises stand in
    # (tests/studies/test_joint_calibration.py tests the method, its CLI test the runs).
    monkeypatch.setattr(joint_calibration, "STEPS", 400)
    monkeypatch.setattr(validation_report, "cross_prediction", made_up_cross_prediction)


def made_up_cross_prediction(progress):
    """Both directions on emulators of rises linear in one input: each experiment's points at 1-2x the measured."""
    experiments = {experiment.name: experiment for experiment in load_experiments()}
    emulators = {}
    unit = np.random.default_rng(1).random((16, 1))
    for name in (cross_prediction.ONE_BALL, cross_prediction.FIVE_BALLS):
        points = experiments[name].points
        rises = np.column_stack([point.rise_K * (1.0 + unit[:, 0]) for point in points])
        training = Training(
            (AssumedInput("friction", 0.1, 0.6, "uniform", "a test's"),),
            tuple(Observable(point.node, point.time_s) for point in points),
            unit,
            rises,
            np.arange(16),
        )
        emulators[name] = emulate(training)
    pair = (experiments[cross_prediction.ONE_BALL], experiments[cross_prediction.FIVE_BALLS])
    directions = tuple(
        cross_prediction._direction(fitted_on, predicted, emulators) for fitted_on, predicted in (pair, pair[::-1])
    )
    return cross_prediction.CrossPrediction("spex8000m-3d-mill-head", ("drive_heat",), emulators, directions)


@pytest.mark.slow
def test_validate_prints_the_five_ball_prediction_the_engines_and_the_sensitivity(quick_runs):
    outcome = runner.invoke(cli.app, ["validate", "--full", "--solver", "averaged", "--no-study"])
    assert outcome.exit_code == 0, outcome.output
    text = outcome.stdout
    assert "Held out: five balls" in text and "nothing was refitted" in text
    for row in ("ball temperature rise after 1 h", "vial temperature rise after 1 h", "vial/ball rise ratio after 1 h"):
        assert row in text
    for case in held_out.ENGINE_CASES:
        assert case.label[:30] in text
    assert "lateral_amplitude × 0.5" in text and "yaw_amplitude × 1.5" in text
    assert "Validation matrix" in text and "It falsifies" in text
    for preset in THERMAL_MODEL_PRESETS:
        assert preset in text


@pytest.mark.slow
def test_validate_json_holds_predictions_with_errors_and_what_was_fitted(quick_runs, tmp_path):
    page = tmp_path / "validation.html"
    outcome = runner.invoke(
        cli.app, ["validate", "--full", "--solver", "averaged", "--no-study", "--json", "--report", str(page)]
    )
    assert outcome.exit_code == 0, outcome.output
    payload = json.loads(outcome.stdout)
    html = page.read_text(encoding="utf-8")
    for row in payload["validation_matrix"]["rows"]:
        assert f"{row['predicted_K']:.3g}" in html
    assert "Held out: five balls" in html and html.count("<img") == 1
    # Both directions of issue 36 point 4, each measured point plainly inside its interval or not.
    cross = payload["cross_prediction"]
    assert [(direction["fitted_on"], direction["predicted"]) for direction in cross["directions"]] == [
        (cross_prediction.ONE_BALL, cross_prediction.FIVE_BALLS),
        (cross_prediction.FIVE_BALLS, cross_prediction.ONE_BALL),
    ]
    for direction in cross["directions"]:
        for point in direction["predictions"]:
            assert point["inside_90"] == (point["p5"] <= point["measured_K"] <= point["p95"])
        assert direction["verdict"][1:] in html
    assert payload["ran"]["cross_prediction"] is True and CROSS_TITLE in html
    # Five SPEX balls and the planetary mill, each without and with its stated powder; the published ordering's sign.
    five_powder, planetary = payload["powder"]
    assert (five_powder["powder_kg"], planetary["powder_kg"]) == (
        powder.FIVE_BALL_POWDER_KG,
        powder.PLANETARY_POWDER_KG,
    )
    vial = next(row for row in planetary["rows"] if row["label"].startswith("vial"))
    assert (vial["measured_without"], vial["measured_with"]) == (10.0, 20.0)
    assert planetary["vial_warmer_with_powder"] == (vial["with_powder"] > vial["without"])
    assert five_powder["rows"][0]["measured_with"] == five_powder["rows"][0]["measured_without"] == 46.0
    assert five_powder["rows"][-1]["without"] is None  # no powder node, no powder temperature
    assert five_powder["title"] in html and "A planetary mill without and with powder" in html
    five = payload["five_balls"]
    assert five["preset"] == "spex8000m-3d-calibrated" and five["fitted_parameters"]
    rows = five["rows"]
    assert (
        rows["ball_rise_C"]["experiment"],
        rows["vial_rise_C"]["experiment"],
        rows["vial_ball_ratio"]["experiment"],
    ) == (46.0, 21.0, 0.46)
    for row in rows.values():
        assert row["relative_error"] == pytest.approx(row["predicted"] / row["experiment"] - 1.0)
    cases = payload["engine_comparison"]["cases"]
    assert [case["label"] for case in cases] == [case.label for case in held_out.ENGINE_CASES]
    assert payload["engine_comparison"]["units"]["heat_power_W"] == "W"
    sensitivity = payload["kinematic_sensitivity"]
    assert [(row["key"], row["factor"]) for row in sensitivity["rows"]] == [
        ("lateral_amplitude", 0.5),
        ("lateral_amplitude", 1.5),
        ("yaw_amplitude", 0.5),
        ("yaw_amplitude", 1.5),
    ]
    assert set(sensitivity["baseline"]) == set(held_out.SENSITIVITY_MEASURES)
    matrix = payload["validation_matrix"]
    assert set(matrix["experiments"]) == {experiment.name for experiment in load_experiments()}
    points = sum(len(experiment.points) for experiment in load_experiments())
    assert len(matrix["rows"]) == points * len(THERMAL_MODEL_PRESETS)
    for row in matrix["rows"]:
        if row["measured_K"] is None:
            assert row["role"] == "prediction" and row["relative_error"] is None
        else:
            assert row["relative_error"] == pytest.approx(row["predicted_K"] / row["measured_K"] - 1.0)
            low, high = row["interval_90_K"]
            assert row["inside_interval"] == (low <= row["measured_K"] <= high)


@pytest.mark.slow
def test_validate_is_quick_by_default_and_says_each_run_when_piped(quick_runs, tmp_path):
    page = tmp_path / "quick.html"
    outcome = runner.invoke(cli.app, ["validate", "--no-study", "--json", "--report", str(page)])
    assert outcome.exit_code == 0, outcome.output
    payload = json.loads(outcome.stdout)
    assert payload["solver"] == "averaged" and payload["full"] is False
    # The experiments of five balls and of none: no lone ball, whose mechanics take minutes, and no held-out studies.
    quick = {experiment.name for experiment in load_experiments() if experiment.conditions.get("n_balls", 1) != 1}
    assert set(payload["validation_matrix"]["experiments"]) == quick == {"takacs-mchenry-five-balls", "empty-mill"}
    assert "five_balls" not in payload and "structure_study" not in payload
    held_out_rows = [row for row in payload["validation_matrix"]["rows"] if row["role"] == "held out"]
    assert {row["experiment"] for row in held_out_rows} == {"takacs-mchenry-five-balls"}
    # Not a terminal: a plain line for each step (Table 5's runs, then each 3-D run, then the two powder comparisons),
    # so a log shows the study moving.
    steps = len(VALIDATION_PRESETS) + len(quick) * len(THERMAL_MODEL_PRESETS) + powder.POWDER_STEPS
    lines = [line for line in outcome.stderr.splitlines() if line.startswith("validation: ")]
    assert [line.split(",")[0] for line in lines] == [
        f"validation: {done}/{steps} steps" for done in range(1, steps + 1)
    ]
    assert outcome.stderr.startswith("validate: quick, ~2.5 min; --full for everything")
    # Its page says it is the quick one, and what --full adds.
    assert html.escape(QUICK_NOTE) in page.read_text(encoding="utf-8")


def test_a_report_that_exists_is_refused_before_the_study_runs(tmp_path, monkeypatch):
    page = tmp_path / "validation.html"
    page.write_text("mine", encoding="utf-8")
    monkeypatch.setattr(validation_report, "validation_report", lambda *args, **kwargs: pytest.fail("the study ran"))
    outcome = runner.invoke(cli.app, ["validate", "--report", str(page)])
    assert outcome.exit_code == 2 and "add --overwrite" in outcome.output
    assert page.read_text(encoding="utf-8") == "mine"
    outcome = runner.invoke(cli.app, ["validate", "--report", str(tmp_path)])
    assert outcome.exit_code == 2 and "a folder" in outcome.output
    outcome = runner.invoke(cli.app, ["validate", "--report", str(page / "under-a-file.html")])
    assert outcome.exit_code == 2 and "is not a folder; choose another --report" in outcome.output
    outcome = runner.invoke(cli.app, ["validate", "--no-three-d", "--report", str(tmp_path / "new.html")])
    assert outcome.exit_code == 2 and "allowed --report with --three-d" in outcome.output
