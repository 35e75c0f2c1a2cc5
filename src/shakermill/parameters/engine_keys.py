"""What each engine takes, by name: the vial motions, how many balls, the thermal models, how the air moves and the
keys it reads (listed from groups of keys stated once here).

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

# The keys an engine reads (``EngineKeys.reads``) are listed from these groups, each stated once, and its own keys: a
# key every engine reads joins its group, not each engine's list. A key set explicitly that the run's engine does not
# read is refused (:class:`Reader`); ``Parameters`` has no key that no engine reads (tests/parameters).

# Every run, whatever its engine: which engine and solver, for how long, what is kept, its budget and its bounds.
# (``attractor_starts`` too: its 1, "no probe", is what an engine without the probe does anyway.)
RUN_CONTROL = frozenset(
    {
        "engine",
        "solver",
        "duration",
        "output_interval",
        "record_windows",
        "max_wall_time",
        "max_steps",
        "stress_energy_thresholds",
        "ball_temperature_limit",
        "attractor_starts",
    }
)
# The averaged solver of any engine (each engine adds the key of its own target error, ``averaging_error_key``).
AVERAGED_SOLVER = frozenset(
    {"averaging_batch_periods", "averaging_min_batches", "averaging_max_time", "averaging_fallback"}
)
# The vial, the ball in it and the vial's drive: its amplitude, its frequency and its phase at t = 0.
GEOMETRY_AND_DRIVE = frozenset({"ball_radius", "vial_length", "vial_diameter", "amplitude", "omega", "phase"})
# Where one ball on the axis starts: its position and momentum.
ONE_BALL_START = frozenset({"ball_position", "ball_momentum"})
# A ball on the vial as a Hertz contact with damping (MODEL.md §2): the bodies' materials (a material name fills
# them), elastic constants and densities, the restitution it is damped to and whether it may pull.
CONTACT_LAW = frozenset(
    {
        "ball_material",
        "vial_material",
        "ball_density",
        "vial_density",
        "ball_youngs_modulus",
        "vial_youngs_modulus",
        "ball_poisson_ratio",
        "vial_poisson_ratio",
        "restitution",
        "no_tension",
    }
)
# The paper's thermal model (MODEL.md §§3-6): the share η of the dissipated energy that is heat and the share λ of it
# that goes to the ball, the network of ball, vial and air that takes it (capacities, convection, exchange and the
# loss to the room through h_outer·outer_area, the 'paper' network's own keys) and its temperatures at the start.
PAPER_THERMAL = frozenset(
    {
        "eta",
        "lam",
        "model",
        "ball_heat_capacity",
        "vial_heat_capacity",
        "vial_mass",
        "air_density",
        "air_viscosity_ref",
        "air_reference_temperature",
        "air_conductivity",
        "air_cp",
        "air_heat_capacity_ratio",
        "sutherland",
        "beta",
        "convection_velocity",
        "h_inner",
        "inner_area",
        *NETWORK_ONLY["paper"],
        "ambient_temperature",
        "initial_temperature",
    }
)
# The network of a real mill (thermal_model = 'mill-head', MODEL.md §13): the choice of network and its own keys.
MILL_HEAD_THERMAL = frozenset({"thermal_model", *MILL_HEAD_ONLY})
# Powder in the vial (MODEL.md §13, engines/thermal/powder.py): its node, the share of the contacts' heat it takes
# and what it does to the contacts it coats.
POWDER = frozenset(
    {
        "powder_mass",
        "powder_material",
        "powder_heat_capacity",
        "powder_heat_share",
        "powder_restitution",
        "powder_contact_coefficient",
    }
)
# Balls of their own (an engine of several): how many, or the fill that makes them, and each ball's values.
SEVERAL_BALLS = frozenset(
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
    }
)


def motion_keys(kinematics: Iterable[str]) -> frozenset[str]:
    """The keys of the named vial motions ``kinematics`` (``KINEMATIC_MODELS``), with the choice among them where there
    is more than one: what an engine that moves the vial so reads of its motion."""
    names = tuple(kinematics)
    keys = {key for name in names for key in KINEMATIC_MODELS[name].keys}
    return frozenset(keys | ({"kinematics"} if len(names) > 1 else set()))


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
    # Every key of ``Parameters`` a run of the engine reads (the groups above and its own): a key set explicitly that
    # it does not read is refused, `shakermill keys --engine` and a run's report leave the others out. A key it takes
    # only at one value (n_balls = 1) is not read.
    reads: frozenset[str]
    # Keys that enter its thermal network alone, never its mechanics: runs that differ in these share one
    # measured mechanics (solvers.simulate.thermal_variants). Empty where the temperatures share the mechanics'
    # error control, as in the 1-D engine.
    thermal_only_keys: tuple[str, ...] = ()
    # The key of how many independent replicas of its mechanics the averaged solver runs and pools, if it takes any:
    # its engine then has the capability ``engines.interface.Replicas``.
    replicas_key: str | None = None

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
    # It integrates with error control (rtol, atol_*), projects each contact's energy and makes heat either way.
    reads=RUN_CONTROL
    | AVERAGED_SOLVER
    | GEOMETRY_AND_DRIVE
    | ONE_BALL_START
    | CONTACT_LAW
    | PAPER_THERMAL
    | {
        "averaging_rel_error",
        "rtol",
        "atol_position",
        "atol_momentum",
        "atol_temperature",
        "energy_projection",
        "heat_model",
    },
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
    # It steps by velocity Verlet at its own contact step, and its heat is η times what each contact dissipates, split
    # by the bodies' effusivities (their conductivities); gravity, friction, rolling and the pair's own contact law.
    reads=RUN_CONTROL
    | AVERAGED_SOLVER
    | GEOMETRY_AND_DRIVE
    | ONE_BALL_START
    | CONTACT_LAW
    | PAPER_THERMAL
    | MILL_HEAD_THERMAL
    | POWDER
    | SEVERAL_BALLS
    | motion_keys(KINEMATIC_MODELS)
    | {
        "dem_averaging_rel_error",
        "dem_replicas",
        "ball_conductivity",
        "vial_conductivity",
        "gravity",
        "friction",
        "pair_friction",
        "pair_restitution",
        "rolling_friction",
        "contact_step_fraction",
        "enduring_step_fraction",
        "max_flight_step",
    },
    # Keys that enter only the thermal network, never a force, the heat a contact makes or the Whitaker term the
    # stepping measures (λ, η and the balls' effusivities split that heat inside the stepper; the air's density and
    # its viscosity at the ambient temperature set each ball's Reynolds number there, the materials' conductivities
    # each contact's conduction).
    thermal_only_keys=(
        "h_inner",
        "h_outer",
        "inner_area",
        "outer_area",
        "vial_mass",
        "vial_heat_capacity",
        "beta",
        "initial_temperature",
        "duration",
        "output_interval",
        "thermal_model",
        *sorted(MILL_HEAD_ONLY),
        # The powder's heat capacity and its layer's coupling: the stepping routes its share of the heat but never
        # reads its temperature.
        "powder_heat_capacity",
        "powder_contact_coefficient",
    ),
    replicas_key="dem_replicas",
)

BUILT_IN = (ONE_DIMENSIONAL.name, THREE_DIMENSIONAL.name)
ENGINE_KEYS: dict[str, EngineKeys] = {keys.name: keys for keys in (ONE_DIMENSIONAL, THREE_DIMENSIONAL)}


def reads(engine: str, key: str) -> bool:
    """Whether the engine named ``engine`` reads ``key`` (:attr:`EngineKeys.reads`)."""
    return key in ENGINE_KEYS[engine].reads


# Keys only the averaged solver reads: a full-resolution run integrates every impact. (``attractor_starts`` too, but
# its 1, "no probe", is what a full run does anyway, and scripts set it for either solver.)
AVERAGED_ONLY = AVERAGED_SOLVER | {"averaging_rel_error", "dem_averaging_rel_error", "dem_replicas"}


# Keys of the vial's motion each kinematic model reads (its ``keys``): the others are read by none of its runs.
MOTION_KEYS = frozenset(key for model in KINEMATIC_MODELS.values() for key in model.keys)
READER_FIELDS = ("engine", "solver", "thermal_model", "kinematics", "powder_mass")
# Where a run has powder (powder_mass > 0), it coats every contact: these keys give way to powder_restitution.
COATED_AWAY = frozenset({"restitution", "pair_restitution"})


@dataclass(frozen=True)
class Reader:
    """What decides whether a run reads a key: its engine, its solver, its thermal network, its vial motion and
    whether it has powder."""

    engine: str
    solver: str
    thermal_model: str
    kinematics: str
    powder_mass: float = 0.0

    def not_read(self, key: str) -> str | None:
        """Why a run would not read ``key`` (a phrase naming where it applies), or None."""
        if not reads(self.engine, key):
            readers = [name for name in ENGINE_KEYS if reads(name, key)]
            where = f"engine = {readers[0]!r}" if len(readers) == 1 else "another engine" if readers else "no engine"
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
        return self._powder_problem(key)

    def _powder_problem(self, key: str) -> str | None:
        has_powder = float(self.powder_mass) > 0.0
        if not has_powder and key in POWDER - {"powder_mass"}:
            return "a run without powder (powder_mass = 0) does not read it; it applies to powder_mass > 0"
        if has_powder and key in COATED_AWAY and reads(self.engine, "powder_restitution"):
            return "the powder coats every contact (powder_mass > 0): powder_restitution applies instead"
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
    return Reader(params.engine, solver or params.solver, params.thermal_model, params.kinematics, params.powder_mass)


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
