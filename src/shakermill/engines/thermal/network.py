"""The thermal network of a run, built from its parameters: its nodes (a node per ball, the vessel, the gas inside,
and those the extensions add: with ``thermal_model = 'mill-head'`` the holder, with powder the powder), the named
heat paths between them and to the room, where each contact's heat goes, and the heat each node receives whatever
the balls do (MODEL.md sections 4-6, 11, 12.5, 13). Every engine builds its network here and evaluates it through
:mod:`kernel`; nodes, deposits and roles are data (:mod:`nodes`), so that the audits, summaries and figures loop over
them."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from importlib import import_module

import numpy as np

from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.air import air_constants
from shakermill.engines.thermal.nodes import (
    BALL,
    BALL_WALL,
    BALLS_GROUP,
    GAS,
    VESSEL,
    BodySplit,
    Deposit,
    NetworkDraft,
    Node,
    Restitution,
    deposit_arrays,
)
from shakermill.engines.thermal.paths import PAPER_PATHS, HeatPath, ball_convection, newton_cooling
from shakermill.parameters.consistency import MIN_THERMAL_TIME_CONSTANT_S
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters


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

    def moved(self, source: ThermalNetwork, target: ThermalNetwork) -> NetworkLoad:
        """This load, measured on the nodes of ``source``, on those of ``target`` by the nodes' names: a network of
        other thermal-only keys may add a node (the holder) before another (the powder). A node ``source`` has not
        receives nothing."""
        names = [node.name for node in source.nodes]
        if names == [node.name for node in target.nodes]:
            return self
        measured = dict(zip(names, self.heat, strict=False))
        heat = np.array([measured.get(node.name, 0.0) for node in target.nodes])
        return replace(self, heat=heat)


@dataclass(frozen=True)
class ThermalNetwork:
    """Nodes, heat paths, where the contacts' heat goes (``split`` between the bodies in contact, ``deposits`` into
    other nodes) and the compiled form (``arrays``). Node order: the balls, the vessel, the gas, then the nodes the
    extensions add."""

    n_balls: int
    nodes: tuple[Node, ...]
    paths: tuple[HeatPath, ...]
    split: BodySplit
    deposits: tuple[Deposit, ...]
    arrays: kernel.NetworkArrays = field(repr=False)
    # What the contacts rebound with: the bare keys', or a coating node's (NetworkDraft).
    restitution: Restitution

    @property
    def vial(self) -> int:
        """The vessel: :func:`build_network` adds it after the balls."""
        return self.n_balls

    @property
    def air(self) -> int:
        """The gas: :func:`build_network` adds it after the vessel."""
        return self.n_balls + 1

    def index_of_role(self, role: str) -> int:
        """The one node of ``role`` (the vessel, the gas, the holder, the powder)."""
        (index,) = (index for index, node in enumerate(self.nodes) if node.role == role)
        return index

    @property
    def others(self) -> tuple[Node, ...]:
        """Every node but the balls, in order: what a table or figure shows one line of each."""
        return self.nodes[self.n_balls :]

    def grouped(self, values: np.ndarray) -> dict[str, float]:
        """Per-node ``values`` (J, W) as an audit shows them: the balls summed (:data:`nodes.BALLS_GROUP`), then each
        other node by name."""
        values = np.asarray(values, dtype=float)
        return {BALLS_GROUP: float(values[: self.n_balls].sum())} | {
            node.name: float(values[index]) for index, node in enumerate(self.nodes) if index >= self.n_balls
        }

    def time_constants_at_rest(self) -> dict[int, float]:
        """Each free node's heat capacity over the conductance of its paths with the balls at rest (s), by index: no
        motion in the convection, no contact conducting. The motion only shortens them."""
        conductances = self.node_conductances(np.zeros(kernel.drive_count(self.n_balls)))
        return {
            int(node): self.nodes[node].capacity / conductances[node] if conductances[node] > 0 else math.inf
            for node in self.free
        }

    def check_not_stiff(self, time_constants: Mapping[int, float]) -> None:
        """Refuse a node whose time constant at rest (``time_constants``, :meth:`time_constants_at_rest`) is below
        :data:`MIN_THERMAL_TIME_CONSTANT_S`, naming the keys that set it: the stepping's thermal steps would shrink
        with it. The nodes :mod:`consistency` cannot see (those of the extensions) are checked here."""
        for node, constant in time_constants.items():
            keys = self.nodes[node].keys
            if keys and constant < MIN_THERMAL_TIME_CONSTANT_S:
                raise ParameterError(
                    f"{', '.join(keys)}: the {self.nodes[node].title}'s thermal time constant is {constant:.3g} s with "
                    f"these values; allowed >= {MIN_THERMAL_TIME_CONSTANT_S:g} s (a larger mass or a weaker coupling)"
                )

    def deposit_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The deposits as compiled stepping reads them (:func:`nodes.deposit_arrays`)."""
        return deposit_arrays(self.deposits)

    def wall_contact_heat(self, heat: float, channel: str = "normal") -> np.ndarray:
        """Heat (W or J) of a ball's contacts with the vessel, all in ``channel``, into each node: the deposits'
        shares, of the rest ``split.wall_ball_share`` to the ball (the first) and the remainder to the vessel. An
        engine of one ball on the vessel's axis loads its network this way."""
        into = np.zeros(len(self.nodes))
        kept = heat
        for deposit in self.deposits:
            part = deposit.share(BALL_WALL, channel) * heat
            into[deposit.node] += part
            kept -= part
        into[0] += self.split.wall_ball_share * kept
        into[self.vial] += (1.0 - self.split.wall_ball_share) * kept
        return into

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

    def check_heat_leaves(self) -> None:
        """Refuse a network in which the heat of the contacts (into the balls, the vessel and the nodes of the deposits)
        has no path that can carry it to the room or a held node, naming the keys of the paths that carry nothing:
        its temperatures would rise without bound, and a fit to them answers millions of degrees. The contacts'
        conduction, measured by the run, counts as a path."""
        paths = len(self.paths)
        by_hot, by_cold = np.empty(paths), np.empty(paths)
        rest = np.full(len(self.nodes), self.ambient)
        kernel.path_slopes(rest, np.ones(kernel.drive_count(self.n_balls)), self.arrays, 0.5, by_hot, by_cold)
        carries = by_hot != 0.0
        reached = set(np.flatnonzero(self.arrays.held)) | {kernel.ROOM}
        grown = True
        while grown:
            grown = False
            for path in np.flatnonzero(carries):
                ends = {int(self.arrays.hot[path]), int(self.arrays.cold[path])} - {kernel.BALLS}
                if ends & reached and not ends <= reached:
                    reached |= ends
                    grown = True
        heated = {*range(self.n_balls), self.vial, *(deposit.node for deposit in self.deposits if deposit.receives)}
        trapped = sorted(heated - reached)
        if not trapped:
            return
        dead = [path for path, carried in zip(self.paths, carries, strict=True) if not carried]
        keys = dict.fromkeys(key for path in dead for key in _leading_keys(path.source))
        names = ", ".join(self.nodes[node].name for node in trapped)
        silent = ", ".join(path.name for path in dead)
        raise ParameterError(
            f"{', '.join(keys) or 'h_outer'}: the heat of {names} has no path to the room ({silent} "
            "carry nothing with these values): the temperatures would rise without bound; allowed a nonzero "
            "coefficient on one of these paths"
        )

    def jacobian(self, theta: np.ndarray, drives: np.ndarray, step: float) -> np.ndarray:
        """∂(dθ/dt)/∂θ (1/s) over the free nodes, at every node's ``theta`` (K) and the motion's mean ``drives``, from
        each path's slopes at its two ends (:func:`kernel.path_slopes`, central differences of ``step`` K)."""
        arrays, nodes = self.arrays, len(self.nodes)
        by_hot, by_cold = np.empty(len(self.paths)), np.empty(len(self.paths))
        kernel.path_slopes(
            np.asarray(theta, dtype=float), np.asarray(drives, dtype=float), arrays, step, by_hot, by_cold
        )
        hot, cold = arrays.hot, arrays.cold
        # d(heat into each node)/dθ (W/K): a flow leaves its hot end and enters its cold end where that is a node.
        into = np.zeros((nodes, nodes))
        np.add.at(into, (hot, hot), -by_hot)
        ends = cold >= 0
        np.add.at(into, (hot[ends], cold[ends]), -by_cold[ends])
        np.add.at(into, (cold[ends], hot[ends]), by_hot[ends])
        np.add.at(into, (cold[ends], cold[ends]), by_cold[ends])
        self._add_among_balls(into, np.asarray(drives, dtype=float), by_cold)
        free = self.free
        return into[np.ix_(free, free)] / arrays.capacity[free][:, None]

    def _add_among_balls(self, into: np.ndarray, drives: np.ndarray, by_cold: np.ndarray) -> None:
        """The slopes of the AMONG_BALLS paths at their cold end, the balls' conductance-weighted mean
        (:func:`kernel.among_balls_mean`), spread over the balls it averages."""
        among = self.arrays.cold == kernel.BALLS
        conductances = drives[self.arrays.drive[among]]
        total = conductances.sum()
        if total <= 0.0:
            return  # no conduction among the balls: these paths carry nothing
        weights = np.zeros(len(self.nodes))
        balls = self.arrays.hot[among]
        np.add.at(weights, balls, conductances / total)
        np.add.at(into, balls, -np.outer(by_cold[among], weights))

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
        ambient, every other node at the ambient (:func:`kernel.node_conductances`)."""
        conductances = np.empty(len(self.nodes))
        kernel.node_conductances(np.asarray(drives, dtype=float), self.arrays, conductances)
        return conductances


# The nodes beyond the balls, the vessel and the gas: the modules of this folder that add one, in the order they add
# it; each has ``add_node(draft)``, which adds its node, paths and deposits where the run's parameters ask for it. A
# new node is a module, its key group (parameters/groups/) and its name here (docs/ARCHITECTURE.md).
NODE_EXTENSIONS: tuple[str, ...] = ("mill_head", "powder")
NodeExtension = Callable[[NetworkDraft], None]


def node_extension(name: str) -> NodeExtension:
    """The ``add_node`` of the extension module ``name`` of :data:`NODE_EXTENSIONS`."""
    add_node: NodeExtension = import_module(f"{__package__}.{name}").add_node
    return add_node


def build_network(
    params: Parameters,
    radii: Sequence[float],
    capacities: Sequence[float],
    ball_names: Sequence[str],
    split_description: str,
) -> ThermalNetwork:
    """The network of ``params`` for balls of ``radii`` (m) and heat ``capacities`` (J/K): each ball convects to
    the gas (Whitaker), the vessel exchanges heat with the gas inside and, under ``thermal_model = 'paper'``, with
    the room outside at a constant h·A; in the ``ball_only`` model the vessel and the gas are held at the ambient
    (the paper's 2023 predecessor). Then each of :data:`NODE_EXTENSIONS`. ``split_description`` says how the
    engine splits a contact's heat between the bodies in contact."""
    held = params.model == "ball_only"
    draft = NetworkDraft(params, tuple(radii), Restitution.bare(params))
    for name, capacity in zip(ball_names, capacities, strict=True):
        draft.add(Node(name, BALL, capacity, name))
    vial = draft.add(Node("vial", VESSEL, params.vial_mass * params.vial_heat_capacity, "vial", held))
    air = draft.add(Node("air", GAS, params.air_mass * params.air_heat_capacity, "inner air", held))
    draft.paths += [
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
    if params.thermal_model == "paper":
        draft.paths.append(
            newton_cooling(
                "vial → room",
                vial,
                kernel.ROOM,
                params.h_outer,
                params.outer_area,
                f"h_outer, outer_area ({PAPER_PATHS}, Table 3 and Table 1 for the SPEX preset)",
            )
        )
    for extend in map(node_extension, NODE_EXTENSIONS):
        extend(draft)
    return ThermalNetwork(
        len(radii),
        tuple(draft.nodes),
        tuple(draft.paths),
        BodySplit(params.lam, split_description),
        tuple(draft.deposits),
        _arrays(params, draft.nodes, draft.paths, np.array(draft.fixed_heat, dtype=float)),
        draft.restitution,
    )


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


def _leading_keys(source: str) -> list[str]:
    """The keys a path's source names first ("h_inner, inner_area (...)"): those that set its coefficient."""
    match = re.match(r"[a-z_]+(?:, [a-z_]+)*", source)
    return match.group(0).split(", ") if match and "_" in match.group(0) else []
