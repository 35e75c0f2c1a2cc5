"""The one posterior type: samples of named keys given measurements, with the prior they were drawn under and the
sampler's diagnostics.

A posterior keeps its samples in the coordinates they were drawn in: the unit cube of its prior (an emulated
calibration over assumed inputs, whose sampler walks the cube) or the keys' natural logarithms (a least-squares fit's,
sampled in the logarithms within their bounds, and what a fitted preset records as ``posterior_log``); its values,
logarithms and unit-cube points are derived from them, so what was sampled is never rounded through another map.

An ensemble carries a calibration's posterior into its design as a Gaussian in the keys' logarithms
(:meth:`Posterior.log_normal`, :class:`LogNormal`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from shakermill.parameters.assumed import AssumedInput
from shakermill.studies.inference.prior import Prior
from shakermill.studies.inference.sampler import Chain

QUANTILES = (0.05, 0.5, 0.95)
# The coordinates of a posterior's samples.
UNIT, LOGARITHMS = "unit", "logarithms"
# emcee's rule of thumb: a chain is long enough at 50 autocorrelation times, its kept half at 25.
CONVERGED_TIMES = 25
# How a design names the normal that carries a fitted key's posterior.
FITTED_SUFFIX = " (fitted)"


@dataclass(frozen=True)
class Posterior:
    """Samples (samples, keys) of ``keys`` in ``space``; ``prior`` is what they were drawn under (needed for the unit
    cube, absent for a posterior read back from a preset, which records the samples alone)."""

    keys: tuple[str, ...]
    samples: np.ndarray
    space: str = UNIT
    prior: Prior | None = None
    acceptance: float = math.nan
    autocorrelation_steps: float = math.nan
    steps: int = 0  # the chain's steps after burn-in (0: not a chain, as a sample of the prior)

    @classmethod
    def sampled(cls, prior: Prior, chain: Chain) -> Posterior:
        """The posterior of a chain run over the unit cube of ``prior``."""
        return cls(
            tuple(prior.keys), chain.samples, UNIT, prior, chain.acceptance, chain.autocorrelation_steps, chain.steps
        )

    @classmethod
    def of_logarithms(
        cls, keys: Sequence[str], samples: Any, prior: Prior | None = None, chain: Chain | None = None
    ) -> Posterior:
        """A posterior of ``keys`` from samples of their natural logarithms (a fit's chain, or a preset's record)."""
        diagnostics = () if chain is None else (chain.acceptance, chain.autocorrelation_steps, chain.steps)
        return cls(tuple(keys), np.asarray(samples, dtype=float), LOGARITHMS, prior, *diagnostics)

    def __len__(self) -> int:
        return len(self.samples)

    @property
    def inputs(self) -> tuple[AssumedInput, ...]:
        """Each key's range, distribution and reason under the prior (none where the prior is not recorded)."""
        return () if self.prior is None else self.prior.inputs

    def _prior(self) -> Prior:
        if self.prior is None:
            raise ValueError("a posterior of unit-cube samples needs the prior they were drawn under")
        return self.prior

    @property
    def values(self) -> np.ndarray:
        """The samples in the keys' own units."""
        return self._prior().values(self.samples) if self.space == UNIT else np.exp(self.samples)

    @property
    def logarithms(self) -> np.ndarray:
        """The samples' natural logarithms (what a fitted preset records as ``posterior_log``)."""
        return self.samples if self.space == LOGARITHMS else np.log(self.values)

    @property
    def unit(self) -> np.ndarray:
        """The samples in the unit cube of the prior (where a surrogate over it is evaluated)."""
        return self.samples if self.space == UNIT else self._prior().unit(np.exp(self.samples))

    def quantiles(
        self, levels: Sequence[float] = QUANTILES, *, in_logarithms: bool = False
    ) -> dict[str, tuple[float, ...]]:
        """Each key's quantiles at ``levels`` (its own unit). ``in_logarithms``: interpolated between neighbouring
        samples in the keys' logarithms (a fit's posterior, uniform there a priori) rather than in their values."""
        table = (
            np.exp(np.quantile(self.logarithms, levels, axis=0))
            if in_logarithms
            else np.quantile(self.values, levels, axis=0)
        )
        return {key: tuple(float(v) for v in table[:, index]) for index, key in enumerate(self.keys)}

    @property
    def medians(self) -> dict[str, float]:
        return {key: middle for key, (_, middle, _) in self.quantiles().items()}

    @property
    def converged(self) -> bool:
        """emcee's rule of thumb: a chain longer than 50 autocorrelation times (its kept half, 25)."""
        return self.steps > CONVERGED_TIMES * self.autocorrelation_steps

    def thinned(self, most: int) -> np.ndarray:
        """The rows of at most ``most`` samples, evenly chosen (what a preset records, what a run carries)."""
        return np.linspace(0, len(self) - 1, min(most, len(self))).astype(int)

    def log_normal(self) -> LogNormal | None:
        """This posterior as a Gaussian in the keys' logarithms (their samples' mean and covariance); None without
        more samples than keys, too few to estimate a covariance."""
        if not self.keys or len(self) <= len(self.keys):
            return None
        logs = self.logarithms
        return LogNormal(self.keys, logs.mean(axis=0), np.linalg.cholesky(np.atleast_2d(np.cov(logs, rowvar=False))))

    def as_dict(self) -> dict[str, Any]:
        """Each key's prior and 5/50/95 %, and the sampler's diagnostics."""
        quantiles = self.quantiles()
        priors = {} if self.prior is None else self.prior.tables()
        return {
            "inputs": {
                key: {**priors.get(key, {}), **dict(zip(("p5", "p50", "p95"), quantiles[key]))} for key in self.keys
            },
            "samples": len(self),
            "acceptance": self.acceptance,
            "autocorrelation_steps": self.autocorrelation_steps,
            "converged": self.converged,
        }


@dataclass(frozen=True)
class LogNormal:
    """A posterior as a Gaussian in its keys' logarithms: their ``mean`` and the lower Cholesky ``factor`` of their
    covariance, drawn through independent normals ξ (log v = mean + L·ξ), so that each ξ is an input of a design of
    its own ("KEY (fitted)"): the part of that key's spread the keys before it do not explain."""

    keys: tuple[str, ...]
    mean: np.ndarray
    factor: np.ndarray

    @classmethod
    def of_covariance(cls, keys: Sequence[str], values: Sequence[float], covariance: Any) -> LogNormal:
        """The Gaussian about a fit's ``values`` with the ``covariance`` of their logarithms (a calibration that
        recorded no samples); ValueError where the covariance is no covariance (not symmetric positive definite)."""
        matrix = np.atleast_2d(np.asarray(covariance, dtype=float))
        if matrix.shape != (len(keys), len(keys)) or not np.allclose(matrix, matrix.T):
            raise ValueError(f"a symmetric {len(keys)} x {len(keys)} matrix is needed, one row per fitted key")
        try:
            factor = np.linalg.cholesky(matrix)
        except np.linalg.LinAlgError:
            raise ValueError("it is not positive definite") from None
        return cls(tuple(keys), np.log(np.asarray(values, dtype=float)), factor)

    def marginal(self, keys: Sequence[str]) -> LogNormal:
        """The Gaussian of ``keys`` alone (some of :attr:`keys`): the others left at whatever values a run gives
        them, these drawn from their own mean and covariance."""
        chosen = [self.keys.index(key) for key in keys]
        covariance = (self.factor @ self.factor.T)[np.ix_(chosen, chosen)]
        return LogNormal(tuple(keys), self.mean[chosen], np.linalg.cholesky(covariance))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f"{key}{FITTED_SUFFIX}" for key in self.keys)

    def values(self, unit: np.ndarray) -> np.ndarray:
        """The keys' values (last axis) at points of the unit cube, one independent normal per key."""
        from scipy.stats import norm

        return np.exp(self.mean + norm.ppf(unit) @ self.factor.T)

    def unit(self, values: np.ndarray) -> np.ndarray:
        """The inverse of :meth:`values`."""
        from scipy.linalg import solve_triangular
        from scipy.stats import norm

        normals = solve_triangular(self.factor, (np.log(values) - self.mean).T, lower=True).T
        return norm.cdf(normals)

    def as_dict(self) -> dict[str, Any]:
        spread = np.sqrt(np.diag(self.factor @ self.factor.T))
        return {
            key: {"median": float(np.exp(centre)), "log_sd": float(sd)}
            for key, centre, sd in zip(self.keys, self.mean, spread)
        }
