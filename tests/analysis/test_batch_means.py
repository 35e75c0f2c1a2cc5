"""Batch means of correlated series: grouped until uncorrelated, drift, the round-off of periodic motion
(MODEL.md §14.2)."""

import math

import numpy as np
import pytest

from shakermill.analysis.batch_means import (
    drifts,
    grouped,
    lag1_autocorrelation,
    mser_truncation,
    standard_error,
    uncorrelated_grouping,
)


def ar1(phi: float, n: int, seed: int) -> np.ndarray:
    """An AR(1) series x_i = φ x_{i-1} + ε_i about 10, started in its stationary distribution."""
    rng = np.random.default_rng(seed)
    noise = rng.normal(size=n)
    values = np.empty(n)
    values[0] = noise[0] / math.sqrt(1 - phi**2)
    for i in range(1, n):
        values[i] = phi * values[i - 1] + noise[i]
    return 10.0 + values


def true_error_of_mean(phi: float, n: int) -> float:
    """Standard deviation of the mean of n values of a unit-innovation AR(1) series (large n)."""
    return math.sqrt(1 / (1 - phi**2) * (1 + phi) / (1 - phi) / n)


def test_lag1_autocorrelation_of_an_ar1_series_is_its_coefficient():
    assert lag1_autocorrelation([ar1(0.8, 20_000, 1)]) == pytest.approx(0.8, abs=0.02)
    assert lag1_autocorrelation([ar1(0.0, 20_000, 2)]) == pytest.approx(0.0, abs=0.02)


def test_lag1_autocorrelation_pools_replicas_without_pairing_across_them():
    # Two constant series at different levels: within each, neighbours sit on the same side of the pooled
    # mean (+1 each); pairing the last of one with the first of the other would add a −1.
    low, high = np.full(5, 1.0), np.full(5, 3.0)
    assert lag1_autocorrelation([low, high]) == pytest.approx(8 / 10)


def test_means_that_spread_less_than_the_error_asked_for_are_not_tested():
    # A periodic motion's batch means, equal but for a slow round-off drift: strongly correlated, and known to
    # 1e-9 whatever their correlation, since the variance of a mean never exceeds that of its values.
    periodic = 7.0 * (1 + 1e-9 * np.linspace(0.0, 1.0, 40))
    assert lag1_autocorrelation([periodic]) > 0.8
    assert not uncorrelated_grouping([periodic[:, None]], 20).uncorrelated
    assert uncorrelated_grouping([periodic[:, None]], 20, negligible=1e-3).uncorrelated
    assert drifts(periodic) and not drifts(periodic, negligible=1e-3)
    assert lag1_autocorrelation([np.full(30, 7.0)]) == 0.0


def test_grouped_leaves_out_the_oldest_batches_that_fill_no_group():
    values = np.arange(7.0)
    np.testing.assert_array_equal(grouped(values, 2), [1.5, 3.5, 5.5])
    np.testing.assert_array_equal(grouped(values[:, None], 3)[:, 0], [2.0, 5.0])


def test_correlated_batches_were_under_reported_and_grouping_corrects_them():
    # Batches of a motion with a memory longer than a batch (φ = 0.85, like the planetary packs' batches of
    # four turns): the plain batch-means error of 4000 batches is ~3.5 times too small; grouped until the
    # group means are uncorrelated, the error is within 30 % of the true one.
    phi, n = 0.85, 4000
    series = ar1(phi, n, 3)
    truth = true_error_of_mean(phi, n)
    assert standard_error(series) < truth / 3
    grouping = uncorrelated_grouping([series[:, None]], 20)
    assert grouping.uncorrelated and grouping.size >= 8 and grouping.groups >= 20
    corrected = standard_error(grouped(series, grouping.size))
    assert corrected == pytest.approx(truth, rel=0.3)


def test_uncorrelated_batches_are_not_grouped():
    grouping = uncorrelated_grouping([ar1(0.0, 400, 4)[:, None]], 20)
    assert (grouping.size, grouping.groups, grouping.uncorrelated) == (1, 400, True)


def test_too_few_groups_is_never_uncorrelated():
    grouping = uncorrelated_grouping([ar1(0.0, 19, 5)[:, None]], 20)
    assert not grouping.uncorrelated and grouping.groups == 19
    # Correlated to the end: the largest grouping with 20 groups, marked correlated.
    strong = uncorrelated_grouping([ar1(0.999, 80, 6)[:, None]], 20)
    assert (strong.size, strong.groups, strong.uncorrelated) == (4, 20, False)


def test_every_column_must_be_uncorrelated():
    white, red = ar1(0.0, 400, 7), ar1(0.9, 400, 8)
    assert uncorrelated_grouping([np.column_stack([white, red])], 20).size > 1


def test_drift_between_the_halves():
    rng = np.random.default_rng(9)
    steady = 5.0 + 0.1 * rng.normal(size=40)
    assert not drifts(steady)
    assert drifts(steady + np.linspace(0.0, 1.0, 40))
    assert not drifts(np.full(40, 5.0))


def test_mser_of_no_batches_cuts_nothing():
    assert mser_truncation(np.array([])) == 0


def test_too_few_means_have_no_autocorrelation():
    assert lag1_autocorrelation([np.array([])]) == 0.0 and lag1_autocorrelation([np.array([3.0])]) == 0.0
