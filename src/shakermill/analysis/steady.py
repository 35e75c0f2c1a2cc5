"""Thermal steady state and time constants of the averaged network (MODEL.md section 11).

With the mechanics replaced by its time averages (mean heat rate and mean
Whitaker velocity term), the thermal network is a small autonomous ODE
``θ̇ = f(θ)``. Its steady state is the root of ``f`` (Sutherland's factor makes
``f`` mildly non-linear, so the root is solved, not linearised), and its time
constants are ``−1/λ_k`` for the eigenvalues ``λ_k`` of the Jacobian there.

The exponential fitted over a run (MODEL.md §8) equals the steady state only
when the run lasts several slowest time constants; the steady state does not
depend on the run's length at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.differentiate import jacobian
from scipy.optimize import root

from shakermill.engines.one_d import model
from shakermill.parameters.schema import Parameters

# A run shorter than this many slowest time constants has not settled: its fit is not the steady state.
SETTLED_TIME_CONSTANTS = 3.0
# Residual of the root (K/s) below which the steady state counts as solved; ~1e-9 K per second.
ROOT_TOLERANCE = 1e-9


@dataclass(frozen=True)
class SteadyState:
    """Steady temperatures (K) and the network's time constants (s, slowest first)."""

    ball: float
    vial: float
    air: float
    time_constants: tuple[float, ...]
    heat_power: float  # W, the mean heat rate it was computed for
    velocity_term: float  # the mean Whitaker velocity term it was computed for
    solved: bool
    message: str
    balls: tuple[float, ...] = ()  # each ball's steady temperature (K), for engines with several balls

    @property
    def slowest_time_constant(self) -> float:
        return self.time_constants[0] if self.time_constants else math.nan

    def as_summary(self) -> dict[str, float | str]:
        return {
            "ball_steady_C": self.ball - 273.15,
            "vial_steady_C": self.vial - 273.15,
            "air_steady_C": self.air - 273.15,
            "slowest_time_constant_min": self.slowest_time_constant / 60.0,
            "steady_state_heat_power_W": self.heat_power,
            "steady_state_message": self.message,
            **({"balls_steady_C": [value - 273.15 for value in self.balls]} if self.balls else {}),
        }


def _rates(params: Parameters, heat_power: float, velocity_term: float):
    """f(θ) of the nodes that evolve: (ball, vial, air), or the ball alone in the ``ball_only`` model."""
    constants = model.constants_from(params)
    ambient = params.ambient_temperature

    def three_nodes(theta: np.ndarray) -> np.ndarray:
        return np.array(model.thermal_network(theta[0], theta[1], theta[2], heat_power, velocity_term, constants)[:3])

    def ball_only(theta: np.ndarray) -> np.ndarray:
        # The predecessor model holds vial and air at ambient: only the ball has a steady state to find.
        return np.array(model.thermal_network(theta[0], ambient, ambient, heat_power, velocity_term, constants)[:1])

    return ball_only if params.model == "ball_only" else three_nodes


def _first_guess(params: Parameters, heat_power: float, size: int) -> np.ndarray:
    """Every node at the vial's linear steady state: all heat leaves through h_o·A_o (MODEL.md §11)."""
    outer_conductance = params.h_outer * params.outer_area
    rise = heat_power / outer_conductance if outer_conductance > 0 else 0.0
    return np.full(size, params.ambient_temperature + rise)


def _vectorised(rates):
    """``rates`` for scipy.differentiate.jacobian, which evaluates many points at once (trailing axes)."""

    def evaluate(theta: np.ndarray) -> np.ndarray:
        flat = theta.reshape(theta.shape[0], -1)
        values = np.stack([rates(flat[:, j]) for j in range(flat.shape[1])], axis=-1)
        return values.reshape(theta.shape)

    return evaluate


def steady_state(params: Parameters, heat_power: float, velocity_term: float) -> SteadyState:
    """The root of the averaged thermal network and its time constants (MODEL.md §11)."""
    size = 1 if params.model == "ball_only" else 3
    ambient = params.ambient_temperature
    if params.model != "ball_only" and params.h_outer * params.outer_area <= 0.0 and heat_power > 0.0:
        return _unsolved(heat_power, velocity_term, NO_HEAT_LEAVES)
    solved = _solve(_rates(params, heat_power, velocity_term), _first_guess(params, heat_power, size))
    if isinstance(solved, str):
        return _unsolved(heat_power, velocity_term, solved)
    theta, time_constants = solved
    ball, vial, air = (theta[0], ambient, ambient) if size == 1 else theta
    return SteadyState(float(ball), float(vial), float(air), time_constants, heat_power, velocity_term, True, "solved")


def network_steady_state(
    params: Parameters, rates: Callable[[np.ndarray], np.ndarray], heat_power: float, velocity_term: float, n_balls: int
) -> SteadyState:
    """Steady state and time constants of a network of ``n_balls`` ball nodes, the vial and the air, whose
    averaged right-hand side is ``rates`` (the 'dem' engine); ``ball`` is the balls' mean."""
    if params.h_outer * params.outer_area <= 0.0 and heat_power > 0.0:
        return _unsolved(heat_power, velocity_term, NO_HEAT_LEAVES)
    solved = _solve(rates, _first_guess(params, heat_power, n_balls + 2))
    if isinstance(solved, str):
        return _unsolved(heat_power, velocity_term, solved)
    theta, time_constants = solved
    balls = tuple(float(value) for value in theta[:n_balls])
    return SteadyState(
        float(np.mean(balls)), float(theta[n_balls]), float(theta[n_balls + 1]), time_constants, heat_power,
        velocity_term, True, "solved", balls,
    )


NO_HEAT_LEAVES = "no heat leaves the vial (h_outer = 0): the temperatures rise without bound"


def _solve(rates: Callable[[np.ndarray], np.ndarray], guess: np.ndarray) -> tuple[np.ndarray, tuple[float, ...]] | str:
    """The root of ``rates`` and the time constants there (s, slowest first), or why it was not found."""
    solution = root(rates, guess, method="hybr", tol=1e-12)
    residual = float(np.max(np.abs(rates(solution.x))))
    if not np.all(np.isfinite(solution.x)) or residual > ROOT_TOLERANCE:
        return f"the root of the thermal network was not found ({solution.message})"
    derivative = jacobian(_vectorised(rates), solution.x, initial_step=1.0).df
    eigenvalues = np.linalg.eigvals(np.atleast_2d(derivative))
    time_constants = tuple(sorted((float(-1.0 / value.real) for value in eigenvalues), reverse=True))
    return solution.x, time_constants


def _unsolved(heat_power: float, velocity_term: float, message: str) -> SteadyState:
    return SteadyState(math.inf, math.inf, math.inf, (math.inf,), heat_power, velocity_term, False, message)


def settled_means(times: np.ndarray, heat_generated: np.ndarray, velocity_term_integral: np.ndarray) -> tuple[float, float]:
    """Mean heat rate (W) and Whitaker velocity term over the second half of a run (its settled motion)."""
    return float(settled_rates(times, heat_generated)), float(settled_rates(times, velocity_term_integral))


def settled_rates(times: np.ndarray, cumulative: np.ndarray) -> np.ndarray:
    """Mean rates over the second half of a run (its settled motion) of a cumulative series over
    (time, ...): one rate per column, zero for a run of no length.

    The same convention as the regime classification: the start-up transient lasts seconds, so the
    second half of any run worth averaging is settled.
    """
    end = times[-1]
    middle = 0.5 * end
    columns = np.asarray(cumulative, dtype=float).reshape(times.size, -1)
    if end <= 0.0:
        return np.zeros(columns.shape[1:]).reshape(np.shape(cumulative)[1:])
    halfway = np.array([np.interp(middle, times, column) for column in columns.T])
    return ((columns[-1] - halfway) / (end - middle)).reshape(np.shape(cumulative)[1:])


def run_length_warning(duration: float, steady: SteadyState) -> str | None:
    """A line for runs too short for their exponential fit to mean the steady state, else None."""
    slowest = steady.slowest_time_constant
    if not math.isfinite(slowest) or duration >= SETTLED_TIME_CONSTANTS * slowest:
        return None
    return (
        f"the run ({duration / 60:.3g} min) is shorter than {SETTLED_TIME_CONSTANTS:g} slowest time constants "
        f"({SETTLED_TIME_CONSTANTS:g} x {slowest / 60:.3g} min): the exponential fitted over it (theta_inf_C) is not "
        f"the steady state; the ball settles at {steady.ball - 273.15:.1f} °C (ball_steady_C)"
    )
