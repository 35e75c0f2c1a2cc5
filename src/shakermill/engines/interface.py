"""The engine interface: what an engine declares (:class:`EngineDescription`) and what a run of it does
(:class:`Engine`). The solvers drive any engine through it, and the files, figures, report and command line
read an engine's description instead of asking which engine a run used (docs/ARCHITECTURE.md, "A new engine")."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, NamedTuple, Protocol

from shakermill.parameters.engine_keys import EngineKeys

if TYPE_CHECKING:
    import numpy as np

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
    # Keys that enter its thermal network alone, never its mechanics: runs that differ in these share one
    # measured mechanics (solvers.simulate.thermal_variants). Empty where the temperatures share the mechanics'
    # error control, as in the 1-D engine.
    thermal_only_keys: tuple[str, ...]
    # Whether its runs can start from the spread of one-ball starts on the axis that the attractor probe settles.
    attractor_starts: bool
    # History variables that accumulate the heat per kelvin its contacts conducted (J/K), if it measures it: their
    # rates over the settled half of a full run are the contact conductances of the network (``kernel.contact_drive``).
    conduction_variables: tuple[str, ...] = ()
    # The key of how many independent replicas of its mechanics the averaged solver runs and pools, if it takes any:
    # its constructor then takes ``replica``, the number that seeds each replica's start (0: the configured start).
    replicas_key: str | None = None

    @property
    def name(self) -> str:
        return self.keys.name

    @property
    def several_balls(self) -> bool:
        return self.keys.several_balls


class Measured(NamedTuple):
    """What the averaged solver averages, cumulative since the start: the heat of each of the engine's heat
    sources (J; its ``load`` turns their rates into the heat into each node), each ball's integral of the Whitaker
    velocity term (s), the energy dissipated in contacts (J) and, for an engine that measures them, the heat per
    kelvin its contacts conducted (J/K, in ``kernel.contact_drive`` order)."""

    heat: np.ndarray
    terms: np.ndarray
    dissipated: float
    conduction: np.ndarray = ()


ProgressCallback = Callable[[float, float], None]


class Engine(Protocol):
    """A run of an engine, from :class:`Parameters`: its state, advanced in budgeted calls, and what it produced."""

    description: ClassVar[EngineDescription]
    params: Parameters
    budget: RunBudget
    network: ThermalNetwork

    def __init__(
        self,
        params: Parameters,
        budget: RunBudget | None = None,
        samples: Sequence[float] = (0.0,),
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
        """Kinetic energy (J) any energy projection of the engine added or removed so far."""

    def no_impact_note(self) -> str:
        """A hint for a run in which no impact happened (appended to its message), or ''."""

    def measured(self) -> Measured:
        """The cumulative quantities the averaged solver averages (:class:`Measured`)."""

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: np.ndarray = ()) -> NetworkLoad:
        """The thermal network's load from the mean rates of the heat of its sources (W), each ball's mean
        velocity term and its contacts' mean conductances (W/K, if it measures them): of :meth:`measured` or of
        ``heat_variables`` and ``term_variables``."""

    def node_hits(self, impacts: Mapping[str, np.ndarray]) -> np.ndarray:
        """How many of ``impacts`` heated each node of the network."""

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
