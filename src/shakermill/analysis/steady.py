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
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from scipy.optimize import root

from shakermill.analysis.sections import Celsius, Key, Minutes, NodeTemperatures, Watts, further_nodes
from shakermill.engines.thermal.network import NetworkLoad, ThermalNetwork

# A run shorter than this many slowest time constants has not settled: its fit is not the steady state.
SETTLED_TIME_CONSTANTS = 3.0
# Residual of the root (K/s) below which the steady state counts as solved; ~1e-9 K per second.
ROOT_TOLERANCE = 1e-9


class SteadySection(NodeTemperatures):
    """The summary's section of the steady state (MODEL.md §11; ``summary.steady``): every node's steady temperature,
    keys ``{node}_steady_C``, and what it was computed for."""

    node_key = "{node}_steady_C"
    node_meaning = (
        "its steady temperature, the root of the thermal network under the run's mean load, where a longer run "
        "would settle (absent where the run stopped before it was computed)."
    )

    each_ball_C: Annotated[list[Celsius] | None, Key("balls_steady_C")] = None
    """Each ball's steady temperature, ball 0 first (an engine of several balls)."""
    slowest_time_constant_min: Minutes
    """The thermal network's slowest time constant at the steady state: a run of several of them has settled."""
    heat_power_W: Annotated[Watts, Key("steady_state_heat_power_W")]
    """The mean heat power the steady state was computed for."""
    message: Annotated[str, Key("steady_state_message")]
    """``solved``, or why the steady state was not found."""


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
    balls: tuple[float, ...] = ()  # each ball's steady temperature (K)
    others: tuple[tuple[str, float], ...] = ()  # each further node's (the clamp's) name and steady temperature (K)

    @property
    def slowest_time_constant(self) -> float:
        return self.time_constants[0] if self.time_constants else math.nan

    def as_summary(self, each_ball: bool = False) -> SteadySection:
        """The summary's section of this steady state, in °C and minutes; ``each_ball``: with each ball's steady
        temperature (an engine of several balls)."""
        holder, others = further_nodes({name: value - 273.15 for name, value in self.others})
        return SteadySection(
            ball=self.ball - 273.15,
            vial=self.vial - 273.15,
            air=self.air - 273.15,
            holder=holder,
            others=others,
            each_ball_C=[value - 273.15 for value in self.balls] if each_ball and self.balls else None,
            slowest_time_constant_min=self.slowest_time_constant / 60.0,
            heat_power_W=self.heat_power,
            message=self.message,
        )


def steady_state(network: ThermalNetwork, load: NetworkLoad) -> SteadyState:
    """The root of ``network`` driven by ``load`` and its time constants (MODEL.md §11). The first guess puts every
    free node where all the heat would leave through the paths to the room."""
    drives = load.drives
    outer = network.room_conductance(drives)
    heat = load.heat_power + network.fixed_heat
    if outer <= 0.0 and not network.arrays.held.any() and heat > 0.0:
        return _unsolved(load, NO_HEAT_LEAVES)
    free = network.free

    def rates(theta: np.ndarray) -> np.ndarray:
        return network.rates(network.with_free(theta), load.heat, drives)[0][free]

    def slopes(theta: np.ndarray, step: float) -> np.ndarray:
        return network.jacobian(network.with_free(theta), drives, step)

    rise = heat / outer if outer > 0 else 0.0
    solved = _solve(rates, slopes, np.full(free.size, network.ambient + rise))
    if isinstance(solved, str):
        return _unsolved(load, solved)
    theta, time_constants = solved
    temperatures = network.with_free(theta)
    balls = tuple(float(value) for value in temperatures[: network.n_balls])
    return SteadyState(
        float(network.mean_ball(temperatures)),
        float(temperatures[network.vial]),
        float(temperatures[network.air]),
        time_constants,
        load.heat_power,
        load.velocity_term,
        True,
        "solved",
        balls,
        tuple(
            (node.name, float(temperatures[index])) for index, node in enumerate(network.nodes) if index > network.air
        ),
    )


NO_HEAT_LEAVES = "no heat leaves the vial (h_outer = 0): the temperatures rise without bound"


def _solve(
    rates: Callable[[np.ndarray], np.ndarray], slopes: Callable[[np.ndarray, float], np.ndarray], guess: np.ndarray
) -> tuple[np.ndarray, tuple[float, ...]] | str:
    """The root of ``rates`` (Jacobian ``slopes(θ, step)``) and the time constants there (s, slowest first), or why
    it was not found."""
    theta = _newton(rates, slopes, guess)
    if theta is None:
        # Newton's steps left the range where the network is defined, or met a node with no path at all: MINPACK's
        # trust region, slower (a dense factorisation per Jacobian), says why it fails where it does.
        solution = root(rates, guess, jac=lambda x: slopes(x, NEWTON_STEP), method="hybr", tol=1e-12)
        theta = solution.x
        residual = float(np.max(np.abs(rates(theta)), initial=0.0))
        if not np.all(np.isfinite(theta)) or residual > ROOT_TOLERANCE:
            return f"the root of the thermal network was not found ({solution.message})"
    # Central differences of step 0.5 K: f is smooth on that scale (Sutherland's factor and Whitaker's Nu vary over
    # tens of kelvin), so the time constants agree with scipy's adaptive differences to ~4e-7.
    eigenvalues = np.linalg.eigvals(np.atleast_2d(slopes(theta, TIME_CONSTANT_STEP)))
    time_constants = tuple(sorted((float(-1.0 / value.real) for value in eigenvalues), reverse=True))
    return theta, time_constants


# Newton's iterations: Sutherland's factor and the radiation's fourth power are mild, so a root takes 3 to 6.
NEWTON_ITERATIONS = 30
NEWTON_STEP = 1e-3  # K, of the differences of Newton's Jacobian: near exact, as its convergence needs
TIME_CONSTANT_STEP = 0.5  # K
NEWTON_TOLERANCE = 1e-12  # relative, of the last step


def _newton(
    rates: Callable[[np.ndarray], np.ndarray], slopes: Callable[[np.ndarray, float], np.ndarray], guess: np.ndarray
) -> np.ndarray | None:
    """The root of ``rates`` by Newton's method from ``guess``, or None where it does not reach
    :data:`ROOT_TOLERANCE`. Each iteration solves one linear system of the network's assembled Jacobian (one
    evaluation per path), where differencing the whole network costs one evaluation per node: thousands of balls,
    thousands of nodes."""
    theta = np.array(guess, dtype=float)
    for _ in range(NEWTON_ITERATIONS):
        residual = rates(theta)
        if not np.all(np.isfinite(residual)):
            return None
        try:
            step = np.linalg.solve(np.atleast_2d(slopes(theta, NEWTON_STEP)), residual)
        except np.linalg.LinAlgError:
            return None
        theta = theta - step
        # Converged to round-off, as MINPACK's tolerance on the root asked before.
        if np.max(np.abs(step), initial=0.0) <= NEWTON_TOLERANCE * np.max(np.abs(theta), initial=0.0):
            solved = np.all(np.isfinite(theta)) and np.max(np.abs(rates(theta)), initial=0.0) <= ROOT_TOLERANCE
            return theta if solved else None
    return None


def _unsolved(load: NetworkLoad, message: str) -> SteadyState:
    return SteadyState(math.inf, math.inf, math.inf, (math.inf,), load.heat_power, load.velocity_term, False, message)


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


def run_length_note(duration: float, steady: SteadyState) -> str | None:
    """A sentence for runs too short for their end (and the balls' fitted exponential) to be the steady state, else
    None. Advice, not a warning: the steady state is reported beside it."""
    slowest = steady.slowest_time_constant
    if not math.isfinite(slowest) or duration >= SETTLED_TIME_CONSTANTS * slowest:
        return None
    if fits_no_exponential(duration, steady):
        return (
            f"The run ({duration / 60:.3g} min) is shorter than the slowest time constant ({slowest / 60:.3g} min): "
            "no exponential describes it, so theta_inf_C, tau_min and rate0_C_per_min are not shown; the steady "
            "state is the answer to read."
        )
    # An empty mill fits no exponential.
    what = "its end and the exponential fitted over it (theta_inf_C) are" if steady.balls else "its end is"
    return (
        f"The run ({duration / 60:.3g} min) is shorter than {SETTLED_TIME_CONSTANTS:g} slowest time constants "
        f"({SETTLED_TIME_CONSTANTS:g} x {slowest / 60:.3g} min), so {what} not the steady state."
    )


def fits_no_exponential(duration: float, steady: SteadyState) -> bool:
    """Whether a run of balls ends before one slowest time constant of its network: an exponential fitted to it
    describes the start of the heating, not where it goes (an empty mill fits none at all)."""
    return (
        bool(steady.balls) and math.isfinite(steady.slowest_time_constant) and duration < steady.slowest_time_constant
    )
