"""Compiled velocity-Verlet stepping of the 'dem' engine (MODEL.md section 12).

One step: half kick with the last forces, drift, forces at the new positions (with the velocities
predicted to the step's end), second half kick with the new forces. Inside contacts the step is the shortest the
touching contacts allow: an impact ``contact_step_fraction`` × model.IMPACT_STEP_SCALE of its own period, its
release at the contact step (``contact_step_fraction`` of the smallest Rayleigh time, the shortest step there is);
a contact that outlasted model.ENDURING_AFTER of its periods (rolling, sliding, resting) ``enduring_step_fraction``
of its period; never beyond 0.9 t_R. In free flight, and for the slots not touching when a contact's step is the
longer one, it is as long as no contact can begin inside it (each gap over its largest closing speed and
acceleration), so that a contact begins inside a contact step, but never shorter than that nor longer than
``max_flight_step``.

The energy bookkeeping is exact per step. The second half kick makes each ball's change of kinetic
energy dt·(F̄·v̄ + M̄·w̄), with F̄, M̄ the means of its forces and torques at the step's two ends and
v̄, w̄ its mean velocities. Each contact's part of that work is split into the vial's work, the change
of the contact's stored energies (Hertz normal, tangential spring) and its dissipation by channel, so
the audit "work of vial and gravity = Δ kinetic energy + Δ stored + dissipated" closes to round-off,
and each channel tends to its continuous formula (MODEL.md §12.4) as the step shrinks. η of the
dissipation becomes heat in the balls and the vial; the thermal network advances on its own coarser
clock with the heat and Whitaker velocity terms gathered meanwhile (MODEL.md §12.5).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from shakermill.engines.dem.contacts import (
    measure_wall_gaps,
    pair_contacts,
    rebuild_neighbours,
    settle,
    sum_forces,
    wall_contacts,
)
from shakermill.engines.dem.description import NEIGHBOURS_FULL
from shakermill.engines.dem.model import (
    ENDURING_AFTER,
    HEAT_LOST,
    LEFT_END,
    N_WALLS,
    SIDE,
    WORK_GRAVITY,
    Constants,
    Scratch,
    State,
)
from shakermill.engines.dem.neighbours import moved_since_build, needs_rebuild
from shakermill.engines.dem.vectors import copy_into, cross_into, distance, dot, norm, squared_distance
from shakermill.engines.status import NOT_FINITE, OVERLAP_TOO_LARGE, REACHED_STOP
from shakermill.engines.thermal import kernel
from shakermill.engines.thermal.kernel import NetworkArrays
from shakermill.physics import kinematics, thermal

PAUSED = 2  # the step allowance of one call is spent; call again
RECORDS_FULL = 3  # the impact buffer is full; grow it and call again

RECORD_COLUMNS = (
    "time",
    "ball",
    "other",
    "normal_speed",
    "tangential_speed",
    "dissipated_normal",
    "dissipated_tangential",
    "dissipated_sliding",
    "dissipated_rolling",
    "peak_force",
    "max_overlap",
    "duration",
    "heat_to_ball",
    "heat_to_other",
    "conduction",
    "heat_to_deposits",
)
COUNTER_NAMES = ("steps", "contact_steps", "flight_steps", "impacts", "thermal_updates", "neighbour_builds")
STEPS, CONTACT_STEPS, FLIGHT_STEPS, IMPACTS, THERMAL_UPDATES, NEIGHBOUR_BUILDS, ROWS_WRITTEN = range(
    len(COUNTER_NAMES) + 1
)
# ``other`` of a record: the other ball's index, or −1 − wall for the vial's left end, right end and side.


@njit(cache=True, inline="always")
def vial_frame(t: float, k: Constants, w: Scratch) -> None:
    """The vial's pose and rates at ``t`` into ``w`` (MODEL.md §12.2)."""
    kinematics.fourier_coordinates(t, k.omega, k.phase, k.harmonics, w.coordinates, w.rates)
    kinematics.rotation_matrix(w.coordinates[3], w.coordinates[4], w.coordinates[5], w.orientation)
    kinematics.angular_velocity(w.coordinates[4], w.coordinates[5], w.rates[3], w.rates[4], w.rates[5], w.angular)


@njit(cache=True, inline="always")
def _convect(dt: float, k: Constants, s: State, w: Scratch) -> None:
    """Gather each ball's Whitaker velocity term over the step (MODEL.md §§4, 12.5) and the gravity's work."""
    for i in range(k.n_balls):
        speed_squared = 0.0
        for axis in range(3):
            mean_velocity = 0.5 * (w.velocity_before[i, axis] + s.velocity[i, axis])
            s.totals[WORK_GRAVITY] += dt * k.mass[i] * k.gravity[axis] * mean_velocity
            w.lever[axis] = s.position[i, axis] - w.coordinates[axis]
        if k.relative_convection:
            cross_into(w.angular, w.lever, w.other_velocity)
            for axis in range(3):
                relative = s.velocity[i, axis] - w.rates[axis] - w.other_velocity[axis]
                speed_squared += relative * relative
        else:
            speed_squared = dot(s.velocity[i], s.velocity[i])
        reynolds = thermal.reynolds_number(k.radius[i], k.air_density, math.sqrt(speed_squared), k.viscosity_ambient)
        term = thermal.whitaker_velocity_term(reynolds) * dt
        s.pending_drives[i] += term
        s.drive_integrals[i] += term


@njit(cache=True)
def advance_thermal(k: Constants, net: NetworkArrays, s: State) -> None:
    """Advance the network (``engines.thermal``) over the time gathered since its last update, with the heat, the
    mean Whitaker terms and the mean contact conductances of that time (explicit Euler, which conserves energy
    exactly)."""
    # Its scratch is allocated here, at most once a thermal step (1 ms): a function of its own, compiled with
    # Numba's runtime, which the stepping loop runs without (:func:`advance`).
    span = s.clock[1]
    if span <= 0.0:
        return
    for drive in range(s.pending_drives.size):
        s.pending_drives[drive] /= span
    s.totals[HEAT_LOST] += kernel.advance(
        s.temperature,
        s.pending_heat,
        s.pending_drives,
        span,
        net,
        np.empty(net.kind.size),
        np.empty(s.temperature.size),
    )
    s.pending_heat[:] = 0.0
    s.pending_drives[:] = 0.0
    s.clock[1] = 0.0


@njit(cache=True)
def _time_to_close(gap: float, speed: float, acceleration: float) -> float:
    """Shortest time in which a gap (m) closing at most at ``speed`` (negative: opening) and ``acceleration`` can
    close (s)."""
    if gap <= 0.0:
        return 0.0
    if acceleration <= 0.0:
        return gap / speed if speed > 0.0 else math.inf
    return (math.sqrt(speed * speed + 2.0 * acceleration * gap) - speed) / acceleration


@njit(cache=True, inline="always")
def _shortened(step: float, gap: float, speed: float, acceleration: float) -> float:
    """``step``, or the shorter :func:`_time_to_close` of the gap; no square root where the gap cannot close within
    ``step`` (the case of most gaps inside contacts, whose steps are short)."""
    if gap > 0.0 and gap >= step * (max(speed, 0.0) + 0.5 * max(acceleration, 0.0) * step):
        return step
    return min(step, _time_to_close(gap, speed, acceleration))


@njit(cache=True, inline="always")
def _flight_step(cap: float, k: Constants, s: State, w: Scratch) -> float:
    """The longest step in which no contact can begin (MODEL.md §12.6), within [contact_step, min(cap,
    max_flight_step)]. Inside contacts ``cap`` is the step they allow: the pairs are sifted against it from the start.

    A ball's centre moves in the vial frame at its velocity relative to the vial's point under it, which can
    change at most by gravity, the vial's acceleration and the Coriolis term within a step, and by the contact
    forces on it (taken twice their last value: they are those of slow contacts, or the step is a contact step
    anyway; in flight they are zero). Its distance from an end face closes at most at the axial part of that
    velocity, its distance from the axis grows at most at the part across the axis (a norm bound, so the
    bore's curvature needs no term of its own). Two balls' gap closes at most at its present rate and their relative
    acceleration. Touching slots are left out: their contacts have begun. Pairs the
    neighbour list leaves out cannot touch while no ball has moved half the skin since its build: each ball's
    distance from that bound closes at most at its speed relative to the vial's centre.
    """
    n = k.n_balls
    walls = N_WALLS * n
    step = min(cap, k.max_flight_step)
    axis = w.orientation[:, 0]
    active = s.contacts.active
    nb = s.neighbours
    listed = math.isfinite(k.skin)
    fastest = hardest = 0.0
    falling = norm(k.gravity) + k.wall_acceleration_bound
    for i in range(n):
        for component in range(3):
            w.lever[component] = s.position[i, component] - w.coordinates[component]
        cross_into(w.angular, w.lever, w.other_velocity)
        for component in range(3):
            w.point_velocity[component] = s.velocity[i, component] - w.rates[component] - w.other_velocity[component]
        along = dot(w.point_velocity, axis)
        across = math.sqrt(max(dot(w.point_velocity, w.point_velocity) - along * along, 0.0))
        pushed = 2.0 * norm(s.force[i]) / k.mass[i]
        w.pushed[i] = pushed
        relative_speed = distance(s.velocity[i], w.rates[:3])  # relative to the vial's centre
        fastest = max(fastest, relative_speed)
        hardest = max(hardest, pushed)
        acceleration = falling + 2.0 * k.angular_speed_bound * (abs(along) + across) + pushed
        for wall in range(N_WALLS):
            if active[N_WALLS * i + wall]:
                continue
            gap = w.wall_gaps[N_WALLS * i + wall]  # of this step's end, where the next one starts
            closing = across if wall == SIDE else (-along if wall == LEFT_END else along)
            step = _shortened(step, gap, max(closing, 0.0), acceleration)
        if listed:
            margin = 0.5 * k.skin - moved_since_build(i, s.position, w.coordinates, nb)
            step = _shortened(step, margin, relative_speed, falling + pushed)
    for entry in range(nb.entries[0]):
        if active[walls + entry]:
            continue
        i, j = nb.first_ball[entry], nb.second_ball[entry]
        # Both balls fall alike in flight: their relative motion changes only by the contact forces. No pair
        # closes faster than at twice the fastest ball's speed relative to the vial's centre and twice the hardest
        # push, so a pair farther apart
        # than that reaches within the step found so far cannot shorten it (most pairs: no square root).
        reach = k.radius[i] + k.radius[j] + 2.0 * fastest * step + hardest * step * step
        if squared_distance(s.position[i], s.position[j]) >= reach * reach:
            continue
        centres = distance(s.position[i], s.position[j])
        gap = centres - k.radius[i] - k.radius[j]
        relative_acceleration = w.pushed[i] + w.pushed[j]
        # The centres' distance is at least its projection on their line now, which changes at the closing speed
        # and by the relative acceleration alone: balls sliding or rolling past each other only part.
        closing = 0.0
        for component in range(3):
            closing -= (s.position[i, component] - s.position[j, component]) * (
                s.velocity[i, component] - s.velocity[j, component]
            )
        step = _shortened(step, gap, closing / centres, relative_acceleration)
    return max(step, k.contact_step)


@njit(cache=True, inline="always")
def _contact_limit(slot: int, t: float, k: Constants, s: State) -> float:
    """The longest step the touching contact in ``slot`` allows at ``t`` (s). An impact: a fraction of its period
    (:func:`contact.contact_period`: its first one, the impact's shortest, or a shorter one where another impact
    loads it), and the contact step once its overlap would open within two of those steps; once it has lasted
    ENDURING_AFTER periods, the enduring fraction of its period now."""
    c = s.contacts
    period = c.period[slot]
    if t - c.started[slot] >= ENDURING_AFTER * period:
        return k.enduring_step_fraction * period
    step = min(k.period_step_fraction * min(period, c.impact_period[slot]), k.longest_contact_step)
    # The release is resolved as the start is: ended inside a long step, an impact's restitution depends on where in
    # that step (its phase), by up to 1.2e-3 at T/83. Two steps ahead, as the overlap's rate changes meanwhile; of
    # the step as taken (a gentle touch's period, at a tiny overlap, is far longer than 0.9 t_R).
    return k.contact_step if c.release[slot] < 2.0 * step else step


@njit(cache=True, inline="always")
def _step_length(touching: int, limit: float, k: Constants, s: State, w: Scratch) -> float:
    """The next step (MODEL.md §12.6). In flight, :func:`_flight_step`. Inside contacts, the shortest of the touching
    contacts' limits (``limit``, :func:`_contact_limit`) but not below the contact step nor beyond 0.9 t_R (MODEL.md
    §7); a step longer than the contact step is also bounded as a flight step by the slots not touching, so that no
    contact begins inside it."""
    if not touching:
        return _flight_step(math.inf, k, s, w)
    step = max(k.contact_step, min(limit, k.longest_contact_step))
    if step <= k.contact_step:
        return k.contact_step
    return _flight_step(step, k, s, w)


@njit(cache=True, inline="always")
def _kick_and_drift(dt: float, k: Constants, s: State, w: Scratch) -> None:
    """First half kick and drift; the velocities are left predicted to the step's end for the forces."""
    for i in range(k.n_balls):
        for axis in range(3):
            acceleration = s.force[i, axis] / k.mass[i] + k.gravity[axis]
            angular_acceleration = s.torque[i, axis] / k.inertia[i]
            w.velocity_before[i, axis] = s.velocity[i, axis]
            w.spin_before[i, axis] = s.spin[i, axis]
            w.half_velocity[i, axis] = s.velocity[i, axis] + 0.5 * dt * acceleration
            w.half_spin[i, axis] = s.spin[i, axis] + 0.5 * dt * angular_acceleration
            s.position[i, axis] += dt * w.half_velocity[i, axis]
            s.velocity[i, axis] = w.half_velocity[i, axis] + 0.5 * dt * acceleration
            s.spin[i, axis] = w.half_spin[i, axis] + 0.5 * dt * angular_acceleration


@njit(cache=True, inline="always")
def _final_kick(dt: float, k: Constants, s: State, w: Scratch) -> None:
    for i in range(k.n_balls):
        for axis in range(3):
            s.velocity[i, axis] = w.half_velocity[i, axis] + 0.5 * dt * (s.force[i, axis] / k.mass[i] + k.gravity[axis])
            s.spin[i, axis] = w.half_spin[i, axis] + 0.5 * dt * s.torque[i, axis] / k.inertia[i]


@njit(cache=True, inline="always")
def _step(
    t: float, dt: float, k: Constants, s: State, w: Scratch, records: np.ndarray, count: int
) -> tuple[int, int, float, float]:
    """One velocity-Verlet step of length ``dt`` ending at ``t``; returns (record count, contacts touching,
    deepest overlap, the longest next step the touching contacts allow)."""
    copy_into(w.angular, w.angular_before)
    _kick_and_drift(dt, k, s, w)
    vial_frame(t, k, w)
    live, deepest_pair = pair_contacts(t, dt, k, s, w, 0)
    live, deepest_wall = wall_contacts(t, dt, k, s, w, live)
    sum_forces(live, k, s, w)
    _final_kick(dt, k, s, w)
    touching = 0
    limit = math.inf
    for index in range(live):
        slot = w.live[index]
        count = settle(slot, t, dt, k, s, w, records, count)
        if w.touching[slot]:
            touching += 1
            limit = min(limit, _contact_limit(slot, t, k, s))
    _convect(dt, k, s, w)
    s.clock[0] = t
    s.clock[1] += dt
    return count, touching, max(deepest_pair, deepest_wall), limit


@njit(cache=True)
def write_row(k: Constants, net: NetworkArrays, s: State, w: Scratch, row: np.ndarray) -> None:
    """The state now as a row laid out as :func:`model.row_fields` says (the thermal network brought up to now)."""
    advance_thermal(k, net, s)
    vial_frame(s.clock[0], k, w)
    row[0] = s.clock[0]
    offset = 1
    for block in (
        s.position.ravel(),
        s.velocity.ravel(),
        s.spin.ravel(),
        s.temperature,
        s.totals,
        s.heat_into,
        s.drive_integrals,
        w.coordinates,
    ):
        row[offset : offset + block.size] = block
        offset += block.size


# nogil: the replicas of an averaged run step side by side on threads (solvers/replicas.py). _nrt=False: no
# reference counting of the arrays inside the loop, which took three quarters of a step (each view and each array
# taken from the tuples counted in and out with an atomic add; benchmarks/README.md, "The per-step cost"). The loop
# allocates nothing, so it needs none of Numba's runtime. The option is Numba's own (``numba.core.options``),
# private by its underscore: a Numba without it would refuse to compile this loop, which every 3-D test runs. Private,
# it is not among the options Numba's type stubs declare, so it is passed as a mapping the stubs do not hold it to.
WITHOUT_REFERENCE_COUNTING: dict[str, Any] = {"_nrt": False}


@njit(cache=True, nogil=True, **WITHOUT_REFERENCE_COUNTING)
def advance(
    t_stop: float,
    max_steps: int,
    k: Constants,
    net: NetworkArrays,
    s: State,
    w: Scratch,
    records: np.ndarray,
    count: int,
    counters: np.ndarray,
    marks: np.ndarray,
    rows: np.ndarray,
) -> tuple[int, int]:
    """Step to ``t_stop`` (s); returns (status, record count). Steps end on each time in ``marks`` (sorted),
    where the state is written into the next row of ``rows``. Hands back early with PAUSED after ``max_steps``
    steps and with RECORDS_FULL when ``records`` may overflow; the thermal network is brought up to the time
    reached either way."""
    slots = s.contacts.active.size
    vial_frame(s.clock[0], k, w)
    measure_wall_gaps(k, s, w)
    touching = 0
    limit = math.inf
    for slot in range(slots):
        if s.contacts.active[slot]:
            touching += 1
            limit = min(limit, _contact_limit(slot, s.clock[0], k, s))
    status = REACHED_STOP
    steps = 0
    while s.clock[0] < t_stop:
        if steps >= max_steps:
            status = PAUSED
            break
        if count + slots > records.shape[0]:
            status = RECORDS_FULL
            break
        if needs_rebuild(k, s.position, w.coordinates, s.neighbours):
            if not rebuild_neighbours(k, s, w.coordinates):
                status = NEIGHBOURS_FULL
                break
            counters[NEIGHBOUR_BUILDS] += 1
        dt = _step_length(touching, limit, k, s, w)
        mark = counters[ROWS_WRITTEN]
        end = min(t_stop, marks[mark]) if mark < marks.size else t_stop
        remaining = end - s.clock[0]
        t = end if dt >= remaining else s.clock[0] + dt
        before = count
        count, touching, deepest, limit = _step(t, min(dt, remaining), k, s, w, records, count)
        steps += 1
        counters[STEPS] += 1
        counters[CONTACT_STEPS if touching else FLIGHT_STEPS] += 1
        counters[IMPACTS] += count - before
        if deepest > k.max_overlap:
            status = OVERLAP_TOO_LARGE
            break
        if not math.isfinite(s.position.sum() + s.velocity.sum() + s.spin.sum()):
            status = NOT_FINITE
            break
        if s.clock[1] >= k.thermal_step:
            advance_thermal(k, net, s)
            counters[THERMAL_UPDATES] += 1
        if mark < marks.size and t == marks[mark]:
            write_row(k, net, s, w, rows[mark])
            counters[ROWS_WRITTEN] += 1
    if status == REACHED_STOP:
        # Not when handing back early: where that happens depends on the wall clock, and the numbers must not.
        advance_thermal(k, net, s)
    return status, count
