"""90 % intervals of a run's predictions (MODEL.md section 13.3): the uncertainty of the calibration it rests on,
and the averaging error of its mechanics, carried through the thermal network.

A calibration records the covariance of the natural logarithms of its fitted keys (``scipy.optimize.least_squares``'
Jacobian with the residual variance) and, where an evaluation costs only a network, samples of their posterior
(emcee, the prior uniform within each key's defensible range; ``studies.calibration.calibrate``). Those keys move
the thermal network alone, so a prediction's spread is taken on the network with the run's own mean load:

* from the posterior samples where there are some: each sample's network (its heat scaled by a draw of the averaging
  error), the 5th and 95th percentiles. One curve often leaves a direction of the keys undetermined; the ranges
  bound it there, and the percentiles show it;
* otherwise linearly (the delta method) from the covariance and the averaging error, symmetric about the value.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from statistics import NormalDist

import numpy as np

from shakermill.analysis.steady import steady_state
from shakermill.engines.registry import describe, engine_named
from shakermill.engines.thermal.network import NetworkLoad
from shakermill.parameters.keys import Parameters
from shakermill.parameters.presets import Preset
from shakermill.solvers.averaged import integrate_network
from shakermill.solvers.result import Result
from shakermill.solvers.summary_sections import PredictionIntervals
from shakermill.studies.inference.posterior import Posterior

LEVEL = 0.90
# Step of the finite differences in the logarithm of a key (and of the heat): small beside a fit's relative errors
# (~10 %), large beside the network integration's own error (1e-9).
LOG_STEP = 1e-3
# The temperatures given intervals: at the end of the run (mean of the balls, the vial) and at steady state (°C).
HEADLINE = ("ball_C", "vial_C", "ball_steady_C", "vial_steady_C")
# Posterior samples carried through the network (evenly chosen from those recorded): the percentiles of 100
# move by about a sample's spacing.
PROPAGATED_SAMPLES = 100
HEAT_DRAW_SEED = 20261125

Quantities = Callable[[Parameters, NetworkLoad], dict[str, float]]


@dataclass(frozen=True)
class Intervals:
    """Each quantity's value and its 90 % interval, and what the interval carries."""

    centre: dict[str, float]
    low: dict[str, float]
    high: dict[str, float]
    sources: tuple[str, ...]

    def bounds(self, key: str) -> tuple[float, float]:
        return self.low[key], self.high[key]

    def as_summary(self) -> PredictionIntervals:
        """The summary's section of the intervals of the :data:`HEADLINE` temperatures."""
        return PredictionIntervals(
            ball_C_low=self.low["ball_C"],
            ball_C_high=self.high["ball_C"],
            vial_C_low=self.low["vial_C"],
            vial_C_high=self.high["vial_C"],
            ball_steady_C_low=self.low["ball_steady_C"],
            ball_steady_C_high=self.high["ball_steady_C"],
            vial_steady_C_low=self.low["vial_steady_C"],
            vial_steady_C_high=self.high["vial_steady_C"],
            note=f"{100 * LEVEL:g} % intervals from {' and '.join(self.sources)}",
        )


@dataclass(frozen=True)
class Uncertainty:
    """What a calibrated preset says of its fitted keys: the covariance and posterior samples of their logarithms."""

    fitted: tuple[str, ...]
    covariance: np.ndarray | None = None
    posterior: Posterior | None = None
    # Fitted keys that move the mechanics (a calibration over every uncertain input): a run's mean load cannot carry
    # them, `shakermill uncertainty` does.
    left_out: tuple[str, ...] = ()


def uncertainty_of(preset: Preset) -> Uncertainty | None:
    """What the calibration of ``preset`` recorded of its uncertainty, of the keys its network alone reads (an
    engine without thermal-only keys reruns everything: all of them); None for a preset that no calibration made or
    that predates the record."""
    if preset.covariance is None and preset.posterior is None:
        return None
    thermal_only = describe(preset.values["engine"].value).thermal_only_keys
    kept = [index for index, key in enumerate(preset.fitted) if not thermal_only or key in thermal_only]
    covariance = None if preset.covariance is None else np.asarray(preset.covariance, dtype=float)[np.ix_(kept, kept)]
    keys = tuple(preset.fitted[index] for index in kept)
    posterior = (
        None
        if preset.posterior is None
        else Posterior.of_logarithms(keys, np.asarray(preset.posterior, dtype=float)[:, kept])
    )
    left_out = tuple(key for index, key in enumerate(preset.fitted) if index not in kept)
    return Uncertainty(keys, covariance, posterior, left_out)


def headline_temperatures(params: Parameters, load: NetworkLoad) -> dict[str, float]:
    """The headline temperatures (°C) of ``params``' network under ``load``, integrated over the run."""
    network = engine_named(params.engine).network_for(params)
    thermal = integrate_network(network, load, params)
    end = thermal.y[:, -1]
    steady = steady_state(network, load)
    return {
        "ball_C": float(network.mean_ball(end)) - 273.15,
        "vial_C": float(end[network.vial]) - 273.15,
        "ball_steady_C": steady.ball - 273.15,
        "vial_steady_C": steady.vial - 273.15,
    }


def heat_error_of(result: Result) -> float:
    """The relative standard error of the heat power the averaged solver measured (0 for a full run)."""
    averages = result.averages
    return averages.heat_power_stderr / averages.heat_power if averages is not None and averages.heat_power > 0 else 0.0


def intervals(result: Result, uncertainty: Uncertainty) -> Intervals | None:
    """The intervals of ``result``'s headline temperatures, about its summary's values; None when the run has no mean
    load to carry them (it stopped early) or nothing is uncertain."""
    if result.load is None or not result.success:
        return None
    found = propagated(result.params, result.load, uncertainty, heat_error_of(result), headline_temperatures)
    if found is None:
        return None
    # The run's own values, which a full run's averaged network only approaches; the spread is the network's.
    reported = {name: result.summary.number(name) for name in HEADLINE}
    shift = {name: reported[name] - found.centre[name] for name in HEADLINE}
    return Intervals(
        reported,
        {name: found.low[name] + shift[name] for name in HEADLINE},
        {name: found.high[name] + shift[name] for name in HEADLINE},
        found.sources,
    )


def propagated(
    params: Parameters, load: NetworkLoad, uncertainty: Uncertainty, heat_error: float, quantities: Quantities
) -> Intervals | None:
    """The 90 % intervals of ``quantities`` of ``params``' network under ``load``: from the posterior samples of
    ``uncertainty`` if it has some, else linearly from its covariance; with a relative error ``heat_error`` of the
    heat, independent of the fit. None when nothing is uncertain."""
    if uncertainty.posterior is not None:
        return _from_samples(params, load, uncertainty, uncertainty.posterior, heat_error, quantities)
    return _linear(params, load, uncertainty, heat_error, quantities)


def _from_samples(
    params: Parameters,
    load: NetworkLoad,
    uncertainty: Uncertainty,
    posterior: Posterior,
    heat_error: float,
    quantities: Quantities,
) -> Intervals:
    chosen = posterior.logarithms[posterior.thinned(PROPAGATED_SAMPLES)]
    heat_draws = np.random.default_rng(HEAT_DRAW_SEED).standard_normal(len(chosen)) * heat_error
    values = []
    for sample, draw in zip(chosen, heat_draws, strict=True):
        moved = params.replace(**{key: float(math.exp(x)) for key, x in zip(uncertainty.fitted, sample, strict=True)})
        values.append(quantities(moved, _heated(load, draw)))
    centre = quantities(params, load)
    table = np.array([[value[name] for name in centre] for value in values])
    low, high = np.percentile(table, [50 * (1 - LEVEL), 50 * (1 + LEVEL)], axis=0)
    sources = ("the calibration's posterior (emcee)",) + (
        ("the averaging error of the heat",) if heat_error > 0 else ()
    )
    if uncertainty.left_out:
        sources += (
            f"not the posterior of {', '.join(uncertainty.left_out)}, which moves the mechanics "
            "(shakermill uncertainty carries it)",
        )
    return Intervals(centre, dict(zip(centre, map(float, low))), dict(zip(centre, map(float, high))), sources)


def _linear(
    params: Parameters, load: NetworkLoad, uncertainty: Uncertainty, heat_error: float, quantities: Quantities
) -> Intervals | None:
    """The delta method: the spread of each quantity from its slopes in the logarithms of the keys and the heat."""
    keys = list(uncertainty.fitted) if uncertainty.covariance is not None else []
    sources = (["the calibration's covariance"] if keys else []) + (
        ["the averaging error of the heat"] if heat_error > 0 else []
    )
    if not sources:
        return None
    variances = np.zeros((len(keys) + 1, len(keys) + 1))
    if keys:
        variances[: len(keys), : len(keys)] = np.asarray(uncertainty.covariance, dtype=float)
    variances[-1, -1] = heat_error**2
    centre = quantities(params, load)
    moves = [(params.replace(**{key: getattr(params, key) * math.exp(LOG_STEP)}), load) for key in keys]
    moves.append((params, _heated(load, LOG_STEP)))
    gradients = np.array([_slopes(quantities(moved_params, moved_load), centre) for moved_params, moved_load in moves])
    # The standard library's normal quantile: scipy.stats would add half a second to every run of a calibrated preset.
    half = NormalDist().inv_cdf(0.5 + LEVEL / 2)
    stderr = {
        name: math.sqrt(max(float(gradients[:, i] @ variances @ gradients[:, i]), 0.0)) for i, name in enumerate(centre)
    }
    return Intervals(
        centre,
        {name: centre[name] - half * stderr[name] for name in centre},
        {name: centre[name] + half * stderr[name] for name in centre},
        tuple(sources),
    )


def _heated(load: NetworkLoad, log_factor: float) -> NetworkLoad:
    """``load`` with every contact's heat scaled by exp(``log_factor``)."""
    factor = math.exp(log_factor)
    return replace(load, heat=load.heat * factor, heat_power=load.heat_power * factor)


def _slopes(moved: Mapping[str, float], centre: Mapping[str, float]) -> np.ndarray:
    """Each quantity's change per unit of the logarithm moved by LOG_STEP: a forward difference."""
    return np.array([(moved[name] - centre[name]) / LOG_STEP for name in centre])
