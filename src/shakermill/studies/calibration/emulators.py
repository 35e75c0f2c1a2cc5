"""Emulators of a calibration's runs: one surrogate per observable over the unit cube of the inputs
(``studies.inference.surrogate``), of the rises' logarithms where every training rise is positive, checked on
mechanical members it did not see (grouped k-fold: held-out Q²); and what they predict at a posterior's samples, each
with a draw of the emulator's error: the posterior-predictive 5/50/95 %."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from shakermill.parameters.assumed import AssumedInput
from shakermill.parameters.errors import ParameterError
from shakermill.studies.calibration.observables import Measured, Observable
from shakermill.studies.calibration.training import Training
from shakermill.studies.inference.posterior import QUANTILES, Posterior
from shakermill.studies.inference.prior import Prior
from shakermill.studies.inference.surrogate import Surrogate, fit_surrogate

# Held-out folds of the mechanical members for the emulators' Q².
FOLDS = 4
# The seed of a prediction's draws (of the emulator's error, and of the inputs a fit left to their prior).
PREDICTION_SEED = 20261129


@dataclass
class Emulator:
    """One surrogate per observable over the unit cube of ``inputs``, of the rises' logarithms where every training
    rise is positive (``logarithmic``), and their held-out Q² (of the rises themselves)."""

    inputs: tuple[AssumedInput, ...]
    observables: tuple[Observable, ...]
    surrogates: list[Surrogate]
    training_points: int
    members: int
    failed: list[str]

    @property
    def prior(self) -> Prior:
        return Prior(self.inputs)

    @property
    def logarithmic(self) -> bool:
        return all(surrogate.logarithmic for surrogate in self.surrogates)

    @property
    def q2(self) -> dict[str, float]:
        return {observable.name: s.q2 for observable, s in zip(self.observables, self.surrogates, strict=True)}

    def _fitted_space(self, unit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        found = [surrogate.fitted_space(unit) for surrogate in self.surrogates]
        return np.column_stack([mean for mean, _ in found]), np.column_stack([sd for _, sd in found])

    def predict(self, unit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The rises and their standard deviations (points, observables) at ``unit`` (points, inputs): for a
        logarithmic emulator the median and its sd to first order."""
        mean, sd = self._fitted_space(unit)
        return (np.exp(mean), np.exp(mean) * sd) if self.logarithmic else (mean, sd)

    def draw(self, unit: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """One rise of each observable at each point, with a draw of the emulator's error."""
        mean, sd = self._fitted_space(unit)
        values = mean + sd * rng.standard_normal(mean.shape)
        return np.exp(values) if self.logarithmic else values

    def at(self, keys: Sequence[str], unit: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Unit-cube points of this emulator's inputs from points over ``keys``: an input not among them drawn from
        its prior (uniform in the cube)."""
        position = {key: index for index, key in enumerate(keys)}
        columns = [
            unit[:, position[item.key]] if item.key in position else rng.random(len(unit)) for item in self.inputs
        ]
        return np.column_stack(columns)

    def as_dict(self) -> dict[str, Any]:
        return {
            "members": self.members,
            "training_points": self.training_points,
            "held_out_q2": self.q2,
            "failed": self.failed,
        }


def emulate(training: Training) -> Emulator:
    """Fit an emulator per observable; measure its Q² on mechanical members held out, FOLDS groups of them. Rises
    that are all positive are emulated in their logarithms: the model multiplies (a heat power by a network's
    response), which the logarithm makes a sum, nearer the smooth function a Gaussian process assumes."""
    members = np.unique(training.member)
    if members.size < FOLDS:
        raise ParameterError(
            f"members: {members.size} runs succeeded, too few to check an emulator on held-out runs (at least {FOLDS})"
        )
    logarithmic = bool(np.all(training.rises > 0))
    surrogates = [
        fit_surrogate(training.unit, training.rises[:, column], FOLDS, training.member, logarithmic)
        for column in range(len(training.observables))
    ]
    return Emulator(
        training.inputs, training.observables, surrogates, len(training.unit), int(members.size), training.failed
    )


@dataclass(frozen=True)
class Prediction:
    """An observable's posterior-predictive 5/50/95 % (K), and the measurement it is held against, if any."""

    observable: Observable
    quantiles: tuple[float, float, float]
    measured_K: float | None = None

    @property
    def inside(self) -> bool | None:
        return None if self.measured_K is None else bool(self.quantiles[0] <= self.measured_K <= self.quantiles[2])

    def as_dict(self) -> dict[str, Any]:
        return {
            "observable": self.observable.name,
            "label": self.observable.label,
            **dict(zip(("p5", "p50", "p95"), self.quantiles)),
            "measured_K": self.measured_K,
            "inside_90": self.inside,
        }


def predict(emulator: Emulator, posterior: Posterior, measured: Sequence[Measured] = ()) -> list[Prediction]:
    """Each observable of ``emulator`` at the ``posterior``'s samples, an input it does not hold drawn from its prior,
    each with a draw of the emulator's error."""
    rng = np.random.default_rng(PREDICTION_SEED)
    draws = emulator.draw(emulator.at(posterior.keys, posterior.unit, rng), rng)
    table = np.quantile(draws, QUANTILES, axis=0)
    known = {item.observable: item.rise_K for item in measured}
    return [
        Prediction(
            observable,
            (float(table[0, column]), float(table[1, column]), float(table[2, column])),
            known.get(observable),
        )
        for column, observable in enumerate(emulator.observables)
    ]


def inside_count(predictions: Sequence[Prediction]) -> int:
    """How many of ``predictions`` hold their measurement inside their 90 % interval."""
    return sum(bool(prediction.inside) for prediction in predictions)
