"""The thermal network of a run, built from its parameters: a node per ball, the vial and the air (and with
``thermal_model = 'mill-head'`` the clamp and mill head), the named heat paths between them and to the room,
and the heat each node receives from the contacts and the drive (MODEL.md sections 4-6, 11, 12.5, 13). Every
engine builds its network here and evaluates it through :mod:`kernel`."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.paths import (
    HeatPath,
    among_balls_conduction,
    ball_convection,
    contact_conduction,
    fixed_conductance,
    newton_cooling,
    radiation,
)
from shakermill.parameters.keys import Parameters
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS, MOTION_COORDINATES, motion_terms
from shakermill.physics import heat_paths, thermal

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
    from the contacts (W), each ball's mean Whitaker velocity term, for the summary their total (W) and the balls'
    mean term, and the mean contact conductances (W/K) in :func:`kernel.contact_drive` order (none for an engine
    that does not measure them)."""

    heat: np.ndarray
    terms: np.ndarray
    heat_power: float
    velocity_term: float
    conductances: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def drives(self) -> np.ndarray:
        """The ``drives`` the network's paths read (:mod:`kernel`)."""
        return np.concatenate([self.terms, self.conductances])


@dataclass(frozen=True)
class ThermalNetwork:
    """Nodes, heat paths and heat sources; ``arrays`` is the compiled form. Node order: the balls, the vial, the
    air, then any others (the clamp)."""

    n_balls: int
    nodes: tuple[Node, ...]
    paths: tuple[HeatPath, ...]
    sources: tuple[HeatSource, ...]
    arrays: kernel.NetworkArrays = field(repr=False)

    @property
    def vial(self) -> int:
        return self.n_balls

    @property
    def air(self) -> int:
        return self.n_balls + 1

    @property
    def ambient(self) -> float:
        return self.arrays.ambient

    def mean_ball(self, values: np.ndarray) -> np.ndarray:
        """The balls' mean of per-node ``values`` (nodes on the last axis, e.g. time × node); NaN in an empty mill
        (``n_balls = 0``)."""
        if self.n_balls:
            return np.mean(values[..., : self.n_balls], axis=-1)
        return np.full(np.shape(values)[:-1], np.nan)

    @property
    def free(self) -> np.ndarray:
        """Indices of the nodes whose temperatures evolve (not held)."""
        return np.flatnonzero(~self.arrays.held)

    def flows(self, theta: np.ndarray, drives: np.ndarray) -> np.ndarray:
        """Each path's heat flow (W) at node temperatures ``theta`` (K) and the motion's mean ``drives``
        (:attr:`NetworkLoad.drives`)."""
        out = np.empty(len(self.paths))
        kernel.path_flows(np.asarray(theta, dtype=float), np.asarray(drives, dtype=float), self.arrays, out)
        return out

    def flows_over(self, theta: np.ndarray, drives: np.ndarray) -> np.ndarray:
        """:meth:`flows` at each column of ``theta`` (node, time), over (time, path)."""
        samples = np.ascontiguousarray(np.asarray(theta, dtype=float).T)
        out = np.empty((samples.shape[0], len(self.paths)))
        kernel.path_flows_over(samples, np.asarray(drives, dtype=float), self.arrays, out)
        return out

    def rates(self, theta: np.ndarray, heat: np.ndarray, drives: np.ndarray) -> tuple[np.ndarray, float]:
        """dθ/dt (K/s) of every node with mean ``heat`` (W) into each from the contacts (the first nodes: those
        after the last it names get none), and the heat leaving the system (W)."""
        out = np.empty(len(self.nodes))
        flows = np.empty(len(self.paths))
        received = np.zeros(len(self.nodes))
        received[: len(heat)] = heat
        lost = kernel.temperature_rates(
            np.asarray(theta, dtype=float), received, np.asarray(drives, dtype=float), self.arrays, flows, out
        )
        return out, lost

    @property
    def fixed_heat(self) -> float:
        """Heat into the network whatever the balls do (W): the drive's."""
        return float(self.arrays.fixed_heat.sum())

    def with_free(self, free_temperatures: np.ndarray) -> np.ndarray:
        """All node temperatures: ``free_temperatures`` for the free nodes, the ambient for the held ones."""
        theta = np.full(len(self.nodes), self.ambient)
        theta[self.free] = free_temperatures
        return theta

    def initial_temperatures(self, initial: float) -> np.ndarray:
        """Every free node at ``initial`` (K), the held ones at the ambient."""
        return self.with_free(np.full(self.free.size, initial))

    def room_conductance(self, drives: np.ndarray) -> float:
        """The conductance (W/K) of the paths to the room with every node 1 K above the ambient: where the heat
        leaves at steady state."""
        flows = self.flows(np.full(len(self.nodes), self.ambient + 1.0), drives)
        return float(sum(flow for path, flow in zip(self.paths, flows, strict=True) if path.cold == kernel.ROOM))

    def node_conductances(self, drives: np.ndarray) -> np.ndarray:
        """The conductance (W/K) of all paths at each node: its heat flows when it alone is 1 K above the
        ambient, every other node at the ambient."""
        conductances = np.zeros(len(self.nodes))
        for node in range(len(self.nodes)):
            theta = np.full(len(self.nodes), self.ambient)
            theta[node] += 1.0
            flows = self.flows(theta, drives)
            for path, flow in zip(self.paths, flows, strict=True):
                if node in (path.hot, path.cold):
                    conductances[node] += abs(flow)
        return conductances


def air_constants(params: Parameters) -> dict[str, float]:
    """The air's viscosity at the ambient temperature (Pa·s) and its Prandtl number: Re and Nu of MODEL.md §4."""
    viscosity = thermal.sutherland_viscosity(
        params.ambient_temperature, params.air_viscosity_ref, params.air_reference_temperature, params.sutherland
    )
    return {
        "viscosity_ambient": viscosity,
        "prandtl": thermal.prandtl_number(params.air_cp, viscosity, params.air_conductivity),
    }


def build_network(
    params: Parameters,
    radii: Sequence[float],
    capacities: Sequence[float],
    ball_names: Sequence[str],
    contact_share: str,
) -> ThermalNetwork:
    """The network of ``params`` for balls of ``radii`` (m) and heat ``capacities`` (J/K): each ball convects to
    the air (Whitaker), the vial exchanges heat with the air inside and the room outside. ``thermal_model``
    'paper': the outside at a constant h·A, and in the ``ball_only`` model the vial and the air held at the ambient
    (the paper's 2023 predecessor); 'mill-head': :func:`mill_head_paths` as well. ``contact_share`` says which part
    of the contacts' heat a ball receives."""
    n = len(radii)
    vial, air = n, n + 1
    held = params.model == "ball_only"
    nodes = [
        *(Node(name, capacity) for name, capacity in zip(ball_names, capacities, strict=True)),
        Node("vial", params.vial_mass * params.vial_heat_capacity, held),
        Node("air", params.air_mass * params.air_heat_capacity, held),
    ]
    paths = [
        *(ball_convection(f"{ball_names[i]} → air", i, air, i, radius) for i, radius in enumerate(radii)),
        newton_cooling(
            "vial → air",
            vial,
            air,
            params.h_inner,
            params.inner_area,
            f"h_inner, inner_area ({PAPER_PATHS}, Table 3 and Table 1 for the SPEX preset)",
        ),
    ]
    sources = [
        *(HeatSource(i, contact_share) for i in range(n)),
        HeatSource(vial, "1 − λ of the heat of each contact with the vial"),
    ]
    fixed_heat = np.zeros(len(nodes))
    if params.thermal_model == "mill-head":
        clamp = len(nodes)
        nodes.append(Node("clamp", params.clamp_heat_capacity))
        paths += mill_head_paths(params, ball_names, vial, clamp)
        sources.append(HeatSource(clamp, "drive_heat: the motor's and bearings' losses, whatever the balls do"))
        fixed_heat = np.append(fixed_heat, params.drive_heat)
    else:
        paths.append(
            newton_cooling(
                "vial → room",
                vial,
                kernel.ROOM,
                params.h_outer,
                params.outer_area,
                f"h_outer, outer_area ({PAPER_PATHS}, Table 3 and Table 1 for the SPEX preset)",
            )
        )
    return ThermalNetwork(n, tuple(nodes), tuple(paths), tuple(sources), _arrays(params, nodes, paths, fixed_heat))


def mill_head_paths(params: Parameters, ball_names: Sequence[str], vial: int, clamp: int) -> list[HeatPath]:
    """The paths of a real mill beyond the paper's (MODEL.md §13.1): the vial's outside to the room by convection
    at its own speed and by radiation, conduction through the contacts of each ball with the vial and with the
    other balls, the vial to the clamp and the clamp to the room."""
    n = len(ball_names)
    outer = vial_outer_convection(params)
    return [
        newton_cooling(
            "vial → room, convection", vial, kernel.ROOM, outer.coefficient, outer.area, outer.source, outer.validity
        ),
        radiation("vial → room, radiation", vial, kernel.ROOM, params.emissivity, outer.area),
        *(
            contact_conduction(f"{ball_names[i]} → vial, contacts", i, vial, kernel.contact_drive(i, -1, n))
            for i in range(n)
        ),
        *(
            among_balls_conduction(f"{ball_names[i]} → other balls, contacts", i, kernel.contact_drive(i, i, n))
            for i in range(n)
            if n > 1
        ),
        fixed_conductance(
            "vial → clamp",
            vial,
            clamp,
            params.clamp_conductance,
            "clamp_conductance (see its source)",
            "a steady joint: the vial's and the clamp's own conduction are fast beside it",
        ),
        fixed_conductance(
            "clamp → room",
            clamp,
            kernel.ROOM,
            params.clamp_loss,
            "clamp_loss (see its source)",
            "the clamp and mill head lumped at one temperature",
        ),
    ]


@dataclass(frozen=True)
class OuterConvection:
    """The vial's outside to the room: the mean coefficient over its faces (W/(m²·K)), their area (m²), the speed it
    is taken at (m/s) and what it rests on."""

    coefficient: float
    area: float
    speed: float
    source: str
    validity: str


# Natural convection depends on the vial's rise itself (as ΔT^1/4): it is taken at a rise typical of a milling
# hour. Beside forced convection at metres per second it changes the outer coefficient by under 1 %.
NATURAL_CONVECTION_RISE_K = 20.0


def vial_outer_convection(params: Parameters) -> OuterConvection:
    """Convection from the vial's outside (a cylinder of ``outer_diameter`` × ``outer_length``) at the rms speed of
    its motion, each face combined with natural convection (Churchill's rule); air properties at the ambient
    temperature. A shaken vial meets the air along its axis (:func:`_along_the_axis`), a planetary jar across it
    (:func:`_across_the_axis`)."""
    constants = air_constants(params)
    viscosity, prandtl = constants["viscosity_ambient"], constants["prandtl"]
    speed = vial_rms_speed(params)
    diameter, length, k_air = params.outer_diameter, params.outer_length, params.air_conductivity
    side_area, end_area = math.pi * diameter * length, 2.0 * math.pi * diameter**2 / 4.0
    rayleigh = heat_paths.rayleigh_number(
        diameter,
        NATURAL_CONVECTION_RISE_K,
        params.ambient_temperature + NATURAL_CONVECTION_RISE_K / 2,
        viscosity,
        params.air_density,
        k_air,
        params.air_cp,
    )
    natural = heat_paths.churchill_chu_cylinder_nusselt(rayleigh, prandtl) * k_air / diameter
    faces = _across_the_axis if KINEMATIC_MODELS[params.kinematics].axis_upright else _along_the_axis
    h_side, h_end, correlations, validity = faces(params, speed, viscosity, prandtl)
    area = side_area + end_area
    return OuterConvection(
        coefficient=(
            heat_paths.mixed_convection_coefficient(h_side, natural) * side_area
            + heat_paths.mixed_convection_coefficient(h_end, natural) * end_area
        )
        / area,
        area=area,
        speed=speed,
        source=(
            f"{correlations}; each with natural convection (Churchill & Chu 1975, horizontal cylinder, at a "
            f"{NATURAL_CONVECTION_RISE_K:g} K rise) by Churchill's rule; at the vial's rms speed {speed:.3g} m/s"
        ),
        validity=validity,
    )


def _reynolds(length: float, params: Parameters, speed: float, viscosity: float) -> float:
    return thermal.reynolds_number(length, params.air_density, speed, viscosity)


def _along_the_axis(
    params: Parameters, speed: float, viscosity: float, prandtl: float
) -> tuple[float, float, str, str]:
    """The forced coefficients (W/(m²·K)) of a vial shaken along its axis: the side a plate along the flow, each end
    a disk facing it; what they rest on and where they hold."""
    diameter, length, k_air = params.outer_diameter, params.outer_length, params.air_conductivity
    side = heat_paths.flat_plate_nusselt(_reynolds(length / 2, params, speed, viscosity), prandtl) * k_air / length
    end = heat_paths.disk_nusselt(_reynolds(diameter / 2, params, speed, viscosity), prandtl) * k_air / diameter
    return (
        side,
        end,
        (
            "side: laminar flat plate, Nu = 0.664 Re_L^1/2 Pr^1/3 (Incropera & DeWitt Eq. 7.30); ends: disk facing the "
            "flow, Nu = 1.05 Re_D^1/2 Pr^0.36 (Sparrow & Geiger 1985, recalled, not re-read)"
        ),
        (
            "quasi-steady flow: the vial's stroke is ~3 diameters (Keulegan-Carpenter number ~3), so steady "
            "correlations at the rms speed are a ±30 % estimate; Re_L < 5e5 (laminar), the disk measured for "
            "5e3 < Re_D < 5e4"
        ),
    )


def _across_the_axis(
    params: Parameters, speed: float, viscosity: float, prandtl: float
) -> tuple[float, float, str, str]:
    """The forced coefficients (W/(m²·K)) of a jar carried across its axis: the side a cylinder in cross flow, each
    end a plate along the flow, as long as the jar is wide; what they rest on and where they hold."""
    diameter, k_air = params.outer_diameter, params.air_conductivity
    reynolds = _reynolds(diameter, params, speed, viscosity)
    side = heat_paths.churchill_bernstein_nusselt(reynolds, prandtl) * k_air / diameter
    end = heat_paths.flat_plate_nusselt(reynolds, prandtl) * k_air / diameter
    return (
        side,
        end,
        (
            "side: cylinder in cross flow, Churchill & Bernstein 1977 (Incropera & DeWitt Eq. 7.54); ends: laminar "
            "flat "
            "plate along the flow, Nu = 0.664 Re_D^1/2 Pr^1/3 (Eq. 7.30)"
        ),
        (
            "the jar's speed round the sun wheel taken as the air's speed past it: the air inside a mill's housing "
            "turns "
            "with the wheel and the jar's own spin adds (1 + k)·ω·D_o/2 at its surface, so this is a ±50 % estimate; "
            "Re_D·Pr > 0.2"
        ),
    )


def vial_rms_speed(params: Parameters) -> float:
    """The rms speed (m/s) of the vial's centre over a drive cycle, from the Fourier terms of its motion."""
    amplitudes: dict[tuple[str, int], np.ndarray] = {}
    for coordinate, k, cosine, sine in motion_terms(params.kinematics, params):
        if coordinate in MOTION_COORDINATES[:3]:
            amplitudes[(coordinate, k)] = amplitudes.get((coordinate, k), np.zeros(2)) + (cosine, sine)
    mean_square = sum(0.5 * (k * params.omega) ** 2 * float(np.sum(pair**2)) for (_, k), pair in amplitudes.items())
    return math.sqrt(mean_square)


def _arrays(
    params: Parameters, nodes: Sequence[Node], paths: Sequence[HeatPath], fixed_heat: np.ndarray
) -> kernel.NetworkArrays:
    constants = air_constants(params)
    return kernel.NetworkArrays(
        capacity=np.array([node.capacity for node in nodes]),
        held=np.array([node.held for node in nodes], dtype=np.bool_),
        fixed_heat=np.asarray(fixed_heat, dtype=float),
        kind=np.array([path.kind for path in paths], dtype=np.int64),
        hot=np.array([path.hot for path in paths], dtype=np.int64),
        cold=np.array([path.cold for path in paths], dtype=np.int64),
        conductance=np.array([path.conductance for path in paths]),
        radius=np.array([path.radius for path in paths]),
        drive=np.array([path.drive for path in paths], dtype=np.int64),
        beta=params.beta,
        prandtl=constants["prandtl"],
        mu_ref=params.air_viscosity_ref,
        t_ref=params.air_reference_temperature,
        sutherland=params.sutherland,
        air_conductivity=params.air_conductivity,
        ambient=params.ambient_temperature,
    )
