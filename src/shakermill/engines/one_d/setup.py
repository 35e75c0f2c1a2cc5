"""A run of the one-dimensional engine set up from its parameters: error control, sample times, the
integrator, and its impact records as named columns."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from shakermill.engines.budget import RunBudget
from shakermill.engines.one_d import model
from shakermill.engines.one_d.integrator import IMPACT_COLUMNS, Integrator, Tolerances
from shakermill.parameters.schema import Parameters
from shakermill.physics import contact

# The step inside a contact stays below this fraction of the Rayleigh time (MODEL.md §7).
RAYLEIGH_FRACTION = 0.9

# A contact overlap beyond this fraction of the ball radius means the step control failed (issue: "a few percent").
MAX_OVERLAP_FRACTION = 0.05

ProgressCallback = Callable[[float, float], None]


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

def sample_times(params: Parameters) -> np.ndarray:
    count = int(math.floor(params.duration / params.output_interval + 1e-9))
    times = np.arange(count + 1) * params.output_interval
    if times[-1] < params.duration:
        times = np.append(times, params.duration)
    return times

def integrator_for(params: Parameters, sample_times: np.ndarray, budget: RunBudget | None = None) -> Integrator:
    """A compiled integrator set up for ``params`` from its initial state, within ``budget`` (a fresh one if None)."""
    constants = model.constants_from(params)
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
    """The impact records from time ``since`` (s) on as columns with SI units (see :data:`IMPACT_UNITS`),
    the wall by name."""
    records = records[records[:, IMPACT_COLUMNS.index("time")] >= since]
    columns = {name: records[:, index] for index, name in enumerate(IMPACT_COLUMNS)}
    columns["wall"] = np.where(columns["wall"] == model.LEFT_WALL, "left", "right")
    columns["heat_to_ball"] = lam * columns["heat_generated"]
    columns["heat_to_vial"] = (1.0 - lam) * columns["heat_generated"]
    return columns


IMPACT_UNITS = {
    "time": "s",
    "wall": "",
    "impact_speed": "m/s",
    "rebound_speed": "m/s",
    "dissipated_energy": "J",
    "heat_generated": "J",
    "max_overlap": "m",
    "peak_force": "N",
    "duration": "s",
    "heat_to_ball": "J",
    "heat_to_vial": "J",
}
