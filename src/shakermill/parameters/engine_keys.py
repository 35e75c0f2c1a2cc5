"""What each engine takes, by name: the vial motions, how many balls, the thermal models and how the air moves.

``Parameters`` checks a run's keys against the engine it names (key ``engine``), so these declarations live
in this layer, below the engines; each engine carries its own as part of its description
(``engines/interface.py``), and registering a new engine (``engines/registry.py``) adds its declaration here.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.kinematic_models import KINEMATIC_MODELS

# The most balls any engine moves: the 'dem' engine's contact search (a neighbour list, engines/dem/neighbours.py) and
# its memory grow linearly with them; a run's preflight refuses what the machine cannot hold or finish.
MAX_BALLS = 2000


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
    # Keys of ``Parameters`` the engine never reads, or only at the one value it takes (n_balls = 1): `shakermill keys
    # --engine` and a run's report leave them out.
    unread: frozenset[str] = frozenset()

    @property
    def several_balls(self) -> bool:
        return self.most_balls > 1


ONE_DIMENSIONAL = EngineKeys(
    name="1d",
    title="the 1-D engine",
    summary="one ball on the vial's axis (MODEL.md sections 1-7)",
    kinematics=("axial",),
    most_balls=1,
    thermal_models=("three_node", "ball_only"),
    # Its right-hand side writes the paper's three nodes out for speed (engines/one_d/model.py).
    networks=("paper",),
    air_moves_with_vial=False,
    unread=frozenset(
        {
            "n_balls",
            "fill",
            "ball_radii",
            "ball_densities",
            "ball_youngs_moduli",
            "ball_poisson_ratios",
            "ball_heat_capacities",
            "ball_conductivities",
            "ball_materials",
            "ball_conductivity",
            "gravity",
            "friction",
            "pair_friction",
            "pair_restitution",
            "rolling_friction",
            "kinematics",
            "lateral_amplitude",
            "yaw_amplitude",
            "swing_radius",
            "motion",
            "revolution_radius",
            "speed_ratio",
            "jar_tilt",
            "contact_step_fraction",
            "enduring_step_fraction",
            "max_flight_step",
            "dem_averaging_rel_error",
            "dem_replicas",
            "thermal_model",
            "outer_diameter",
            "outer_length",
            "emissivity",
            "vial_conductivity",
            "clamp_heat_capacity",
            "clamp_conductance",
            "clamp_loss",
            "drive_heat",
        }
    ),
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
    # It steps by velocity Verlet at its own contact step, and its heat is η times what each contact dissipates.
    unread=frozenset(
        {
            "rtol",
            "atol_position",
            "atol_momentum",
            "atol_temperature",
            "energy_projection",
            "heat_model",
            "averaging_rel_error",
        }
    ),
)

BUILT_IN = (ONE_DIMENSIONAL.name, THREE_DIMENSIONAL.name)
ENGINE_KEYS: dict[str, EngineKeys] = {keys.name: keys for keys in (ONE_DIMENSIONAL, THREE_DIMENSIONAL)}


def reads(engine: str, key: str) -> bool:
    """Whether the engine named ``engine`` reads ``key`` (see :attr:`EngineKeys.unread`)."""
    return key not in ENGINE_KEYS[engine].unread


# Keys only the averaged solver reads: a full-resolution run integrates every impact. (``attractor_starts`` too, but
# its 1, "no probe", is what a full run does anyway, and scripts set it for either solver.)
AVERAGED_ONLY = frozenset(
    {
        "averaging_rel_error",
        "dem_averaging_rel_error",
        "dem_replicas",
        "averaging_batch_periods",
        "averaging_min_batches",
        "averaging_max_time",
        "averaging_fallback",
    }
)
# Keys only one thermal network reads (engines/thermal/network.py), stated once for both directions: 'paper' loses
# the vial's heat to the room through a constant h_outer·outer_area; 'mill-head' computes that loss from the vial's
# outside and its speed instead, and adds the clamp. A key of one network set on a run of the other changes nothing.
NETWORK_ONLY: dict[str, frozenset[str]] = {
    "paper": frozenset({"h_outer", "outer_area"}),
    "mill-head": frozenset(
        {
            "outer_diameter",
            "outer_length",
            "emissivity",
            "clamp_heat_capacity",
            "clamp_conductance",
            "clamp_loss",
            "drive_heat",
        }
    ),
}
MILL_HEAD_ONLY = NETWORK_ONLY["mill-head"]


# Keys of the vial's motion each kinematic model reads (its ``keys``): the others are read by none of its runs.
MOTION_KEYS = frozenset(key for model in KINEMATIC_MODELS.values() for key in model.keys)
READER_FIELDS = ("engine", "solver", "thermal_model", "kinematics")


@dataclass(frozen=True)
class Reader:
    """What decides whether a run reads a key: its engine, its solver, its thermal network and its vial motion."""

    engine: str
    solver: str
    thermal_model: str
    kinematics: str

    def not_read(self, key: str) -> str | None:
        """Why a run would not read ``key`` (a phrase naming where it applies), or None."""
        if not reads(self.engine, key):
            readers = [name for name in ENGINE_KEYS if reads(name, key)]
            where = f"engine = {readers[0]!r}" if len(readers) == 1 else "another engine"
            return (
                f"{ENGINE_KEYS[self.engine].title} (engine = {self.engine!r}) does not read it; it applies to {where}"
            )
        if self.solver != "averaged" and key in AVERAGED_ONLY:
            return f"the {self.solver!r} solver does not read it; it applies to solver = 'averaged'"
        for network, keys in NETWORK_ONLY.items():
            if key in keys and self.thermal_model != network:
                return f"the {self.thermal_model!r} network does not read it; it applies to thermal_model = {network!r}"
        if key in MOTION_KEYS and key not in KINEMATIC_MODELS[self.kinematics].keys:
            readers = " or ".join(repr(name) for name, model in KINEMATIC_MODELS.items() if key in model.keys)
            return f"kinematics = {self.kinematics!r} does not read it; it applies to kinematics = {readers}"
        return None

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
            and key not in AVERAGED_ONLY
        ]
        if not ignored:
            return None
        return f"Ignored, as this run does not read them: the preset's {', '.join(ignored)}."


def reader_of(params: Any, solver: str | None = None) -> Reader:
    """The :class:`Reader` of a run of ``params`` (a ``Parameters``), with ``solver`` instead of its own if given."""
    return Reader(params.engine, solver or params.solver, params.thermal_model, params.kinematics)


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
    keys = ENGINE_KEYS[params.engine]
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
