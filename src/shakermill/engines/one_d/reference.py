"""Cross-check path: the same right-hand side through ``scipy.integrate.solve_ivp``.

This is the slow, independent route the compiled integrator is tested against
(MODEL.md §7 keeps it "only as a cross-check"). Contacts are handled with
SciPy's own event location: flight segments stop at the contact onset, contact
segments run with ``max_step`` = 0.9 t_R and stop at separation. It shares only
:func:`shakermill.model.rhs` with the default path, not the stepping, the onset
search or the energy projection.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from shakermill.engines.one_d import model
from shakermill.engines.one_d.engine import tolerances_for
from shakermill.parameters.keys import Parameters

# Flight segments: SciPy only sees a contact if the gap changes sign between two steps, so the step is
# bounded to a small part of the drive period to make a grazing touch unlikely to be missed.
FLIGHT_STEPS_PER_PERIOD = 50
# Quadrature components are integrated but must not drive SciPy's error control.
_QUADRATURE_ATOL = 1e300


@dataclass(frozen=True)
class ScipyRun:
    t_end: float
    y: np.ndarray
    impact_times: np.ndarray
    rhs_evaluations: int
    steps: int
    wall_time: float
    status: int
    message: str

    @property
    def heat_power(self) -> float:
        """Mean irreversible heat rate over the run (W)."""
        return float(self.y[model.HEAT_GENERATED]) / self.t_end

    @property
    def impacts(self) -> int:
        return int(self.impact_times.size)

    @property
    def impact_rate(self) -> float:
        return self.impacts / self.t_end


@dataclass(frozen=True)
class _WallEvent:
    """The gap to ``wall`` as an event of ``solve_ivp``, which reads ``terminal`` and ``direction`` off it: the
    integration stops where the gap crosses zero going ``direction`` (−1 the ball reaching the wall, +1 leaving it)."""

    wall: int
    k: model.Constants
    direction: float
    terminal: bool = True

    def __call__(self, t: float, y: np.ndarray) -> float:
        return model.gap(t, y[model.X], self.wall, self.k)


def simulate_scipy(params: Parameters, t_end: float | None = None, method: str = "RK23") -> ScipyRun:
    """Integrate ``params`` with ``solve_ivp`` up to ``t_end`` (default: the full duration)."""
    k = model.constants_from(params)
    t_end = params.duration if t_end is None else t_end
    tolerances = tolerances_for(params, k)
    atol = np.full(model.N_STATE, _QUADRATURE_ATOL)
    atol[: model.N_DYNAMIC] = tolerances.atol
    contact_step = tolerances.contact_step_limit
    flight_step = params.period / FLIGHT_STEPS_PER_PERIOD
    onsets = [_WallEvent(wall, k, -1.0) for wall in (model.LEFT_WALL, model.RIGHT_WALL)]
    separations = {wall: [_WallEvent(wall, k, +1.0)] for wall in (model.LEFT_WALL, model.RIGHT_WALL)}

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        return model.rhs_numpy(t, y, k)

    started = time.perf_counter()
    t, y = 0.0, model.initial_state(params)
    impact_times: list[float] = []
    evaluations = steps = 0
    wall = model.NO_WALL
    status, message = 0, "The solver reached the end of the integration interval."
    while t < t_end:
        in_contact = wall != model.NO_WALL
        solution = solve_ivp(
            fun,
            (t, t_end),
            y,
            method=method,
            rtol=params.rtol,
            atol=atol,
            max_step=contact_step if in_contact else flight_step,
            events=separations[wall] if in_contact else onsets,
        )
        evaluations += solution.nfev
        steps += solution.t.size - 1
        if solution.status < 0:
            status, message = solution.status, str(solution.message)
            break
        t, y = float(solution.t[-1]), solution.y[:, -1].copy()
        if solution.status == 1:  # an event ended the segment
            if in_contact:
                wall = model.NO_WALL
            else:
                wall = model.LEFT_WALL if solution.t_events[0].size else model.RIGHT_WALL
                impact_times.append(t)
    return ScipyRun(
        t_end=t,
        y=y,
        impact_times=np.array(impact_times),
        rhs_evaluations=evaluations,
        steps=steps,
        wall_time=time.perf_counter() - started,
        status=status,
        message=message,
    )
