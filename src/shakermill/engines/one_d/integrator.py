"""Compiled adaptive Runge–Kutta integration of the full-resolution 1-D model (MODEL.md section 7).

The method is an explicit FSAL Runge–Kutta pair given as data (``tableau``, Bogacki–Shampine 3(2) by default).
Step-size control follows SciPy's RK23: RMS error norm over the dynamic state, scale
``atol + rtol·max(|y_n|, |y_n+1|)``; inside a contact the mechanics are measured against the impact's own scales
instead (:func:`_contact_error_scale`). Contacts are events of the mechanics (``contacts``): a free-flight step
lands on the contact onset, never steps over it, and inside a contact the step is at most
``contact_step_limit`` (0.9 t_R by default); the overlap, the momentum and the dissipated energy are controlled
relative to the Hertz maximum overlap, m·v_in and m·v_in²/2 at a share of rtol (``CONTACT_TOLERANCE_SHARE``).
One record per impact is written when the ball leaves the wall.

Everything runs in chunks (:meth:`Integrator.advance`), so a caller can show progress and keep what was
computed when interrupted; within a chunk the compiled loop hands control back about every tenth of a second
of wall time (``engines.calls``), so that tiny steps cannot hold off Ctrl-C, the run's budget or progress.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, NamedTuple

import numpy as np
from numba import njit

from shakermill.engines.budget import RunBudget
from shakermill.engines.calls import PAUSED, CompiledRun
from shakermill.engines.one_d.contacts import (
    SLOWEST_APPROACH,
    STACK_ROWS,
    TIME_RESOLUTION,
    bound_step,
    rate_into_wall,
    shortest_contact_step,
)
from shakermill.engines.one_d.description import MAX_WINDOW_POINTS, STATUS_MESSAGES, STEP_UNDERFLOW, WINDOWS_FULL
from shakermill.engines.one_d.model import (
    DISSIPATED,
    HEAT_GENERATED,
    N_DYNAMIC,
    N_STATE,
    NO_WALL,
    WORK_VIAL,
    Constants,
    P,
    X,
    contact_forces,
    gap,
    rhs,
)
from shakermill.engines.one_d.tableau import BOGACKI_SHAMPINE, ButcherTableau, StepController
from shakermill.engines.status import BUDGET_EXCEEDED, NOT_FINITE, OVERLAP_TOO_LARGE, REACHED_STOP
from shakermill.physics import kinematics
from shakermill.physics.contact import elastic_energy, hertz_max_overlap

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
# Share of rtol given to each step of a contact. Its ~16 steps add local errors of one sign: against the
# full scale an impact's dissipated energy comes out 0.3–1 % low at rtol 1e-3 (the energy projection passes
# that on to the rebound, and the motion shifts with it); at a quarter it is 0.2–0.4 % low, and the default
# heat power stays within 1 % of converged over the operating range (benchmarks/bench_converged_defaults.py).
CONTACT_TOLERANCE_SHARE = 0.25
# Components under error control. In a contact also the dissipated energy: it is the heat and, through
# the energy projection, sets the rebound. The vial's work needs no control of its own: it is the force
# times the smooth wall velocity, integrated with the same weights as the momentum.
_FLIGHT_CONTROLLED = np.arange(N_DYNAMIC)
_CONTACT_CONTROLLED = np.append(np.arange(N_DYNAMIC), DISSIPATED)


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


# What a compiled call of the loop (:func:`_advance`) reads and writes, grouped as it travels from
# :class:`Integrator`. Numba passes a NamedTuple as one argument, as it does ``Constants``; _advance
# unpacks the arrays once per call (see there why).


class _StepControl(NamedTuple):
    """The step-size controller (:class:`StepController`) with the exponent of the method's error order."""

    safety: float
    min_factor: float
    max_factor: float
    error_exponent: float  # −1/(error order + 1)


class _Accuracy(NamedTuple):
    """What each step is held to (see :class:`Tolerances`), and whether contacts end with the energy projection."""

    rtol: float
    atol: np.ndarray
    origin: np.ndarray
    contact_step_limit: float
    max_overlap: float
    project_energy: bool


class _State(NamedTuple):
    """The integration state the compiled loop changes in place and the next call starts from."""

    clock: np.ndarray  # (t, the step to try next)
    y: np.ndarray
    f: np.ndarray  # f(t, y): the first stage of the next step (first same as last)
    impact: np.ndarray  # the impact in progress, laid out as _ACTIVE, _WALL, ...
    counters: np.ndarray  # STEPS, REJECTED, ...
    diagnostics: np.ndarray  # of the energy projection: _CORRECTION, _UNPROJECTED


class _Recording(NamedTuple):
    """The regular output grid with the samples written on it, and the record windows as (start, end) rows."""

    sample_times: np.ndarray
    samples: np.ndarray
    windows: np.ndarray


@njit(cache=True)
def _grow(buffer: np.ndarray) -> np.ndarray:
    larger = np.empty((2 * buffer.shape[0], buffer.shape[1]))
    larger[: buffer.shape[0]] = buffer
    return larger


@njit(cache=True)
def _hermite(
    theta: float, h: float, y0: np.ndarray, f0: np.ndarray, y1: np.ndarray, f1: np.ndarray, out: np.ndarray
) -> None:
    """Cubic Hermite interpolant of a step at fraction ``theta`` (the dense output of ode23)."""
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = t3 - 2.0 * t2 + theta
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = t3 - t2
    for i in range(y0.shape[0]):
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i]


# Inlined into the loop: as a call it cost a reference count for each of its seven arrays on every trial
# step, ~1.5 % of a default run.
@njit(cache=True, inline="always")
def _rk_step(
    t: float,
    h: float,
    y: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    c: np.ndarray,
    k: Constants,
    stages: np.ndarray,
    y_new: np.ndarray,
    work: np.ndarray,
) -> None:
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
def _lab_error_scale(
    y: np.ndarray, y_new: np.ndarray, rtol: float, atol: np.ndarray, origin: np.ndarray, scale: np.ndarray
) -> None:
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
    speed = max(speed_in, SLOWEST_APPROACH)
    share = CONTACT_TOLERANCE_SHARE * rtol
    scale[X] = share * hertz_max_overlap(k.ball_mass, k.radius, k.e_star, speed)
    scale[P] = share * k.ball_mass * speed
    scale[DISSIPATED] = share * 0.5 * k.ball_mass * speed * speed


@njit(cache=True)
def _error_norm(h: float, stages: np.ndarray, error_weights: np.ndarray, scale: np.ndarray, in_contact: bool) -> float:
    """RMS of the error estimate over the components under control, in units of ``scale``."""
    components = _CONTACT_CONTROLLED if in_contact else _FLIGHT_CONTROLLED
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
def _project_momentum(
    impact: np.ndarray, y_new: np.ndarray, elastic_new: float, k: Constants, diagnostics: np.ndarray
) -> None:
    """Project |p| onto the mechanical energy balance of the contact so far.

    E_mech(now) = E_mech(onset) + W_vial − E_diss over the contact, with W_vial
    and E_diss the quadratures integrated with the same stages (the standard
    projection method, Hairer, Lubich & Wanner, Geometric Numerical Integration,
    §IV.4). It is applied when the ball leaves the wall (and at the end of a
    chunk inside a contact), keeps the order of the method and leaves the
    dissipated energy, which makes the heat, untouched. Every correction is
    accumulated in ``diagnostics`` so the truncation error stays visible.
    """
    target = impact[_ENERGY0] + (y_new[WORK_VIAL] - impact[_WORK0]) - (y_new[DISSIPATED] - impact[_DISSIPATED0])
    kinetic_now = 0.5 * y_new[P] * y_new[P] / k.ball_mass
    kinetic_target = target - elastic_new
    if kinetic_target > 0.0 and y_new[P] != 0.0:
        y_new[P] = np.sign(y_new[P]) * np.sqrt(2.0 * k.ball_mass * kinetic_target)
        diagnostics[_CORRECTION] += abs(kinetic_target - kinetic_now)
    else:
        # At a turning point the balance may ask for negative kinetic energy; leave that state alone.
        diagnostics[_UNPROJECTED] += 1.0


@njit(cache=True)
def _work_arrays(n_stages: int, n: int) -> tuple[np.ndarray, ...]:
    """Work arrays of one compiled call, allocated once per call rather than per step.

    The stages (the last, f(t + h, y_new), also as a row of its own), the end of the step being tried, the
    argument of a stage, a state by dense output, the error scale, and the pending intervals of the
    contact-onset search.
    """
    stages = np.empty((n_stages, n))
    return stages, stages[n_stages - 1], np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty((STACK_ROWS, 4))


@njit(cache=True)
def _step_factor(error: float, rejected_last: bool, control: _StepControl) -> float:
    """Factor on the step size after a trial step with error norm ``error``: below 1 when the step is
    rejected (error > 1 or NaN), up to max_factor when it is accepted."""
    if not error <= 1.0:
        if not np.isfinite(error):
            return control.min_factor
        return max(control.min_factor, control.safety * error**control.error_exponent)
    factor = control.max_factor
    if error != 0.0:
        factor = min(control.max_factor, control.safety * error**control.error_exponent)
    # A step accepted right after a rejection does not grow: the larger step it replaces just failed.
    return min(1.0, factor) if rejected_last else factor


@njit(cache=True)
def _project_energy(
    t_new: float,
    y_new: np.ndarray,
    f_new: np.ndarray,
    elastic_new: float,
    impact: np.ndarray,
    k: Constants,
    counters: np.ndarray,
    diagnostics: np.ndarray,
) -> None:
    """Apply :func:`_project_momentum` to the end of a contact step, and evaluate the derivative there again.

    Called where the ball left the wall during the step, and where a compiled call ends inside a contact,
    so that the energy audit of every chunk closes.
    """
    _project_momentum(impact, y_new, elastic_new, k, diagnostics)
    # The projected state is where the next step starts: its derivative is that step's first stage.
    rhs(t_new, y_new, k, f_new)
    counters[RHS_EVALUATIONS] += 1


@njit(cache=True)
def _all_finite(values: np.ndarray) -> bool:
    """True when no value is NaN or infinite."""
    for i in range(values.shape[0]):
        if not np.isfinite(values[i]):
            return False
    return True


@njit(cache=True)
def _sample_due(t_new: float, sample_times: np.ndarray, counters: np.ndarray) -> bool:
    """Whether a step ending at ``t_new`` reaches the next time of the regular output grid."""
    index = counters[SAMPLES_WRITTEN]
    return index < sample_times.shape[0] and sample_times[index] <= t_new


@njit(cache=True)
def _meets_a_window(t: float, t_new: float, windows: np.ndarray) -> bool:
    """Whether the step from ``t`` to ``t_new`` meets a record window (edges included)."""
    # Windows run forwards (start < end), so every step that _record_windows writes a point for passes.
    for w in range(windows.shape[0]):
        if windows[w, 0] <= t_new and t <= windows[w, 1]:
            return True
    return False


@njit(cache=True)
def _record_samples(
    t: float,
    h: float,
    y: np.ndarray,
    f0: np.ndarray,
    y_new: np.ndarray,
    f_new: np.ndarray,
    sample_times: np.ndarray,
    samples: np.ndarray,
    counters: np.ndarray,
    point: np.ndarray,
) -> None:
    """Write the samples of the regular output grid that fall in the accepted step (t, t + h], by dense output."""
    t_new = t + h
    index = counters[SAMPLES_WRITTEN]
    while index < sample_times.shape[0] and sample_times[index] <= t_new:
        if h > 0.0:
            _hermite((sample_times[index] - t) / h, h, y, f0, y_new, f_new, point)
            samples[index] = point
        else:
            samples[index] = y_new
        index += 1
    counters[SAMPLES_WRITTEN] = index


@njit(cache=True)
def _record_windows(
    t: float,
    h: float,
    y: np.ndarray,
    f0: np.ndarray,
    y_new: np.ndarray,
    f_new: np.ndarray,
    windows: np.ndarray,
    buffer: np.ndarray,
    counters: np.ndarray,
    point: np.ndarray,
) -> np.ndarray:
    """Append the accepted step's points inside the record windows to ``buffer``; returns it (grown when full).

    Every step point inside a window is kept, and a window's edges by dense output, so that it spans
    exactly the interval asked for even when flight steps are long.
    """
    t_new = t + h
    for w in range(windows.shape[0]):
        start, end = windows[w, 0], windows[w, 1]
        if h > 0.0 and t < start < t_new:
            _hermite((start - t) / h, h, y, f0, y_new, f_new, point)
            buffer = _append_window_point(buffer, counters, start, point)
        if start <= t_new <= end:
            buffer = _append_window_point(buffer, counters, t_new, y_new)
        elif h > 0.0 and t < end < t_new:
            _hermite((end - t) / h, h, y, f0, y_new, f_new, point)
            buffer = _append_window_point(buffer, counters, end, point)
    return buffer


@njit(cache=True)
def _open_impact(
    t_new: float, y_new: np.ndarray, wall: int, speed_in: float, elastic_new: float, impact: np.ndarray, k: Constants
) -> None:
    """Start the impact in progress on ``wall`` at the contact onset ``t_new``, approached at ``speed_in``.

    The dissipated energy, heat, mechanical energy and vial work at the onset are kept so that the
    impact's record and the energy projection can take differences over the contact.
    """
    impact[_ACTIVE] = 1.0
    impact[_WALL] = wall
    impact[_START] = t_new
    impact[_SPEED_IN] = speed_in
    impact[_DISSIPATED0] = y_new[DISSIPATED]
    impact[_HEAT0] = y_new[HEAT_GENERATED]
    impact[_MAX_OVERLAP] = 0.0
    impact[_PEAK_FORCE] = 0.0
    impact[_ENERGY0] = 0.5 * y_new[P] * y_new[P] / k.ball_mass + elastic_new
    impact[_WORK0] = y_new[WORK_VIAL]


@njit(cache=True)
def _follow_contact(overlap: float, overlap_rate: float, max_overlap: float, impact: np.ndarray, k: Constants) -> bool:
    """Keep the largest overlap and contact force of the impact in progress; True when the overlap exceeds
    ``max_overlap``, which means the materials are too soft for the impact or the step control failed."""
    force, _ = contact_forces(overlap, overlap_rate, k)
    impact[_MAX_OVERLAP] = max(impact[_MAX_OVERLAP], overlap)
    impact[_PEAK_FORCE] = max(impact[_PEAK_FORCE], force)
    return overlap > max_overlap


@njit(cache=True)
def _close_impact(
    t_new: float,
    y_new: np.ndarray,
    overlap: float,
    overlap_rate: float,
    impact: np.ndarray,
    impact_buffer: np.ndarray,
    counters: np.ndarray,
    k: Constants,
) -> np.ndarray:
    """Write the record of the impact in progress, which ended during the step to ``t_new``, and end it.

    Returns the impact buffer (grown when full).
    """
    wall = int(impact[_WALL])
    # The separation lies inside the step: back-extrapolate it on the free flight.
    separation = max(t_new - (-overlap) / max(-overlap_rate, 1e-300), impact[_START])
    vial_at_separation = kinematics.vial_velocity(separation, k.amplitude, k.omega, k.phase)
    row = counters[IMPACTS]
    if row >= impact_buffer.shape[0]:
        impact_buffer = _grow(impact_buffer)
    impact_buffer[row, 0] = impact[_START]
    impact_buffer[row, 1] = wall
    impact_buffer[row, 2] = impact[_SPEED_IN]
    impact_buffer[row, 3] = -rate_into_wall(wall, y_new[P] / k.ball_mass, vial_at_separation)
    impact_buffer[row, 4] = y_new[DISSIPATED] - impact[_DISSIPATED0]
    impact_buffer[row, 5] = y_new[HEAT_GENERATED] - impact[_HEAT0]
    impact_buffer[row, 6] = impact[_MAX_OVERLAP]
    impact_buffer[row, 7] = impact[_PEAK_FORCE]
    impact_buffer[row, 8] = separation - impact[_START]
    counters[IMPACTS] = row + 1
    impact[_ACTIVE] = 0.0
    return impact_buffer


@njit(cache=True)
def _next_step_size(
    h: float, factor: float, landed: bool, left_wall: bool, speed_in: float, k: Constants, contact_step_limit: float
) -> float:
    """The step to try after an accepted step of ``h`` whose error allows ``factor`` times it."""
    if landed:
        # A contact starts with a short step: see ONSET_STEP_FRACTION.
        return min(contact_step_limit, shortest_contact_step(speed_in, k))
    h = h * factor
    if left_wall:
        # Flight is exact for the mechanics and smooth for the temperatures, so offer a whole drive
        # period: the onset search cuts it at the next contact.
        h = max(h, k.period)
    return h


@njit(cache=True)
def _advance(
    t_stop: float,
    steps_allowed: int,
    k: Constants,
    tableau: tuple,
    control: _StepControl,
    accuracy: _Accuracy,
    state: _State,
    recording: _Recording,
    window_buffer: np.ndarray,
    impact_buffer: np.ndarray,
) -> tuple[int, np.ndarray, np.ndarray]:
    """Integrate from ``state.clock[0]`` to ``t_stop``, or for ``steps_allowed`` accepted steps (status PAUSED)
    if that comes first (see :meth:`Integrator.advance`); returns (status, window buffer, impact buffer).

    The arrays are unpacked once, here: every array passed to a compiled call that is not inlined costs
    a reference count, so the helpers called on every step take few arrays, or none."""
    a, b, error_weights, c = tableau
    rtol, atol, origin, contact_step_limit, max_overlap, project_energy = accuracy
    clock, y, f0, impact, counters, diagnostics = state
    sample_times, samples, windows = recording
    stages, f_new, y_new, work, point, scale, stack = _work_arrays(c.shape[0], y.shape[0])
    t, h = clock[0], clock[1]
    last_step = counters[STEPS] + steps_allowed
    status, rejected_last = REACHED_STOP, False
    while t < t_stop:
        in_contact = impact[_ACTIVE] != 0.0
        wall = int(impact[_WALL]) if in_contact else NO_WALL
        h, wall = bound_step(t, h, t_stop, y[X], y[P], wall, impact[_SPEED_IN], k, contact_step_limit, stack)
        touching, landing = wall != NO_WALL, wall != NO_WALL and not in_contact
        if not landing and h <= TIME_RESOLUTION * max(1.0, abs(t)):
            status = STEP_UNDERFLOW
            break
        stages[0] = f0
        if h > 0.0:
            _rk_step(t, h, y, a, b, c, k, stages, y_new, work)
            counters[RHS_EVALUATIONS] += c.shape[0] - 1
            _lab_error_scale(y, y_new, rtol, atol, origin, scale)
            if in_contact:
                _contact_error_scale(impact[_SPEED_IN], rtol, k, scale)
            error = _error_norm(h, stages, error_weights, scale, in_contact)
        else:  # a landing right where the step starts: nothing to estimate
            y_new[:] = y
            f_new[:] = f0
            error = 0.0
        factor = _step_factor(error, rejected_last, control)
        rejected_last = not error <= 1.0  # also rejects NaN
        if rejected_last:
            counters[REJECTED] += 1
            h *= factor
            continue
        t_new = t + h
        if touching:
            overlap = -gap(t_new, y_new[X], wall, k)
            vial_velocity = kinematics.vial_velocity(t_new, k.amplitude, k.omega, k.phase)
            elastic_new = elastic_energy(overlap, k.e_star, k.radius) if overlap > 0.0 else 0.0
            if in_contact and project_energy and (overlap <= 0.0 or t_new >= t_stop):
                _project_energy(t_new, y_new, f_new, elastic_new, impact, k, counters, diagnostics)
        if not _all_finite(y_new):
            status = NOT_FINITE
            break
        # Most steps record nothing: the cheap tests spare them the calls, which take many arrays.
        if _sample_due(t_new, sample_times, counters):
            _record_samples(t, h, y, f0, y_new, f_new, sample_times, samples, counters, point)
        if _meets_a_window(t, t_new, windows):
            window_buffer = _record_windows(t, h, y, f0, y_new, f_new, windows, window_buffer, counters, point)
        if touching:
            overlap_rate = rate_into_wall(wall, y_new[P] / k.ball_mass, vial_velocity)
            if landing:
                _open_impact(t_new, y_new, wall, overlap_rate, elastic_new, impact, k)
            elif overlap > 0.0:  # still touching; overlap <= 0 below means it left the wall
                if _follow_contact(overlap, overlap_rate, max_overlap, impact, k):
                    status = OVERLAP_TOO_LARGE
            else:
                impact_buffer = _close_impact(t_new, y_new, overlap, overlap_rate, impact, impact_buffer, counters, k)
        t = t_new
        y[:] = y_new
        f0[:] = f_new
        if status != REACHED_STOP:  # the overlap is too large: stop on the state that shows it
            break
        counters[STEPS] += 1
        left_wall = in_contact and impact[_ACTIVE] == 0.0
        h = _next_step_size(h, factor, landing, left_wall, impact[_SPEED_IN], k, contact_step_limit)
        if counters[STEPS] == last_step:
            # After an accepted step: t, h and the state in the arrays are all the next call needs, and
            # rejected_last is False as on entry, so a pause leaves the integration bit for bit unchanged.
            break
    clock[0], clock[1] = t, h
    return (PAUSED if status == REACHED_STOP and t < t_stop else status), window_buffer, impact_buffer


@dataclass
class Integrator(CompiledRun):
    """Chunked driver of the compiled loop; holds the state between chunks."""

    # A step costs ~0.5 µs in flight, but up to ~0.4 ms where the contact search is hard (ω ~ 1e5 rad/s).
    # After its first call a default run's 10-s chunks (~10⁴ steps, ~5 ms) end long before the adapted
    # count, so it makes no further calls.
    first_steps_per_call: ClassVar[int] = 1_000
    most_steps_per_call: ClassVar[int] = 10_000_000

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
        self._tableau = self.tableau.arrays()
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

    def steps_taken(self) -> int:
        return int(self.counters[STEPS])

    def limit_reached(self) -> int | None:
        """BUDGET_EXCEEDED or WINDOWS_FULL when the integration may not go on, else None."""
        if self.budget.spent():
            return BUDGET_EXCEEDED
        return WINDOWS_FULL if self.counters[WINDOW_POINTS] >= MAX_WINDOW_POINTS else None

    def explain(self, status: int) -> str:
        """The message of ``status``; for BUDGET_EXCEEDED, which limit was reached and how to raise it."""
        return self.budget.explain(status, STATUS_MESSAGES)

    def compiled_call(self, t_stop: float, steps_allowed: int) -> int:
        controller, tolerances = self.controller, self.tolerances
        control = _StepControl(
            controller.safety, controller.min_factor, controller.max_factor, -1.0 / (self.tableau.error_order + 1)
        )
        accuracy = _Accuracy(
            tolerances.rtol,
            tolerances.atol,
            tolerances.origin,
            tolerances.contact_step_limit,
            tolerances.max_overlap,
            self.project_energy,
        )
        state = _State(self.clock, self.y, self.f, self._impact, self.counters, self.diagnostics)
        recording = _Recording(self.sample_times, self.samples, self.windows)
        status, self._window_buffer, self._impact_buffer = _advance(
            t_stop,
            steps_allowed,
            self.constants,
            self._tableau,
            control,
            accuracy,
            state,
            recording,
            self._window_buffer,
            self._impact_buffer,
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
