"""The validation matrix (studies/validation/matrix.py): experiments as data with their roles, and the predictions
that need no mechanics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shakermill.parameters.presets import PRESETS
from shakermill.solvers.simulate import simulate
from shakermill.studies.calibration.calibrate import DEFENSIBLE_RANGES
from shakermill.studies.validation.matrix import (
    STRUCTURES,
    THERMAL_MODEL_PRESETS,
    Structure,
    StructureOutcome,
    load_experiments,
    predict,
)

EXPERIMENTS = {experiment.name: experiment for experiment in load_experiments()}


def test_every_experiment_says_where_it_comes_from_and_what_it_measured():
    assert set(EXPERIMENTS) == {"takacs-mchenry-one-ball", "takacs-mchenry-five-balls", "empty-mill", "one-ball-vial"}
    for experiment in EXPERIMENTS.values():
        assert experiment.title and experiment.source and experiment.how_measured and experiment.points
    five = EXPERIMENTS["takacs-mchenry-five-balls"]
    assert five.conditions["n_balls"] == 5 and [(point.node, point.rise_K) for point in five.points] == [
        ("ball", 46.0),
        ("vial", 21.0),
    ]
    # The one-ball points are the summary's exponential 28·(1 − exp(−t/16.7 min)).
    for point in EXPERIMENTS["takacs-mchenry-one-ball"].points:
        assert point.rise_K == pytest.approx(28.0 * (1.0 - math.exp(-point.time_s / 60.0 / 16.7)), abs=1e-4)


@pytest.mark.parametrize("preset", THERMAL_MODEL_PRESETS)
def test_the_one_ball_curve_is_fitted_the_rest_held_out_or_predicted(preset):
    roles = {name: experiment.role(preset) for name, experiment in EXPERIMENTS.items()}
    assert roles == {
        "takacs-mchenry-one-ball": "fitted",
        "takacs-mchenry-five-balls": "held out",
        "empty-mill": "prediction",
        "one-ball-vial": "prediction",
    }
    assert EXPERIMENTS["takacs-mchenry-one-ball"].role("spex8000m-3d") == "held out"  # no calibration fitted it there


def test_an_empty_mill_warms_on_the_drives_heat_alone():
    rows = {preset: predict(preset, EXPERIMENTS["empty-mill"], simulate)[0] for preset in THERMAL_MODEL_PRESETS}
    paper, mill_head = rows["spex8000m-3d-calibrated-paper"], rows["spex8000m-3d-calibrated"]
    assert paper.predicted_K == 0.0 and paper.thermal_model == "paper"
    drive = PRESETS["spex8000m-3d-calibrated"].values["drive_heat"].value
    assert mill_head.thermal_model == "mill-head" and drive > 0.0 and mill_head.predicted_K > 0.0
    assert mill_head.low_K < mill_head.predicted_K < mill_head.high_K
    assert mill_head.role == "prediction" and mill_head.inside is None and np.isnan(mill_head.error)


@pytest.mark.parametrize(
    ("preset", "free", "rms", "edges", "meets"),
    [
        ("spex8000m-3d-mill-head", ("drive_heat",), 1.9, (), True),
        ("spex8000m-3d-mill-head", ("drive_heat",), 2.1, (), False),
        ("spex8000m-3d-mill-head", ("drive_heat",), 1.0, ("clamp_loss",), False),
        ("spex8000m-3d-mill-head", ("drive_heat", "beta"), 0.5, (), False),
        ("spex8000m-3d", ("vial_mass",), 0.5, (), False),
    ],
)
def test_the_bar_needs_the_curve_within_two_kelvin_no_edge_and_computed_paths(preset, free, rms, edges, meets):
    outcome = StructureOutcome(Structure("s", preset, free), {key: 1.0 for key in free}, rms, edges, 50.0, 20.0)
    assert outcome.meets_point_7 is meets
    assert outcome.as_dict()["meets_point_7"] is meets


def test_every_structure_fits_only_keys_with_a_stated_range_or_beta():
    for structure in STRUCTURES:
        assert set(structure.free) <= set(DEFENSIBLE_RANGES)
        at_correlation = dict(structure.fixed).get("beta", 1.0) == 1.0 and "beta" not in structure.free
        assert structure.physical == (at_correlation and structure.preset == "spex8000m-3d-mill-head")
    # β fixed away from Whitaker's correlation is not physical, however it was set.
    assert not Structure("s", "spex8000m-3d-mill-head", ("drive_heat",), (("beta", 1.3),)).physical
    assert Structure("s", "spex8000m-3d-mill-head", ("drive_heat",), (("beta", 1.0),)).physical
    # A mill-head network whose convection is not Whitaker's as published is not physical either.
    assert not Structure("s", "spex8000m-3d-calibrated-paper", ("drive_heat",)).physical
