"""The thermal network of a run, built from its parameters: a node per ball, the vial and the air, the named
heat paths between them and to the room, and the heat each node receives from the contacts (MODEL.md sections
4-6, 11, 12.5). Every engine builds its network here and evaluates it through :mod:`kernel`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.paths import HeatPath, ball_convection, newton_cooling
from shakermill.parameters.keys import Parameters
from shakermill.physics import thermal

PAPER_PATHS = "Son 2025 (Mathematics 13, 446)"


@dataclass(frozen=True)
class Node:
    """A lumped heat capacity (J/K); a ``held`` node stays at the ambient temperature (a reservoir)."""

    name: str
    capacity: float
    held: bool = False


@dataclass(frozen=True)
class HeatSource:
    """Heat the contacts put into a node: of the η·dissipation of every channel (MODEL.md §§3, 12.4), ``share``."""

    node: int
    share: str


@dataclass(frozen=True)
class NetworkLoad:
    """What drives the network with the mechanics replaced by its means (MODEL.md §11): the heat into each node
    (W), each ball's mean Whitaker velocity term, and for the summary their total (W) and the balls' mean term."""

    heat: np.ndarray
    terms: np.ndarray
    heat_power: float
    velocity_term: float


@dataclass(frozen=True)
class ThermalNetwork:
    """Nodes, heat paths and heat sources; ``arrays`` is the compiled form. Node order: the balls, the vial, the air."""

    nodes: tuple[Node, ...]
    paths: tuple[HeatPath, ...]
    sources: tuple[HeatSource, ...]
    arrays: kernel.NetworkArrays = field(repr=False)

    @property
    def n_balls(self) -> int:
        return len(self.nodes) - 2

    @property
    def vial(self) -> int:
        return self.n_balls

    @property
    def air(self) -> int:
        return self.n_balls + 1

    @property
    def ambient(self) -> float:
        return self.arrays.ambient

    @property
    def free(self) -> np.ndarray:
        """Indices of the nodes whose temperatures evolve (not held)."""
        return np.flatnonzero(~self.arrays.held)

    def flows(self, theta: np.ndarray, velocity_terms: np.ndarray) -> np.ndarray:
        """Each path's heat flow (W) at node temperatures ``theta`` (K) and the balls' mean velocity terms."""
        out = np.empty(len(self.paths))
        kernel.path_flows(np.asarray(theta, dtype=float), np.asarray(velocity_terms, dtype=float), self.arrays, out)
        return out

    def rates(self, theta: np.ndarray, heat: np.ndarray, velocity_terms: np.ndarray) -> tuple[np.ndarray, float]:
        """dθ/dt (K/s) of every node with mean ``heat`` (W) into each, and the heat leaving the system (W)."""
        out = np.empty(len(self.nodes))
        flows = np.empty(len(self.paths))
        lost = kernel.temperature_rates(
            np.asarray(theta, dtype=float), np.asarray(heat, dtype=float), np.asarray(velocity_terms, dtype=float),
            self.arrays, flows, out,
        )
        return out, lost

    def with_free(self, free_temperatures: np.ndarray) -> np.ndarray:
        """All node temperatures: ``free_temperatures`` for the free nodes, the ambient for the held ones."""
        theta = np.full(len(self.nodes), self.ambient)
        theta[self.free] = free_temperatures
        return theta

    def initial_temperatures(self, initial: float) -> np.ndarray:
        """Every free node at ``initial`` (K), the held ones at the ambient."""
        return self.with_free(np.full(self.free.size, initial))

    def outer_conductance(self) -> float:
        """The conductance (W/K) of the constant paths to the room: where the heat leaves at steady state."""
        return sum(path.conductance for path in self.paths if path.cold == kernel.ROOM and path.kind == kernel.CONSTANT)

    def node_conductances(self, velocity_terms: np.ndarray) -> np.ndarray:
        """The conductance (W/K) of all paths at each node: its heat flows when it alone is 1 K above the
        ambient, every other node at the ambient."""
        conductances = np.zeros(len(self.nodes))
        for node in range(len(self.nodes)):
            theta = np.full(len(self.nodes), self.ambient)
            theta[node] += 1.0
            flows = self.flows(theta, velocity_terms)
            for path, flow in zip(self.paths, flows, strict=True):
                if node in (path.hot, path.cold):
                    conductances[node] += abs(flow)
        return conductances


def air_constants(params: Parameters) -> dict[str, float]:
    """The air's viscosity at the ambient temperature (Pa·s) and its Prandtl number: Re and Nu of MODEL.md §4."""
    viscosity = thermal.sutherland_viscosity(
        params.ambient_temperature, params.air_viscosity_ref, params.air_reference_temperature, params.sutherland
    )
    return {"viscosity_ambient": viscosity, "prandtl": thermal.prandtl_number(params.air_cp, viscosity, params.air_conductivity)}


def build_network(params: Parameters, radii: Sequence[float], capacities: Sequence[float],
                  ball_names: Sequence[str], contact_share: str) -> ThermalNetwork:
    """The network of ``params`` for balls of ``radii`` (m) and heat ``capacities`` (J/K): each ball convects to
    the air (Whitaker), the vial exchanges heat with the air inside and the room outside (constant h·A). In the
    ``ball_only`` model the vial and the air are held at the ambient (the paper's 2023 predecessor).
    ``contact_share`` says which part of the contacts' heat a ball receives."""
    n = len(radii)
    vial, air = n, n + 1
    held = params.model == "ball_only"
    nodes = (
        *(Node(name, capacity) for name, capacity in zip(ball_names, capacities, strict=True)),
        Node("vial", params.vial_mass * params.vial_heat_capacity, held),
        Node("air", params.air_mass * params.air_heat_capacity, held),
    )
    paths = (
        *(ball_convection(f"{ball_names[i]} → air", i, air, i, radius) for i, radius in enumerate(radii)),
        newton_cooling("vial → air", vial, air, params.h_inner, params.inner_area,
                       f"h_inner, inner_area ({PAPER_PATHS}, Table 3 and Table 1 for the SPEX preset)"),
        newton_cooling("vial → room", vial, kernel.ROOM, params.h_outer, params.outer_area,
                       f"h_outer, outer_area ({PAPER_PATHS}, Table 3 and Table 1 for the SPEX preset)"),
    )
    sources = (
        *(HeatSource(i, contact_share) for i in range(n)),
        HeatSource(vial, "1 − λ of the heat of each contact with the vial"),
    )
    return ThermalNetwork(nodes, paths, sources, _arrays(params, nodes, paths))


def _arrays(params: Parameters, nodes: Sequence[Node], paths: Sequence[HeatPath]) -> kernel.NetworkArrays:
    constants = air_constants(params)
    return kernel.NetworkArrays(
        capacity=np.array([node.capacity for node in nodes]),
        held=np.array([node.held for node in nodes], dtype=np.bool_),
        kind=np.array([path.kind for path in paths], dtype=np.int64),
        hot=np.array([path.hot for path in paths], dtype=np.int64),
        cold=np.array([path.cold for path in paths], dtype=np.int64),
        conductance=np.array([path.conductance for path in paths]),
        radius=np.array([path.radius for path in paths]),
        ball=np.array([path.ball for path in paths], dtype=np.int64),
        beta=params.beta,
        prandtl=constants["prandtl"],
        mu_ref=params.air_viscosity_ref,
        t_ref=params.air_reference_temperature,
        sutherland=params.sutherland,
        air_conductivity=params.air_conductivity,
        ambient=params.ambient_temperature,
    )
