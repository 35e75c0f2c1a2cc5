"""The surrogate of what runs give: a Gaussian process over a prior's unit cube (scikit-learn: one length scale per
key, Matérn 5/2, a noise term for the averaging error of the mechanics), of a quantity or of its logarithm, with its
Q² on runs it did not see (k-fold, or grouped k-fold where several points share a run). A surrogate whose held-out
Q² is below LEAST_Q2 does not predict: what is computed on it (Sobol' indices, a posterior) is not reported."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

# The held-out Q² below which a surrogate is not relied on.
LEAST_Q2 = 0.5


def gaussian_process(unit: np.ndarray, values: np.ndarray) -> Any:
    """A Gaussian process fitted to ``values`` at ``unit``, with one length scale per input (Matérn 5/2) and a noise
    term for the averaging error."""
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel

    kernel = ConstantKernel(1.0) * Matern(
        length_scale=np.ones(unit.shape[1]), length_scale_bounds=(1e-2, 1e3), nu=2.5
    ) + WhiteKernel(1e-3, noise_level_bounds=(1e-8, 1.0))
    regressor = GaussianProcessRegressor(kernel, normalize_y=True, n_restarts_optimizer=2, random_state=0)
    # A length scale at its upper bound is an input the headline does not depend on: an answer, not a problem.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        return regressor.fit(unit, values)


def q2_of(values: np.ndarray, predicted: np.ndarray) -> float:
    """1 − (sum of squared errors of the predictions of held-out ``values``)/(their sum of squares about the mean);
    NaN for values that do not vary."""
    spread = float(np.sum((values - values.mean()) ** 2))
    return 1.0 - float(np.sum((values - predicted) ** 2)) / spread if spread > 0 else math.nan


def held_out_q2(
    unit: np.ndarray,
    values: np.ndarray,
    folds: int,
    groups: np.ndarray | None = None,
    logarithmic: bool = False,
) -> float:
    """The Q² of ``values`` predicted by Gaussian processes fitted without them, over ``folds`` folds: shuffled
    k-fold, or, with ``groups``, grouped k-fold (the points of one run held out together). A ``logarithmic``
    surrogate is fitted to the logarithms and its predictions turned back: the Q² is of the values themselves."""
    from sklearn.model_selection import GroupKFold, KFold

    fitted = np.log(values) if logarithmic else values
    splits = (
        KFold(folds, shuffle=True, random_state=0).split(unit)
        if groups is None
        else GroupKFold(folds).split(unit, values, groups)
    )
    predicted = np.empty_like(values)
    for train, held in splits:
        found = gaussian_process(unit[train], fitted[train]).predict(unit[held])
        predicted[held] = np.exp(found) if logarithmic else found
    return q2_of(values, predicted)


@dataclass(frozen=True)
class Surrogate:
    """A Gaussian process of one quantity over a prior's unit cube, of its logarithm where ``logarithmic``, and its
    held-out Q². ``model`` is None where the Q² fell below the least a study asked for: it was not worth fitting."""

    model: Any
    q2: float
    logarithmic: bool = False

    def fitted_space(self, unit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The mean and standard deviation at ``unit`` of what the process was fitted to (the logarithm, if so)."""
        mean, sd = self.model.predict(unit, return_std=True)
        return mean, sd

    def mean(self, unit: np.ndarray) -> np.ndarray:
        """The process's mean at ``unit``, in the space it was fitted in."""
        return self.model.predict(unit)


def fit_surrogate(
    unit: np.ndarray,
    values: np.ndarray,
    folds: int,
    groups: np.ndarray | None = None,
    logarithmic: bool = False,
    least_q2: float = -math.inf,
) -> Surrogate:
    """The :class:`Surrogate` of ``values`` at ``unit``: its held-out Q² (:func:`held_out_q2`) and, where that
    reaches ``least_q2``, the process fitted to every point."""
    q2 = held_out_q2(unit, values, folds, groups, logarithmic)
    if not q2 >= least_q2:
        return Surrogate(None, q2, logarithmic)
    return Surrogate(gaussian_process(unit, np.log(values) if logarithmic else values), q2, logarithmic)
