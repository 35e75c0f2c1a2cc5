"""A run of the 'dem' engine driven from Python: the compiled stepping in calls of ~0.1 s, within the
run's budget, with the impact records grown as they fill (MODEL.md section 12)."""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from shakermill.engines.budget import RunBudget, interrupt_after_compiled_code
from shakermill.engines.dem import model, stepper
from shakermill.engines.status import BUDGET_EXCEEDED, NOT_FINITE, OVERLAP_TOO_LARGE, REACHED_STOP
from shakermill.parameters.schema import Parameters

STATUS_MESSAGES = {
    REACHED_STOP: "The engine reached the end of the integration interval.",
    NOT_FINITE: "The state became NaN or infinite.",
    OVERLAP_TOO_LARGE: (
        "A contact overlap exceeded 5 % of the smallest ball radius: the materials are too soft for these impact "
        "speeds, or contact_step_fraction is too large."
    ),
}
# Wall time (s) one compiled call aims at, so that Ctrl-C and the budget are heard several times a second.
CALL_SECONDS = 0.1
FIRST_STEPS_PER_CALL = 2_000
MAX_STEPS_PER_CALL = 50_000_000
INITIAL_RECORDS = 4096


class Engine:
    """The balls, the vial and the thermal network of one run, advanced by :meth:`advance`."""

    def __init__(self, params: Parameters, budget: RunBudget | None = None, marks: np.ndarray | None = None) -> None:
        """``marks``: sorted times (s) at which the state is recorded (:attr:`rows`)."""
        self.params = params
        self.constants = model.constants_from(params)
        self.state = model.initial_state(params, self.constants)
        self.scratch = stepper.scratch_for(params.n_balls, model.slot_count(params.n_balls))
        self.budget = budget if budget is not None else RunBudget.of(params)
        self.counters = np.zeros(len(stepper.COUNTER_NAMES) + 1, dtype=np.int64)
        self.marks = np.zeros(0) if marks is None else np.asarray(marks, dtype=float)
        self._rows = np.zeros((self.marks.size, model.row_width(params.n_balls)))
        self._records = np.zeros((INITIAL_RECORDS, len(stepper.RECORD_COLUMNS)))
        self._count = 0
        self._steps_per_call = FIRST_STEPS_PER_CALL

    @property
    def t(self) -> float:
        return float(self.state.clock[0])

    @property
    def records(self) -> np.ndarray:
        """One row per finished contact (:data:`stepper.RECORD_COLUMNS`), in the order they ended."""
        return self._records[: self._count].copy()

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        """Step to ``t_stop`` (s); returns a status (:data:`STATUS_MESSAGES`, or BUDGET_EXCEEDED).

        ``heartbeat(t)`` is called between compiled calls; Ctrl-C raises ``KeyboardInterrupt`` once the
        call under way has returned, with the state consistent at its last step.
        """
        while not self.budget.spent():
            steps_before = int(self.counters[stepper.STEPS])
            started = time.perf_counter()
            allowed = min(self._steps_per_call, self.budget.steps_left)
            with interrupt_after_compiled_code():
                status, self._count = stepper.advance(
                    t_stop, allowed, self.constants, self.state, self.scratch, self._records, self._count,
                    self.counters, self.marks, self._rows,
                )
            steps = int(self.counters[stepper.STEPS]) - steps_before
            self.budget.steps += steps
            if status == stepper.RECORDS_FULL:
                self._records = np.concatenate([self._records, np.zeros_like(self._records)])
                continue
            if status != stepper.PAUSED:
                return int(status)
            rate = steps / max(time.perf_counter() - started, 1e-9)
            self._steps_per_call = int(min(max(rate * CALL_SECONDS, 1.0), MAX_STEPS_PER_CALL))
            if heartbeat is not None:
                heartbeat(self.t)
        return BUDGET_EXCEEDED

    @property
    def rows(self) -> np.ndarray:
        """The states recorded at the marks reached so far (:func:`model.row_fields` layout)."""
        return self._rows[: self.counters[stepper.ROWS_WRITTEN]]

    def row_now(self) -> np.ndarray:
        """The state now, laid out as a recorded row."""
        row = np.zeros((1, self._rows.shape[1]))
        stepper.write_row(self.constants, self.state, self.scratch, row[0])
        return row

    def explain(self, status: int) -> str:
        return str(self.budget.reason) if status == BUDGET_EXCEEDED else STATUS_MESSAGES[status]

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

    def thermal_energy(self) -> float:
        """Σ C·θ of balls, vial and air (J above 0 K): its change is the heat they stored."""
        k, theta = self.constants, self.state.temperature
        n = k.n_balls
        return float(np.dot(k.capacity_ball, theta[:n]) + k.capacity_vial * theta[n] + k.capacity_air * theta[n + 1])


TARGETS = np.array(["left", "right", "side"])


def impact_columns(records: np.ndarray, since: float = -np.inf) -> dict[str, np.ndarray]:
    """The contact records that began at ``since`` (s) or later, in time order, as columns with SI units
    (:data:`IMPACT_UNITS`): ``target`` names the other body (left, right, side, ball), ``other_ball`` is
    its index (−1 for a wall)."""
    column = {name: index for index, name in enumerate(stepper.RECORD_COLUMNS)}
    records = records[records[:, column["time"]] >= since]
    records = records[np.argsort(records[:, column["time"]], kind="stable")]
    other = records[:, column["other"]].astype(np.int64)
    channels = records[:, column["dissipated_normal"] : column["dissipated_rolling"] + 1]
    heat_to_ball, heat_to_other = records[:, column["heat_to_ball"]], records[:, column["heat_to_other"]]
    return {
        "time": records[:, column["time"]],
        "ball": records[:, column["ball"]].astype(np.int64),
        "target": np.where(other >= 0, "ball", TARGETS[np.clip(-1 - other, 0, 2)]),
        "other_ball": np.where(other >= 0, other, -1),
        "impact_speed": records[:, column["normal_speed"]],
        "tangential_speed": records[:, column["tangential_speed"]],
        **{f"dissipated_{name}": channels[:, index] for index, name in enumerate(model.CHANNELS)},
        "dissipated_energy": channels.sum(axis=1),
        "heat_generated": heat_to_ball + heat_to_other,
        "heat_to_ball": heat_to_ball,
        "heat_to_other": heat_to_other,
        "peak_force": records[:, column["peak_force"]],
        "max_overlap": records[:, column["max_overlap"]],
        "duration": records[:, column["duration"]],
    }


IMPACT_UNITS = {
    "time": "s",
    "ball": "",
    "target": "",
    "other_ball": "",
    "impact_speed": "m/s",
    "tangential_speed": "m/s",
    **{f"dissipated_{name}": "J" for name in model.CHANNELS},
    "dissipated_energy": "J",
    "heat_generated": "J",
    "heat_to_ball": "J",
    "heat_to_other": "J",
    "peak_force": "N",
    "max_overlap": "m",
    "duration": "s",
}
