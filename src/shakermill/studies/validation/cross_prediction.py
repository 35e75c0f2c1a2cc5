"""Both directions of the SPEX measurements (issue 36 point 4, for ``validate --full``): fitted over every uncertain
input on the one-ball curve, is the five-ball measurement inside the 90 % posterior-predictive interval; fitted on
the five-ball point, is the one-ball curve inside. Each fit frees the assumed inputs its run can feel, with their
stated ranges as priors, and the network's own free keys over their defensible ranges
(:mod:`studies.calibration.joint`); nothing else is tuned.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.defaults import DEFAULT_FREE_BY_NETWORK
from shakermill.parameters.presets import PRESETS, default_parameters
from shakermill.studies.calibration.emulators import Emulator, Prediction, emulate, inside_count, predict
from shakermill.studies.calibration.joint import fit_inputs, prior_sample, reliability_problems, sample_posterior
from shakermill.studies.calibration.observables import (
    ASSUMED_MEASUREMENT_SD_K,
    Measured,
    Observable,
    measured_of,
)
from shakermill.studies.calibration.training import train
from shakermill.studies.inference.posterior import Posterior
from shakermill.studies.sweeps.executor import LOCAL_POOL, Execution
from shakermill.studies.validation.matrix import Experiment, load_experiments

# The uncalibrated preset both fits start from: the calibrated one was fitted to the one-ball curve already.
BASE_PRESET = "spex8000m-3d-mill-head"
ONE_BALL, FIVE_BALLS = "takacs-mchenry-one-ball", "takacs-mchenry-five-balls"
# Mechanical runs of each configuration and network points per run: 32 x 8 = 256 training points a configuration.
MEMBERS, THERMAL_DRAWS = 32, 8
# The averaged mechanics' target error: 5 % of the heat power is ~1 K of a rise, half the measurements' 2 K, and the
# emulator's white noise takes it up; at 1 % a lone ball on some of the design's clamp motions takes minutes.
AVERAGING_ERROR = 0.05


@dataclass(frozen=True)
class Direction:
    """A fit on one experiment and what it then predicts of the other, beside what the prior alone predicts."""

    fitted_on: Experiment
    predicted: Experiment
    posterior: Posterior
    fitted: tuple[Prediction, ...]  # the fitted experiment's own points at the posterior
    predictions: tuple[Prediction, ...]
    prior_predictions: tuple[Prediction, ...]
    problems: tuple[str, ...] = ()  # why it cannot be relied on (calibration.joint.reliability_problems)

    @property
    def verdict(self) -> str:
        return (
            f"fitted on {self.fitted_on.name} ({inside_count(self.fitted)} of its {len(self.fitted)} points inside "
            f"their own 90 % intervals): {inside_count(self.predictions)} of the {len(self.predictions)} measured "
            f"points of {self.predicted.name} inside their 90 % intervals"
        )

    def as_dict(self) -> dict[str, Any]:
        return {
            "fitted_on": self.fitted_on.name,
            "predicted": self.predicted.name,
            "verdict": self.verdict,
            "unreliable": self.problems,
            "posterior": self.posterior.as_dict(),
            "fitted_points": [prediction.as_dict() for prediction in self.fitted],
            "predictions": [prediction.as_dict() for prediction in self.predictions],
            "prior_predictions": [prediction.as_dict() for prediction in self.prior_predictions],
        }


@dataclass(frozen=True)
class CrossPrediction:
    preset: str
    free: tuple[str, ...]
    emulators: Mapping[str, Emulator]
    directions: tuple[Direction, ...]

    def as_dict(self) -> dict[str, Any]:
        return {
            "preset": self.preset,
            "network_free": list(self.free),
            "measurement_sd_K": ASSUMED_MEASUREMENT_SD_K,
            "averaging_error": AVERAGING_ERROR,
            "emulators": {name: emulator.as_dict() for name, emulator in self.emulators.items()},
            "directions": [direction.as_dict() for direction in self.directions],
        }


def cross_prediction(
    preset: str = BASE_PRESET,
    members: int = MEMBERS,
    thermal_draws: int = THERMAL_DRAWS,
    overrides: Mapping[str, Any] | None = None,
    progress: Callable[[int, int], None] | None = None,
    execution: Execution = LOCAL_POOL,
) -> CrossPrediction:
    """Emulate both experiments over their uncertain inputs, fit each and predict the other (module docstring);
    ``progress(done, total)`` counts the mechanical members of both, which run as ``execution`` says (in parallel
    on one worker a core by default) into a temporary folder: validate writes nothing until its end."""
    experiments = {experiment.name: experiment for experiment in load_experiments()}
    pair = (experiments[ONE_BALL], experiments[FIVE_BALLS])
    settings = {
        "solver": "averaged",
        "record_windows": (),
        "attractor_starts": 1,
        "dem_averaging_rel_error": AVERAGING_ERROR,
        **(overrides or {}),
    }
    free = DEFAULT_FREE_BY_NETWORK[PRESETS[preset].values["thermal_model"].value]
    emulators = {}
    for index, experiment in enumerate(pair):
        params = default_parameters(preset, **{**settings, **experiment.conditions})
        observables = [Observable(point.node, point.time_s) for point in experiment.points]
        shown = (
            None
            if progress is None
            else (lambda done, total, before=index * members: progress(before + done, 2 * members))
        )
        inputs = fit_inputs(PRESETS[preset], params, free)
        training = train(params, inputs, observables, members, thermal_draws, shown, execution=execution)
        emulators[experiment.name] = emulate(training)
    directions = tuple(_direction(fitted_on, predicted, emulators) for fitted_on, predicted in (pair, pair[::-1]))
    return CrossPrediction(preset, tuple(free), emulators, directions)


def _direction(fitted_on: Experiment, predicted: Experiment, emulators: Mapping[str, Emulator]) -> Direction:
    measured: list[Measured] = measured_of(fitted_on)
    source, target = emulators[fitted_on.name], emulators[predicted.name]
    posterior = sample_posterior([(source, measured)])
    return Direction(
        fitted_on,
        predicted,
        posterior,
        tuple(predict(source, posterior, measured)),
        tuple(predict(target, posterior, measured_of(predicted))),
        tuple(predict(target, prior_sample(target.inputs), measured_of(predicted))),
        tuple(reliability_problems((source, target), posterior)),
    )
