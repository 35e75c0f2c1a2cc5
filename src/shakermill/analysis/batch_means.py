"""Batch-means statistics of a settling time series (the averaged solvers' convergence test, MODEL.md §14.2).

The start-up transient is cut by the MSER rule (White 1997). The standard error of the remaining batch means
says how well their mean is known only when the means are uncorrelated: consecutive batches are grouped
(1, 2, 4, … batches a group) until the lag-1 autocorrelation of the group means is insignificant,
|r₁| < 2/√k for k groups (the large-sample bound of r₁ for white noise, Box & Jenkins), and a drift between
the halves of the settled window says the motion is not yet stationary.

The variance of a mean of correlated values is at most their own variance, so a column whose batch means
spread by less than the error asked for (``negligible``, relative) is known well enough whatever their
correlation: such columns (a periodic motion's, equal up to round-off) are not tested.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

# Halves of the settled window whose means differ by more than this many of their standard errors drift:
# three, so that a stationary motion is called drifting about once in 400 tests of one column.
DRIFT_SIGMAS = 3.0


def mser_truncation(batch_means: np.ndarray) -> int:
    """Number of leading batches to discard (MSER: minimise the marginal standard error, d ≤ n/2)."""
    n = batch_means.size
    if n == 0:
        return 0
    best, best_score = 0, math.inf
    for cut in range(n // 2 + 1):
        rest = batch_means[cut:]
        score = float(np.sum((rest - rest.mean()) ** 2)) / rest.size**2
        if score < best_score:
            best, best_score = cut, score
    return best


def batch_rates(cumulative: np.ndarray, batch_length: float) -> np.ndarray:
    """Mean rate of each batch from a cumulative series sampled at batch ends (along its first axis)."""
    return np.diff(cumulative, axis=0) / batch_length


def standard_error(values: np.ndarray) -> float:
    return float(values.std(ddof=1) / math.sqrt(values.size)) if values.size > 1 else math.inf


def normalised(values: np.ndarray) -> np.ndarray:
    if values.size == 0:
        return values
    scale = abs(values.mean())
    return values / scale if scale > 0 else values


def relative_error(values: np.ndarray) -> float:
    mean = abs(values.mean())
    error = standard_error(values)
    if mean == 0.0:
        return 0.0 if error == 0.0 else math.inf
    return error / mean


def lag1_autocorrelation(series: Sequence[np.ndarray]) -> float:
    """Lag-1 autocorrelation of batch means pooled over independent ``series`` (replicas of one run): the
    products of neighbours within each series about the pooled mean, over the pooled sum of squares; 0 for
    equal means."""
    values = np.concatenate(series)
    if values.size < 2:
        return 0.0
    deviations = [part - values.mean() for part in series]
    squares = float(np.sum((values - values.mean()) ** 2))
    if squares == 0.0:
        return 0.0
    return sum(float(np.sum(part[:-1] * part[1:])) for part in deviations) / squares


def grouped(rates: np.ndarray, size: int) -> np.ndarray:
    """Means of consecutive groups of ``size`` batches (along the first axis). The batches that do not fill a
    group are the oldest, nearest the transient, and are left out."""
    whole = rates.shape[0] // size * size
    kept = rates[rates.shape[0] - whole :]
    return kept.reshape(-1, size, *rates.shape[1:]).mean(axis=1)


def significant_autocorrelation(r1: float, groups: int) -> bool:
    return abs(r1) >= 2.0 / math.sqrt(groups) if groups > 0 else True


@dataclass(frozen=True)
class Grouping:
    """Batches a group, the groups pooled, the largest |lag-1 autocorrelation| of every column's group means as
    measured (reported as it is, also where a column's spread is too small to matter), and whether those whose spread
    matters are uncorrelated with at least the fewest groups asked for."""

    size: int
    groups: int
    autocorrelation: float
    uncorrelated: bool


def negligible_spread(values: np.ndarray, negligible: float) -> bool:
    # No batch has no spread to test: a budget that ends before the first batch must not warn on NumPy's empty mean.
    return values.size == 0 or bool(values.std() <= negligible * abs(values.mean()))


def power_of_two_at_least(count: int) -> int:
    """The smallest group size of :func:`uncorrelated_grouping` (1, 2, 4, …) that holds ``count`` batches."""
    return 1 << max(0, math.ceil(math.log2(count))) if count > 1 else 1


def uncorrelated_grouping(
    series: Sequence[np.ndarray], least: int, negligible: float = 0.0, smallest: int = 1
) -> Grouping:
    """The smallest grouping (1, 2, 4, … batches, at least ``smallest``) of every replica's batch means ``series``
    (rows: batches, columns: the quantities checked) whose group means are uncorrelated, with at least ``least``
    groups in all; the largest grouping with ``least`` groups, marked correlated, when none is. Columns whose spread
    is ``negligible`` are not tested."""
    pooled = np.concatenate(series)
    tested = [column for column in range(pooled.shape[1]) if not negligible_spread(pooled[:, column], negligible)]
    size, found = power_of_two_at_least(smallest), None
    while True:
        groups = [grouped(part, size) for part in series]
        count = sum(len(part) for part in groups)
        if count < least and found is not None:
            return found
        r1 = [abs(lag1_autocorrelation([part[:, column] for part in groups])) for column in range(pooled.shape[1])]
        decisive = max((r1[column] for column in tested), default=0.0)
        found = Grouping(
            size, count, max(r1, default=0.0), count >= least and not significant_autocorrelation(decisive, count)
        )
        if found.uncorrelated or count < least:
            return found
        size *= 2


def drifts(values: np.ndarray, negligible: float = 0.0) -> bool:
    """Whether the means of the first and second half of uncorrelated group means ``values`` differ by more than
    :data:`DRIFT_SIGMAS` standard errors and by more than the ``negligible`` share of their mean (too few values to
    tell: no)."""
    half = values.size // 2
    if half < 2:
        return False
    first, second = values[:half], values[-half:]
    difference = abs(first.mean() - second.mean())
    spread = math.hypot(standard_error(first), standard_error(second))
    return bool(difference > DRIFT_SIGMAS * spread and difference > negligible * abs(values.mean()))
