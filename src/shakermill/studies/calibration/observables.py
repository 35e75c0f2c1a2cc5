"""What a measurement or a prediction of a calibration is of: a node's mean rise above the start at a time, and the
rises of such points computed from a thermal network under a run's mean load (milliseconds: no mechanics)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork
from shakermill.parameters.keys import Parameters
from shakermill.solvers.averaged import integrate_network

# A measured rise's standard deviation where its source states none (K): the one-ball curve is an exponential
# fitted to intermittent calorimetric measurements, which a model following within 2 K follows within their likely
# scatter (studies/validation/matrix.FOLLOWS_CURVE_K); the five-ball point is quoted without an error.
ASSUMED_MEASUREMENT_SD_K = 2.0


class AtNode(Protocol):
    """A node ('ball': the balls' mean, or 'vial') at a time (s)."""

    @property
    def node(self) -> str: ...

    @property
    def time_s(self) -> float: ...


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


def measured_of(experiment: Any) -> list[Measured]:
    """The measured points of a validation experiment (``studies/validation/matrix.Experiment``)."""
    return [
        Measured(Observable(point.node, point.time_s), point.rise_K)
        for point in experiment.points
        if point.rise_K is not None
    ]


def node_rises(
    points: Sequence[AtNode], network_of: Callable[[Parameters], ThermalNetwork]
) -> Callable[[Parameters, NetworkLoad], dict[str, float]]:
    """The rises (K) of ``points`` of the network ``network_of`` builds, under a mean load, as named quantities."""

    def rises(params: Parameters, load: NetworkLoad) -> dict[str, float]:
        network = network_of(params)
        thermal = integrate_network(network, load, params)
        index = {"ball": slice(0, network.n_balls), "vial": network.vial}
        values = {}
        for point in points:
            history = np.atleast_2d(thermal.y[index[point.node]]).mean(axis=0)
            values[f"{point.node}@{point.time_s:g}"] = (
                float(np.interp(point.time_s, thermal.t, history)) - params.initial_temperature
            )
        return values

    return rises
