"""The statistics of a least-squares fit in the logarithms of its keys: their covariance from the Jacobian, each
key's standard error, the posterior sampled with emcee, and the sensitivities of the targets and curves."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from shakermill.studies.inference.sampler import Chain, sample
from shakermill.studies.measured import ASSUMED_CURVE_SD_K, Curve

# Scalar targets are matched relatively; curve points in kelvin: one kelvin weighs like 1 % on a target.
CURVE_SCALE_K = 100.0


def log_covariance(
    jacobian: np.ndarray, residuals: np.ndarray, free_count: int, curves: Sequence[Curve]
) -> np.ndarray | None:
    """The covariance of the logarithms of the fitted keys, (JᵀJ)⁻¹·s² with s² the residual variance; meaningful
    only for curves of more points than parameters, None otherwise or where JᵀJ is singular.

    The residual variance is floored at the curves' measurement error (stated, or ASSUMED_CURVE_SD_K): a curve
    that is itself a smooth summary, or one of few points, can be fitted exactly, which says nothing about how
    well it was measured.
    """
    if not curves or residuals.size <= free_count:
        return None
    try:
        return np.linalg.inv(jacobian.T @ jacobian) * residual_variance(residuals, free_count, curves)
    except np.linalg.LinAlgError:
        return None


def residual_variance(residuals: np.ndarray, free_count: int, curves: Sequence[Curve]) -> float:
    """The residuals' variance over their degrees of freedom, floored at the largest measurement error of a curve
    (its stated one, or ASSUMED_CURVE_SD_K)."""
    variance = float(np.sum(residuals**2)) / (residuals.size - free_count)
    stated = max(ASSUMED_CURVE_SD_K if measured.sigma_K is None else measured.sigma_K for measured in curves)
    return max(variance, (stated / CURVE_SCALE_K) ** 2)


# The posterior: emcee's affine-invariant ensemble (``studies.inference.sampler``), WALKERS_PER_KEY walkers a key,
# POSTERIOR_STEPS steps of which the first half is burn-in; POSTERIOR_KEPT samples are kept, evenly thinned. ~2400
# evaluations of a three-key fit, a few minutes of networks (benchmarks/bench_calibrate_3d.py); the seed makes it
# deterministic.
WALKERS_PER_KEY = 4
POSTERIOR_STEPS = 200
POSTERIOR_KEPT = 200
POSTERIOR_SEED = 20261125


def posterior_evaluations(keys: int) -> int:
    """How many model evaluations :func:`posterior_samples` makes for ``keys`` keys."""
    return POSTERIOR_STEPS * WALKERS_PER_KEY * keys


def posterior_samples(
    residuals_of: Callable[[np.ndarray], np.ndarray],
    best: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    variance: float,
) -> Chain:
    """POSTERIOR_KEPT samples (keys) of the logarithms of the fitted keys: a Gaussian likelihood of the residuals with
    ``variance`` (the fit's), a prior uniform in the logarithms within [``lower``, ``upper``] (the defensible
    ranges). Where one curve leaves a direction of the keys undetermined, the ranges bound it, which the
    covariance cannot."""

    def log_probability(x: np.ndarray) -> float:
        if np.any(x < lower) or np.any(x > upper):
            return -np.inf
        return -0.5 * float(np.sum(residuals_of(x) ** 2)) / variance

    keys = best.size
    walkers = WALKERS_PER_KEY * keys
    rng = np.random.default_rng(POSTERIOR_SEED)
    start = np.clip(best + 1e-3 * rng.standard_normal((walkers, keys)), lower, upper)
    return sample(log_probability, start, POSTERIOR_STEPS, POSTERIOR_KEPT, POSTERIOR_SEED)


def standard_errors(
    covariance: np.ndarray | None, free: Sequence[str], fitted: Mapping[str, float]
) -> dict[str, float]:
    """Each fitted key's standard error in its own unit: in log space the standard error is relative."""
    if covariance is None:
        return {key: math.nan for key in free}
    return {key: float(fitted[key] * math.sqrt(max(covariance[i, i], 0.0))) for i, key in enumerate(free)}


def sensitivities(
    jacobian: np.ndarray, free: Sequence[str], targets: Mapping[str, float], curves: Sequence[Curve]
) -> dict[str, dict[str, float]]:
    """From the least-squares Jacobian: d ln(target)/d ln(parameter) for scalar targets, and for each curve
    d θ/d ln(parameter) of its node in K at its middle and last point."""
    values = {
        target: {key: float(jacobian[row, column]) for column, key in enumerate(free)}
        for row, target in enumerate(targets)
    }
    offset = len(targets)
    for measured in curves:
        conditions = f" ({', '.join(measured.conditions)})" if measured.conditions else ""
        for point in (measured.times.size // 2, measured.times.size - 1):
            label = f"{measured.node}_C at {measured.times[point] / 60.0:g} min{conditions}"
            values[label] = {
                key: float(CURVE_SCALE_K * jacobian[offset + point, column]) for column, key in enumerate(free)
            }
        offset += measured.times.size
    return values
