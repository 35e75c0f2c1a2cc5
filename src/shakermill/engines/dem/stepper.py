"""Compiled velocity-Verlet stepping of the 'dem' engine (MODEL.md section 12).

One step: half kick with the last forces, drift, forces at the new positions (with the velocities
predicted to the step's end), second half kick with the new forces. Inside contacts the step is
``contact_step_fraction`` of the smallest Rayleigh time, or of the touching contacts' shortest oscillation
period over 9.5 where that is longer (model.RAYLEIGH_TIMES_PER_PERIOD: a ball resting, rolling or hopping on
the bore steps longer; impacts of 0.1 m/s and faster keep the Rayleigh step), never beyond 0.9 t_R. In free
flight, and for the slots not touching when a contact's step is the longer one, it is as long as no contact
can begin inside it (each gap over its largest closing speed and acceleration), but never shorter than the
Rayleigh step nor longer than ``max_flight_step``.

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
from typing import NamedTuple

import numpy as np
from numba import njit

from shakermill.engines.dem import network
from shakermill.engines.dem.model import (
    DISSIPATED_NORMAL,
    DISSIPATED_ROLLING,
    DISSIPATED_SLIDING,
    DISSIPATED_TANGENTIAL,
    HEAT_GENERATED,
    HEAT_LOST,
    LEFT_END,
    N_WALLS,
    RIGHT_END,
    SIDE,
    WORK_GRAVITY,
    WORK_STIFFENING,
    WORK_VIAL,
    Constants,
    State,
)
from shakermill.engines.status import NOT_FINITE, OVERLAP_TOO_LARGE, REACHED_STOP
from shakermill.physics import contact, kinematics, thermal

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
)
COUNTER_NAMES = ("steps", "contact_steps", "flight_steps", "impacts", "thermal_updates")
STEPS, CONTACT_STEPS, FLIGHT_STEPS, IMPACTS, THERMAL_UPDATES, ROWS_WRITTEN = range(len(COUNTER_NAMES) + 1)
# ``other`` of a record: the other ball's index, or −1 − wall for the vial's left end, right end and side.


class Scratch(NamedTuple):
    """Arrays of one call, allocated once so that the compiled loop allocates nothing per step."""

    coordinates: np.ndarray  # (6,) the vial's x, y, z, roll, pitch, yaw
    rates: np.ndarray  # (6,) their time derivatives
    orientation: np.ndarray  # (3, 3) vial frame to lab frame
    angular: np.ndarray  # (3,) the vial's angular velocity now
    angular_before: np.ndarray  # (3,) at the step's start
    half_velocity: np.ndarray  # (N, 3) after the first half kick
    half_spin: np.ndarray  # (N, 3)
    velocity_before: np.ndarray  # (N, 3) at the step's start
    spin_before: np.ndarray  # (N, 3)
    normal_force: np.ndarray  # (S, 3) new forces and torques on ball i per slot
    tangential_force: np.ndarray
    lever_torque_i: np.ndarray
    lever_torque_j: np.ndarray
    rolling_torque: np.ndarray
    wall_velocity: np.ndarray  # (S, 3) the vial's velocity at the contact point
    elastic_energy: np.ndarray  # (S,)
    stiffness: np.ndarray  # (S,) tangential k_t
    stretch: np.ndarray  # (S,) |δ_t|²
    live: np.ndarray  # (S,) slots touching now or at the step's start
    touching: np.ndarray  # (S,) bool: touching at the step's end
    normal: np.ndarray  # (3,) vectors of the contact being evaluated
    point_velocity: np.ndarray
    other_velocity: np.ndarray
    lever: np.ndarray
    relative_spin: np.ndarray
    flow: np.ndarray  # (N + 2,) heat flows of the thermal network


def scratch_for(n_balls: int, slots: int) -> Scratch:
    return Scratch(
        coordinates=np.zeros(6),
        rates=np.zeros(6),
        orientation=np.zeros((3, 3)),
        angular=np.zeros(3),
        angular_before=np.zeros(3),
        half_velocity=np.zeros((n_balls, 3)),
        half_spin=np.zeros((n_balls, 3)),
        velocity_before=np.zeros((n_balls, 3)),
        spin_before=np.zeros((n_balls, 3)),
        normal_force=np.zeros((slots, 3)),
        tangential_force=np.zeros((slots, 3)),
        lever_torque_i=np.zeros((slots, 3)),
        lever_torque_j=np.zeros((slots, 3)),
        rolling_torque=np.zeros((slots, 3)),
        wall_velocity=np.zeros((slots, 3)),
        elastic_energy=np.zeros(slots),
        stiffness=np.zeros(slots),
        stretch=np.zeros(slots),
        live=np.zeros(slots, dtype=np.int64),
        touching=np.zeros(slots, dtype=np.bool_),
        normal=np.zeros(3),
        point_velocity=np.zeros(3),
        other_velocity=np.zeros(3),
        lever=np.zeros(3),
        relative_spin=np.zeros(3),
        flow=np.zeros(n_balls + 2),
    )


@njit(cache=True)
def _dot(a: np.ndarray, b: np.ndarray) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def _cross_into(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    z = a[0] * b[1] - a[1] * b[0]
    out[0], out[1], out[2] = x, y, z


@njit(cache=True)
def _norm(a: np.ndarray) -> float:
    return math.sqrt(_dot(a, a))


@njit(cache=True)
def _scaled_into(a: np.ndarray, scale: float, out: np.ndarray) -> None:
    """out = scale·a, without a temporary array."""
    for axis in range(3):
        out[axis] = scale * a[axis]


@njit(cache=True)
def _difference_into(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    for axis in range(3):
        out[axis] = a[axis] - b[axis]


@njit(cache=True)
def _distance(a: np.ndarray, b: np.ndarray) -> float:
    dx, dy, dz = a[0] - b[0], a[1] - b[1], a[2] - b[2]
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, inline="always")
def vial_frame(t: float, k: Constants, w: Scratch) -> None:
    """The vial's pose and rates at ``t`` into ``w`` (MODEL.md §12.2)."""
    kinematics.fourier_coordinates(t, k.omega, k.phase, k.harmonics, w.coordinates, w.rates)
    kinematics.rotation_matrix(w.coordinates[3], w.coordinates[4], w.coordinates[5], w.orientation)
    kinematics.angular_velocity(w.coordinates[4], w.coordinates[5], w.rates[3], w.rates[4], w.rates[5], w.angular)


@njit(cache=True, inline="always")
def wall_gap(position: np.ndarray, radius: float, wall: int, k: Constants, w: Scratch) -> float:
    """Gap (m; negative: overlap) between a ball and ``wall``; ``w.normal`` gets the unit normal into the ball."""
    q = w.orientation
    rx = position[0] - w.coordinates[0]
    ry = position[1] - w.coordinates[1]
    rz = position[2] - w.coordinates[2]
    axial = q[0, 0] * rx + q[1, 0] * ry + q[2, 0] * rz
    if wall == LEFT_END:
        _scaled_into(q[:, 0], 1.0, w.normal)
        return axial + k.half_length - radius
    if wall == RIGHT_END:
        _scaled_into(q[:, 0], -1.0, w.normal)
        return k.half_length - axial - radius
    across_1 = q[0, 1] * rx + q[1, 1] * ry + q[2, 1] * rz
    across_2 = q[0, 2] * rx + q[1, 2] * ry + q[2, 2] * rz
    off_axis = math.hypot(across_1, across_2)
    if off_axis > 0.0:
        for axis in range(3):
            w.normal[axis] = -(q[axis, 1] * across_1 + q[axis, 2] * across_2) / off_axis
    else:
        _scaled_into(q[:, 2], -1.0, w.normal)
    return k.bore_radius - off_axis - radius


@njit(cache=True, inline="always")
def _response(slot: int, overlap: float, relative_spin: np.ndarray, modulus: float, shear_modulus: float,
              radius: float, mass: float, dt: float, k: Constants, s: State, w: Scratch) -> None:
    """Normal, tangential and rolling response of a contact (MODEL.md §12.3) into ``w``'s arrays of ``slot``.

    ``w.normal`` points into ball i; ``w.point_velocity`` is i's contact point's velocity relative to the
    other body's. Updates the tangential spring and the running contact's record in place.
    """
    c = s.contacts
    normal, relative = w.normal, w.point_velocity
    approach = _dot(relative, normal)
    # A contact that began inside this step starts with an unstretched spring: it did not exist for the
    # step's earlier part, which in free flight can be far longer than a contact step.
    stretching = dt if c.active[slot] else 0.0
    elastic = contact.hertz_force(overlap, modulus, radius)
    damping = contact.damping_coefficient(overlap, mass, radius, modulus, k.beta_e)
    magnitude = contact.contact_force(elastic, damping, -approach, k.no_tension)
    w.elastic_energy[slot] = contact.elastic_energy(overlap, modulus, radius)
    spring = c.spring[slot]
    length = _norm(spring)
    along = _dot(spring, normal)
    for axis in range(3):  # the spring turns with the tangent plane, keeping its length
        spring[axis] -= along * normal[axis]
    turned = _norm(spring)
    if turned > 0.0:
        spring *= length / turned
    stiffness = contact.tangential_stiffness(shear_modulus, radius, overlap)
    damping_t = contact.tangential_damping(k.beta_e, stiffness, mass)
    pressing = max(magnitude, 0.0)
    limit = k.friction * pressing
    c.slip_loss[slot] = 0.0
    for axis in range(3):
        sliding = relative[axis] - approach * normal[axis]
        spring[axis] += sliding * stretching
        w.normal_force[slot, axis] = magnitude * normal[axis]
        w.tangential_force[slot, axis] = -stiffness * spring[axis] - damping_t * sliding
    size = _norm(w.tangential_force[slot])
    if size > limit:
        # The force is scaled down to the Coulomb limit, and the spring with it (so that without a damper the
        # spring alone gives the limit): its end slips by the part of the stretch it loses, and sliding
        # dissipates μF_n⁺·|slip|. Holding the whole force in the spring instead would stretch it absurdly
        # where k_t is tiny, in a contact's first step, when the damper gives most of the trial force.
        ratio = limit / size
        c.slip_loss[slot] = limit * (1.0 - ratio) * _norm(spring)
        w.tangential_force[slot] *= ratio
        spring *= ratio
    w.stiffness[slot] = stiffness
    w.stretch[slot] = _dot(spring, spring)
    spin = _norm(relative_spin)
    for axis in range(3):
        w.rolling_torque[slot, axis] = -k.rolling_friction * radius * pressing * relative_spin[axis] / spin if spin > 0 else 0.0
    c.period[slot] = contact.contact_period(mass, radius, modulus, shear_modulus, overlap, approach)
    c.peak_force[slot] = max(c.peak_force[slot], abs(magnitude))
    c.max_overlap[slot] = max(c.max_overlap[slot], overlap)


@njit(cache=True, inline="always")
def _touch(slot: int, t: float, s: State, w: Scratch) -> None:
    """A contact begins in ``slot`` at ``t``: start its record from the approach velocities."""
    c = s.contacts
    approach = _dot(w.point_velocity, w.normal)
    c.started[slot] = t
    c.normal_speed_in[slot] = -approach
    c.tangential_speed_in[slot] = math.sqrt(max(_dot(w.point_velocity, w.point_velocity) - approach * approach, 0.0))
    c.dissipated[slot, :] = 0.0
    c.peak_force[slot] = 0.0
    c.max_overlap[slot] = 0.0
    c.spring[slot, :] = 0.0


@njit(cache=True, inline="always")
def _release(slot: int, w: Scratch) -> None:
    """No force in ``slot`` now (a contact that just ended)."""
    w.touching[slot] = False
    w.normal_force[slot, :] = 0.0
    w.tangential_force[slot, :] = 0.0
    w.lever_torque_i[slot, :] = 0.0
    w.lever_torque_j[slot, :] = 0.0
    w.rolling_torque[slot, :] = 0.0
    w.elastic_energy[slot] = 0.0
    w.stiffness[slot] = 0.0
    w.stretch[slot] = 0.0


@njit(cache=True, inline="always")
def _release_if_touching(slot: int, s: State, w: Scratch, live: int) -> int:
    """A slot apart now: if it touched at the step's start, it is released and live for the step's bookkeeping."""
    if not s.contacts.active[slot]:
        return live
    _release(slot, w)
    w.live[live] = slot
    return live + 1


@njit(cache=True, inline="always")
def _contact_point_velocity(ball: int, lever_sign: float, s: State, w: Scratch, out: np.ndarray) -> None:
    """Velocity of the point of ``ball`` at lever_sign·R·n from its centre (n = ``w.normal``)."""
    for axis in range(3):
        w.lever[axis] = lever_sign * w.normal[axis]
    _cross_into(s.spin[ball], w.lever, out)
    for axis in range(3):
        out[axis] += s.velocity[ball, axis]


@njit(cache=True, inline="always")
def _engage(slot: int, t: float, overlap: float, modulus: float, shear_modulus: float, radius: float, mass: float,
            ball_radius: float, dt: float, k: Constants, s: State, w: Scratch, live: int) -> int:
    """A touching slot (ball pair or wall): start its record if it is new, its response with these effective
    values, the tangential force's torque on ball i (of radius ``ball_radius``); returns the live-slot count."""
    if not s.contacts.active[slot]:
        _touch(slot, t, s, w)
    _response(slot, overlap, w.relative_spin, modulus, shear_modulus, radius, mass, dt, k, s, w)
    _scaled_into(w.normal, -ball_radius, w.lever)
    _cross_into(w.lever, w.tangential_force[slot], w.lever_torque_i[slot])
    w.touching[slot] = True
    w.live[live] = slot
    return live + 1


@njit(cache=True, inline="always")
def _pair_contacts(t: float, dt: float, k: Constants, s: State, w: Scratch, live: int) -> tuple[int, float]:
    """Responses of the touching ball pairs; returns the live-slot count and the deepest overlap (m)."""
    n = k.n_balls
    deepest = 0.0
    for i in range(n):
        for j in range(i + 1, n):
            slot = i * n + j
            distance = _distance(s.position[i], s.position[j])
            overlap = k.radius[i] + k.radius[j] - distance
            if overlap <= 0.0:
                live = _release_if_touching(slot, s, w, live)
                continue
            deepest = max(deepest, overlap)
            for axis in range(3):
                w.normal[axis] = (s.position[i, axis] - s.position[j, axis]) / distance
            _contact_point_velocity(i, -k.radius[i], s, w, w.point_velocity)
            _contact_point_velocity(j, k.radius[j], s, w, w.other_velocity)
            w.point_velocity[:] -= w.other_velocity
            _difference_into(s.spin[i], s.spin[j], w.relative_spin)
            live = _engage(slot, t, overlap, k.pair_modulus[i, j], k.pair_shear_modulus[i, j], k.pair_radius[i, j],
                           k.pair_mass[i, j], k.radius[i], dt, k, s, w, live)
            _scaled_into(w.lever_torque_i[slot], k.radius[j] / k.radius[i], w.lever_torque_j[slot])
            w.wall_velocity[slot, :] = 0.0
    return live, deepest


@njit(cache=True, inline="always")
def _wall_contacts(t: float, dt: float, k: Constants, s: State, w: Scratch, live: int) -> tuple[int, float]:
    """Responses of the balls touching the vial's walls; returns the live-slot count and the deepest overlap."""
    n = k.n_balls
    deepest = 0.0
    for i in range(n):
        for wall in range(N_WALLS):
            slot = n * n + N_WALLS * i + wall
            overlap = -wall_gap(s.position[i], k.radius[i], wall, k, w)
            if overlap <= 0.0:
                live = _release_if_touching(slot, s, w, live)
                continue
            deepest = max(deepest, overlap)
            # The vial's velocity at the contact point c = r − R·n: ṙ_v + Ω × (c − r_v).
            for axis in range(3):
                w.lever[axis] = s.position[i, axis] - k.radius[i] * w.normal[axis] - w.coordinates[axis]
            _cross_into(w.angular, w.lever, w.other_velocity)
            for axis in range(3):
                w.wall_velocity[slot, axis] = w.rates[axis] + w.other_velocity[axis]
            _contact_point_velocity(i, -k.radius[i], s, w, w.point_velocity)
            w.point_velocity[:] -= w.wall_velocity[slot]
            _difference_into(s.spin[i], w.angular, w.relative_spin)
            live = _engage(slot, t, overlap, k.wall_modulus[i], k.wall_shear_modulus[i], k.wall_radius[i, wall],
                           k.mass[i], k.radius[i], dt, k, s, w, live)
            w.lever_torque_j[slot, :] = 0.0
    return live, deepest


@njit(cache=True, inline="always")
def _sum_forces(live: int, k: Constants, s: State, w: Scratch) -> None:
    """The new contact forces and torques on every ball (gravity apart)."""
    n = k.n_balls
    s.force[:, :] = 0.0
    s.torque[:, :] = 0.0
    for index in range(live):
        slot = w.live[index]
        i = slot // n if slot < n * n else (slot - n * n) // N_WALLS
        for axis in range(3):
            force = w.normal_force[slot, axis] + w.tangential_force[slot, axis]
            s.force[i, axis] += force
            s.torque[i, axis] += w.lever_torque_i[slot, axis] + w.rolling_torque[slot, axis]
            if slot < n * n:
                j = slot % n
                s.force[j, axis] -= force
                s.torque[j, axis] += w.lever_torque_j[slot, axis] - w.rolling_torque[slot, axis]


@njit(cache=True, inline="always")
def _mean_work(slot: int, i: int, j: int, dt: float, s: State, w: Scratch) -> tuple[float, float, float, float]:
    """(normal, tangential, rolling) work the contact in ``slot`` absorbed over the step, and the vial's work
    through it (J); ``j`` < 0 for a wall. Means of the step's two ends, as the half kicks apply them."""
    c = s.contacts
    normal = tangential = rolling = vial = 0.0
    for axis in range(3):
        normal_force = 0.5 * (c.normal_force[slot, axis] + w.normal_force[slot, axis])
        tangential_force = 0.5 * (c.tangential_force[slot, axis] + w.tangential_force[slot, axis])
        rolling_torque = 0.5 * (c.rolling_torque[slot, axis] + w.rolling_torque[slot, axis])
        lever_i = 0.5 * (c.lever_torque_i[slot, axis] + w.lever_torque_i[slot, axis])
        velocity_i = 0.5 * (w.velocity_before[i, axis] + s.velocity[i, axis])
        spin_i = 0.5 * (w.spin_before[i, axis] + s.spin[i, axis])
        if j >= 0:
            other_velocity = 0.5 * (w.velocity_before[j, axis] + s.velocity[j, axis])
            other_spin = 0.5 * (w.spin_before[j, axis] + s.spin[j, axis])
            tangential -= 0.5 * (c.lever_torque_j[slot, axis] + w.lever_torque_j[slot, axis]) * other_spin
        else:
            before = c.wall_velocity[slot, axis] if c.active[slot] else w.wall_velocity[slot, axis]
            after = w.wall_velocity[slot, axis] if w.touching[slot] else before
            other_velocity = 0.5 * (before + after)
            other_spin = 0.5 * (w.angular_before[axis] + w.angular[axis])
            vial += (normal_force + tangential_force) * other_velocity + rolling_torque * other_spin
        normal -= normal_force * (velocity_i - other_velocity)
        tangential -= tangential_force * (velocity_i - other_velocity) + lever_i * spin_i
        rolling -= rolling_torque * (spin_i - other_spin)
    return normal * dt, tangential * dt, rolling * dt, vial * dt


@njit(cache=True, inline="always")
def _settle(slot: int, t: float, dt: float, k: Constants, s: State, w: Scratch, records: np.ndarray,
            count: int) -> int:
    """Book the step's work of the contact in ``slot`` by channel, turn it into heat, keep the new forces,
    and close the contact's record if it ended. Returns the record count."""
    n = k.n_balls
    c = s.contacts
    pair = slot < n * n
    i = slot // n if pair else (slot - n * n) // N_WALLS
    j = slot % n if pair else -1
    normal, tangential, rolling, vial = _mean_work(slot, i, j, dt, s, w)
    normal -= w.elastic_energy[slot] - c.elastic_energy[slot]
    # The spring energy ½k_t|δ_t|² changes by stretching (its own work, from the tangential work) and by
    # stiffening with the overlap (a supply of the model's own, booked apart: model.TOTAL_NAMES). A step at
    # the Coulomb limit sets the stretch from the new stiffness, the old stretch having slipped away: only
    # the new one stiffens. (Both splits add up to the change exactly; the midpoint one, used otherwise, would
    # book huge opposite terms where k_t jumps by orders of magnitude in a contact's first steps.)
    if c.slip_loss[slot] > 0.0:
        stiffened_stretch, stretching_stiffness = w.stretch[slot], c.stiffness[slot]
    else:
        stiffened_stretch = 0.5 * (w.stretch[slot] + c.stretch[slot])
        stretching_stiffness = 0.5 * (w.stiffness[slot] + c.stiffness[slot])
    tangential -= 0.5 * stretching_stiffness * (w.stretch[slot] - c.stretch[slot])
    s.totals[WORK_STIFFENING] += 0.5 * stiffened_stretch * (w.stiffness[slot] - c.stiffness[slot])
    # Sliding dissipates μF_n⁺|slip| (MODEL.md §12.4); the rest of the tangential work, the damper's.
    sliding = c.slip_loss[slot]
    channels = (normal, tangential - sliding, sliding, rolling)
    totals = (DISSIPATED_NORMAL, DISSIPATED_TANGENTIAL, DISSIPATED_SLIDING, DISSIPATED_ROLLING)
    dissipated = 0.0
    for channel in range(4):
        c.dissipated[slot, channel] += channels[channel]
        s.totals[totals[channel]] += channels[channel]
        dissipated += channels[channel]
    heat = k.eta * dissipated
    share = k.pair_heat_share[i, j] if pair else k.lam
    other = j if pair else n
    s.totals[WORK_VIAL] += vial
    s.totals[HEAT_GENERATED] += heat
    for node, part in ((i, share * heat), (other, (1.0 - share) * heat)):
        s.pending_heat[node] += part
        s.heat_into[node] += part
    c.normal_force[slot] = w.normal_force[slot]
    c.tangential_force[slot] = w.tangential_force[slot]
    c.lever_torque_i[slot] = w.lever_torque_i[slot]
    c.lever_torque_j[slot] = w.lever_torque_j[slot]
    c.rolling_torque[slot] = w.rolling_torque[slot]
    c.wall_velocity[slot] = w.wall_velocity[slot]
    c.elastic_energy[slot] = w.elastic_energy[slot]
    c.stiffness[slot] = w.stiffness[slot]
    c.stretch[slot] = w.stretch[slot]
    c.active[slot] = w.touching[slot]
    if w.touching[slot]:
        return count
    row = records[count]
    row[0], row[1], row[2] = c.started[slot], i, j if pair else -1 - (slot - n * n) % N_WALLS
    row[3], row[4] = c.normal_speed_in[slot], c.tangential_speed_in[slot]
    row[5:9] = c.dissipated[slot]
    row[9], row[10], row[11] = c.peak_force[slot], c.max_overlap[slot], t - c.started[slot]
    total = k.eta * (c.dissipated[slot, 0] + c.dissipated[slot, 1] + c.dissipated[slot, 2] + c.dissipated[slot, 3])
    row[12], row[13] = share * total, (1.0 - share) * total
    c.spring[slot, :] = 0.0
    return count + 1


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
            _cross_into(w.angular, w.lever, w.other_velocity)
            for axis in range(3):
                relative = s.velocity[i, axis] - w.rates[axis] - w.other_velocity[axis]
                speed_squared += relative * relative
        else:
            speed_squared = _dot(s.velocity[i], s.velocity[i])
        reynolds = thermal.reynolds_number(k.radius[i], k.air_density, math.sqrt(speed_squared), k.viscosity_ambient)
        term = thermal.whitaker_velocity_term(reynolds) * dt
        s.pending_velocity_term[i] += term
        s.velocity_term_integral[i] += term


@njit(cache=True)
def advance_thermal(k: Constants, s: State, flow: np.ndarray) -> None:
    """Advance the N + 2 node network (:mod:`network`) over the time gathered since its last update, with
    the heat and mean Whitaker terms of that time (explicit Euler, which conserves energy exactly)."""
    span = s.clock[1]
    if span <= 0.0:
        return
    n = k.n_balls
    theta = s.temperature
    for i in range(n):
        s.pending_velocity_term[i] /= span
    network.flows(theta, s.pending_velocity_term, k, flow)
    for i in range(n):
        theta[i] += (s.pending_heat[i] - flow[i] * span) / k.capacity_ball[i]
        theta[n + 1] += flow[i] * span / k.capacity_air
    theta[n + 1] += flow[n] * span / k.capacity_air
    theta[n] += (s.pending_heat[n] - (flow[n] + flow[n + 1]) * span) / k.capacity_vial
    s.totals[HEAT_LOST] += flow[n + 1] * span
    s.pending_heat[:] = 0.0
    s.pending_velocity_term[:] = 0.0
    s.clock[1] = 0.0


@njit(cache=True)
def _time_to_close(gap: float, speed: float, acceleration: float) -> float:
    """Shortest time in which a gap (m) closing at most at ``speed`` and ``acceleration`` can close (s)."""
    if gap <= 0.0:
        return 0.0
    if acceleration <= 0.0:
        return gap / speed if speed > 0.0 else math.inf
    return (math.sqrt(speed * speed + 2.0 * acceleration * gap) - speed) / acceleration


@njit(cache=True, inline="always")
def _flight_step(k: Constants, s: State, w: Scratch) -> float:
    """The longest step in which no contact can begin (MODEL.md §12.6), within [contact_step, max_flight_step].

    A ball's centre moves in the vial frame at its velocity relative to the vial's point under it, which can
    change at most by gravity, the vial's acceleration and the Coriolis term within a step, and by the contact
    forces on it (taken twice their last value: they are those of slow contacts, or the step is a contact step
    anyway; in flight they are zero). Its distance from an end face closes at most at the axial part of that
    velocity, its distance from the axis grows at most at the part across the axis (a norm bound, so the
    bore's curvature needs no term of its own). Touching slots are left out: their contacts have begun.
    """
    n = k.n_balls
    step = k.max_flight_step
    axis = w.orientation[:, 0]
    active = s.contacts.active
    for i in range(n):
        for component in range(3):
            w.lever[component] = s.position[i, component] - w.coordinates[component]
        _cross_into(w.angular, w.lever, w.other_velocity)
        for component in range(3):
            w.point_velocity[component] = s.velocity[i, component] - w.rates[component] - w.other_velocity[component]
        along = _dot(w.point_velocity, axis)
        across = math.sqrt(max(_dot(w.point_velocity, w.point_velocity) - along * along, 0.0))
        pushed = 2.0 * _norm(s.force[i]) / k.mass[i]
        acceleration = (_norm(k.gravity) + k.wall_acceleration_bound + 2.0 * k.angular_speed_bound * (abs(along) + across)
                        + pushed)
        for wall in range(N_WALLS):
            if active[n * n + N_WALLS * i + wall]:
                continue
            gap = wall_gap(s.position[i], k.radius[i], wall, k, w)
            closing = across if wall == SIDE else (-along if wall == LEFT_END else along)
            step = min(step, _time_to_close(gap, max(closing, 0.0), acceleration))
        for j in range(i + 1, n):
            if active[i * n + j]:
                continue
            # Both balls fall alike in flight: their relative motion changes only by the contact forces.
            gap = _distance(s.position[i], s.position[j]) - k.radius[i] - k.radius[j]
            relative_acceleration = pushed + 2.0 * _norm(s.force[j]) / k.mass[j]
            step = min(step, _time_to_close(gap, _distance(s.velocity[i], s.velocity[j]), relative_acceleration))
    return max(step, k.contact_step)


@njit(cache=True, inline="always")
def _step_length(touching: int, period: float, k: Constants, s: State, w: Scratch) -> float:
    """The next step (MODEL.md §12.6). In flight, :func:`_flight_step`. Inside contacts, contact_step_fraction
    of the longer of the smallest Rayleigh time and 1/9.5 of ``period``, the shortest period of the touching
    contacts (:func:`contact.contact_period`, from each one's overlap and normal speed at its last evaluation),
    so that impacts keep the Rayleigh step and slow, lasting contacts take longer ones (never beyond 0.9 t_R,
    MODEL.md §7); a step longer than the Rayleigh one is also bounded as a flight step by the slots not
    touching, so that no contact begins inside it."""
    if not touching:
        return _flight_step(k, s, w)
    step = max(k.contact_step, min(k.period_step_fraction * period, k.longest_contact_step))
    if step <= k.contact_step:
        return k.contact_step
    return min(step, _flight_step(k, s, w))


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
def _step(t: float, dt: float, k: Constants, s: State, w: Scratch, records: np.ndarray,
          count: int) -> tuple[int, int, float, float]:
    """One velocity-Verlet step of length ``dt`` ending at ``t``; returns (record count, contacts touching,
    deepest overlap, shortest period of the touching contacts)."""
    w.angular_before[:] = w.angular
    _kick_and_drift(dt, k, s, w)
    vial_frame(t, k, w)
    live, deepest_pair = _pair_contacts(t, dt, k, s, w, 0)
    live, deepest_wall = _wall_contacts(t, dt, k, s, w, live)
    _sum_forces(live, k, s, w)
    _final_kick(dt, k, s, w)
    touching = 0
    period = math.inf
    for index in range(live):
        slot = w.live[index]
        count = _settle(slot, t, dt, k, s, w, records, count)
        if w.touching[slot]:
            touching += 1
            period = min(period, s.contacts.period[slot])
    _convect(dt, k, s, w)
    s.clock[0] = t
    s.clock[1] += dt
    return count, touching, max(deepest_pair, deepest_wall), period


@njit(cache=True)
def write_row(k: Constants, s: State, w: Scratch, row: np.ndarray) -> None:
    """The state now as a row laid out as :func:`model.row_fields` says (the thermal network brought up to now)."""
    advance_thermal(k, s, w.flow)
    vial_frame(s.clock[0], k, w)
    row[0] = s.clock[0]
    offset = 1
    for block in (s.position.ravel(), s.velocity.ravel(), s.spin.ravel(), s.temperature, s.totals, s.heat_into,
                  s.velocity_term_integral, w.coordinates):
        row[offset : offset + block.size] = block
        offset += block.size


@njit(cache=True)
def advance(t_stop: float, max_steps: int, k: Constants, s: State, w: Scratch, records: np.ndarray, count: int,
            counters: np.ndarray, marks: np.ndarray, rows: np.ndarray) -> tuple[int, int]:
    """Step to ``t_stop`` (s); returns (status, record count). Steps end on each time in ``marks`` (sorted),
    where the state is written into the next row of ``rows``. Hands back early with PAUSED after ``max_steps``
    steps and with RECORDS_FULL when ``records`` may overflow; the thermal network is brought up to the time
    reached either way."""
    slots = s.contacts.active.size
    vial_frame(s.clock[0], k, w)
    touching = 0
    period = math.inf
    for slot in range(slots):
        if s.contacts.active[slot]:
            touching += 1
            period = min(period, s.contacts.period[slot])
    status = REACHED_STOP
    steps = 0
    while s.clock[0] < t_stop:
        if steps >= max_steps:
            status = PAUSED
            break
        if count + slots > records.shape[0]:
            status = RECORDS_FULL
            break
        dt = _step_length(touching, period, k, s, w)
        mark = counters[ROWS_WRITTEN]
        end = min(t_stop, marks[mark]) if mark < marks.size else t_stop
        remaining = end - s.clock[0]
        t = end if dt >= remaining else s.clock[0] + dt
        before = count
        count, touching, deepest, period = _step(t, min(dt, remaining), k, s, w, records, count)
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
            advance_thermal(k, s, w.flow)
            counters[THERMAL_UPDATES] += 1
        if mark < marks.size and t == marks[mark]:
            write_row(k, s, w, rows[mark])
            counters[ROWS_WRITTEN] += 1
    if status == REACHED_STOP:
        # Not when handing back early: where that happens depends on the wall clock, and the numbers must not.
        advance_thermal(k, s, w.flow)
    return status, count
