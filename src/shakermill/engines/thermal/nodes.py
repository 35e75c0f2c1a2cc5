"""What a thermal network is made of, as data: its nodes with their roles, where each contact kind's heat goes, and
the draft a network is built in, so that a new node is a module that adds itself to the draft
(:data:`network.NODE_EXTENSIONS`: ``mill_head.py``, ``powder.py``) and nothing else needs to know
its name: audits, summaries, tables and figures loop over the nodes and their roles."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from shakermill.engines.thermal.paths import HeatPath
    from shakermill.parameters.keys import Parameters

# What a node is, for everything that treats nodes alike: a ball, the vessel the balls hit, the gas inside it; an
# extension names the role of the node it adds (mill_head.HOLDER, powder.POWDER).
BALL, VESSEL, GAS = "ball", "vessel", "gas"

# The kinds of contact whose heat a network routes: a ball on the vessel's wall, two balls.
BALL_WALL, BALL_BALL = "ball-wall", "ball-ball"
CONTACT_KINDS = (BALL_WALL, BALL_BALL)
# The dissipation channels of a contact (MODEL.md §12.4), in the order the engines book them; the 1-D engine's
# impacts dissipate in the first alone.
HEAT_CHANNELS = ("normal", "tangential", "sliding", "rolling")

# The audit's name for the balls together: a charge of thousands has one line, not one per ball.
BALLS_GROUP = "balls"
# A node's name beyond the balls: one word of lower-case letters (``lid``), as its keys in a run's summary take it
# (``lid_C``, ``lid_steady_C``), so that no other key reads as a node's.
NODE_NAME = "[a-z]+"


@dataclass(frozen=True)
class Node:
    """A lumped heat capacity (J/K) with its ``role`` and the ``title`` tables and figures give it; a ``held`` node
    stays at the ambient temperature (a reservoir). ``keys`` set its capacity and its paths: a message about the node
    names them. A node of a material whose melting point is known carries it (K) and the material's name: above it
    the node is no longer what the model says it is."""

    name: str
    role: str
    capacity: float
    title: str
    held: bool = False
    keys: tuple[str, ...] = ()
    melting_point: float | None = None
    material: str = ""

    def __post_init__(self) -> None:
        # Checked where the node is made: a name the summary cannot take would fail every run at its end.
        if self.role != BALL and not re.fullmatch(NODE_NAME, self.name):
            raise ValueError(
                f"node {self.name!r}: a node's name is one word of lower-case letters ({NODE_NAME}), as the run's "
                "summary names its temperature (<name>_C)"
            )


@dataclass(frozen=True)
class Deposit:
    """A share of the contacts' heat put into a node that is neither body in contact (the powder between them):
    ``shares[kind][channel]`` of η times that channel's dissipation (MODEL.md §§3, 12.4), with what it rests on. The
    bodies share the rest (:class:`BodySplit`)."""

    node: int
    shares: Mapping[str, Mapping[str, float]]
    source: str

    def share(self, kind: str, channel: str) -> float:
        return float(self.shares.get(kind, {}).get(channel, 0.0))

    @property
    def receives(self) -> bool:
        """Whether any contact puts heat into the node."""
        return any(share > 0.0 for channels in self.shares.values() for share in channels.values())


@dataclass(frozen=True)
class BodySplit:
    """How the heat a contact keeps for its two bodies divides (MODEL.md §§3, 12.4): a ball on the vessel keeps
    ``wall_ball_share`` (λ), the vessel the rest; two balls share theirs by effusivity, which the engine evaluates
    per pair. ``description`` says it in words."""

    wall_ball_share: float
    description: str


@dataclass(frozen=True)
class Restitution:
    """The restitution a run's contacts are configured with, of a ball on the vessel and of two balls, and the key
    that sets each: the one place the engine, its contact-step guard and their messages read it from."""

    wall: float
    pair: float
    wall_key: str
    pair_key: str

    @classmethod
    def bare(cls, params: Parameters) -> Restitution:
        """Of uncoated contacts: ``restitution`` and ``pair_restitution``."""
        return cls(params.restitution, params.pair_restitution, "restitution", "pair_restitution")


@dataclass
class NetworkDraft:
    """A network being built: the nodes, paths, deposits and the heat each node receives whatever the balls do (W),
    and the balls' radii, for the extensions that add to it (:data:`network.NODE_EXTENSIONS`). A node that coats the
    bodies in contact (the powder) replaces their ``restitution``."""

    params: Parameters
    radii: Sequence[float]
    restitution: Restitution
    nodes: list[Node] = field(default_factory=list)
    paths: list[HeatPath] = field(default_factory=list)
    deposits: list[Deposit] = field(default_factory=list)
    fixed_heat: list[float] = field(default_factory=list)

    def add(self, node: Node, fixed_heat: float = 0.0) -> int:
        """Add ``node`` (receiving ``fixed_heat`` W whatever the balls do); its index."""
        self.nodes.append(node)
        self.fixed_heat.append(fixed_heat)
        return len(self.nodes) - 1

    def of_role(self, role: str) -> list[int]:
        return [index for index, node in enumerate(self.nodes) if node.role == role]

    def one_of_role(self, role: str) -> int:
        (index,) = self.of_role(role)
        return index


def deposit_arrays(
    deposits: Sequence[Deposit], channels: Sequence[str] = HEAT_CHANNELS
) -> tuple[np.ndarray, np.ndarray]:
    """The deposits as compiled code reads them: their nodes (m,) and shares over (contact kind in
    :data:`CONTACT_KINDS` order, channel, deposit)."""
    nodes = np.array([deposit.node for deposit in deposits], dtype=np.int64)
    shares = np.array(
        [[[deposit.share(kind, channel) for deposit in deposits] for channel in channels] for kind in CONTACT_KINDS],
        dtype=float,
    ).reshape(len(CONTACT_KINDS), len(channels), len(deposits))
    return nodes, shares
