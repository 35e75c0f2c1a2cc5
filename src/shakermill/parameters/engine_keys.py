"""What each engine takes, by name: the vial motions, how many balls, the thermal models, how the air moves and the
keys it reads (the key groups it names and the components it takes, ``parameters/groups/``), and what decides whether
a run reads a key (:class:`Reader`).

``Parameters`` checks a run's keys against the engine it names (key ``engine``), so these declarations live
in this layer, below the engines; each engine carries its own as part of its description
(``engines/interface.py``), and registering a new engine (``engines/registry.py``) adds its declaration here.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.groups import (
    GROUP_OF,
    GROUPS,
    AveragedSolver,
    BallPairs,
    Balls,
    ContactDamping,
    ContactHeat,
    DemAveraging,
    DemContacts,
    DemStepping,
    Drive,
    EnduringContacts,
    HeatSplit,
    LabFrame,
    NetworkChoice,
    OneBallStart,
    OneDAveraging,
    OneDIntegrator,
    PaperNetwork,
    RoomLoss,
    RunControl,
    SeveralBalls,
    Stroke,
    Vial,
    VialWall,
    WhatAnImpactIs,
    default_of,
    keys_of,
    keys_of_role,
    marked,
)
from shakermill.parameters.key_group import CONTACT_COATING, NETWORK_NODE, VIAL_MOTION, KeyGroup
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.support.limits import MAX_BALLS


def reads_of(*groups: type[KeyGroup], roles: Iterable[str] = (), kinematics: Iterable[str] = ()) -> frozenset[str]:
    """The keys a reader reads: those of the core ``groups`` it names, of every component group of ``roles``, and of
    the vial-motion groups that the motions ``kinematics`` take (with ``kinematics`` itself where there is a choice,
    whose group the reader names)."""
    motion_keys = {key for name in kinematics for key in KINEMATIC_MODELS[name].keys}
    return (
        keys_of(*groups)
        | frozenset().union(*(keys_of_role(role) for role in roles))
        | (keys_of_role(VIAL_MOTION) & motion_keys)
    )


def thermal_only_of(reads: Iterable[str]) -> tuple[str, ...]:
    """The keys of ``reads`` that enter the thermal network alone (their fields' ``thermal_only``), in the groups'
    order."""
    chosen = set(reads)
    return tuple(key for key in GROUP_OF if key in chosen and marked(key, "thermal_only"))


@dataclass(frozen=True)
class EngineKeys:
    """The keys and values an engine takes, stated once for validation and for its description."""

    name: str  # the value of the key ``engine``
    title: str  # how messages name it: "the 1-D engine"
    summary: str  # what it moves, for `shakermill keys`
    kinematics: tuple[str, ...]  # values of ``kinematics`` it moves the vial by
    most_balls: int
    thermal_models: tuple[str, ...]  # values of ``model``
    networks: tuple[str, ...]  # values of ``thermal_model``
    # Whether the air moves with the vial, so that convection takes the ball's speed relative to it by default
    # (``convection_velocity = 'auto'``, MODEL.md §§4, 12.5).
    air_moves_with_vial: bool
    # Every key of ``Parameters`` a run of the engine reads (:func:`reads_of`: the core groups it names and the
    # components it takes): a key set explicitly that it does not read is refused, `shakermill keys --engine` and a
    # run's report leave the others out. A key it takes only at one value (n_balls = 1) is not read.
    reads: frozenset[str]
    # Keys that enter its thermal network alone, never its mechanics (:func:`thermal_only_of`): runs that differ in
    # these share one measured mechanics (solvers.simulate.thermal_variants). Empty where the temperatures share the
    # mechanics' error control, as in the 1-D engine.
    thermal_only_keys: tuple[str, ...] = ()
    # The key of how many independent replicas of its mechanics the averaged solver runs and pools, if it takes any:
    # its engine then has the capability ``engines.interface.Replicas``.
    replicas_key: str | None = None

    @property
    def several_balls(self) -> bool:
        return self.most_balls > 1


# The groups every built-in engine reads: the run and its averaged solver, the vial, its drive and stroke, the balls,
# where one ball starts, the vial's wall, the contacts' damping and heat, the paper's network and its loss to the room.
EVERY_ENGINE = (
    RunControl,
    AveragedSolver,
    Vial,
    Drive,
    Stroke,
    Balls,
    OneBallStart,
    VialWall,
    ContactDamping,
    ContactHeat,
    PaperNetwork,
    RoomLoss,
)
ONE_DIMENSIONAL = EngineKeys(
    name="1d",
    title="the 1-D engine",
    summary="one ball on the vial's axis (MODEL.md sections 1-7)",
    kinematics=("axial",),
    most_balls=1,
    thermal_models=("three_node", "ball_only"),
    # Its right-hand side writes the paper's three nodes out for speed (engines/one_d/model.py): it takes no node of
    # the network's extensions.
    networks=("paper",),
    air_moves_with_vial=False,
    # It integrates with error control (rtol, atol_*), projects each contact's energy and makes heat either way.
    reads=reads_of(*EVERY_ENGINE, OneDIntegrator, OneDAveraging),
)
# It steps by velocity Verlet at its own contact step, and its heat is η times what each contact dissipates, split
# by the bodies' effusivities (their conductivities); gravity, friction, rolling and the pair's own contact law; its
# network takes every node of the extensions, its contacts every coating, its vial every motion.
_DEM_READS = reads_of(
    *EVERY_ENGINE,
    NetworkChoice,
    SeveralBalls,
    DemContacts,
    BallPairs,
    HeatSplit,
    LabFrame,
    DemStepping,
    EnduringContacts,
    DemAveraging,
    WhatAnImpactIs,
    roles=(NETWORK_NODE, CONTACT_COATING),
    kinematics=KINEMATIC_MODELS,
)
THREE_DIMENSIONAL = EngineKeys(
    name="dem",
    title="the 'dem' engine",
    summary="n_balls spheres in three dimensions with friction and rotation (section 12)",
    kinematics=tuple(KINEMATIC_MODELS),
    most_balls=MAX_BALLS,
    thermal_models=("three_node",),
    networks=("paper", "mill-head"),
    air_moves_with_vial=True,
    reads=_DEM_READS,
    # λ, η and the balls' effusivities split a contact's heat inside the stepper, and the air's density and its
    # viscosity at the ambient temperature set each ball's Reynolds number there: those are not thermal-only.
    thermal_only_keys=thermal_only_of(_DEM_READS),
    replicas_key="dem_replicas",
)

BUILT_IN = (ONE_DIMENSIONAL.name, THREE_DIMENSIONAL.name)
ENGINE_KEYS: dict[str, EngineKeys] = {keys.name: keys for keys in (ONE_DIMENSIONAL, THREE_DIMENSIONAL)}


def reads(engine: str, key: str) -> bool:
    """Whether the engine named ``engine`` reads ``key`` (:attr:`EngineKeys.reads`)."""
    return key in ENGINE_KEYS[engine].reads


# The keys whose values decide whether a run reads a key: its engine, and those the groups' rules read.
DECIDING: tuple[str, ...] = tuple(dict.fromkeys(("engine", *(key for group in GROUPS for key in group.rule.deciding))))
# A solver's own numerical settings: they say nothing of the answer of a run that chose another solver.
SOLVER_KEYS = frozenset(key for group in GROUPS if group.rule.deciding == ("solver",) for key in group.keys())


def keys_decided_by(deciding: str, value: Any) -> frozenset[str]:
    """The keys a run reads only where its ``deciding`` key has ``value`` (and a run with another value not): a
    network's own keys (``keys_decided_by("thermal_model", "mill-head")``), a solver's."""
    return frozenset(
        key
        for group in GROUPS
        if group.rule.deciding == (deciding,)
        for key in group.keys()
        if key != deciding and group.rule.refusal(key, {deciding: value}) is None
    )


class Reader:
    """What decides whether a run reads a key: the values of the keys of :data:`DECIDING` (its engine, its solver,
    its thermal network, its vial motion, whether it has powder), those not given at the paper's preset's."""

    def __init__(self, **values: Any) -> None:
        unknown = sorted(set(values) - set(DECIDING))
        if unknown:
            raise TypeError(f"Reader: {', '.join(unknown)} decide nothing a run reads; those that do: {DECIDING}")
        self.values: dict[str, Any] = {key: values.get(key, default_of(key)) for key in DECIDING}

    def __repr__(self) -> str:
        return f"Reader({', '.join(f'{key}={value!r}' for key, value in self.values.items())})"

    @property
    def engine(self) -> EngineKeys:
        return ENGINE_KEYS[self.values["engine"]]

    def not_read(self, key: str) -> str | None:
        """Why a run would not read ``key`` (a phrase naming where it applies), or None."""
        engine = self.engine
        if key not in engine.reads:
            readers = [name for name in ENGINE_KEYS if reads(name, key)]
            where = f"engine = {readers[0]!r}" if len(readers) == 1 else "another engine" if readers else "no engine"
            return f"{engine.title} (engine = {engine.name!r}) does not read it; it applies to {where}"
        why = GROUP_OF[key].rule.refusal(key, self.values)
        if why is not None:
            return why
        return next(
            (group.superseded_because for group in GROUPS if key in group.supersedes and self._takes(group)), None
        )

    def _takes(self, group: type[KeyGroup]) -> bool:
        """Whether the run reads ``group``: its engine does and its rule lets it."""
        return bool(set(group.keys()) & self.engine.reads) and group.rule.active(self.values)

    def unread_problem(self, keys: Iterable[str], how: str = "set explicitly") -> str | None:
        """One line for the first of ``keys``, given as ``how`` says, that the run would ignore, or None: a key set
        and silently ignored gives wrong numbers with exit code 0."""
        for key in keys:
            why = self.not_read(key)
            if why is not None:
                return f"{key}: {how}, but {why}"
        return None

    def ignored_note(
        self, values: Mapping[str, Any], defaults: Mapping[str, Any], preset: Reader | None = None
    ) -> str | None:
        """A sentence naming the keys of a preset (``values``) that differ from ``defaults``, that a run of the preset
        itself reads (``preset``, its own reader) and that this run does not, or None: inherited, not asked for, so
        ignored, but said. (A key the preset's own run does not read either, inherited from a preset it builds on,
        was never part of its answer.)"""
        # A solver's own numerical settings say nothing of the answer of a run that chose another solver: not said.
        ignored = [
            key
            for key, value in values.items()
            if key in defaults
            and value != defaults[key]
            and self.not_read(key) is not None
            and (preset is None or preset.not_read(key) is None)
            and key not in SOLVER_KEYS
        ]
        if not ignored:
            return None
        return f"Ignored, as this run does not read them: the preset's {', '.join(ignored)}."


def reader_of(params: Any, solver: str | None = None) -> Reader:
    """The :class:`Reader` of a run of ``params`` (a ``Parameters``), with ``solver`` instead of its own if given."""
    values = {key: getattr(params, key) for key in DECIDING}
    return Reader(**{**values, **({"solver": solver} if solver else {})})


def reader_for(values: Mapping[str, Any]) -> Reader:
    """The :class:`Reader` of a run of the plain ``values`` (a preset's, a sweep point's): its deciding keys among
    them, the others at the paper's preset's."""
    return Reader(**{key: values[key] for key in DECIDING if key in values})


def declare(keys: EngineKeys) -> None:
    """Make ``keys.name`` a value of ``engine`` that parameters accept; an engine's name is declared once."""
    known = ENGINE_KEYS.get(keys.name)
    if known is not None and known != keys:
        raise ValueError(f"engine {keys.name!r} is declared already, with other keys")
    ENGINE_KEYS[keys.name] = keys


def undeclare(name: str) -> None:
    """Take a registered engine's name out of the values ``engine`` takes; the built-in ones stay."""
    if name in BUILT_IN:
        raise ValueError(f"engine {name!r} is built in")
    del ENGINE_KEYS[name]


def engines_taking(accepts: Callable[[EngineKeys], bool]) -> str:
    """ "engine = 'dem'" (or "engine one of 'a', 'b'"): the engines whose keys satisfy ``accepts``, for a message."""
    names = [repr(keys.name) for keys in ENGINE_KEYS.values() if accepts(keys)]
    return f"engine = {names[0]}" if len(names) == 1 else f"engine one of {', '.join(names)}"


def engine_problem(params: Any, fill: bool = False) -> str | None:
    """Why ``params`` (a ``Parameters``) ask of their engine what it does not take, in one line, or None: more
    balls than it moves (or, with ``fill``, a fill of the vial from an engine of one ball), a vial motion or a
    thermal model it does not have."""
    keys = params.engine_keys
    engine = f"engine = {keys.name!r}"
    if fill and not keys.several_balls:
        return (
            f"fill: sets the number of balls of an engine that moves several; allowed fill = 0 with {engine}, or set "
            f"{engines_taking(lambda other: other.several_balls)}"
        )
    if params.n_balls == 0 and not keys.several_balls:
        return (
            f"n_balls: {keys.title} moves one ball; allowed n_balls = 1 with {engine}; an empty mill (n_balls = 0) "
            "needs "
            f"{engines_taking(lambda other: other.several_balls)}"
        )
    if params.n_balls > keys.most_balls:
        moves = "one ball" if keys.most_balls == 1 else f"at most {keys.most_balls} balls"
        return (
            f"n_balls: {keys.title} moves {moves}; allowed n_balls {'=' if keys.most_balls == 1 else '<='} "
            f"{keys.most_balls} with {engine}, or set "
            f"{engines_taking(lambda other: other.most_balls >= params.n_balls)}"
        )
    if params.kinematics not in keys.kinematics:
        allowed = ", ".join(map(repr, keys.kinematics))
        return (
            f"kinematics: {keys.title} does not move the vial as {params.kinematics!r}; allowed {allowed} with "
            f"{engine}, "
            f"or set {engines_taking(lambda other: params.kinematics in other.kinematics)}"
        )
    if params.model not in keys.thermal_models:
        allowed = ", ".join(map(repr, keys.thermal_models))
        return f"model: {keys.title} has no {params.model!r} thermal model; allowed {allowed} with {engine}"
    if params.thermal_model not in keys.networks:
        allowed = ", ".join(map(repr, keys.networks))
        return (
            f"thermal_model: {keys.title} has no {params.thermal_model!r} network; allowed {allowed} with {engine}, or "
            "set "
            f"{engines_taking(lambda other: params.thermal_model in other.networks)}"
        )
    return None
