"""Calibration: fit free parameters to measured targets by bounded least squares.

What the paper did by hand (tuning β until θ∞ and τ matched Table 5), done by
``scipy.optimize.least_squares`` and reported honestly: which keys were free,
which quantities were targets, the residuals, the sensitivities, and whether a
parameter ended on a bound (a sign that the targets cannot be met with that
choice of free parameters).

The default target is the experiment's ball-temperature curve as the paper
summarises it, θ(t) = 48 − 28·exp(−t/16.7 min) over 0–60 min
(:func:`experiment_curve`); the Table 5 numbers of the model's own exponential
fit (``theta_inf_C``, ``tau_min``, ``rate0_C_per_min``, ``vial_ball_ratio``)
remain available as targets, and any measured curve can be given. Positive
parameters are fitted in log space, so bounds are ratios and steps are
relative; keys with a physically defensible range (:data:`DEFENSIBLE_RANGES`)
are bounded by it, so a fitted value on its edge says the data pull beyond
what physics allows. The averaged solver is used unless asked otherwise: it
makes each evaluation a few hundredths of a second.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from shakermill.engines.interface import ProgressCallback
from shakermill.parameters.config import parse_overrides
from shakermill.parameters.defaults import DEFAULT_FREE, DEFAULT_FREE_BY_NETWORK
from shakermill.parameters.engine_keys import reader_of
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters, bounds, check_known_keys
from shakermill.solvers.result import Result
from shakermill.solvers.simulate import preflight, thermal_variants
from shakermill.studies.calibration.defensible import DEFENSIBLE_RANGES
from shakermill.studies.calibration.fit_statistics import (
    CURVE_SCALE_K,
    log_covariance,
    posterior_evaluations,
    posterior_samples,
    residual_variance,
    sensitivities,
    standard_errors,
)
from shakermill.studies.calibration.identifiability import check_determinable, loosely_determined, undetermined_keys
from shakermill.studies.inference.posterior import Posterior
from shakermill.studies.inference.prior import Prior, fitted_key
from shakermill.studies.measured import (
    CURVE_TOLERANCE_K,
    TARGET_KEYS,
    Curve,
    check_targets,
    experiment_curve,
    target_range,
)
from shakermill.support.limits import MAX_VALUE_LENGTH, quoted

# The free set of the shipped calibrated preset: the smallest set that follows the experiment's curve
# within 1 K RMS with every value inside its defensible range (see README, "Against the experiment").
# A free parameter may move this factor either way from its starting value.
BOUND_FACTOR = 100.0
# Relative step of the finite-difference Jacobian in log space: large enough to rise above the
# averaged solver's statistical noise (relative standard error ~1e-4 to 1e-3 on mechanical inputs).
JACOBIAN_STEP = 1e-2
# A parameter within this relative distance (1 %) of a bound is reported as on it: an ill-conditioned fit stops just
# short of the bound it is pulled to.
AT_BOUND = 1e-2
# A scalar target further off than this (relative) after the fit counts as not met.
TARGET_TOLERANCE = 5e-3
# The posterior's range a calibration reports of each key: its 5th and 95th percentiles.
POSTERIOR_RANGE = (0.05, 0.95)
# Quantities a calibration predicts without fitting them, reported beside the fit.
PREDICTED_KEYS = ("vial_ball_ratio", "ball_steady_C", "vial_steady_C", "air_steady_C", "slowest_time_constant_min")


@dataclass
class Calibration:
    """The outcome of :func:`calibrate`."""

    params: Parameters
    free: tuple[str, ...]
    fitted: dict[str, float]
    start: dict[str, float]
    targets: dict[str, float]
    achieved: dict[str, float]
    curve_rms_K: float | None
    parameter_stderr: dict[str, float]
    # Of the natural logarithms of ``free``, in that order (None where the Jacobian does not determine it)
    covariance: list[list[float]] | None
    # The posterior of ``free``, sampled in their logarithms (emcee), where an evaluation is cheap enough to sample it
    posterior: Posterior | None
    # target -> parameter -> d ln(target)/d ln(parameter); for a curve, "ball_C at T min" -> K per e-fold
    sensitivities: dict[str, dict[str, float]]
    predictions: dict[str, float]  # what the fitted model says of quantities that were not fitted
    prediction_stderr: dict[str, float]  # their standard errors from the keys' covariance (NaN without one)
    at_bounds: list[str]
    success: bool
    message: str
    # 'undetermined' (the data leave a direction of the keys free: a singular Jacobian, whatever the residuals),
    # 'fitted' (the targets met) or 'not met'; only 'fitted' is a success.
    status: str
    evaluations: int
    solver: str
    curve_source: str = ""
    result: Result | None = field(default=None, repr=False)

    @property
    def relative_residuals(self) -> dict[str, float]:
        return {key: (self.achieved[key] - value) / value for key, value in self.targets.items()}

    @property
    def posterior_ranges(self) -> dict[str, tuple[float, float]]:
        """Each fitted key's 5th and 95th posterior percentiles (its own unit); empty without a posterior."""
        if self.posterior is None:
            return {}
        # Interpolated in the logarithms, where the fit sampled them.
        ranges = self.posterior.quantiles(POSTERIOR_RANGE, in_logarithms=True)
        return {key: (ranges[key][0], ranges[key][1]) for key in self.free}

    @property
    def defensible(self) -> dict[str, str]:
        """For each fitted key: whether its value is physically defensible, and why."""
        verdicts = {}
        for key, value in self.fitted.items():
            bounds = DEFENSIBLE_RANGES.get(key)
            if bounds is None:
                verdicts[key] = "no defensible range is recorded for this key: judge it yourself"
                continue
            where = "inside" if bounds.contains(value) else "OUTSIDE"
            edge = " (on its edge: the data pull beyond it)" if key in self.at_bounds else ""
            verdicts[key] = f"{where} {bounds.low:g} to {bounds.high:g}{edge}: {bounds.reason}"
        return verdicts

    def as_dict(self) -> dict:
        return {
            "free": list(self.free),
            "fitted": self.fitted,
            "start": self.start,
            "targets": self.targets,
            "achieved": self.achieved,
            "relative_residuals": self.relative_residuals,
            "curve_rms_K": self.curve_rms_K,
            "parameter_stderr": self.parameter_stderr,
            "covariance_log": self.covariance,
            "posterior_samples": 0 if self.posterior is None else len(self.posterior),
            "posterior_90": {key: list(bounds) for key, bounds in self.posterior_ranges.items()},
            "sensitivities": self.sensitivities,
            "predictions": self.predictions,
            "prediction_stderr": self.prediction_stderr,
            "defensible": self.defensible,
            "at_bounds": self.at_bounds,
            "success": self.success,
            "status": self.status,
            "message": self.message,
            "evaluations": self.evaluations,
            "solver": self.solver,
        }


def parse_targets(items: Sequence[str]) -> dict[str, float]:
    """``["theta_inf_C=48", ...]`` -> ``{"theta_inf_C": 48.0}`` with one-line errors."""
    targets: dict[str, float] = {}
    for item in items:
        name, separator, value = item.partition("=")
        name = name.strip()
        if not separator:
            raise ParameterError(f"target: expected NAME=VALUE, got {item!r}")
        if name not in TARGET_KEYS:
            raise ParameterError(f"target: unknown target {quoted(name)}; allowed: {', '.join(TARGET_KEYS)}")
        number = _plain_number(value)
        if number is None:
            raise ParameterError(f"target: {name} needs a number, got {quoted(value)}; allowed {target_range(name)}")
        targets[name] = number
    check_targets(targets)
    return targets


def _plain_number(text: str) -> float | None:
    """``text`` as a float; None when it is not one, or longer than any number is written."""
    if len(text) > MAX_VALUE_LENGTH:
        return None
    try:
        return float(text)
    except ValueError:
        return None


# Keys that reach the network through the balls alone: an empty mill (n_balls = 0) reads none of them.
BALL_HEAT_KEYS = frozenset({"beta", "lam", "eta"})


def default_free(params: Parameters) -> tuple[str, ...]:
    """The free set a calibration of ``params`` fits when none is given, derived from what its run reads: its
    network's keys (DEFAULT_FREE_BY_NETWORK) less those the run does not read (another network's, the balls' of an
    empty mill), those that would move the mechanics of an engine whose fits measure them once (it declares
    thermal-only keys: the 'dem' engine), and those that start at 0 (:func:`unstarted_defaults`)."""
    return tuple(key for key in _default_candidates(params) if getattr(params, key) > 0)


def unstarted_defaults(params: Parameters) -> tuple[str, ...]:
    """The keys of the network's default free set that ``params`` start at 0 (a planetary preset's drive_heat): fitted
    in log space, they need a positive start, so the default leaves them out and the command line says so."""
    return tuple(key for key in _default_candidates(params) if getattr(params, key) <= 0)


def _default_candidates(params: Parameters) -> tuple[str, ...]:
    reader = reader_of(params)
    thermal_only = params.engine_keys.thermal_only_keys
    return tuple(
        key
        for key in DEFAULT_FREE_BY_NETWORK[params.thermal_model]
        if reader.not_read(key) is None
        and (not thermal_only or key in thermal_only)
        and not (params.n_balls == 0 and key in BALL_HEAT_KEYS)
    )


def parse_free(items: Sequence[str], default: tuple[str, ...] = DEFAULT_FREE) -> tuple[str, ...]:
    """``["beta,vial_mass", "eta"]`` -> ``("beta", "vial_mass", "eta")``, ``default`` for none; only float keys."""
    keys = tuple(key.strip() for item in items for key in item.split(",") if key.strip()) or default
    check_known_keys(list(keys))
    for key in keys:
        if Parameters.model_fields[key].annotation is not float:
            raise ParameterError(f"free: {key} is not a numeric parameter and cannot be fitted")
    if len(set(keys)) != len(keys):
        raise ParameterError(f"free: a key is listed twice in {', '.join(keys)}")
    return keys


# An open hard bound is approached to this relative distance: exp(log(bound)) may round onto it.
OPEN_BOUND_MARGIN = 1e-9


def log_bounds(key: str, start: float) -> tuple[float, float]:
    """Bounds in log space: the defensible range (widened to include the start), else a factor either way;
    always inside the key's hard bounds, so that no step of the fit tries a value the model refuses."""
    if key in DEFENSIBLE_RANGES:
        defensible = DEFENSIBLE_RANGES[key]
        low, high = min(defensible.low, start), max(defensible.high, start)
    else:
        low, high = start / BOUND_FACTOR, start * BOUND_FACTOR
    hard = bounds(key)
    low = max(low, hard.low * (1 + OPEN_BOUND_MARGIN) if hard.low_open else hard.low)
    high = min(high, hard.high * (1 - OPEN_BOUND_MARGIN) if hard.high_open else hard.high)
    # A start on the upper limit still needs an open interval.
    return math.log(low), max(math.log(high), math.log(start) + 1e-12)


def fitted_prior(params: Parameters, free: Sequence[str]) -> Prior:
    """The prior of ``free`` keys of a fit from ``params``: each log-uniform within its :func:`log_bounds` (the
    defensible range, else a factor either way of its start), with the reason for the range. The least-squares fit
    and its posterior move the keys within it; a calibration over every uncertain input frees them over it."""
    entries = []
    for key in free:
        low, high = (math.exp(bound) for bound in log_bounds(key, float(getattr(params, key))))
        reason = DEFENSIBLE_RANGES[key].reason if key in DEFENSIBLE_RANGES else "a factor either way of its start"
        entries.append(fitted_key(key, low, high, reason))
    return Prior(tuple(entries))


def calibrate(
    base: Parameters,
    free: Sequence[str] = DEFAULT_FREE,
    targets: Mapping[str, float] | None = None,
    curve: Curve | Sequence[Curve] | None = None,
    *,
    full_resolution: bool = False,
    progress: Callable[[int, float | None], None] | None = None,
    mechanics_progress: ProgressCallback | None = None,
    on_posterior: Callable[[int], None] | None = None,
    sample_posterior: bool = True,
    on_start: Callable[[], None] | None = None,
) -> Calibration:
    """Fit ``free`` keys of ``base`` to ``targets`` and/or one or several curves (``curve``), each of a node under
    its own conditions (:class:`~shakermill.studies.measured.Curve`); see the module docstring.

    ``on_start()`` is called once every input has been checked, before the first evaluation;
    ``progress(evaluations, curve_rms_K)`` after every model evaluation (the RMS of that evaluation against the
    curves, None without curves); ``mechanics_progress(done, total)`` the simulated seconds of the mechanics measured
    once for every evaluation, where the engine has thermal-only keys; ``on_posterior(evaluations)`` before the
    posterior's evaluations begin, with their number. With ``sample_posterior``, a fit whose
    evaluations integrate the network alone (the engine has thermal-only keys) also samples the posterior of its keys
    (:func:`posterior_samples`, a few minutes). A run that uses up its budget stops the fit
    (:class:`~shakermill.budget.BudgetExceeded`): its partial result is no evaluation.
    """
    targets, curves, free = _checked(base, free, targets, curve)
    start = {key: float(getattr(base, key)) for key in free}
    x0 = np.log([start[key] for key in free])
    lower, upper = (np.array(side) for side in zip(*(log_bounds(key, start[key]) for key in free)))
    fitting = _fitting_parameters(base, curves, full_resolution)
    solver = fitting.solver
    if on_start is not None:
        on_start()
    evaluate, cache = _evaluator(fitting, free, targets, curves, progress, mechanics_progress)
    solution = least_squares(
        lambda x: evaluate(x)[0], x0, bounds=(lower, upper), diff_step=JACOBIAN_STEP, x_scale=1.0, method="trf"
    )
    residuals, results = evaluate(solution.x)
    result = results[()]
    fitted = {key: float(math.exp(v)) for key, v in zip(free, solution.x)}
    achieved = {key: result.summary.number(key) for key in targets}
    at_bounds = [
        key for key, x, lo, hi in zip(free, solution.x, lower, upper) if x - lo < AT_BOUND or hi - x < AT_BOUND
    ]
    missed = {key: (achieved[key] - value) / value for key, value in targets.items()}
    missed = {key: error for key, error in missed.items() if abs(error) > TARGET_TOLERANCE}
    curve_rms = _curve_rms(results, curves)
    covariance = log_covariance(solution.jac, residuals, len(free), curves)
    predicted = [key for key in PREDICTED_KEYS if key not in targets]
    prediction_stderr = {} if full_resolution else _prediction_stderr(evaluate, solution.x, covariance, predicted)
    # Sampled only where an evaluation is a network alone: thousands of them take minutes there, hours elsewhere.
    sampled = sample_posterior and covariance is not None and base.engine_keys.thermal_only_keys and not full_resolution
    posterior = (
        _sampled_posterior(base, free, evaluate, solution.x, (lower, upper), residuals, curves, on_posterior)
        if sampled
        else None
    )
    status, message = _verdict(solution, result.success, free, missed, at_bounds, curve_rms, covariance)
    return Calibration(
        params=result.params.replace(solver=base.solver, attractor_starts=base.attractor_starts),
        free=free,
        fitted=fitted,
        start=start,
        targets=targets,
        achieved=achieved,
        curve_rms_K=curve_rms,
        parameter_stderr=standard_errors(covariance, free, fitted),
        covariance=None if covariance is None else covariance.tolist(),
        posterior=posterior,
        sensitivities=sensitivities(solution.jac, free, targets, curves),
        predictions={key: result.summary.number(key) for key in predicted},
        prediction_stderr=prediction_stderr,
        at_bounds=at_bounds,
        success=status == "fitted",
        message=message,
        status=status,
        evaluations=len(cache),
        solver=solver,
        curve_source="; ".join(_described(measured) for measured in curves),
        result=result,
    )


def _fitting_parameters(base: Parameters, curves: Sequence[Curve], full_resolution: bool) -> Parameters:
    """The parameters every evaluation of a fit runs, checked once (the preflight) before the first: its solver, the
    configured motion only (probing other attractors would cost every evaluation), long enough for every curve."""
    longest = max((float(measured.times.max()) for measured in curves), default=0.0)
    if full_resolution:
        check_full_resolution_work(base, max(base.duration, longest))
    fitting = base.replace(
        solver="full" if full_resolution else "averaged", attractor_starts=1, duration=max(base.duration, longest)
    )
    preflight(fitting)
    return fitting


def _verdict(
    solution: Any,
    run_success: bool,
    free: Sequence[str],
    missed: Mapping[str, float],
    at_bounds: Sequence[str],
    curve_rms: float | None,
    covariance: np.ndarray | None,
) -> tuple[str, str]:
    """The fit's status ('fitted', 'undetermined' or 'not met') and its message: undetermined where a direction of
    the keys leaves the residuals unmoved, or a key's standard error exceeds its value."""
    off_curve = curve_rms is not None and curve_rms > CURVE_TOLERANCE_K
    stuck = [key for key in at_bounds if key not in DEFENSIBLE_RANGES]
    met = bool(solution.success) and not stuck and not missed and not off_curve and run_success
    # A fit that misses its data has large errors for that reason: its verdict is the miss, not its errors.
    undetermined = undetermined_keys(solution.jac, free) or (
        "" if missed or off_curve else loosely_determined(covariance, free, at_bounds)
    )
    message = _outcome(str(solution.message), free, missed, at_bounds, curve_rms if off_curve else None)
    if undetermined:
        return "undetermined", f"{undetermined}; {message}"
    return ("fitted" if met else "not met"), message


Evaluation = tuple[np.ndarray, dict[tuple[str, ...], Result]]


# Runs a fit keeps whole, the latest: thousands of them (a posterior's) would fill the memory with their records.
RUNS_KEPT = 8


def _evaluator(
    fitting: Parameters,
    free: Sequence[str],
    targets: Mapping[str, float],
    curves: Sequence[Curve],
    progress: Callable[[int, float | None], None] | None,
    mechanics_progress: ProgressCallback | None = None,
) -> tuple[Callable[[np.ndarray], Evaluation], dict[tuple[float, ...], np.ndarray]]:
    """The model a fit evaluates at the logarithms ``x`` of its free keys: the residuals and the run of each set of
    conditions (the fitted parameters' own, ``()``, always: the targets and the predictions are of it). The
    residuals of every evaluation are kept (the cache it returns), the runs of the latest RUNS_KEPT: an older one
    asked for again is run again (the runs are deterministic), uncounted. Every set measures its mechanics once."""
    bases = {
        conditions: fitting.replace(**parse_overrides(conditions))
        for conditions in ((), *(c.conditions for c in curves))
    }
    models = {conditions: thermal_variants(params, mechanics_progress) for conditions, params in bases.items()}
    cache: dict[tuple[float, ...], np.ndarray] = {}
    runs: dict[tuple[float, ...], dict[tuple[str, ...], Result]] = {}

    def evaluate(x: np.ndarray) -> Evaluation:
        key = tuple(np.round(x, 14))
        if key not in runs:
            values = {name: float(math.exp(v)) for name, v in zip(free, x)}
            runs[key] = {
                conditions: models[conditions](params.replace(**values)) for conditions, params in bases.items()
            }
            while len(runs) > RUNS_KEPT:
                runs.pop(next(iter(runs)))
        if key not in cache:
            cache[key] = _residuals(runs[key], targets, curves)
            if progress is not None:
                progress(len(cache), _curve_rms(runs[key], curves))
        return cache[key], runs[key]

    return evaluate, cache


# The longest run a full-resolution fit of an engine of several balls may evaluate (s): one of its simulated seconds
# takes 1-20 s of wall time here (benchmarks/README.md), and a fit evaluates hundreds to thousands of runs.
LONGEST_FULL_RESOLUTION_FIT_S = 60.0
# Model evaluations of the 3-D calibrations shipped (benchmarks/README.md).
TYPICAL_EVALUATIONS = 2000


def check_full_resolution_work(base: Parameters, duration: float) -> None:
    """Refuse, with the estimate, a full-resolution fit that could not end in reasonable time: each evaluation a
    run of the 'dem' engine over the whole curve."""
    if not base.engine_keys.several_balls or duration <= LONGEST_FULL_RESOLUTION_FIT_S:
        return
    raise ParameterError(
        f"--full-resolution: each of the fit's ~{TYPICAL_EVALUATIONS} evaluations would run {duration:g} s of "
        f"engine = {base.engine!r} at full resolution (1-20 s of wall time a simulated second here), days in all; "
        f"allowed the averaged solver (the default) for it, or runs of at most {LONGEST_FULL_RESOLUTION_FIT_S:g} s"
    )


def _checked(
    base: Parameters, free: Sequence[str], targets: Mapping[str, float] | None, curve: Curve | Sequence[Curve] | None
) -> tuple[dict[str, float], tuple[Curve, ...], tuple[str, ...]]:
    """The targets, the curves (the experiment's when neither is given) and the free keys of a fit, checked: every
    target in its range, no curve's conditions setting a fitted key, every free key one the engine's fits may move,
    starting positive (fitted in log space)."""
    targets = dict(targets or {})
    check_targets(targets)
    curves = (curve,) if isinstance(curve, Curve) else tuple(curve or ())
    if not targets and not curves:
        curves = (experiment_curve(),)
    free = tuple(free)
    if targets and base.n_balls == 0:
        raise ParameterError(
            "target: the targets are the balls' temperatures, and an empty mill (n_balls = 0) has no "
            "balls; allowed a vial_C curve (--curve) for it"
        )
    for measured in curves:
        conditions = parse_overrides(measured.conditions)
        clash = sorted(set(conditions) & set(free))
        if clash:
            raise ParameterError(
                f"curve: the conditions of {measured.source} set {', '.join(clash)}, which the fit moves"
            )
        if measured.node == "ball" and str(conditions.get("n_balls", base.n_balls)).strip() == "0":
            raise ParameterError(
                f"curve: {measured.source or 'the curve'} is of the balls, and its run has none "
                "(n_balls = 0); allowed a vial_C curve for an empty mill"
            )
    check_free_for_engine(base, free)
    check_determinable(free, targets, curves)
    for key in free:
        if getattr(base, key) <= 0:
            raise ParameterError(f"free: {key} must start positive to be fitted in log space, got {getattr(base, key)}")
    return targets, curves, free


def check_free_for_engine(base: Parameters, free: Sequence[str]) -> None:
    """A free key must be one the run reads (a fit of a key it ignores would wander its whole range), and an engine
    with thermal-only keys (the 'dem' engine) has its calibration measure the mechanics once: only keys of the
    thermal network may move."""
    problem = reader_of(base).unread_problem(free, how="fitted")
    if problem is not None:
        raise ParameterError(f"free: {problem}")
    thermal_only = base.engine_keys.thermal_only_keys
    moving = [key for key in free if key not in thermal_only]
    if thermal_only and moving:
        raise ParameterError(
            f"free: {', '.join(moving)} would change the {base.engine} engine's mechanics, which a calibration "
            "measures "
            f"once (calibrate --with-assumed frees the preset's assumed inputs, over their stated ranges); allowed for "
            f"engine = {base.engine!r}: {', '.join(thermal_only)}"
        )


def _outcome(
    solver_message: str,
    free: Sequence[str],
    missed: Mapping[str, float],
    at_bounds: Sequence[str],
    curve_missed_by: float | None,
) -> str:
    """What the fit achieved, in words: the optimiser's message, or why the targets were not met, and the
    keys that ended on the edge of their physically defensible range."""
    edges = [key for key in at_bounds if key in DEFENSIBLE_RANGES]
    stuck = [key for key in at_bounds if key not in DEFENSIBLE_RANGES]
    message = solver_message.rstrip(".")
    if missed or stuck or curve_missed_by is not None:
        reasons = [f"{key} is off by {100 * error:+.2f} %" for key, error in missed.items()]
        reasons += [f"{key} ended on a bound" for key in stuck]
        if curve_missed_by is not None:
            reasons.append(f"the curve is missed by {curve_missed_by:.2f} K RMS (more than {CURVE_TOLERANCE_K:g} K)")
        message = (
            f"the targets cannot be met by moving {', '.join(free)} alone ({'; '.join(reasons)}); "
            "free another parameter or check the targets"
        )
    if edges:
        message += (
            f"; {', '.join(edges)} ended on the edge of {'its' if len(edges) == 1 else 'their'} physically defensible "
            "range: the data pull beyond what physics allows"
        )
    return message


def _described(measured: Curve) -> str:
    """A curve's source, its node and its conditions, for the record of a fit."""
    conditions = f", {', '.join(measured.conditions)}" if measured.conditions else ""
    return (
        f"{measured.source} ({measured.node}{conditions})" if measured.node != "ball" or conditions else measured.source
    )


def _curve_residuals_K(results: Mapping[tuple[str, ...], Result], measured: Curve) -> np.ndarray:
    """The run of ``measured``'s conditions minus ``measured`` at its times (K)."""
    series = results[measured.conditions].timeseries
    return measured.residuals_K(series["time"].values, series[measured.variable].values)


def _residuals(
    results: Mapping[tuple[str, ...], Result], targets: Mapping[str, float], curves: Sequence[Curve]
) -> np.ndarray:
    parts = [(results[()].summary.number(key) - value) / value for key, value in targets.items()]
    for measured in curves:
        parts.extend(_curve_residuals_K(results, measured) / CURVE_SCALE_K)
    values = np.array(parts, dtype=float)
    # A failed or unfittable run must push the optimiser away, not stop it.
    return np.where(np.isfinite(values), values, 1e3)


def _curve_rms(results: Mapping[tuple[str, ...], Result], curves: Sequence[Curve]) -> float | None:
    """The RMS residual (K) over every point of every curve; None without curves."""
    if not curves:
        return None
    residuals = np.concatenate([_curve_residuals_K(results, measured) for measured in curves])
    return math.sqrt(float(np.mean(residuals**2)))


def _sampled_posterior(
    base: Parameters,
    free: Sequence[str],
    evaluate: Callable[[np.ndarray], Evaluation],
    best: np.ndarray,
    limits: tuple[np.ndarray, np.ndarray],
    residuals: np.ndarray,
    curves: Sequence[Curve],
    on_posterior: Callable[[int], None] | None,
) -> Posterior:
    """The posterior of a fit's keys at the fit's residual variance, ``on_posterior`` told how many
    evaluations they take before they begin."""
    if on_posterior is not None:
        on_posterior(posterior_evaluations(best.size))
    variance = residual_variance(residuals, best.size, curves)
    chain = posterior_samples(lambda x: evaluate(x)[0], best, *limits, variance)
    return Posterior.of_logarithms(free, chain.samples, fitted_prior(base, free), chain)


def _prediction_stderr(
    evaluate: Callable[[np.ndarray], Evaluation], best: np.ndarray, covariance: np.ndarray | None, keys: Sequence[str]
) -> dict[str, float]:
    """Each prediction's standard error (its own unit) by the delta method: its forward differences in the logarithms
    of the keys (one run each) through their covariance; NaN without a covariance."""
    if covariance is None:
        return {key: math.nan for key in keys}
    summary = evaluate(best)[1][()].summary
    gradients = np.array(
        [
            [
                ((evaluate(best + JACOBIAN_STEP * unit)[1][()]).summary.number(key) - summary.number(key))
                / JACOBIAN_STEP
                for key in keys
            ]
            for unit in np.eye(best.size)
        ]
    )
    variances = np.einsum("ik,ij,jk->k", gradients, covariance, gradients)
    return {key: float(math.sqrt(max(variance, 0.0))) for key, variance in zip(keys, variances)}


# Free sets compared by `validate` and the README: which follow the experiment's curve and which cannot.
FREE_SET_STUDY: tuple[tuple[str, ...], ...] = (
    ("beta", "vial_mass"),
    ("beta", "vial_mass", "h_outer"),
    ("beta", "vial_mass", "outer_area"),
    ("vial_mass", "h_outer", "lam"),
    DEFAULT_FREE,
    ("beta", "vial_mass", "h_outer", "lam", "eta"),
)
# The experiment's time constant (min): a model whose slowest one is far longer still rises at the hour.
EXPERIMENT_TAU_MIN = 16.7


@dataclass(frozen=True)
class FreeSetOutcome:
    """One free set fitted to the experiment's curve, and why it does or does not follow it."""

    free: tuple[str, ...]
    calibration: Calibration

    @property
    def follows_curve(self) -> bool:
        rms = self.calibration.curve_rms_K
        return rms is not None and rms <= CURVE_TOLERANCE_K

    @property
    def verdict(self) -> str:
        calibration = self.calibration
        rms = calibration.curve_rms_K
        slowest = calibration.predictions.get("slowest_time_constant_min", math.nan)
        parts = [f"{'follows' if self.follows_curve else 'does not follow'} the curve ({rms:.2f} K RMS)"]
        if not self.follows_curve and slowest > 1.5 * EXPERIMENT_TAU_MIN:
            parts.append(
                f"its slowest time constant is {slowest:.0f} min against the experiment's {EXPERIMENT_TAU_MIN:g}: "
                f"the ball is still rising at the hour (steady state {calibration.predictions['ball_steady_C']:.1f} °C)"
            )
        edges = [key for key in calibration.at_bounds if key in DEFENSIBLE_RANGES]
        if edges:
            parts.append(f"{', '.join(edges)} on the edge of the defensible range")
        return "; ".join(parts)


def free_set_study(
    base: Parameters,
    free_sets: Sequence[tuple[str, ...]] = FREE_SET_STUDY,
    curve: Curve | None = None,
    progress: Callable[[int], None] | None = None,
) -> list[FreeSetOutcome]:
    """Fit each free set to ``curve`` (the experiment's by default) from ``base``; ``progress(fits done)`` after
    each."""
    curve = curve or experiment_curve()
    outcomes = []
    for free in free_sets:
        outcomes.append(FreeSetOutcome(tuple(free), calibrate(base, free, curve=curve)))
        if progress is not None:
            progress(len(outcomes))
    return outcomes
