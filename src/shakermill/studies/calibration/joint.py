"""Calibration over every uncertain input (MODEL.md §14.1, issue 36 point 4): the assumed inputs' ranges as priors,
the measurements as the likelihood, the posterior by emcee, and predictions with posterior-predictive intervals.

A fit of the thermal network alone (``studies/calibration/calibrate.py``) measures the mechanics once and moves keys the
mechanics does not read. Freeing friction, restitution, λ or the clamp's motion changes the mechanics, which costs a
three-dimensional run (seconds to minutes) where emcee needs tens of thousands of evaluations. So the model is
emulated, as Kennedy & O'Hagan (2001) calibrate a costly computer model:

* the training runs are a scrambled Sobol' design over the prior (:mod:`.training`): ``members`` runs of the
  mechanics over the inputs it reads, and at each ``thermal_draws`` points of the keys only the thermal network
  reads, run through the executor of many runs (in parallel, resumable);
* each measured quantity (a node's rise at a time) gets a surrogate over the unit cube of the inputs
  (:mod:`.emulators`, ``studies.inference.surrogate``), checked on mechanical members it did not see (grouped
  k-fold: held-out Q²);
* the posterior is sampled by emcee in the unit cube (``studies.inference.sampler``), the prior uniform there (each
  input's distribution maps the cube onto its range: ``studies.inference.prior``), the likelihood Gaussian with the
  measurement's standard deviation and the emulator's own predictive variance added, so that an emulator unsure of a
  region cannot pin the fit there;
* a prediction for other conditions (five balls from a one-ball fit, and back) is that configuration's emulator at
  the posterior samples, an input the fit did not constrain (the ball-ball pair keys for a one-ball fit) drawn from
  its prior, each sample with a draw of the emulator's error: the 5/50/95 % of those are the posterior-predictive
  interval, carrying the fit, the inputs it left free and the emulator.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC
from pathlib import Path
from typing import Any

import numpy as np

from shakermill.parameters.assumed import AssumedInput
from shakermill.parameters.engine_keys import reader_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.parameters.presets import Preset
from shakermill.studies.calibration.calibrate import check_free_for_engine, fitted_prior
from shakermill.studies.calibration.emulators import Emulator, Prediction, emulate, inside_count, predict
from shakermill.studies.calibration.fitted_preset import write_preset_file
from shakermill.studies.calibration.observables import ASSUMED_MEASUREMENT_SD_K, Measured, Observable
from shakermill.studies.calibration.training import group_folder, train
from shakermill.studies.inference.posterior import Posterior
from shakermill.studies.inference.prior import Prior
from shakermill.studies.inference.sampler import sample
from shakermill.studies.inference.surrogate import LEAST_Q2
from shakermill.studies.sweeps.executor import LOCAL_POOL, Execution

METHOD = "emulated Bayesian calibration over every uncertain input (MODEL.md §14.1)"
# emcee: walkers per input (at least LEAST_WALKERS), steps (the first half burn-in), samples kept; the seed makes
# the posterior reproducible.
WALKERS_PER_INPUT, LEAST_WALKERS = 4, 16
STEPS = 10000
KEPT = 2000
SEED = 20261128


def fit_inputs(preset: Preset, params: Parameters, free: Sequence[str]) -> list[AssumedInput]:
    """The inputs a calibration of ``params`` over everything uncertain frees: the assumed inputs ``preset`` states
    that the run reads (a run of one ball no pair key: the group's rule), and the thermal ``free`` keys, each
    log-uniform over its defensible range (the prior of the network's own fit, ``calibrate.fitted_prior``)."""
    reader = reader_of(params)
    assumed = [item for key, item in preset.assumed.items() if reader.not_read(key) is None and key not in free]
    return assumed + list(fitted_prior(params, free).inputs)


Data = Sequence[tuple[Emulator, Sequence[Measured]]]


def sample_posterior(data: Data, progress: Callable[[int, int], None] | None = None) -> Posterior:
    """The posterior of the inputs of every emulator of ``data`` given its measurements (each an observable of it);
    ``progress(step, steps)`` as the sampler goes."""
    import emcee

    prior = Prior.union(emulator.prior for emulator, _ in data)
    keys = prior.keys
    parts = []
    for emulator, measured in data:
        columns = [emulator.observables.index(item.observable) for item in measured]
        positions = [keys.index(item.key) for item in emulator.inputs]
        parts.append(
            (
                emulator,
                positions,
                columns,
                np.array([item.rise_K for item in measured]),
                np.array([item.sd_K for item in measured]) ** 2,
            )
        )

    def log_probability(unit: np.ndarray) -> np.ndarray:
        inside = np.all((unit > 0) & (unit < 1), axis=1)
        result = np.full(len(unit), -np.inf)
        if inside.any():
            total = np.zeros(int(inside.sum()))
            for emulator, positions, columns, observed, variance in parts:
                mean, sd = emulator.predict(unit[inside][:, positions])
                spread = variance + sd[:, columns] ** 2
                total -= 0.5 * np.sum((mean[:, columns] - observed) ** 2 / spread + np.log(spread), axis=1)
            result[inside] = total
        return result

    walkers = max(WALKERS_PER_INPUT * len(prior), LEAST_WALKERS)
    rng = np.random.default_rng(SEED)
    # Differential-evolution moves (ter Braak 2006; emcee's DEMove and DESnookerMove) mix faster than the default
    # stretch in a dozen dimensions where most inputs are barely constrained.
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    start = rng.uniform(0.05, 0.95, (walkers, len(prior)))
    return Posterior.sampled(
        prior, sample(log_probability, start, STEPS, KEPT, SEED, vectorize=True, moves=moves, progress=progress)
    )


def prior_sample(inputs: Sequence[AssumedInput]) -> Posterior:
    """KEPT points of the prior alone: what a prediction says before any measurement."""
    prior = Prior(tuple(inputs))
    return Posterior(tuple(prior.keys), np.random.default_rng(SEED).random((KEPT, len(prior))), prior=prior)


# A curve enters the fit at this many times, evenly spread over its points: its shape informs the fit, and an
# emulator a time is the cost (the points of one curve are not independent measurements anyway).
CURVE_POINTS = 6


@dataclass(frozen=True)
class JointCalibration:
    """A calibration over every uncertain input: the posterior, the curves' points and the run's end at it."""

    free: tuple[str, ...]  # the network's free keys; the assumed inputs are the rest of posterior.keys
    posterior: Posterior
    emulators: Mapping[tuple[str, ...], Emulator]  # by the conditions of their curves
    fitted: tuple[Prediction, ...]  # each curve point entered, with its measured rise
    predictions: tuple[Prediction, ...]  # the run's own configuration at its end
    curve_source: str

    @property
    def medians(self) -> dict[str, float]:
        return self.posterior.medians

    @property
    def status(self) -> str:
        """'sampled' where the chain is long enough and every emulator predicts runs it did not see (Q² ≥ 0.5);
        'unreliable' otherwise, and :attr:`message` says which."""
        return "sampled" if not self.problems else "unreliable"

    @property
    def problems(self) -> list[str]:
        return reliability_problems(self.emulators.values(), self.posterior)

    @property
    def message(self) -> str:
        said = (
            f"{inside_count(self.fitted)} of {len(self.fitted)} measured points inside their 90 % "
            "posterior-predictive intervals"
        )
        return said + (f"; unreliable: {'; '.join(self.problems)}" if self.problems else "")

    def as_dict(self) -> dict[str, Any]:
        return {
            "method": METHOD,
            "network_free": list(self.free),
            "status": self.status,
            "message": self.message,
            "posterior": self.posterior.as_dict(),
            "emulators": {
                ", ".join(conditions) or "the run's own": emulator.as_dict()
                for conditions, emulator in self.emulators.items()
            },
            "fitted_points": [item.as_dict() for item in self.fitted],
            "predictions": [item.as_dict() for item in self.predictions],
            "curve": self.curve_source,
        }


def reliability_problems(emulators: Iterable[Emulator], posterior: Posterior) -> list[str]:
    """Why a posterior and what it predicts cannot be relied on: an emulator that predicts runs it did not see with
    Q² below LEAST_Q2, or a chain shorter than 25 of its autocorrelation times after burn-in."""
    found = [
        f"the emulator of {observable} predicts held-out runs with Q² {value:.2f} (< {LEAST_Q2:g})"
        for emulator in emulators
        for observable, value in emulator.q2.items()
        if not value >= LEAST_Q2
    ]
    if not posterior.converged:
        found.append(
            f"the chain is {posterior.steps} steps after burn-in, under 25 of its autocorrelation times "
            f"({posterior.autocorrelation_steps:.0f} steps)"
        )
    return found


def calibrate_jointly(
    preset: Preset,
    base: Parameters,
    free: Sequence[str],
    curves: Sequence[Any],
    members: int,
    thermal_draws: int = 8,
    progress: Callable[[int, int], None] | None = None,
    on_start: Callable[[], None] | None = None,
    runs: Path | None = None,
    execution: Execution = LOCAL_POOL,
    say: Callable[[str], None] | None = None,
) -> JointCalibration:
    """Fit ``curves`` (``studies.measured.Curve``) over the network's ``free`` keys and every assumed input of
    ``preset`` that a run of ``base`` can feel (module docstring). As for ``calibrate``: the ``free`` keys must be
    the network's and read by the run, ``on_start()`` is called once they are, before the first run; ``progress(done,
    total)`` counts the mechanical members of every set of conditions. The members run as ``execution`` says, into
    ``runs`` (one folder a set of conditions; a temporary one where None): Ctrl-C raises
    ``executor.RunsInterrupted`` with the finished members kept there, and the same calibration resumes from them.
    ``say`` is told each phase after the runs (the emulators, the sampler's steps)."""
    check_free_for_engine(base, free)
    groups: dict[tuple[str, ...], list[Any]] = {(): []}
    for curve in curves:
        groups.setdefault(tuple(curve.conditions), []).append(curve)
    # Every curve's conditions checked before the first run: a bad one found after a set's runs wastes them.
    conditioned = {conditions: _conditioned(base, conditions) for conditions in groups}
    if on_start is not None:
        on_start()
    tell = say or (lambda _: None)
    data, emulators, total = [], {}, members * len(groups)
    for index, (conditions, chosen) in enumerate(groups.items()):
        params = conditioned[conditions]
        measured = [
            Measured(
                Observable(curve.node, float(curve.times[point])),
                float(curve.temperature_C[point]) + 273.15 - params.initial_temperature,
                curve.sigma_K if curve.sigma_K is not None else ASSUMED_MEASUREMENT_SD_K,
            )
            for curve in chosen
            for point in _spread_points(curve.times.size)
        ]
        at_end = [Observable(node, params.duration) for node in ("ball", "vial")] if not conditions else []
        observables = list(dict.fromkeys([item.observable for item in measured] + at_end))
        shown = None if progress is None else (lambda done, _, before=index * members: progress(before + done, total))
        inputs = fit_inputs(preset, params, free)
        training = train(
            params, inputs, observables, members, thermal_draws, shown, group_folder(runs, conditions), execution
        )
        tell(f"fitting the emulators of {len(observables)} measured quantities to the runs (held-out Q² each)")
        emulator = emulate(training)
        emulators[conditions] = emulator
        data.append((emulator, measured))
    posterior = sample_posterior(data, lambda step, steps: tell(f"sampling the posterior: step {step} of {steps}"))
    fitted = tuple(
        item
        for emulator, measured in data
        for item in predict(emulator, posterior, measured)
        if item.measured_K is not None
    )
    ends = tuple(item for item in predict(emulators[()], posterior) if item.observable.time_s == base.duration)
    source = "; ".join(curve.source for curve in curves)
    return JointCalibration(tuple(free), posterior, emulators, fitted, ends, source)


def check_has_balls(params: Parameters) -> None:
    """An empty mill heats nothing by impacts: its rises are the drive's alone, and the emulators of them would fit no
    ball (the runs all succeed, the fit fails only after them)."""
    if params.n_balls == 0:
        raise ParameterError(
            "n_balls: 0 is out of range for a calibration --with-assumed, which fits the balls' heat to a measured "
            "rise; allowed 1 or more"
        )


def _conditioned(base: Parameters, conditions: Sequence[str]) -> Parameters:
    """``base`` under a curve's ``conditions`` ("KEY=VALUE"): each value checked, each key one its run reads, and
    balls in the mill."""
    from shakermill.parameters.config import parse_overrides

    settings = parse_overrides(conditions)
    params = base.replace(**settings)
    problem = reader_of(params).unread_problem(settings, how="a curve's condition")
    if problem is not None:
        raise ParameterError(problem)
    check_has_balls(params)
    return params


def _spread_points(count: int) -> list[int]:
    return sorted(set(np.linspace(0, count - 1, min(count, CURVE_POINTS)).round().astype(int).tolist()))


# Posterior samples a preset records (their logarithms, as a network fit's posterior_log).
PRESET_SAMPLES = 200


def write_joint_preset(
    joint: JointCalibration, path: Path | str, *, base_preset: str, command: str, settings: Mapping[str, Any]
) -> Path:
    """A preset with every freed key at its posterior median, and the posterior's samples (their logarithms) in its
    provenance: ``shakermill uncertainty`` carries them into any run of it, a run's own interval those of the keys its
    network alone reads."""
    from datetime import datetime

    from shakermill.support.version import __version__

    keys = joint.posterior.keys
    chosen = joint.posterior.values[joint.posterior.thinned(PRESET_SAMPLES)]
    medians = joint.medians
    document = {
        "preset": base_preset,
        **{key: value for key, value in settings.items() if key not in medians},
        **medians,
        "provenance": {
            "description": f"{base_preset} with {', '.join(keys)} at the medians of their posterior given "
            f"{joint.curve_source} (MODEL.md §14.1)",
            "command": command,
            "fitted": list(keys),
            "method": METHOD,
            "status": joint.status,
            "message": joint.message,
            "priors": {item.key: item.table() for item in joint.posterior.inputs},
            "posterior_90": {key: [low, high] for key, (low, _, high) in joint.posterior.quantiles().items()},
            "posterior_log": np.log(chosen).tolist(),
            "predictions": {item.observable.name: list(item.quantiles) for item in joint.predictions},
            "curve": joint.curve_source,
            "shakermill_version": __version__,
            "date_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        },
    }
    return write_preset_file(
        path,
        f"# shakermill preset fitted over its uncertain inputs; keys not listed come from {base_preset!r}.",
        document,
    )
