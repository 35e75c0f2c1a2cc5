"""A prior: the keys a study varies or infers, each with its range, distribution and reason, and the map between the
unit cube and their values.

An assumed input of a preset (``parameters.assumed.AssumedInput``, MODEL.md §14.1) is one entry; so is a key a fit
moves, log-uniform over the range it bounds the key by (:func:`fitted_key`). A design samples the unit cube
(:mod:`.design`), a surrogate is fitted over it (:mod:`.surrogate`) and a sampler walks it (:mod:`.sampler`); the
prior maps its points onto the keys' values, each through its distribution.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from shakermill.parameters.assumed import AssumedInput

# How a fitted key's reason starts: a fit's range of it, not a preset's assumption.
FITTED_REASON = "fitted: "


def fitted_key(key: str, low: float, high: float, reason: str) -> AssumedInput:
    """A key a fit moves as an entry of a prior: uniform in its logarithm over [``low``, ``high``], as the
    least-squares fit moves it (steps relative, bounds ratios), with the reason for the range."""
    return AssumedInput(key, low, high, "log-uniform", f"{FITTED_REASON}{reason}")


@dataclass(frozen=True)
class Prior:
    """The keys, in order, each with its range and distribution: the unit cube's axes."""

    inputs: tuple[AssumedInput, ...]

    @classmethod
    def union(cls, priors: Iterable[Prior]) -> Prior:
        """Every key of ``priors``, each once, in the order met (the first one's range)."""
        found: dict[str, AssumedInput] = {}
        for prior in priors:
            for item in prior.inputs:
                found.setdefault(item.key, item)
        return cls(tuple(found.values()))

    @property
    def keys(self) -> list[str]:
        return [item.key for item in self.inputs]

    def __len__(self) -> int:
        return len(self.inputs)

    def values(self, unit: np.ndarray) -> np.ndarray:
        """Points of the unit cube (last axis: the keys) mapped onto the keys' ranges by their distributions."""
        values = np.empty_like(unit, dtype=float)
        for column, item in enumerate(self.inputs):
            share = unit[..., column]
            if item.distribution == "log-uniform":
                values[..., column] = np.exp(np.log(item.low) + share * (np.log(item.high) - np.log(item.low)))
            else:
                values[..., column] = item.low + share * (item.high - item.low)
        return values

    def unit(self, values: np.ndarray) -> np.ndarray:
        """The inverse of :meth:`values`."""
        unit = np.empty_like(values, dtype=float)
        for column, item in enumerate(self.inputs):
            if item.distribution == "log-uniform":
                unit[..., column] = np.log(values[..., column] / item.low) / np.log(item.high / item.low)
            else:
                unit[..., column] = (values[..., column] - item.low) / (item.high - item.low)
        return unit

    def columns(self, keys: Sequence[str]) -> list[int]:
        """The positions of this prior's keys among ``keys`` (each of them must be there)."""
        return [list(keys).index(key) for key in self.keys]

    def tables(self) -> dict[str, dict[str, Any]]:
        """Each key's ``[assumed.KEY]`` table: range, distribution and reason."""
        return {item.key: item.table() for item in self.inputs}
