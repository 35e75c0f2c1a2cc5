"""Calibration over every uncertain input (MODEL.md §14.1, issue 36 point 4): the assumed inputs' ranges as priors,
the measurements as the likelihood, the posterior by emcee, and predictions with posterior-predictive intervals.

A fit of the thermal network alone (``studies/calibration/calibrate.py``) measures the mechanics once and moves keys the
mechanics does not read. Freeing friction, restitution, λ or the clamp's motion changes the mechanics, which costs a
three-dimensional run (seconds to minutes) where emcee needs tens of thousands of evaluations. So the model is
emulated, as Kennedy & O'Hagan (2001) calibrate a costly computer model:

* the training runs are a scrambled Sobol' design (``scipy.stats.qmc``) over the prior: ``members`` runs of the
  mechanics over the inputs it reads, and at each ``thermal_draws`` points of the keys only the thermal network
  reads (a network under the member's mean load, milliseconds), so the cheap directions are sampled densely;
* each measured quantity (a node's rise at a time) gets a Gaussian-process emulator over the unit cube of the inputs
  (scikit-learn, the ensemble's kernel), checked on mechanical members it did not see (grouped k-fold: held-out
  Q²);
* the posterior is sampled by emcee in the unit cube, the prior uniform there (each input's distribution maps the
  cube onto its range), the likelihood Gaussian with the measurement's standard deviation and the emulator's own
  predictive variance added, so that an emulator unsure of a region cannot pin the fit there;
* a prediction for other conditions (five balls from a one-ball fit, and back) is that configuration's emulator at
  the posterior samples, an input the fit did not constrain (the ball-ball pair keys for a one-ball fit) drawn from
  its prior, each sample with a draw of the emulator's error: the 5/50/95 % of those are the posterior-predictive
  interval, carrying the fit, the inputs it left free and the emulator.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC
from typing import Any

import numpy as np

from shakermill.engines.registry import engine_named
from shakermill.parameters.assumed import AssumedInput, with_derived
from shakermill.parameters.engine_keys import reader_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.parameters.presets import Preset
from shakermill.solvers.simulate import thermal_variants
from shakermill.studies.calibration.calibrate import check_free_for_engine, log_bounds
from shakermill.studies.calibration.defensible import DEFENSIBLE_RANGES
from shakermill.studies.calibration.fitted_preset import write_preset_file
from shakermill.studies.ensembles.ensemble import LEAST_Q2, QUANTILES, design_seed, from_unit, gaussian_process, q2_of

# A measured rise's standard deviation where its source states none (K): the one-ball curve is an exponential
# fitted to intermittent calorimetric measurements, which a model following within 2 K follows within their likely
# scatter (studies/validation_matrix.FOLLOWS_CURVE_K); the five-ball point is quoted without an error.
ASSUMED_MEASUREMENT_SD_K = 2.0
METHOD = "emulated Bayesian calibration over every uncertain input (MODEL.md §14.1)"
# emcee: walkers per input (at least LEAST_WALKERS), steps (the first half burn-in), samples kept; the seed makes
# the posterior reproducible.
WALKERS_PER_INPUT, LEAST_WALKERS = 4, 16
STEPS = 10000
KEPT = 2000
SEED = 20261128
# Held-out folds of the mechanical members for the emulators' Q².
FOLDS = 4
# Pair keys act between two balls: a run of one ball cannot feel them.
PAIR_PREFIX = "pair_"


@dataclass(frozen=True)
class Observable:
    """A node's mean rise above the start (K) at a time (s): what a measurement or a prediction is of."""

    node: str
    time_s: float

    @property
    def name(self) -> str:
        return f"{self.node}@{self.time_s:g}s"

    @property
    def label(self) -> str:
        return f"{self.node} rise at {self.time_s / 60:g} min"


@dataclass(frozen=True)
class Measured:
    observable: Observable
    rise_K: float
    sd_K: float = ASSUMED_MEASUREMENT_SD_K


def fit_inputs(preset: Preset, params: Parameters, free: Sequence[str]) -> list[AssumedInput]:
    """The inputs a calibration of ``params`` over everything uncertain frees: the assumed inputs ``preset`` states
    that the run reads and can feel (no pair key for one ball), and the thermal ``free`` keys, each log-uniform over
    its defensible range (the prior of the network's own fit, ``calibrate.log_bounds``)."""
    reader = reader_of(params)
    assumed = [
        item
        for key, item in preset.assumed.items()
        if reader.not_read(key) is None and key not in free and feels(params, key)
    ]
    fitted = []
    for key in free:
        low, high = (math.exp(bound) for bound in log_bounds(key, float(getattr(params, key))))
        reason = DEFENSIBLE_RANGES[key].reason if key in DEFENSIBLE_RANGES else "a factor either way of its start"
        fitted.append(AssumedInput(key, low, high, "log-uniform", f"fitted: {reason}"))
    return assumed + fitted


def feels(params: Parameters, key: str) -> bool:
    """Whether a run of ``params`` can be moved by ``key``: a pair key needs two balls."""
    return not key.startswith(PAIR_PREFIX) or params.n_balls >= 2


@dataclass
class Training:
    """The runs an emulator learns from: the inputs, their unit-cube points, the observables' rises (K) and the
    mechanical member each point belongs to."""

    inputs: tuple[AssumedInput, ...]
    observables: tuple[Observable, ...]
    unit: np.ndarray
    rises: np.ndarray
    member: np.ndarray
    failed: list[str] = field(default_factory=list)


def train(
    params: Parameters,
    inputs: Sequence[AssumedInput],
    observables: Sequence[Observable],
    members: int,
    thermal_draws: int,
    progress: Callable[[int, int], None] | None = None,
) -> Training:
    """Run ``params`` at ``members`` points of a Sobol' design over the inputs its mechanics reads, and its network
    at ``thermal_draws`` points each over the inputs only the network reads (module docstring); ``progress(done,
    members)`` after each member. A member whose run fails is left out and named in ``failed``."""
    from scipy.stats import qmc

    for name, count in (("members", members), ("thermal draws", thermal_draws)):
        if count < 1 or count & (count - 1):
            raise ParameterError(f"{name}: {count} is not allowed; a power of two (a Sobol' design is balanced there)")
    thermal_only = set(params.engine_keys.thermal_only_keys)
    mechanical = [index for index, item in enumerate(inputs) if item.key not in thermal_only]
    network = [index for index, item in enumerate(inputs) if item.key in thermal_only]
    draws = thermal_draws if network else 1
    seed = design_seed(params, inputs)
    unit = np.empty((members * draws, len(inputs)))
    mechanics = qmc.Sobol(max(len(mechanical), 1), scramble=True, seed=seed).random_base2(int(math.log2(members)))
    unit[:, mechanical] = np.repeat(mechanics[:, : len(mechanical)], draws, axis=0)
    if network:
        sampler = qmc.Sobol(len(network), scramble=True, seed=seed + 1)
        unit[:, network] = sampler.random_base2(int(math.log2(members * draws)))
    values = from_unit(inputs, unit)
    keys = [item.key for item in inputs]
    rises = np.full((len(unit), len(observables)), np.nan)
    failed = []
    rise_of = _rises(observables)
    for member in range(members):
        rows = range(member * draws, (member + 1) * draws)
        runs = [
            params.replace(**with_derived(params, inputs, dict(zip(keys, map(float, values[row]))))) for row in rows
        ]
        result = thermal_variants(runs[0])(runs[0])
        if not result.success or result.load is None:
            failed.append(f"member {member}: {result.message}")
        else:
            for row, run in zip(rows, runs):
                rises[row] = rise_of(run, result.load)
        if progress is not None:
            progress(member + 1, members)
    kept = np.isfinite(rises).all(axis=1)
    return Training(
        tuple(inputs), tuple(observables), unit[kept], rises[kept], np.repeat(np.arange(members), draws)[kept], failed
    )


def _rises(observables: Sequence[Observable]) -> Callable[[Parameters, Any], np.ndarray]:
    from shakermill.studies.validation.matrix import Point, node_rises

    points = tuple(Point(item.node, item.time_s, None) for item in observables)

    def rises(params: Parameters, load: Any) -> np.ndarray:
        return np.array(list(node_rises(points, engine_named(params.engine).network_for)(params, load).values()))

    return rises


@dataclass
class Emulator:
    """One Gaussian process per observable over the unit cube of ``inputs``, of the rises' logarithms where every
    training rise is positive (``logarithmic``), and its held-out Q² (of the rises themselves)."""

    inputs: tuple[AssumedInput, ...]
    observables: tuple[Observable, ...]
    models: list[Any]
    q2: dict[str, float]
    training_points: int
    members: int
    failed: list[str]
    logarithmic: bool = False

    def _fitted_space(self, unit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        found = [model.predict(unit, return_std=True) for model in self.models]
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


def emulate(training: Training) -> Emulator:
    """Fit an emulator per observable; measure its Q² on mechanical members held out, FOLDS groups of them. Rises
    that are all positive are emulated in their logarithms: the model multiplies (a heat power by a network's
    response), which the logarithm makes a sum, nearer the smooth function a Gaussian process assumes."""
    from sklearn.model_selection import GroupKFold

    members = np.unique(training.member)
    if members.size < FOLDS:
        raise ParameterError(
            f"members: {members.size} runs succeeded, too few to check an emulator on held-out runs (at least {FOLDS})"
        )
    logarithmic = bool(np.all(training.rises > 0))
    fitted = np.log(training.rises) if logarithmic else training.rises
    back = np.exp if logarithmic else (lambda values: values)
    q2 = {}
    for column, observable in enumerate(training.observables):
        values = training.rises[:, column]
        predicted = np.empty_like(values)
        for fit, held in GroupKFold(FOLDS).split(training.unit, values, training.member):
            predicted[held] = back(
                gaussian_process(training.unit[fit], fitted[fit, column]).predict(training.unit[held])
            )
        q2[observable.name] = q2_of(values, predicted)
    models = [gaussian_process(training.unit, fitted[:, column]) for column in range(len(training.observables))]
    return Emulator(
        training.inputs,
        training.observables,
        models,
        q2,
        len(training.unit),
        int(members.size),
        training.failed,
        logarithmic,
    )


@dataclass(frozen=True)
class Posterior:
    """Samples of the inputs (unit cube and values) given the measurements, and the sampler's diagnostics."""

    inputs: tuple[AssumedInput, ...]
    unit: np.ndarray
    acceptance: float
    autocorrelation_steps: float

    @property
    def keys(self) -> list[str]:
        return [item.key for item in self.inputs]

    @property
    def values(self) -> np.ndarray:
        return from_unit(self.inputs, self.unit)

    def quantiles(self) -> dict[str, tuple[float, float, float]]:
        table = np.quantile(self.values, QUANTILES, axis=0)
        return {key: tuple(float(v) for v in table[:, index]) for index, key in enumerate(self.keys)}

    @property
    def converged(self) -> bool:
        """emcee's rule of thumb: a chain longer than 50 autocorrelation times (its kept half, 25)."""
        return STEPS / 2 > 25 * self.autocorrelation_steps


Data = Sequence[tuple[Emulator, Sequence[Measured]]]


def union_inputs(data: Data) -> tuple[AssumedInput, ...]:
    """Every input of the emulators of ``data``, each once, in the order met."""
    found: dict[str, AssumedInput] = {}
    for emulator, _ in data:
        for item in emulator.inputs:
            found.setdefault(item.key, item)
    return tuple(found.values())


def sample_posterior(data: Data) -> Posterior:
    """The posterior of the inputs of every emulator of ``data`` given its measurements (each an observable of it)."""
    import emcee

    inputs = union_inputs(data)
    keys = [item.key for item in inputs]
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

    walkers = max(WALKERS_PER_INPUT * len(inputs), LEAST_WALKERS)
    rng = np.random.default_rng(SEED)
    # Differential-evolution moves (ter Braak 2006; emcee's DEMove and DESnookerMove) mix faster than the default
    # stretch in a dozen dimensions where most inputs are barely constrained.
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    sampler = emcee.EnsembleSampler(walkers, len(inputs), log_probability, vectorize=True, moves=moves)
    sampler.random_state = np.random.RandomState(SEED).get_state()
    sampler.run_mcmc(rng.uniform(0.05, 0.95, (walkers, len(inputs))), STEPS)
    chain = sampler.get_chain(discard=STEPS // 2, flat=True)
    kept = chain[np.linspace(0, len(chain) - 1, KEPT).astype(int)]
    tau = float(np.max(sampler.get_autocorr_time(discard=STEPS // 2, quiet=True, tol=0)))
    return Posterior(inputs, kept, float(np.mean(sampler.acceptance_fraction)), tau)


def prior_sample(inputs: Sequence[AssumedInput]) -> Posterior:
    """KEPT points of the prior alone: what a prediction says before any measurement."""
    return Posterior(tuple(inputs), np.random.default_rng(SEED).random((KEPT, len(inputs))), math.nan, 0.0)


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
    rng = np.random.default_rng(SEED + 1)
    draws = emulator.draw(emulator.at(posterior.keys, posterior.unit, rng), rng)
    table = np.quantile(draws, QUANTILES, axis=0)
    known = {item.observable: item.rise_K for item in measured}
    return [
        Prediction(observable, tuple(float(v) for v in table[:, column]), known.get(observable))
        for column, observable in enumerate(emulator.observables)
    ]


def posterior_as_dict(posterior: Posterior) -> dict[str, Any]:
    quantiles = posterior.quantiles()
    return {
        "inputs": {
            item.key: {**item.table(), **dict(zip(("p5", "p50", "p95"), quantiles[item.key]))}
            for item in posterior.inputs
        },
        "samples": len(posterior.unit),
        "acceptance": posterior.acceptance,
        "autocorrelation_steps": posterior.autocorrelation_steps,
        "converged": posterior.converged,
    }


def emulator_as_dict(emulator: Emulator) -> dict[str, Any]:
    return {
        "members": emulator.members,
        "training_points": emulator.training_points,
        "held_out_q2": emulator.q2,
        "failed": emulator.failed,
    }


def measured_of(experiment: Any) -> list[Measured]:
    """The measured points of a validation experiment (``studies/validation_matrix.Experiment``)."""
    return [
        Measured(Observable(point.node, point.time_s), point.rise_K)
        for point in experiment.points
        if point.rise_K is not None
    ]


# A curve enters the fit at this many times, evenly spread over its points: its shape informs the fit, and an
# emulator a time is the cost (the points of one curve are not independent measurements anyway).
CURVE_POINTS = 6


@dataclass(frozen=True)
class JointCalibration:
    """A calibration over every uncertain input: the posterior, the curves' points and the run's end at it."""

    free: tuple[str, ...]  # the network's free keys; the assumed inputs are the rest of posterior.inputs
    posterior: Posterior
    emulators: Mapping[tuple[str, ...], Emulator]  # by the conditions of their curves
    fitted: tuple[Prediction, ...]  # each curve point entered, with its measured rise
    predictions: tuple[Prediction, ...]  # the run's own configuration at its end
    curve_source: str

    @property
    def medians(self) -> dict[str, float]:
        return {key: middle for key, (_, middle, _) in self.posterior.quantiles().items()}

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
        inside = [prediction.inside for prediction in self.fitted]
        said = f"{sum(inside)} of {len(inside)} measured points inside their 90 % posterior-predictive intervals"
        return said + (f"; unreliable: {'; '.join(self.problems)}" if self.problems else "")

    def as_dict(self) -> dict[str, Any]:
        return {
            "method": METHOD,
            "network_free": list(self.free),
            "status": self.status,
            "message": self.message,
            "posterior": posterior_as_dict(self.posterior),
            "emulators": {
                ", ".join(conditions) or "the run's own": emulator_as_dict(emulator)
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
            f"the chain is {STEPS // 2} steps after burn-in, under 25 of its autocorrelation times "
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
) -> JointCalibration:
    """Fit ``curves`` (``studies/validation.Curve``) over the network's ``free`` keys and every assumed input of
    ``preset`` that a run of ``base`` can feel (module docstring). As for ``calibrate``: the ``free`` keys must be
    the network's and read by the run, ``on_start()`` is called once they are, before the first run; ``progress(done,
    total)`` counts the mechanical members of every set of conditions."""
    from shakermill.parameters.config import parse_overrides

    check_free_for_engine(base, free)
    if on_start is not None:
        on_start()
    groups: dict[tuple[str, ...], list[Any]] = {(): []}
    for curve in curves:
        groups.setdefault(tuple(curve.conditions), []).append(curve)
    data, emulators, total = [], {}, members * len(groups)
    for index, (conditions, chosen) in enumerate(groups.items()):
        params = base.replace(**parse_overrides(conditions))
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
        emulator = emulate(train(params, fit_inputs(preset, params, free), observables, members, thermal_draws, shown))
        emulators[conditions] = emulator
        data.append((emulator, measured))
    posterior = sample_posterior(data)
    fitted = tuple(
        item
        for emulator, measured in data
        for item in predict(emulator, posterior, measured)
        if item.measured_K is not None
    )
    ends = tuple(item for item in predict(emulators[()], posterior) if item.observable.time_s == base.duration)
    source = "; ".join(curve.source for curve in curves)
    return JointCalibration(tuple(free), posterior, emulators, fitted, ends, source)


def _spread_points(count: int) -> list[int]:
    return sorted(set(np.linspace(0, count - 1, min(count, CURVE_POINTS)).round().astype(int).tolist()))


# Posterior samples a preset records (their logarithms, as a network fit's posterior_log).
PRESET_SAMPLES = 200


def write_joint_preset(
    joint: JointCalibration, path: Any, *, base_preset: str, command: str, settings: Mapping[str, Any]
) -> Any:
    """A preset with every freed key at its posterior median, and the posterior's samples (their logarithms) in its
    provenance: ``shakermill uncertainty`` carries them into any run of it, a run's own interval those of the keys its
    network alone reads."""
    from datetime import datetime

    from shakermill.support.version import __version__

    keys = joint.posterior.keys
    values = joint.posterior.values
    chosen = values[np.linspace(0, len(values) - 1, min(PRESET_SAMPLES, len(values))).astype(int)]
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
