"""Batch-means statistics of a settling time series (the averaged solvers' convergence test).

The start-up transient is cut by the MSER rule (White 1997); the standard error of the remaining batch
means says how well their mean is known.
"""

from __future__ import annotations

import math

import numpy as np


def mser_truncation(batch_means: np.ndarray) -> int:
    """Number of leading batches to discard (MSER: minimise the marginal standard error, d ≤ n/2)."""
    n = batch_means.size
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
    scale = abs(values.mean())
    return values / scale if scale > 0 else values


def relative_error(values: np.ndarray) -> float:
    mean = abs(values.mean())
    error = standard_error(values)
    if mean == 0.0:
        return 0.0 if error == 0.0 else math.inf
    return error / mean
