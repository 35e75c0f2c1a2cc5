"""What an engine's run records, independent of the engine: its state history with units (:class:`StateHistory`)
and where the supplied work went (:class:`EnergyAudit`). The solvers assemble a ``Result`` from these."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, overload

import numpy as np

if TYPE_CHECKING:
    import xarray as xr


# Temperatures (K) that the datasets also carry in °C, as ``<name>_C``.
CELSIUS_VARIABLES = ("theta_ball", "theta_vial", "theta_air")

TIME_ATTRIBUTES = {"units": "s", "long_name": "simulated time"}

# The variable of every ball's temperature (K), over (time, ball), of an engine that moves several balls.
BALL_TEMPERATURES = "theta_balls"
# The variable of the contacts' cumulative heat (J) into each node but the balls, over (time, node), and its attribute
# that names the nodes in order (comma-separated): a run's files carry its network's nodes, whatever they are.
HEAT_INTO_NODES = "heat_into_nodes"
NODE_NAMES = "node_names"
# The contact records' column of each pair's Hertz duration at 1 m/s, where an engine records one: what tells a
# contact's chatter from a new impact (analysis/impacts.py, MODEL.md §14.4).
HERTZ_SCALE = "hertz_duration_1m_s"


@dataclass(frozen=True)
class StateHistory:
    """A state history as NumPy arrays over ``times`` (s), each variable with its attributes (units, long_name).
    A variable is over ``time`` alone unless ``dimensions`` names its dimensions (e.g. time, ball, axis).

    Run files are written from it directly, and :meth:`dataset` is the xarray view: a run that only
    writes its files never imports xarray, whose first Dataset imports dask and pint (half a second).
    """

    times: np.ndarray
    variables: dict[str, tuple[np.ndarray, dict[str, str]]]
    dimensions: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    def dims(self, name: str) -> tuple[str, ...]:
        return self.dimensions.get(name, ("time",))

    def __getitem__(self, name: str) -> np.ndarray:
        return self.variables[name][0]

    def with_attributes(self, extra: Mapping[str, Mapping[str, str]]) -> StateHistory:
        """The same history with ``extra[name]`` added to the attributes of variable ``name``."""
        variables = {
            name: (values, {**attributes, **extra.get(name, {})})
            for name, (values, attributes) in self.variables.items()
        }
        return StateHistory(self.times, variables, self.dimensions)

    def dataset(self) -> xr.Dataset:
        import xarray as xr

        data_vars = {
            name: (self.dims(name), values, dict(attributes)) for name, (values, attributes) in self.variables.items()
        }
        return xr.Dataset(data_vars, coords={"time": ("time", self.times, dict(TIME_ATTRIBUTES))})


def attributes(units: str, long_name: str) -> dict[str, str]:
    """A history variable's attributes."""
    return {"units": units, "long_name": long_name}


def with_celsius(variables: dict[str, tuple[np.ndarray, dict[str, str]]], names: tuple[str, ...]) -> None:
    """Add ``<name>_C`` beside each temperature ``name`` (K): ``ds.theta_ball_C.plot()`` is then labelled with the
    unit of its values, which converting ``theta_ball`` by hand would not change from [K]."""
    for name in names:
        kelvin, kelvin_attributes = variables[name]
        variables[f"{name}_C"] = (kelvin_to_celsius(kelvin), attributes("degC", kelvin_attributes["long_name"]))


@dataclass(frozen=True)
class EnergyAudit:
    """Where the vial's work went, in J, over the simulated interval.

    work_by_vial = Δkinetic + Δelastic + dissipated
    dissipated   = heat_generated + not_converted_to_heat
    heat_generated + drive_heat = Σ stored (every node) + heat_lost_to_surroundings

    ``heat_into`` and ``stored`` hold the heat each node received from the contacts and the heat it stored, by node
    as ``ThermalNetwork.grouped`` names them (the balls summed as "balls", then the vial, the air and any further
    node: the holder, the powder), so that a new node is audited without a field of its own.

    ``projection_correction`` is the total |Δ kinetic energy| the energy
    projection applied at the end of contacts: the integrator's truncation
    error in the contact mechanics, which the projection removes from the
    balance above but which this field keeps visible.
    """

    work_by_vial: float
    kinetic_energy_change: float
    elastic_energy_change: float
    dissipated: float
    heat_generated: float
    heat_into: Mapping[str, float]
    not_converted_to_heat: float
    stored: Mapping[str, float]
    heat_lost_to_surroundings: float
    projection_correction: float
    # The 'dem' engine adds the work of gravity and splits the dissipation by channel (MODEL.md §12.4).
    work_by_gravity: float = 0.0
    # ... and the energy its tangential springs gain by stiffening with the load (engines.dem.model.TOTAL_NAMES)
    work_by_stiffening: float = 0.0
    dissipated_by_channel: Mapping[str, float] = field(default_factory=dict)
    # Heat a node receives whatever the balls do: the drive's, into the holder of a mill head (thermal_model =
    # 'mill-head').
    drive_heat: float = 0.0

    @property
    def mechanical_residual(self) -> float:
        supplied = self.work_by_vial + self.work_by_gravity + self.work_by_stiffening
        return supplied - self.kinetic_energy_change - self.elastic_energy_change - self.dissipated

    @property
    def thermal_residual(self) -> float:
        stored = sum(self.stored.values())
        return self.heat_generated + self.drive_heat - stored - self.heat_lost_to_surroundings

    @property
    def residual(self) -> float:
        return self.mechanical_residual + self.thermal_residual

    @property
    def relative_residual(self) -> float:
        """|residual| over the largest flow in the balance (0 when nothing flowed, NaN when a term is not finite).
        The drive's heat counts: in an empty mill it is the only flow."""
        if not math.isfinite(self.residual):
            return math.nan
        scale = max(abs(self.work_by_vial), abs(self.dissipated), abs(self.heat_generated), abs(self.drive_heat))
        return abs(self.residual) / scale if scale > 0.0 else 0.0

    def as_dict(self) -> dict[str, float]:
        """Every term as one flat mapping (J): the mappings by channel and by node spread as ``dissipated_<channel>``,
        ``heat_into_<node>`` and ``stored_<node>``, and the residuals."""
        mappings = {"dissipated_by_channel": "dissipated", "heat_into": "heat_into", "stored": "stored"}
        values = {key: value for key, value in self.__dict__.items() if key not in mappings}
        for key, prefix in mappings.items():
            values.update({f"{prefix}_{name}": value for name, value in getattr(self, key).items()})
        values.update(
            mechanical_residual=self.mechanical_residual,
            thermal_residual=self.thermal_residual,
            residual=self.residual,
            relative_residual=self.relative_residual,
        )
        return values


@overload
def kelvin_to_celsius(kelvin: float) -> float: ...


@overload
def kelvin_to_celsius(kelvin: np.ndarray) -> np.ndarray: ...


def kelvin_to_celsius(kelvin: float | np.ndarray) -> float | np.ndarray:
    """A temperature (K), or an array of them, in °C."""
    return kelvin - 273.15
