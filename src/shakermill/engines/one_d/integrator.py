"""Compiled adaptive Runge–Kutta integration of the full-resolution model (MODEL.md section 7).

The solver is an explicit FSAL Runge–Kutta pair given as data
(:class:`ButcherTableau`, checked at construction); the default is
Bogacki–Shampine 3(2), the method of MATLAB's ``ode23`` and SciPy's ``RK23``.
Step-size control (:class:`StepController`) follows SciPy's RK23: RMS error
norm over the dynamic state, scale ``atol + rtol·max(|y_n|, |y_n+1|)``; inside
a contact the mechanics are measured against the impact's own scales instead
(:func:`_contact_error_scale`).

Contacts are events of the mechanics, handled in the compiled loop:

* In flight the ball moves on a straight line and the walls on a sine, so the
  gap to each wall is known exactly over a trial step. Its first zero is
  searched with a curvature bound (|gap''| ≤ X_v·ω²) that rules out a wall
  touching and leaving within the step; the step is then shortened to land on
  the contact onset. A contact start is therefore never stepped over.
* Inside a contact the step is at most ``contact_step_limit`` (0.9 t_R by
  default); the overlap, the momentum and the dissipated energy are controlled
  relative to the Hertz maximum overlap, m·v_in and m·v_in²/2 at a share of
  rtol (``CONTACT_TOLERANCE_SHARE``), and the steps are graded towards both ends of the contact, where the
  damping force has a ζ^{1/4} singularity.
* One record per impact is written when the ball leaves the wall.

Everything runs in chunks (:meth:`Integrator.advance`), so a caller can show
progress and keep what was computed when interrupted. Within a chunk the
compiled loop also hands control back about every CALL_SECONDS of wall time, so
that tiny steps cannot hold off Ctrl-C, the run's budget or progress.
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Callable, Iterator

import numpy as np
from numba import njit

from shakermill.engines.budget import RunBudget
from shakermill.engines.one_d.model import (
    DISSIPATED,
    HEAT_GENERATED,
    LEFT_WALL,
    N_DYNAMIC,
    N_STATE,
    NO_WALL,
    RIGHT_WALL,
    WORK_VIAL,
    Constants,
    P,
    X,
    contact_forces,
    gap,
    rhs,
)
from shakermill.physics import kinematics
from shakermill.physics.contact import elastic_energy, hertz_contact_time, hertz_max_overlap

# Status codes of the compiled loop (negative: failure).
REACHED_STOP = 0
NOT_FINITE = -1
OVERLAP_TOO_LARGE = -2
STEP_UNDERFLOW = -3
# Checked between compiled calls (Integrator.advance), not in the loop: the run's budget (RunBudget.reason
# says which limit) and the size of the record windows.
BUDGET_EXCEEDED = -4
WINDOWS_FULL = -7
# Every step inside a record window is kept: ~1000 rows a simulated second at the defaults (35 min of
# windows fit, 4 min at rtol 1e-6), but tiny steps would fill memory and disk (a vacuum vial,
# air_density = 1e-8, takes 1.7e8 steps a second). 2·10⁶ rows are ~220 MB, in memory and in windows.nc.
MAX_WINDOW_POINTS = 2_000_000
# Not an outcome: the loop took the steps it was allowed and hands control back mid-chunk.
_PAUSED = 2

STATUS_MESSAGES = {
    REACHED_STOP: "The solver reached the end of the integration interval.",
    NOT_FINITE: "The state became NaN or infinite.",
    OVERLAP_TOO_LARGE: (
        "The contact overlap exceeded the allowed fraction of the ball radius: the materials are too soft for "
        "this impact speed (check ball_youngs_modulus and vial_youngs_modulus), or the step control failed."
    ),
    STEP_UNDERFLOW: "The step size fell below the resolution of the time variable.",
    BUDGET_EXCEEDED: "The run used up its budget (max_wall_time or max_steps).",
    WINDOWS_FULL: (
        f"The record windows filled the {MAX_WINDOW_POINTS:,} points (~220 MB) a run keeps of them: the steps "
        "inside them are tiny. Shorten record_windows, or leave it empty, to run on."
    ),
}

# Wall time (s) a compiled call aims at before it hands control back to Python. The steps it may take
# adapt to this: a step costs ~0.5 µs in flight, but up to ~0.4 ms where the contact search is hard
# (ω ~ 1e5 rad/s), so no fixed count keeps Ctrl-C prompt. After its first call a default run's 10-s
# chunks (~10⁴ steps, ~5 ms) end long before the adapted count, so it makes no further calls.
CALL_SECONDS = 0.1
FIRST_STEPS_PER_CALL = 1_000
MAX_STEPS_PER_CALL = 10_000_000

# Columns of the impact records.
IMPACT_COLUMNS = (
    "time",
    "wall",
    "impact_speed",
    "rebound_speed",
    "dissipated_energy",
    "heat_generated",
    "max_overlap",
    "peak_force",
    "duration",
)
_IMPACT_WIDTH = len(IMPACT_COLUMNS)
# Layout of the impact in progress, carried between chunks.
_ACTIVE, _WALL, _START, _SPEED_IN, _DISSIPATED0, _HEAT0, _MAX_OVERLAP, _PEAK_FORCE, _ENERGY0, _WORK0 = range(10)
# Counters.
STEPS, REJECTED, RHS_EVALUATIONS, IMPACTS, SAMPLES_WRITTEN, WINDOW_POINTS = range(6)
COUNTER_NAMES = ("steps", "rejected_steps", "rhs_evaluations", "impacts")
# Diagnostics of the energy projection: total |ΔKE| applied (J) and steps left unprojected.
_CORRECTION, _UNPROJECTED = range(2)

_INITIAL_CAPACITY = 1024
# Pending intervals of the contact-onset search: one per halving of a step, and a step halves at most
# ~60 times before reaching the resolution of the time variable.
_STACK_ROWS = 128
# Safeguarded Newton converges in a handful of iterations; bisection alone would need ~60.
_ROOT_ITERATIONS = 100
# First step of a contact as a fraction of the Hertz duration at the approach speed. The damping
# force grows like ζ^{1/4} from the onset, so the error estimate of a step that starts there is
# unreliable; a short first step followed by the controller's geometric growth grades the mesh
# towards the singular point and keeps its error small (~0.1 % of the impact's dissipated energy at
# rtol 1e-3; at tighter tolerances the controller shortens it).
ONSET_STEP_FRACTION = 1e-2
# The damping force falls like ζ^{1/4} into the separation too. A step that straddles it samples a zero
# force in its last stages while the dissipation is still large, and the embedded estimate (its weights
# nearly cancel on equal stages) does not see it: one such step took up to ~0.8 % off an impact's
# dissipated energy. So a contact step is kept below this fraction of the time the overlap needs to close
# at its current rate, which grades the mesh towards the separation as the onset step does from the
# onset, down to the same ONSET_STEP_FRACTION of the contact.
SEPARATION_GRADING = 0.9
# Share of rtol given to each step of a contact. Its ~16 steps add local errors of one sign: against the
# full scale an impact's dissipated energy comes out 0.3–1 % low at rtol 1e-3 (the energy projection passes
# that on to the rebound, and the motion shifts with it); at a quarter it is 0.2–0.4 % low, and the default
# heat power stays within 1 % of converged over the operating range (benchmarks/bench_converged_defaults.py).
CONTACT_TOLERANCE_SHARE = 0.25
# Approach speed (m/s) below which a contact's scales stop shrinking: guards a tangential onset against 0.
_SLOWEST_APPROACH = 1e-12
# Components under error control. In a contact also the dissipated energy: it is the heat and, through
# the energy projection, sets the rebound. The vial's work needs no control of its own: it is the force
# times the smooth wall velocity, integrated with the same weights as the momentum.
_FLIGHT_CONTROLLED = np.arange(N_DYNAMIC)
_CONTACT_CONTROLLED = np.append(np.arange(N_DYNAMIC), DISSIPATED)
# Relative resolution of the time variable used to stop bisection of a contact onset.
_TIME_RESOLUTION = 4.0 * np.finfo(float).eps


@dataclass(frozen=True)
class ButcherTableau:
    """An explicit, first-same-as-last embedded Runge–Kutta pair.

    ``b`` gives the propagated solution (order ``order``), ``b_hat`` the
    embedded one (order ``error_order``); their difference estimates the error.
    The order conditions up to ``order`` are checked at construction.
    """

    name: str
    order: int
    error_order: int
    a: tuple[tuple[Fraction, ...], ...]
    b: tuple[Fraction, ...]
    b_hat: tuple[Fraction, ...]
    c: tuple[Fraction, ...]

    def __post_init__(self) -> None:
        stages = len(self.c)
        if len(self.a) != stages or any(len(row) != stages for row in self.a):
            raise ValueError(f"{self.name}: a must be {stages}x{stages}")
        for i, row in enumerate(self.a):
            if any(row[j] != 0 for j in range(i, stages)):
                raise ValueError(f"{self.name}: a must be strictly lower triangular for an explicit method")
            if sum(row) != self.c[i]:
                raise ValueError(f"{self.name}: row {i} of a does not sum to c[{i}]")
        if tuple(self.a[-1]) != tuple(self.b) or self.c[-1] != 1:
            raise ValueError(f"{self.name}: not first-same-as-last (last row of a must equal b, c[-1] = 1)")
        self._check_order(self.b, self.order, "b")
        self._check_order(self.b_hat, self.error_order, "b_hat")

    def _check_order(self, weights: tuple[Fraction, ...], order: int, label: str) -> None:
        a, c = self.a, self.c
        ac = [sum(a[i][j] * c[j] for j in range(len(c))) for i in range(len(c))]
        conditions = {
            1: [(sum(weights), Fraction(1))],
            2: [(sum(w * ci for w, ci in zip(weights, c)), Fraction(1, 2))],
            3: [
                (sum(w * ci * ci for w, ci in zip(weights, c)), Fraction(1, 3)),
                (sum(w * aci for w, aci in zip(weights, ac)), Fraction(1, 6)),
            ],
        }
        if order > max(conditions):
            raise ValueError(f"{self.name}: order conditions above {max(conditions)} are not implemented")
        for level in range(1, order + 1):
            for value, expected in conditions[level]:
                if value != expected:
                    raise ValueError(f"{self.name}: {label} violates an order-{level} condition")

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(a, b, error weights b − b_hat, c) as float arrays for the compiled loop."""
        a = np.array([[float(v) for v in row] for row in self.a])
        b = np.array([float(v) for v in self.b])
        error = np.array([float(bi - bh) for bi, bh in zip(self.b, self.b_hat)])
        c = np.array([float(v) for v in self.c])
        return a, b, error, c


_F = Fraction
BOGACKI_SHAMPINE = ButcherTableau(
    name="Bogacki-Shampine 3(2)",
    order=3,
    error_order=2,
    a=(
        (_F(0), _F(0), _F(0), _F(0)),
        (_F(1, 2), _F(0), _F(0), _F(0)),
        (_F(0), _F(3, 4), _F(0), _F(0)),
        (_F(2, 9), _F(1, 3), _F(4, 9), _F(0)),
    ),
    b=(_F(2, 9), _F(1, 3), _F(4, 9), _F(0)),
    b_hat=(_F(7, 24), _F(1, 4), _F(1, 3), _F(1, 8)),
    c=(_F(0), _F(1, 2), _F(3, 4), _F(1)),
)


@dataclass(frozen=True)
class StepController:
    """Elementary error-per-step controller with SciPy's RK23 constants."""

    safety: float = 0.9
    min_factor: float = 0.2
    max_factor: float = 10.0


@dataclass
class Tolerances:
    """Error control of the dynamic components: |error| ≤ atol + rtol·|y − origin|.

    Inside a contact the mechanics use the impact's own scales instead (:func:`_contact_error_scale`).
    ``origin`` lets the relative tolerance act on a temperature rise rather than on
    an absolute temperature in kelvin, as ode23 did on the paper's internal energies.
    """

    rtol: float
    atol: np.ndarray  # one per dynamic component
    origin: np.ndarray  # one per dynamic component
    contact_step_limit: float  # s
    max_overlap: float  # m


@njit(cache=True)
def _grow(buffer: np.ndarray) -> np.ndarray:
    larger = np.empty((2 * buffer.shape[0], buffer.shape[1]))
    larger[: buffer.shape[0]] = buffer
    return larger


@njit(cache=True)
def _gap_rate(t: float, velocity: float, wall: int, k: Constants) -> float:
    """d(gap)/dt in free flight (m/s)."""
    vial_velocity = kinematics.vial_velocity(t, k.amplitude, k.omega, k.phase)
    return velocity - vial_velocity if wall == LEFT_WALL else vial_velocity - velocity


@njit(cache=True)
def _refine_root(t: float, x: float, velocity: float, wall: int, k: Constants,
                 a: float, b: float, resolution: float) -> float:
    """The single zero of a monotone gap on [a, b] (gap(a) > 0 ≥ gap(b)), by safeguarded Newton.

    Returns the lower end of the final bracket: the landing point is a hair before the onset
    (gap > 0), so the step that lands feels no contact force. A force in its last stage would
    enter the error estimate through the embedded weights and get the step rejected.
    """
    s = b
    for _ in range(_ROOT_ITERATIONS):
        if b - a <= resolution:
            break
        gap_s = gap(t + s, x + velocity * s, wall, k)
        if gap_s > 0.0:
            a = s
        else:
            b = s
        rate = _gap_rate(t + s, velocity, wall, k)
        newton = s - gap_s / rate if rate != 0.0 else a
        # Step a little past the Newton point so the bracket closes from both sides.
        newton += resolution if gap_s > 0.0 else -resolution
        s = newton if a < newton < b else 0.5 * (a + b)
    return a


@njit(cache=True)
def _first_touch_of_wall(t: float, h: float, x: float, velocity: float, wall: int, curvature: float,
                         k: Constants, stack: np.ndarray) -> float:
    """Earliest s in [0, h] where the free-flight gap to ``wall`` reaches 0, or −1 if none.

    Intervals are examined left to right. One is discarded only when the bound
    gap(s) ≥ min(gap(a), gap(b)) − curvature·(b − a)²/8 proves it free of zeros;
    a sign change is refined once the slope bound |gap'(b)| > curvature·(b − a)
    proves the gap monotone there, so the zero found is the first one.
    ``stack`` is scratch space of at least 2 × 64 rows: each halving leaves one pending interval.
    """
    resolution = _TIME_RESOLUTION * max(1.0, abs(t) + h)
    stack[0, 0] = 0.0
    stack[0, 1] = h
    stack[0, 2] = gap(t, x, wall, k)
    stack[0, 3] = gap(t + h, x + velocity * h, wall, k)
    if stack[0, 2] < 0.0:
        return 0.0
    top = 1
    while top > 0:
        top -= 1
        a, b, gap_a, gap_b = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        width = b - a
        if min(gap_a, gap_b) - curvature * width * width / 8.0 > 0.0:
            continue
        if gap_b <= 0.0 and (width <= resolution or abs(_gap_rate(t + b, velocity, wall, k)) > curvature * width):
            return _refine_root(t, x, velocity, wall, k, a, b, resolution)
        if width <= resolution:
            continue
        middle = 0.5 * (a + b)
        gap_middle = gap(t + middle, x + velocity * middle, wall, k)
        # right half below the left half, so the left half is examined first
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = middle, b, gap_middle, gap_b
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2], stack[top + 1, 3] = a, middle, gap_a, gap_middle
        top += 2
    return -1.0


@njit(cache=True)
def _hermite(theta: float, h: float, y0: np.ndarray, f0: np.ndarray, y1: np.ndarray, f1: np.ndarray, out: np.ndarray) -> None:
    """Cubic Hermite interpolant of a step at fraction ``theta`` (the dense output of ode23)."""
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = t3 - 2.0 * t2 + theta
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = t3 - t2
    for i in range(y0.shape[0]):
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i]


@njit(cache=True)
def _rk_step(t: float, h: float, y: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray, k: Constants,
             stages: np.ndarray, y_new: np.ndarray, work: np.ndarray) -> None:
    """One explicit FSAL step: ``stages[0]`` holds f(t, y) on entry, the last stage holds f(t+h, y_new) on exit."""
    n_stages = c.shape[0]
    n = y.shape[0]
    for s in range(1, n_stages - 1):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += a[s, j] * stages[j, i]
            work[i] = y[i] + h * acc
        rhs(t + c[s] * h, work, k, stages[s])
    for i in range(n):
        acc = 0.0
        for j in range(n_stages - 1):
            acc += b[j] * stages[j, i]
        y_new[i] = y[i] + h * acc
    rhs(t + h, y_new, k, stages[n_stages - 1])


@njit(cache=True)
def _lab_error_scale(y: np.ndarray, y_new: np.ndarray, rtol: float, atol: np.ndarray, origin: np.ndarray,
                     scale: np.ndarray) -> None:
    """SciPy's scale of the dynamic components, atol + rtol·max(|y − origin|, |y_new − origin|)."""
    for i in range(atol.shape[0]):
        scale[i] = atol[i] + rtol * max(abs(y[i] - origin[i]), abs(y_new[i] - origin[i]))


@njit(cache=True)
def _contact_error_scale(speed_in: float, rtol: float, k: Constants, scale: np.ndarray) -> None:
    """Measure the mechanics of a contact against the impact's own scales.

    The lab-frame scale allows a position error of rtol·|x|, with |x| up to ~25 mm, against an overlap
    of ~40 µm, and a momentum error of rtol·|p| with a lab momentum unrelated to the impact: the contact
    was barely error-controlled, and at rtol 1e-3 a run could land on a different motion. Here the
    overlap (x enters only through it) is measured against the Hertz maximum overlap at the approach
    speed, the momentum against m·v_in and the dissipated energy against m·v_in²/2. There is no
    absolute term, so the contact converges as rtol → 0.
    """
    speed = max(speed_in, _SLOWEST_APPROACH)
    share = CONTACT_TOLERANCE_SHARE * rtol
    scale[X] = share * hertz_max_overlap(k.ball_mass, k.radius, k.e_star, speed)
    scale[P] = share * k.ball_mass * speed
    scale[DISSIPATED] = share * 0.5 * k.ball_mass * speed * speed


@njit(cache=True)
def _error_norm(h: float, stages: np.ndarray, error_weights: np.ndarray, scale: np.ndarray,
                components: np.ndarray) -> float:
    """RMS of the error estimate over ``components``, in units of ``scale``."""
    total = 0.0
    for i in components:
        estimate = 0.0
        for j in range(error_weights.shape[0]):
            estimate += error_weights[j] * stages[j, i]
        ratio = h * estimate / scale[i]
        total += ratio * ratio
    return np.sqrt(total / components.shape[0])


@njit(cache=True)
def _append_window_point(buffer: np.ndarray, counters: np.ndarray, time: float, state: np.ndarray) -> np.ndarray:
    row = counters[WINDOW_POINTS]
    if row >= buffer.shape[0]:
        buffer = _grow(buffer)
    buffer[row, 0] = time
    buffer[row, 1:] = state
    counters[WINDOW_POINTS] = row + 1
    return buffer


@njit(cache=True)
def _project_momentum(impact: np.ndarray, y_new: np.ndarray, elastic_new: float, k: Constants,
                      diagnostics: np.ndarray) -> None:
    """Project |p| onto the mechanical energy balance of the contact so far.

    E_mech(now) = E_mech(onset) + W_vial − E_diss over the contact, with W_vial
    and E_diss the quadratures integrated with the same stages (the standard
    projection method, Hairer, Lubich & Wanner, Geometric Numerical Integration,
    §IV.4). It is applied when the ball leaves the wall (and at the end of a
    chunk inside a contact), keeps the order of the method and leaves the
    dissipated energy, which makes the heat, untouched. Every correction is
    accumulated in ``diagnostics`` so the truncation error stays visible.
    """
    target = (
        impact[_ENERGY0]
        + (y_new[WORK_VIAL] - impact[_WORK0])
        - (y_new[DISSIPATED] - impact[_DISSIPATED0])
    )
    kinetic_now = 0.5 * y_new[P] * y_new[P] / k.ball_mass
    kinetic_target = target - elastic_new
    if kinetic_target > 0.0 and y_new[P] != 0.0:
        y_new[P] = np.sign(y_new[P]) * np.sqrt(2.0 * k.ball_mass * kinetic_target)
        diagnostics[_CORRECTION] += abs(kinetic_target - kinetic_now)
    else:
        # At a turning point the balance may ask for negative kinetic energy; leave that state alone.
        diagnostics[_UNPROJECTED] += 1.0


@njit(cache=True)
def _rate_into_wall(wall: int, velocity: float, vial_velocity: float) -> float:
    """ζ̇ for ``wall``: positive while the ball and the wall approach (MODEL.md §2)."""
    return vial_velocity - velocity if wall == LEFT_WALL else velocity - vial_velocity


@njit(cache=True)
def _shortest_contact_step(speed_in: float, k: Constants) -> float:
    """First and last steps of a contact (s): ONSET_STEP_FRACTION of the Hertz duration at the approach speed."""
    return ONSET_STEP_FRACTION * hertz_contact_time(k.ball_mass, k.radius, k.e_star, max(speed_in, _SLOWEST_APPROACH))


@njit(cache=True)
def _separation_step_limit(t: float, y: np.ndarray, impact: np.ndarray, k: Constants) -> float:
    """Longest contact step that keeps the mesh graded towards the separation (see SEPARATION_GRADING)."""
    wall = int(impact[_WALL])
    vial_velocity = kinematics.vial_velocity(t, k.amplitude, k.omega, k.phase)
    overlap_rate = _rate_into_wall(wall, y[P] / k.ball_mass, vial_velocity)
    if overlap_rate >= 0.0:
        return np.inf
    overlap = -gap(t, y[X], wall, k)
    return max(SEPARATION_GRADING * overlap / -overlap_rate, _shortest_contact_step(impact[_SPEED_IN], k))


@njit(cache=True)
def _advance(
    t_stop, clock, y, f0, a, b, error_weights, c, k, rtol, atol, origin, contact_step_limit, max_overlap,
    safety, min_factor, max_factor, error_exponent,
    sample_times, samples, windows, window_buffer, impact_buffer, impact, counters,
    project_energy, diagnostics, steps_allowed,
):
    """Integrate from ``clock[0]`` to ``t_stop``, or for ``steps_allowed`` accepted steps (status _PAUSED)
    if that comes first; see :meth:`Integrator.advance`. Returns (status, buffers)."""
    n = y.shape[0]
    stages = np.empty((c.shape[0], n))
    y_new = np.empty(n)
    work = np.empty(n)
    point = np.empty(n)
    scale = np.empty(n)
    stack = np.empty((_STACK_ROWS, 4))
    curvature = k.amplitude * k.omega * k.omega
    drive_period = 2.0 * np.pi / k.omega
    t = clock[0]
    h = clock[1]
    last_step = counters[STEPS] + steps_allowed
    rejected_last = False
    while t < t_stop:
        in_contact = impact[_ACTIVE] != 0.0
        h = min(h, t_stop - t)
        landed_wall = NO_WALL
        if in_contact:
            h = min(h, contact_step_limit, _separation_step_limit(t, y, impact, k))
        else:
            # Shorten a flight step to the first contact onset: the flight path is exact, so this
            # costs no right-hand-side evaluations and no trial step ever runs into a wall.
            velocity = y[P] / k.ball_mass
            for wall in (LEFT_WALL, RIGHT_WALL):
                touch = _first_touch_of_wall(t, h, y[X], velocity, wall, curvature, k, stack)
                if touch >= 0.0 and (landed_wall == NO_WALL or touch < h):
                    h, landed_wall = touch, wall
        if landed_wall == NO_WALL and h <= _TIME_RESOLUTION * max(1.0, abs(t)):
            clock[0], clock[1] = t, h
            return STEP_UNDERFLOW, window_buffer, impact_buffer
        stages[0] = f0
        if h > 0.0:
            _rk_step(t, h, y, a, b, c, k, stages, y_new, work)
            counters[RHS_EVALUATIONS] += c.shape[0] - 1
            _lab_error_scale(y, y_new, rtol, atol, origin, scale)
            if in_contact:
                _contact_error_scale(impact[_SPEED_IN], rtol, k, scale)
            components = _CONTACT_CONTROLLED if in_contact else _FLIGHT_CONTROLLED
            error = _error_norm(h, stages, error_weights, scale, components)
        else:
            y_new[:] = y
            stages[c.shape[0] - 1] = f0
            error = 0.0
        if not error <= 1.0:  # also rejects NaN
            counters[REJECTED] += 1
            factor = min_factor if not np.isfinite(error) else max(min_factor, safety * error**error_exponent)
            h *= factor
            rejected_last = True
            continue
        factor = max_factor if error == 0.0 else min(max_factor, safety * error**error_exponent)
        if rejected_last:
            factor = min(1.0, factor)
        rejected_last = False

        t_new = t + h
        touching = in_contact or landed_wall != NO_WALL
        elastic_new = 0.0
        if touching:
            wall = int(impact[_WALL]) if in_contact else landed_wall
            overlap = -gap(t_new, y_new[X], wall, k)
            vial_velocity = kinematics.vial_velocity(t_new, k.amplitude, k.omega, k.phase)
            if overlap > 0.0:
                elastic_new = elastic_energy(overlap, k.e_star, k.radius)
            if in_contact and project_energy and (overlap <= 0.0 or t_new >= t_stop):
                _project_momentum(impact, y_new, elastic_new, k, diagnostics)
                rhs(t_new, y_new, k, stages[c.shape[0] - 1])
                counters[RHS_EVALUATIONS] += 1
        for i in range(n):
            if not np.isfinite(y_new[i]):
                clock[0], clock[1] = t, h
                return NOT_FINITE, window_buffer, impact_buffer
        f_new = stages[c.shape[0] - 1]

        # Samples on the regular output grid, by dense output.
        index = counters[SAMPLES_WRITTEN]
        while index < sample_times.shape[0] and sample_times[index] <= t_new:
            if h > 0.0:
                _hermite((sample_times[index] - t) / h, h, y, f0, y_new, f_new, point)
                samples[index] = point
            else:
                samples[index] = y_new
            index += 1
        counters[SAMPLES_WRITTEN] = index

        # Full-resolution windows: every step point inside, and the edges by dense output, so that a
        # window spans exactly the interval asked for even when flight steps are long.
        for w in range(windows.shape[0]):
            start, end = windows[w, 0], windows[w, 1]
            if h > 0.0 and t < start < t_new:
                _hermite((start - t) / h, h, y, f0, y_new, f_new, point)
                window_buffer = _append_window_point(window_buffer, counters, start, point)
            if start <= t_new <= end:
                window_buffer = _append_window_point(window_buffer, counters, t_new, y_new)
            elif h > 0.0 and t < end < t_new:
                _hermite((end - t) / h, h, y, f0, y_new, f_new, point)
                window_buffer = _append_window_point(window_buffer, counters, end, point)

        # Impact bookkeeping.
        if touching:
            velocity_new = y_new[P] / k.ball_mass
            overlap_rate = _rate_into_wall(wall, velocity_new, vial_velocity)
            if landed_wall != NO_WALL:
                impact[_ACTIVE] = 1.0
                impact[_WALL] = landed_wall
                impact[_START] = t_new
                impact[_SPEED_IN] = overlap_rate
                impact[_DISSIPATED0] = y_new[DISSIPATED]
                impact[_HEAT0] = y_new[HEAT_GENERATED]
                impact[_MAX_OVERLAP] = 0.0
                impact[_PEAK_FORCE] = 0.0
                impact[_ENERGY0] = 0.5 * y_new[P] * y_new[P] / k.ball_mass + elastic_new
                impact[_WORK0] = y_new[WORK_VIAL]
            elif overlap > 0.0:  # still touching; overlap <= 0 below means it left the wall
                force, _ = contact_forces(overlap, overlap_rate, k)
                impact[_MAX_OVERLAP] = max(impact[_MAX_OVERLAP], overlap)
                impact[_PEAK_FORCE] = max(impact[_PEAK_FORCE], force)
                if overlap > max_overlap:
                    t, clock[0], clock[1] = t_new, t_new, h
                    y[:] = y_new
                    f0[:] = f_new
                    return OVERLAP_TOO_LARGE, window_buffer, impact_buffer
            else:
                # Left the wall during this step: back-extrapolate the separation on the free flight.
                separation = max(t_new - (-overlap) / max(-overlap_rate, 1e-300), impact[_START])
                vial_at_separation = kinematics.vial_velocity(separation, k.amplitude, k.omega, k.phase)
                row = counters[IMPACTS]
                if row >= impact_buffer.shape[0]:
                    impact_buffer = _grow(impact_buffer)
                impact_buffer[row, 0] = impact[_START]
                impact_buffer[row, 1] = wall
                impact_buffer[row, 2] = impact[_SPEED_IN]
                impact_buffer[row, 3] = -_rate_into_wall(wall, velocity_new, vial_at_separation)
                impact_buffer[row, 4] = y_new[DISSIPATED] - impact[_DISSIPATED0]
                impact_buffer[row, 5] = y_new[HEAT_GENERATED] - impact[_HEAT0]
                impact_buffer[row, 6] = impact[_MAX_OVERLAP]
                impact_buffer[row, 7] = impact[_PEAK_FORCE]
                impact_buffer[row, 8] = separation - impact[_START]
                counters[IMPACTS] = row + 1
                impact[_ACTIVE] = 0.0

        t = t_new
        y[:] = y_new
        f0[:] = f_new
        counters[STEPS] += 1
        if landed_wall == NO_WALL:
            h = h * factor
            if in_contact and impact[_ACTIVE] == 0.0:
                # Just left the wall. Flight is exact for the mechanics and smooth for the temperatures,
                # so offer a whole drive period: the onset search cuts it at the next contact.
                h = max(h, drive_period)
        else:
            h = min(contact_step_limit, _shortest_contact_step(impact[_SPEED_IN], k))
        if counters[STEPS] == last_step:
            # After an accepted step: t, h and the state in the arrays are all the next call needs, and
            # rejected_last is False as on entry, so a pause leaves the integration bit for bit unchanged.
            break
    clock[0], clock[1] = t, h
    return (REACHED_STOP if t >= t_stop else _PAUSED), window_buffer, impact_buffer


@dataclass
class Integrator:
    """Chunked driver of the compiled loop; holds the state between chunks."""

    constants: Constants
    y: np.ndarray
    t0: float
    tolerances: Tolerances
    sample_times: np.ndarray
    windows: np.ndarray
    tableau: ButcherTableau = BOGACKI_SHAMPINE
    controller: StepController = field(default_factory=StepController)
    initial_step: float = 1e-5
    project_energy: bool = True
    budget: RunBudget = field(default_factory=RunBudget.unlimited)

    def __post_init__(self) -> None:
        self._a, self._b, self._error_weights, self._c = self.tableau.arrays()
        self.clock = np.array([self.t0, self.initial_step])
        self.y = np.array(self.y, dtype=float)
        self.f = np.empty(N_STATE)
        rhs(self.t0, self.y, self.constants, self.f)
        self.samples = np.full((self.sample_times.shape[0], N_STATE), np.nan)
        self._window_buffer = np.empty((_INITIAL_CAPACITY, N_STATE + 1))
        self._impact_buffer = np.empty((_INITIAL_CAPACITY, _IMPACT_WIDTH))
        self._impact = np.zeros(10)
        self.counters = np.zeros(6, dtype=np.int64)
        self.counters[RHS_EVALUATIONS] = 1
        self.diagnostics = np.zeros(2)
        self._steps_per_call = FIRST_STEPS_PER_CALL

    @property
    def energy_correction(self) -> float:
        """Total |ΔKE| applied by the energy projection so far (J)."""
        return float(self.diagnostics[_CORRECTION])

    @property
    def unprojected_steps(self) -> int:
        return int(self.diagnostics[_UNPROJECTED])

    @property
    def t(self) -> float:
        return float(self.clock[0])

    def advance(self, t_stop: float, heartbeat: Callable[[float], None] | None = None) -> int:
        """Integrate up to ``t_stop``; returns a status code (see ``STATUS_MESSAGES``).

        The compiled loop runs in calls of about CALL_SECONDS each. Before every call the budget and
        the record windows' size are checked: a spent budget ends the integration with BUDGET_EXCEEDED
        (:meth:`explain` says which limit), full windows with WINDOWS_FULL.
        After a call that stopped short of ``t_stop``, ``heartbeat(t)`` is called. Ctrl-C during a call
        raises ``KeyboardInterrupt`` once it has returned.
        """
        while (limit := self._limit_reached()) is None:
            steps_before = int(self.counters[STEPS])
            started = time.perf_counter()
            status = self._compiled_call(t_stop, min(self._steps_per_call, self.budget.steps_left))
            steps = int(self.counters[STEPS]) - steps_before
            self.budget.steps += steps
            if status != _PAUSED:
                return status
            self._steps_per_call = _steps_for_call_seconds(steps, time.perf_counter() - started)
            if heartbeat is not None:
                heartbeat(self.t)
        return limit

    def _limit_reached(self) -> int | None:
        """BUDGET_EXCEEDED or WINDOWS_FULL when the integration may not go on, else None."""
        if self.budget.spent():
            return BUDGET_EXCEEDED
        return WINDOWS_FULL if self.counters[WINDOW_POINTS] >= MAX_WINDOW_POINTS else None

    def explain(self, status: int) -> str:
        """The message of ``status``; for BUDGET_EXCEEDED, which limit was reached and how to raise it."""
        return str(self.budget.reason) if status == BUDGET_EXCEEDED else STATUS_MESSAGES[status]

    def _compiled_call(self, t_stop: float, steps_allowed: int) -> int:
        with _interrupt_after_compiled_code():
            status, self._window_buffer, self._impact_buffer = _advance(
                t_stop, self.clock, self.y, self.f, self._a, self._b, self._error_weights, self._c, self.constants,
                self.tolerances.rtol, self.tolerances.atol, self.tolerances.origin, self.tolerances.contact_step_limit,
                self.tolerances.max_overlap, self.controller.safety, self.controller.min_factor,
                self.controller.max_factor, -1.0 / (self.tableau.error_order + 1),
                self.sample_times, self.samples, self.windows, self._window_buffer, self._impact_buffer,
                self._impact, self.counters, self.project_energy, self.diagnostics, steps_allowed,
            )
        return int(status)

    @property
    def samples_written(self) -> int:
        return int(self.counters[SAMPLES_WRITTEN])

    @property
    def window_points(self) -> np.ndarray:
        """(time, state...) rows of all windows in time order (overlapping windows are merged)."""
        points = self._window_buffer[: self.counters[WINDOW_POINTS]]
        return points[np.argsort(points[:, 0], kind="stable")]

    @property
    def impacts(self) -> np.ndarray:
        return self._impact_buffer[: self.counters[IMPACTS]].copy()


def _steps_for_call_seconds(steps: int, seconds: float) -> int:
    """The steps that take about CALL_SECONDS at the rate of the last call (``steps`` in ``seconds``)."""
    rate = steps / max(seconds, 1e-9)
    return int(min(max(rate * CALL_SECONDS, 1.0), MAX_STEPS_PER_CALL))


@contextmanager
def _interrupt_after_compiled_code() -> Iterator[None]:
    """Hold a SIGINT that arrives while compiled code runs and deliver it to the previous handler afterwards.

    A KeyboardInterrupt raised inside a Numba call surfaces as ``SystemError: CPUDispatcher(...) returned a
    result with an exception set``, which no caller can tell from a crash. Only the main thread can set
    handlers; elsewhere, and where SIGINT is ignored (sweep workers) or default, nothing changes.
    """
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or not callable(previous):
        yield
        return
    received: list[object] = []
    signal.signal(signal.SIGINT, lambda signum, frame: received.append(frame))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if received:
        previous(signal.SIGINT, received[0])
