"""The engine interface: what an engine declares (:class:`EngineDescription`), the core every run of an engine
implements (:class:`Engine`: all the full solver needs) and the capabilities a solver may need beyond it and checks
for (:class:`Averaging`, :class:`Replicas`, :class:`StepBound`, :class:`MemoryBound`). The solvers drive any engine
through it, and the files, figures, report and command line read an engine's description instead of asking which
engine a run used (docs/ARCHITECTURE.md, "The engine interface"). mypy checks that the built-in engines implement
what they declare (pyproject.toml, ``[tool.mypy]``)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, NamedTuple, Protocol, runtime_checkable

from shakermill.parameters.engine_keys import EngineKeys

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike

    from shakermill.engines.budget import RunBudget
    from shakermill.engines.records import EnergyAudit, StateHistory
    from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork
    from shakermill.parameters.keys import Parameters


@dataclass(frozen=True)
class EngineDescription:
    """What an engine is and what its runs hold, for everything above the engines."""

    keys: EngineKeys  # its name, and the kinematics, balls and thermal models it takes (parameters/engine_keys.py)
    channels: tuple[str, ...]  # the dissipation channels of its contacts (MODEL.md §12.4), as named in its records
    impact_units: Mapping[str, str]  # each column of its impact records and its unit
    impact_target: str  # the impact column that names what a ball hit: end faces, side wall, another ball
    per_ball: tuple[str, ...]  # history variables with a ball dimension, (time, ball, ...)
    read_back: tuple[str, ...]  # history variables that plot and report read from a run folder
    motion: tuple[str, ...]  # history variables of the balls' motion: not computed by the averaged solver (NaN)
    # Cumulative history variables that an averaged run fills with its averaging window's mean rates times time.
    averaged_flows: tuple[str, ...]
    # History variables that accumulate the heat of its sources (J) and each ball's Whitaker term (s): their rates
    # over a run's second half, through ``Engine.load``, drive its steady state.
    heat_variables: tuple[str, ...]
    term_variables: tuple[str, ...]
    status_messages: Mapping[
        int, str
    ]  # every status code it reports (engines/status.py's and its own) and what it means
    averaging_error_key: str  # the key of its averaged solver's target relative standard error
    # Whether its runs can start from the spread of one-ball starts on the axis that the attractor probe settles.
    attractor_starts: bool
    # History variables that accumulate the heat per kelvin its contacts conducted (J/K), if it measures it: their
    # rates over the settled half of a full run are the contact conductances of the network (``kernel.contact_drive``).
    conduction_variables: tuple[str, ...] = ()
    # Whether its contacts are the 'dem' engine's contact law stepped at ``contact_step_fraction``, so that a run of it
    # is first checked on one lone impact of that law against the configured restitution (solvers/impact.py).
    contact_step_guard: bool = False

    @property
    def name(self) -> str:
        return self.keys.name

    @property
    def several_balls(self) -> bool:
        return self.keys.several_balls

    @property
    def thermal_only_keys(self) -> tuple[str, ...]:
        """The keys that enter its thermal network alone (:attr:`EngineKeys.thermal_only_keys`)."""
        return self.keys.thermal_only_keys

    @property
    def replicas_key(self) -> str | None:
        """The key of its number of replicas of the mechanics, if it takes any (:attr:`EngineKeys.replicas_key`)."""
        return self.keys.replicas_key


class Measured(NamedTuple):
    """What the averaged solver averages, cumulative since the start: the heat of each of the engine's heat
    sources (J; its ``load`` turns their rates into the heat into each node), each ball's integral of the Whitaker
    velocity term (s), the energy dissipated in contacts (J) and, for an engine that measures them, the heat per
    kelvin its contacts conducted (J/K, in ``kernel.contact_drive`` order)."""

    heat: np.ndarray
    terms: np.ndarray
    dissipated: float
    conduction: ArrayLike = ()


ProgressCallback = Callable[[float, float], None]


class Engine(Protocol):
    """The core every engine implements, and all the full solver needs: a run of it from :class:`Parameters`, its
    state advanced in budgeted calls, what it produced and the load of its thermal network. What else a solver needs
    is a capability the engine declares by deriving from it (:class:`Averaging`, :class:`Replicas`,
    :class:`StepBound`, :class:`MemoryBound`), which the solver checks for."""

    description: ClassVar[EngineDescription]
    params: Parameters
    budget: RunBudget
    network: ThermalNetwork

    def __init__(
        self,
        params: Parameters,
        budget: RunBudget | None = None,
        samples: Sequence[float] | np.ndarray = (0.0,),
        horizon: float = 0.0,
    ) -> None:
        """A run from ``params``' initial state, within ``budget`` (``params``' own if None); its history is sampled
        at ``samples`` (s, sorted) and its record windows (``params.record_windows``) are kept up to ``horizon`` (s)."""

    @classmethod
    def network_for(cls, params: Parameters) -> ThermalNetwork:
        """The thermal network of a run of ``params`` (the engine's ``network``)."""

    @property
    def t(self) -> float:
        """Simulated time reached (s)."""

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        """Advance to ``t_stop`` (s), calling ``heartbeat(t)`` between compiled calls; returns a status
        (engines/status.py or the engine's own). Ctrl-C raises ``KeyboardInterrupt`` with the state consistent."""

    def explain(self, status: int) -> str:
        """What ``status`` means; for BUDGET_EXCEEDED, which limit was reached and how to raise it."""

    def history(self) -> StateHistory:
        """The samples reached so far, closed with the state now where that lies past the last one."""

    def window_history(self) -> StateHistory:
        """The full-resolution states inside the record windows."""

    def impact_columns(self, since: float = -math.inf) -> dict[str, np.ndarray]:
        """One entry per impact that began at ``since`` (s) or later, in time order; units: ``impact_units``."""

    def counters(self) -> dict[str, int]:
        """Work done so far: at least ``steps``, ``rejected_steps``, ``rhs_evaluations`` and ``impacts``."""

    def energy_audit(self) -> EnergyAudit:
        """Where the supplied work went, from the start to now."""

    @property
    def projection_correction(self) -> float:
        """Kinetic energy (J) any energy projection of the engine added or removed so far (``energy_audit``'s)."""

    def no_impact_note(self) -> str:
        """A hint for a run in which no impact happened (appended to its message), or ''."""

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: ArrayLike = ()) -> NetworkLoad:
        """The thermal network's load from the mean rates of the heat of its sources (W), each ball's mean
        velocity term and its contacts' mean conductances (W/K, if it measures them), of ``heat_variables``,
        ``term_variables`` and ``conduction_variables`` (or of :meth:`Averaging.measured`): the steady state of every
        run, and the drive of an averaged run's network."""


# The members of the core, by name: what `engines.registry.register` checks a class it is given for (the data
# members ``params``, ``budget`` and ``network`` are set by the constructor, and ``description`` is checked there).
ENGINE_CORE = tuple(name for name in vars(Engine) if not name.startswith("_"))


@runtime_checkable
class Averaging(Protocol):
    """Capability: the averaged solver can drive it (``solver = 'averaged'``). It measures cumulative means while its
    mechanics runs, counts the impacts that heat each node, and builds the history of an averaged run."""

    def measured(self) -> Measured:
        """The cumulative quantities the averaged solver averages (:class:`Measured`)."""

    def node_hits(self, impacts: Mapping[str, np.ndarray], weights: np.ndarray | None = None) -> np.ndarray:
        """How many of ``impacts`` heated each node of the network, or the sum of their ``weights`` (one value per
        impact, counted whole on each node it heats: its heat, for what a node gets in impacts at most)."""

    def averaged_history(
        self,
        times: np.ndarray,
        temperatures: np.ndarray,
        heat_lost: np.ndarray,
        load: NetworkLoad,
        dissipated_power: float,
        network: ThermalNetwork,
    ) -> StateHistory:
        """The history of an averaged run: the network's ``temperatures`` (node, time) and the cumulative heat
        lost; the flows as the load's mean rates times time; the motion, not computed, NaN."""


@runtime_checkable
class Replicas(Protocol):
    """Capability: independent replicas of its mechanics, pooled by the averaged solver (solvers/replicas.py), for an
    engine whose keys name a ``replicas_key``. Its constructor takes ``replica``, the number that seeds a replica's
    start (0: the configured start); a replica advanced on a Dask cluster is counted by these two."""

    def steps_taken(self) -> int:
        """Accepted steps of the run so far."""

    def take_impact_times(self) -> np.ndarray:
        """The start times (s) of the impacts recorded since the last call, which it then forgets."""


@runtime_checkable
class StepBound(Protocol):
    """Capability: a floor on a run's steps, so that a run its ``max_steps`` cannot finish is refused before it starts
    (``solvers.simulate.preflight``)."""

    @classmethod
    def least_steps(cls, params: Parameters, simulated: float) -> float:
        """The fewest steps ``simulated`` seconds of a run of ``params`` can take."""


@runtime_checkable
class MemoryBound(Protocol):
    """Capability: what a run allocates at its start, so that one the machine's free memory cannot hold is refused
    before it starts (``solvers.simulate.preflight``)."""

    @classmethod
    def memory_needed(cls, params: Parameters, samples: int) -> int:
        """Bytes a run of ``params`` sampled ``samples`` times allocates at its start."""


# Every capability an engine may have beyond the core.
CAPABILITIES: tuple[type, ...] = (Averaging, Replicas, StepBound, MemoryBound)


def capabilities_of(engine: type) -> tuple[str, ...]:
    """The names of the capabilities the engine class ``engine`` has."""
    return tuple(capability.__name__ for capability in CAPABILITIES if issubclass(engine, capability))


class AveragedEngine(Engine, Averaging, Protocol):
    """An engine with the :class:`Averaging` capability, as the averaged solver types it."""


class ReplicatedEngine(AveragedEngine, Replicas, Protocol):
    """An engine with :class:`Averaging` and :class:`Replicas`, built as the replica ``replica`` of a run."""

    def __init__(
        self,
        params: Parameters,
        budget: RunBudget | None = None,
        samples: Sequence[float] | np.ndarray = (0.0,),
        horizon: float = 0.0,
        replica: int = 0,
    ) -> None: ...
