"""A run of the 'dem' engine (MODEL.md section 12) behind the engine interface (``engines/interface.py``): the
compiled stepping driven in budgeted calls, the state recorded at the output samples and inside the record
windows, its history with units, its contact records as named columns, its energy audit and the load of its
thermal network."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from shakermill.engines.budget import RunBudget
from shakermill.engines.calls import CALL_AGAIN, PAUSED, CompiledRun
from shakermill.engines.dem import model, stepper
from shakermill.engines.dem.description import CHANNELS, DESCRIPTION
from shakermill.engines.interface import (
    Averaging,
    EngineDescription,
    Measured,
    MemoryBound,
    Replicas,
    ReplicatedEngine,
    StepBound,
)
from shakermill.engines.records import (
    BALL_TEMPERATURES,
    HEAT_INTO_NODES,
    HERTZ_SCALE,
    NODE_NAMES,
    EnergyAudit,
    StateHistory,
    attributes,
    with_celsius,
)
from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork
from shakermill.parameters.keys import Parameters
from shakermill.physics import contact
from shakermill.physics.kinematics import fourier_coordinates

INITIAL_RECORDS = 4096
# The record windows hold the motion at this interval (10 kHz): a drive period in ~570 points.
WINDOW_INTERVAL = 1e-4
TARGETS = np.array(model.WALL_NAMES)
_PER_BALL = ("time", "ball")
_VECTORS = ("time", "ball", "axis")


def marks(params: Parameters, samples: np.ndarray, end: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times up to ``end`` at which the run is recorded, in order, from 0 (the start), and whether each is one of the
    output ``samples`` and whether it lies in a record window."""
    points = [
        np.arange(start, min(start + length, end) + 0.5 * WINDOW_INTERVAL, WINDOW_INTERVAL)
        for start, length in params.record_windows
        if start < end
    ]
    window = np.unique(np.concatenate(points)) if points else np.empty(0)
    times = np.union1d(np.append(0.0, samples[samples <= end]), window)
    return times, np.isin(times, samples), np.isin(times, window)


class DemEngine(CompiledRun, Averaging, Replicas, StepBound, MemoryBound):
    """The balls, the vial and the thermal network of one run, advanced by :meth:`advance`: the engine core and every
    capability (``engines/interface.py``)."""

    description: ClassVar[EngineDescription] = DESCRIPTION
    first_steps_per_call: ClassVar[int] = 2_000
    most_steps_per_call: ClassVar[int] = 50_000_000

    def __init__(
        self,
        params: Parameters,
        budget: RunBudget | None = None,
        samples: Sequence[float] | np.ndarray = (0.0,),
        horizon: float = 0.0,
        replica: int = 0,
    ) -> None:
        """See :class:`~shakermill.engines.interface.Engine`. The state is recorded as a row (:func:`model.row_fields`)
        at each sample and every WINDOW_INTERVAL inside the record windows; the start before the first step.
        A ``replica`` > 0 starts from the configured state with its balls kicked (:func:`model.kick_for_replica`)."""
        self.params = params
        self.budget = budget if budget is not None else RunBudget.of(params)
        self.network = self.network_for(params)
        self.constants = model.constants_from(params, self.network)
        self.state = model.initial_state(params, self.constants, self.network)
        if replica:
            model.kick_for_replica(self.state, replica)
        self.scratch = model.scratch_for(params.n_balls, self.state.contacts.active.size)
        self.stepper_counters = np.zeros(len(stepper.COUNTER_NAMES) + 1, dtype=np.int64)
        times, self._is_sample, self._in_window = marks(params, np.asarray(samples, dtype=float), horizon)
        self.marks = times[1:]
        self._rows = np.zeros((self.marks.size, model.row_width(params.n_balls, self.node_count)))
        # The stepping hands back when fewer rows are free than there are slots: a large charge starts with room.
        self._records = np.zeros(
            (max(INITIAL_RECORDS, 2 * self.state.contacts.active.size), len(stepper.RECORD_COLUMNS))
        )
        self._count = 0
        self.start = self.row_now()

    @classmethod
    def network_for(cls, params: Parameters) -> ThermalNetwork:
        return model.network_of(params)

    @classmethod
    def memory_needed(cls, params: Parameters, samples: int) -> int:
        """Bytes a run of ``params`` allocates at its start: the state rows, one at each of its ``samples`` and every
        WINDOW_INTERVAL of its record windows (50 balls over 600 s of windows: ~28 GiB), and its contacts' memory
        (:func:`model.contact_memory`: ~40 MB for 2000 balls)."""
        windows = sum(max(0.0, min(length, params.duration - start)) for start, length in params.record_windows)
        rows = samples + windows / WINDOW_INTERVAL
        network = cls.network_for(params)
        row_bytes = rows * model.row_width(params.n_balls, len(network.nodes)) * 8
        constants = model.constants_from(params, network)
        return int(row_bytes + model.contact_memory(constants, len(stepper.RECORD_COLUMNS)))

    @classmethod
    def least_steps(cls, params: Parameters, simulated: float) -> float:
        """The fewest steps ``simulated`` seconds of a run of ``params`` can take: no step is longer than
        ``max_flight_step`` (MODEL.md §12.6); in contact they are far shorter."""
        return simulated / params.max_flight_step

    @property
    def node_count(self) -> int:
        return len(self.network.nodes)

    @property
    def t(self) -> float:
        return float(self.state.clock[0])

    def steps_taken(self) -> int:
        return int(self.stepper_counters[stepper.STEPS])

    def compiled_call(self, t_stop: float, steps_allowed: int) -> int:
        status, self._count = stepper.advance(
            t_stop,
            steps_allowed,
            self.constants,
            self.network.arrays,
            self.state,
            self.scratch,
            self._records,
            self._count,
            self.stepper_counters,
            self.marks,
            self._rows,
        )
        if status == stepper.RECORDS_FULL:
            self._records = np.concatenate([self._records, np.zeros_like(self._records)])
            return CALL_AGAIN
        return PAUSED if status == stepper.PAUSED else int(status)

    def explain(self, status: int) -> str:
        return self.budget.explain(status, DESCRIPTION.status_messages)

    @property
    def records(self) -> np.ndarray:
        """One row per finished contact (:data:`stepper.RECORD_COLUMNS`), in the order they ended."""
        return self._records[: self._count].copy()

    @property
    def rows(self) -> np.ndarray:
        """The states recorded at the marks reached so far (:func:`model.row_fields` layout)."""
        return self._rows[: self.stepper_counters[stepper.ROWS_WRITTEN]]

    def row_now(self) -> np.ndarray:
        """The state now, laid out as a recorded row."""
        row = np.zeros((1, self._rows.shape[1]))
        stepper.write_row(self.constants, self.network.arrays, self.state, self.scratch, row[0])
        return row

    def history(self) -> StateHistory:
        rows = np.vstack([self.start, self.rows])
        samples = rows[self._is_sample[: len(rows)]]
        if samples[-1, 0] < self.t:
            samples = np.vstack([samples, self.row_now()])  # a stopped run shows its last state
        return self._history(samples)

    def window_history(self) -> StateHistory:
        return self._history(np.vstack([self.start, self.rows])[self._in_window[: len(self.rows) + 1]])

    def _history(self, rows: np.ndarray) -> StateHistory:
        return history_of(*model.unpack_rows(rows, self.params.n_balls, self.node_count), self.constants, self.network)

    def take_impact_times(self) -> np.ndarray:
        """The start times (s) of the contacts recorded since the last call, which are then forgotten: a replica
        advanced elsewhere (solvers/replicas.py) sends back only what the averaged solver counts of its impacts."""
        column = stepper.RECORD_COLUMNS.index("time")
        times = np.sort(self._records[: self._count, column])
        self._count = 0
        return times

    def impact_columns(self, since: float = -math.inf) -> dict[str, np.ndarray]:
        # The rows it selects are copied there: no copy of every record first (the averaged solver asks each batch).
        columns = impact_columns(self._records[: self._count], since)
        columns[HERTZ_SCALE] = hertz_scales(columns["ball"], columns["other_ball"], columns["target"], self.constants)
        return columns

    def counters(self) -> dict[str, int]:
        counters = {name: int(value) for name, value in zip(stepper.COUNTER_NAMES, self.stepper_counters)}
        counters.update(rejected_steps=0, rhs_evaluations=counters["steps"])
        return counters

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy of the balls (J)."""
        k, s = self.constants, self.state
        translational = 0.5 * np.sum(k.mass * np.sum(s.velocity**2, axis=1))
        rotational = 0.5 * np.sum(k.inertia * np.sum(s.spin**2, axis=1))
        return float(translational + rotational)

    def stored_contact_energy(self) -> float:
        """Elastic energy held in the contacts now (Hertz normal plus tangential springs), J."""
        contacts = self.state.contacts
        springs = 0.5 * contacts.stiffness * contacts.stretch
        return float(np.sum(contacts.elastic_energy[contacts.active]) + np.sum(springs[contacts.active]))

    def energy_audit(self) -> EnergyAudit:
        """Where the work of the vial and of gravity went (MODEL.md §12.6), from the start to now."""
        k, s = self.constants, self.state
        n = k.n_balls
        capacity = self.network.arrays.capacity
        initial = {name: values[0] for name, values in model.unpack_rows(self.start, n, self.node_count)[1].items()}
        kinetic_start = 0.5 * float(
            np.sum(k.mass * np.sum(initial["velocity"] ** 2, axis=1))
            + np.sum(k.inertia * np.sum(initial["angular_velocity"] ** 2, axis=1))
        )
        warming = s.temperature - initial["temperature"]
        totals = s.totals - initial["totals"]
        channels = dict(zip(CHANNELS, totals[model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1], strict=True))
        dissipated = float(sum(channels.values()))
        heat = float(totals[model.HEAT_GENERATED])
        return EnergyAudit(
            work_by_vial=float(totals[model.WORK_VIAL]),
            kinetic_energy_change=self.kinetic_energy() - kinetic_start,
            elastic_energy_change=self.stored_contact_energy(),
            dissipated=dissipated,
            heat_generated=heat,
            heat_into=self.network.grouped(s.heat_into - initial["heat_into"]),
            not_converted_to_heat=dissipated - heat,
            stored=self.network.grouped(capacity * warming),
            drive_heat=self.network.fixed_heat * (self.t - float(self.start[0, 0])),
            heat_lost_to_surroundings=float(totals[model.HEAT_LOST]),
            projection_correction=0.0,
            work_by_gravity=float(totals[model.WORK_GRAVITY]),
            work_by_stiffening=float(totals[model.WORK_STIFFENING]),
            dissipated_by_channel={name: float(value) for name, value in channels.items()},
        )

    @property
    def projection_correction(self) -> float:
        """No projection: the velocity-Verlet bookkeeping closes the energy balance exactly."""
        return 0.0

    def no_impact_note(self) -> str:
        return ""

    def measured(self) -> Measured:
        s = self.state
        dissipated = float(s.totals[model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1].sum())
        n = self.params.n_balls
        return Measured(s.heat_into.copy(), s.drive_integrals[:n].copy(), dissipated, s.drive_integrals[n:].copy())

    def load(self, heat_rates: np.ndarray, term_means: np.ndarray, conductances: ArrayLike = ()) -> NetworkLoad:
        """The heat into each node as measured (the stepper routes each contact's heat: ``network.split`` and
        ``network.deposits``); the contacts' mean conductances."""
        heat = np.asarray(heat_rates, dtype=float)
        terms = np.asarray(term_means, dtype=float)
        mean_term = float(terms.mean()) if terms.size else math.nan  # an empty mill has no ball to convect
        return NetworkLoad(heat, terms, float(heat.sum()), mean_term, np.asarray(conductances, dtype=float))

    def node_hits(self, impacts: Mapping[str, np.ndarray], weights: np.ndarray | None = None) -> np.ndarray:
        """Each ball's contacts, with the vial or another ball; the vial's; each deposit's node every contact of the
        kinds it takes a share of; the others none (or the sums of the contacts' ``weights``)."""
        n = self.params.n_balls
        weight = np.ones(len(impacts["target"])) if weights is None else np.asarray(weights, dtype=float)
        own = np.bincount(impacts["ball"], weight, minlength=n) + np.bincount(
            impacts["other_ball"][impacts["other_ball"] >= 0], weight[impacts["other_ball"] >= 0], minlength=n
        )
        hits = np.zeros(len(self.network.nodes))
        hits[:n] = own[:n]
        on_wall = impacts["target"] != "ball"
        walls, pairs = float(weight[on_wall].sum()), float(weight[~on_wall].sum())
        hits[self.network.vial] = walls
        k = self.constants
        for index, node in enumerate(k.deposit_nodes):
            shares = k.deposit_shares[:, :, index]
            hits[node] += walls * bool(shares[0].any()) + pairs * bool(shares[1].any())
        return hits

    def averaged_history(
        self,
        times: np.ndarray,
        temperatures: np.ndarray,
        heat_lost: np.ndarray,
        load: NetworkLoad,
        dissipated_power: float,
        network: ThermalNetwork,
    ) -> StateHistory:
        k, n = self.constants, self.params.n_balls
        count = times.size
        totals = np.zeros((count, len(model.TOTAL_NAMES)))
        totals[:, model.WORK_VIAL] = dissipated_power * times  # on average the balls' kinetic energy does not change
        totals[:, model.HEAT_GENERATED] = load.heat_power * times
        totals[:, model.HEAT_LOST] = heat_lost
        totals[:, model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1] = (
            np.nan
        )  # the split is in the window's impacts
        vial = np.zeros((count, 6))
        rates = np.zeros(6)
        for row, t in enumerate(times):
            fourier_coordinates(t, k.omega, k.phase, k.harmonics, vial[row], rates)
        motion = np.full((count, n, 3), np.nan)
        fields = {
            "position": motion,
            "velocity": motion,
            "angular_velocity": motion,
            "temperature": temperatures.T,
            "totals": totals,
            "heat_into": np.outer(times, load.heat),
            "drive_integrals": np.outer(times, load.drives),
            "vial": vial,
        }
        return history_of(times, fields, k, network)


# The engine contract, checked by mypy (pyproject.toml): the core with Averaging and Replicas, StepBound, MemoryBound.
# One assignment each: mypy refuses a class that lacks a method of a capability it derives from only in a plain one.
_CONTRACT: type[ReplicatedEngine] = DemEngine
_STEPS: type[StepBound] = DemEngine
_MEMORY: type[MemoryBound] = DemEngine


def impact_columns(records: np.ndarray, since: float = -np.inf) -> dict[str, np.ndarray]:
    """The contact records that began at ``since`` (s) or later, in time order, as columns with SI units
    (``description.IMPACT_UNITS``): ``target`` names the other body (left, right, side, ball), ``other_ball`` is
    its index (−1 for a wall)."""
    column = {name: index for index, name in enumerate(stepper.RECORD_COLUMNS)}
    records = records[records[:, column["time"]] >= since]
    records = records[np.argsort(records[:, column["time"]], kind="stable")]
    other = records[:, column["other"]].astype(np.int64)
    channels = records[:, column["dissipated_normal"] : column["dissipated_rolling"] + 1]
    heat_to_ball, heat_to_other = records[:, column["heat_to_ball"]], records[:, column["heat_to_other"]]
    heat_to_deposits = records[:, column["heat_to_deposits"]]
    return {
        "time": records[:, column["time"]],
        "ball": records[:, column["ball"]].astype(np.int64),
        "target": np.where(other >= 0, "ball", TARGETS[np.clip(-1 - other, 0, 2)]),
        "other_ball": np.where(other >= 0, other, -1),
        "impact_speed": records[:, column["normal_speed"]],
        "tangential_speed": records[:, column["tangential_speed"]],
        **{f"dissipated_{name}": channels[:, index] for index, name in enumerate(CHANNELS)},
        "dissipated_energy": channels.sum(axis=1),
        "heat_generated": heat_to_ball + heat_to_other + heat_to_deposits,
        "heat_to_ball": heat_to_ball,
        "heat_to_other": heat_to_other,
        "heat_to_deposits": heat_to_deposits,
        "peak_force": records[:, column["peak_force"]],
        "max_overlap": records[:, column["max_overlap"]],
        "duration": records[:, column["duration"]],
        "conduction": records[:, column["conduction"]],
    }


def hertz_scales(ball: np.ndarray, other: np.ndarray, target: np.ndarray, k: model.Constants) -> np.ndarray:
    """The Hertz duration at 1 m/s (s) of each contact of ``ball`` with the ball ``other`` (≥ 0) or the wall
    ``target``: of the pair's m*, R* and E* (MODEL.md §12.3), what tells its chatter from a new impact
    (analysis/impacts.py)."""
    on_ball = other >= 0
    partner = np.where(on_ball, other, ball)
    youngs, poisson = k.youngs_modulus, k.poisson_ratio
    compliance = (1 - poisson[ball] ** 2) / youngs[ball] + (1 - poisson[partner] ** 2) / youngs[partner]
    wall = sum(np.where(target == name, index, 0) for index, name in enumerate(model.WALL_NAMES))
    mass_i, mass_j, radius_i, radius_j = k.mass[ball], k.mass[partner], k.radius[ball], k.radius[partner]
    return contact.hertz_duration_at_unit_speed(
        np.where(on_ball, mass_i * mass_j / (mass_i + mass_j), mass_i),
        np.where(on_ball, radius_i * radius_j / (radius_i + radius_j), k.wall_radius[ball, wall]),
        np.where(on_ball, 1.0 / compliance, k.wall_modulus[ball]),
    )


def history_of(
    times: np.ndarray, fields: dict[str, np.ndarray], k: model.Constants, network: ThermalNetwork
) -> StateHistory:
    """The states with units: temperatures of each ball (and their mean, ``theta_ball``) and of every other node of
    ``network`` (``theta_<name>``: the vial, the air, then the holder or the powder where the network has them), the
    balls' motion in the lab frame (axis x, y, z; z up), the vial's pose, the running totals and the heat into each
    node."""
    n = k.n_balls
    theta, totals, heat_into = fields["temperature"], fields["totals"], fields["heat_into"]
    terms, vial = fields["drive_integrals"][:, :n], fields["vial"]
    variables: dict[str, tuple[np.ndarray, dict[str, str]]] = {
        "theta_ball": (network.mean_ball(theta), attributes("K", "mean ball temperature")),
        BALL_TEMPERATURES: (theta[:, :n], attributes("K", "temperature of each ball")),
    }
    others = tuple(f"theta_{node.name}" for node in network.others)
    for index, (name, node) in enumerate(zip(others, network.others, strict=True), start=n):
        variables[name] = (theta[:, index], attributes("K", f"{node.title} temperature"))
    with_celsius(variables, ("theta_ball", BALL_TEMPERATURES, *others))
    for name, units, long_name in (
        ("position", "m", "ball centre, lab frame"),
        ("velocity", "m s-1", "ball velocity, lab frame"),
        ("angular_velocity", "rad s-1", "ball angular velocity, lab frame"),
    ):
        variables[name] = (fields[name], attributes(units, long_name))
    variables["vial_centre"] = (vial[:, :3], attributes("m", "vial centre, lab frame"))
    variables["vial_angles"] = (vial[:, 3:], attributes("rad", "vial roll, pitch and yaw"))
    for index, name in enumerate(model.TOTAL_NAMES):
        variables[name] = (totals[:, index], attributes("J", f"cumulative {name.replace('_', ' ')}"))
    dissipated = totals[:, model.DISSIPATED_NORMAL : model.DISSIPATED_ROLLING + 1].sum(axis=1)
    variables["dissipated"] = (dissipated, attributes("J", "cumulative energy dissipated in contacts"))
    variables["heat_into_balls"] = (heat_into[:, :n], attributes("J", "cumulative impact heat into each ball"))
    variables[HEAT_INTO_NODES] = (
        heat_into[:, n:],
        {
            **attributes("J", "cumulative contact heat into each node but the balls"),
            NODE_NAMES: ", ".join(node.name for node in network.others),
        },
    )
    variables["velocity_term_integrals"] = (
        terms,
        attributes("s", "time integral of each ball's Whitaker velocity term"),
    )
    variables["velocity_term_integral"] = (
        network.mean_ball(terms),
        attributes("s", "the balls' mean of velocity_term_integrals"),
    )
    variables["contact_conduction"] = (
        fields["drive_integrals"][:, n:],
        attributes(
            "J K-1", "heat per kelvin conducted by the contacts of each ball with the vial, then with the other balls"
        ),
    )
    dimensions: dict[str, tuple[str, ...]] = {
        name: _PER_BALL
        for name in (BALL_TEMPERATURES, f"{BALL_TEMPERATURES}_C", "heat_into_balls", "velocity_term_integrals")
    }
    dimensions["contact_conduction"] = ("time", "contact")
    dimensions[HEAT_INTO_NODES] = ("time", "node")
    dimensions.update({name: _VECTORS for name in ("position", "velocity", "angular_velocity")})
    dimensions.update(vial_centre=("time", "axis"), vial_angles=("time", "angle"))
    return StateHistory(times, variables, dimensions)
