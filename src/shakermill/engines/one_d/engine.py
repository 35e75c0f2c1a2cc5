"""A run of the 1-D engine (MODEL.md sections 1-7) behind the engine interface (``engines/interface.py``): the
compiled integrator set up from parameters, its state history with units, its impact records as named columns,
its energy audit, and the load of its thermal network for the averaged solver and the steady state."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from shakermill.engines.budget import RunBudget
from shakermill.engines.interface import AveragedEngine, Averaging, EngineDescription, Measured
from shakermill.engines.one_d import model
from shakermill.engines.one_d.description import DESCRIPTION
from shakermill.engines.one_d.integrator import COUNTER_NAMES, IMPACT_COLUMNS, Integrator, Tolerances
from shakermill.engines.records import CELSIUS_VARIABLES, EnergyAudit, StateHistory, attributes, with_celsius
from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork
from shakermill.parameters.keys import Parameters
from shakermill.physics import contact

# The step inside a contact stays below this fraction of the Rayleigh time (MODEL.md §7).
RAYLEIGH_FRACTION = 0.9
# A contact overlap beyond this fraction of the ball radius means the step control failed (issue: "a few percent").
MAX_OVERLAP_FRACTION = 0.05

# History variables of the state vector: (state index, units, long name).
_VARIABLES = {
    "x": (model.X, "m", "ball centre position"),
    "p": (model.P, "kg m s-1", "ball momentum"),
    "theta_ball": (model.THETA_BALL, "K", "ball temperature"),
    "theta_vial": (model.THETA_VIAL, "K", "vial temperature"),
    "theta_air": (model.THETA_AIR, "K", "inner air temperature"),
    "work_vial": (model.WORK_VIAL, "J", "cumulative work done by the vial on the ball"),
    "dissipated": (model.DISSIPATED, "J", "cumulative energy dissipated in contacts"),
    "heat_generated": (model.HEAT_GENERATED, "J", "cumulative irreversible heat generated"),
    "heat_lost": (model.HEAT_LOST, "J", "cumulative heat lost from the vial to the surroundings"),
    "velocity_term_integral": (
        model.VELOCITY_TERM,
        "s",
        "time integral of Whitaker's velocity term 0.4 Re^(1/2) + 0.06 Re^(2/3)",
    ),
}


def tolerances_for(params: Parameters, constants: model.Constants) -> Tolerances:
    """Error control and contact limits of a run (MODEL.md §7)."""
    atol = np.empty(model.N_DYNAMIC)
    atol[model.X] = params.atol_position
    atol[model.P] = params.atol_momentum
    atol[model.THETA_BALL : model.THETA_AIR + 1] = params.atol_temperature
    # The paper integrates internal energies from zero, so ode23's RelTol bounded the error of the temperature
    # rise; measured against absolute kelvin the same rtol would allow errors of ~0.3 K per step.
    origin = np.zeros(model.N_DYNAMIC)
    origin[model.THETA_BALL : model.THETA_AIR + 1] = params.ambient_temperature
    rayleigh = contact.rayleigh_time(
        params.ball_radius, params.ball_density, params.ball_youngs_modulus, params.ball_poisson_ratio
    )
    return Tolerances(
        rtol=params.rtol,
        atol=atol,
        origin=origin,
        contact_step_limit=RAYLEIGH_FRACTION * rayleigh,
        max_overlap=MAX_OVERLAP_FRACTION * constants.radius,
    )


def integrator_for(
    params: Parameters,
    sample_times: np.ndarray,
    budget: RunBudget | None = None,
    network: ThermalNetwork | None = None,
) -> Integrator:
    """A compiled integrator set up for ``params`` from its initial state, within ``budget`` (a fresh one if None),
    its thermal network written out from ``network`` (``model.network_of(params)`` if None)."""
    constants = model.constants_from(params, network)
    windows = np.array([(start, start + length) for start, length in params.record_windows], dtype=float).reshape(-1, 2)
    return Integrator(
        constants=constants,
        y=model.initial_state(params),
        t0=0.0,
        tolerances=tolerances_for(params, constants),
        sample_times=sample_times,
        windows=windows,
        project_energy=params.energy_projection,
        budget=budget if budget is not None else RunBudget.of(params),
    )


def impact_columns(records: np.ndarray, lam: float, since: float = -math.inf) -> dict[str, np.ndarray]:
    """The impact records from time ``since`` (s) on as columns with SI units (``description.IMPACT_UNITS``),
    the wall by name."""
    records = records[records[:, IMPACT_COLUMNS.index("time")] >= since]
    columns = {name: records[:, index] for index, name in enumerate(IMPACT_COLUMNS)}
    columns["wall"] = np.where(columns["wall"] == model.LEFT_WALL, "left", "right")
    columns["heat_to_ball"] = lam * columns["heat_generated"]
    columns["heat_to_vial"] = (1.0 - lam) * columns["heat_generated"]
    return columns


def state_history(
    times: np.ndarray, states: np.ndarray, constants: model.Constants, params: Parameters
) -> StateHistory:
    """The state history with units and long names, temperatures also in °C, the ball's velocity and the vial's
    position."""
    variables = {
        name: (states[:, index], attributes(units, long_name)) for name, (index, units, long_name) in _VARIABLES.items()
    }
    with_celsius(variables, CELSIUS_VARIABLES)
    variables["velocity"] = (states[:, model.P] / constants.ball_mass, attributes("m s-1", "ball velocity"))
    variables["vial_position"] = (
        params.amplitude * np.sin(params.omega * times + params.phase),
        attributes("m", "vial centre position"),
    )
    return StateHistory(times, variables)


class OneDimensionalEngine(Averaging):
    """One ball on the axis of an axially driven vial, integrated by :class:`Integrator`: the engine core and the
    capability Averaging (``engines/interface.py``)."""

    description: ClassVar[EngineDescription] = DESCRIPTION

    def __init__(
        self,
        params: Parameters,
        budget: RunBudget | None = None,
        samples: Sequence[float] | np.ndarray = (0.0,),
        horizon: float = 0.0,
    ) -> None:
        """See :class:`~shakermill.engines.interface.Engine`; the integrator keeps every step inside a record
        window as it takes it, so ``horizon`` asks nothing of it."""
        self.params = params
        self.budget = budget if budget is not None else RunBudget.of(params)
        self.network = self.network_for(params)
        self.integrator = integrator_for(params, np.asarray(samples, dtype=float), self.budget, self.network)
        self.constants = self.integrator.constants
        self.start = self.integrator.y.copy()

    @classmethod
    def network_for(cls, params: Parameters) -> ThermalNetwork:
        return model.network_of(params)

    @property
    def t(self) -> float:
        return self.integrator.t

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        return self.integrator.advance(t_stop, heartbeat)

    def explain(self, status: int) -> str:
        return self.integrator.explain(status)

    def history(self) -> StateHistory:
        integrator = self.integrator
        written = integrator.samples_written
        times = integrator.sample_times[:written]
        samples = integrator.samples[:written]
        if written == 0 or times[-1] < integrator.t:
            # Close the series with the state where the run stopped, so a failed run shows its last state.
            times = np.append(times, integrator.t)
            samples = np.vstack([samples, integrator.y])
        return state_history(times, samples, self.constants, self.params)

    def window_history(self) -> StateHistory:
        points = self.integrator.window_points
        return state_history(points[:, 0], points[:, 1:], self.constants, self.params)

    def impact_columns(self, since: float = -math.inf) -> dict[str, np.ndarray]:
        return impact_columns(self.integrator.impacts, self.params.lam, since)

    def counters(self) -> dict[str, int]:
        return {name: int(self.integrator.counters[i]) for i, name in enumerate(COUNTER_NAMES)}

    def energy_audit(self) -> EnergyAudit:
        y0, y1, k = self.start, self.integrator.y, self.constants
        t_end = self.integrator.t
        mechanical_change = model.mechanical_energy(t_end, y1, k) - model.mechanical_energy(0.0, y0, k)
        kinetic_change = 0.5 * (y1[model.P] ** 2 - y0[model.P] ** 2) / k.ball_mass
        heat = y1[model.HEAT_GENERATED] - y0[model.HEAT_GENERATED]
        dissipated = y1[model.DISSIPATED] - y0[model.DISSIPATED]

        warming = y1[model.THETA_BALL : model.THETA_AIR + 1] - y0[model.THETA_BALL : model.THETA_AIR + 1]
        return EnergyAudit(
            work_by_vial=y1[model.WORK_VIAL] - y0[model.WORK_VIAL],
            kinetic_energy_change=kinetic_change,
            elastic_energy_change=mechanical_change - kinetic_change,
            dissipated=dissipated,
            heat_generated=heat,
            heat_into=self.network.grouped(self.network.wall_contact_heat(heat)),
            not_converted_to_heat=dissipated - heat,
            stored=self.network.grouped(self.network.arrays.capacity * warming),
            heat_lost_to_surroundings=y1[model.HEAT_LOST] - y0[model.HEAT_LOST],
            projection_correction=self.integrator.energy_correction,
        )

    @property
    def projection_correction(self) -> float:
        return self.integrator.energy_correction

    def no_impact_note(self) -> str:
        params = self.params
        free_gap = params.vial_length / 2.0 - params.ball_radius
        if params.amplitude < free_gap:
            return (
                f" No impact happened: the amplitude ({params.amplitude * 1e3:g} mm) is smaller than the free gap "
                f"({free_gap * 1e3:g} mm), so in one dimension a slow ball is never reached; "
                "give it an initial ball_momentum or ball_position."
            )
        return " No impact happened."

    def measured(self) -> Measured:
        y = self.integrator.y
        return Measured(
            np.array([y[model.HEAT_GENERATED]]), np.array([y[model.VELOCITY_TERM]]), float(y[model.DISSIPATED])
        )

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: ArrayLike = ()) -> NetworkLoad:
        """The impacts' heat P splits λ : 1 − λ between the ball and the vial (MODEL.md §3); its network (the paper's)
        has no contact conduction."""
        power, term = float(heat_rates[0]), float(term_means[0])
        return NetworkLoad(self.network.wall_contact_heat(power), np.array([term]), power, term)

    def node_hits(self, impacts: Mapping[str, np.ndarray], weights: np.ndarray | None = None) -> np.ndarray:
        """Every impact heats the ball and the vial; the air only by convection."""
        count = len(impacts["time"]) if weights is None else float(np.sum(weights))
        return np.array([count, count, 0])

    def averaged_history(
        self,
        times: np.ndarray,
        temperatures: np.ndarray,
        heat_lost: np.ndarray,
        load: NetworkLoad,
        dissipated_power: float,
        network: ThermalNetwork,
    ) -> StateHistory:
        states = np.full((times.size, model.N_STATE), np.nan)
        states[:, model.THETA_BALL] = temperatures[0]
        states[:, model.THETA_VIAL] = temperatures[1]
        states[:, model.THETA_AIR] = temperatures[2]
        states[:, model.HEAT_LOST] = heat_lost
        states[:, model.HEAT_GENERATED] = load.heat_power * times
        states[:, model.DISSIPATED] = dissipated_power * times
        # On average the ball's kinetic energy does not change: the vial's work is all dissipated.
        states[:, model.WORK_VIAL] = dissipated_power * times
        states[:, model.VELOCITY_TERM] = load.velocity_term * times
        return state_history(times, states, self.constants, self.params)


# The engine contract, checked by mypy (pyproject.toml): the core and Averaging.
_CONTRACT: type[AveragedEngine] = OneDimensionalEngine
