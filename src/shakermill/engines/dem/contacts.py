"""Contacts of the 'dem' engine, compiled (MODEL.md sections 12.3-12.4): the gap to each wall, the Hertz–Mindlin
response of a touching pair or ball and wall, the forces summed on each ball, each contact's work over a step
booked by dissipation channel and turned into heat in the balls and the vial, and the contacts carried to their
entries when the neighbour list is rebuilt."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from shakermill.engines.dem import neighbours
from shakermill.engines.dem.model import (
    DISSIPATED_NORMAL,
    DISSIPATED_ROLLING,
    DISSIPATED_SLIDING,
    DISSIPATED_TANGENTIAL,
    HEAT_GENERATED,
    LEFT_END,
    N_WALLS,
    RIGHT_END,
    WORK_STIFFENING,
    WORK_VIAL,
    Constants,
    Contacts,
    Scratch,
    State,
)
from shakermill.engines.dem.vectors import copy_into, cross_into, difference_into, distance, dot, norm, scaled_into
from shakermill.engines.thermal import kernel
from shakermill.physics import contact, heat_paths


@njit(cache=True, inline="always")
def wall_gap(position: np.ndarray, radius: float, wall: int, k: Constants, w: Scratch) -> float:
    """Gap (m; negative: overlap) between a ball and ``wall``; ``w.normal`` gets the unit normal into the ball."""
    q = w.orientation
    rx = position[0] - w.coordinates[0]
    ry = position[1] - w.coordinates[1]
    rz = position[2] - w.coordinates[2]
    axial = q[0, 0] * rx + q[1, 0] * ry + q[2, 0] * rz
    if wall == LEFT_END:
        scaled_into(q[:, 0], 1.0, w.normal)
        return axial + k.half_length - radius
    if wall == RIGHT_END:
        scaled_into(q[:, 0], -1.0, w.normal)
        return k.half_length - axial - radius
    across_1 = q[0, 1] * rx + q[1, 1] * ry + q[2, 1] * rz
    across_2 = q[0, 2] * rx + q[1, 2] * ry + q[2, 2] * rz
    off_axis = math.hypot(across_1, across_2)
    if off_axis > 0.0:
        for axis in range(3):
            w.normal[axis] = -(q[axis, 1] * across_1 + q[axis, 2] * across_2) / off_axis
    else:
        scaled_into(q[:, 2], -1.0, w.normal)
    return k.bore_radius - off_axis - radius


@njit(cache=True)
def measure_wall_gaps(k: Constants, s: State, w: Scratch) -> None:
    """Every ball's gap to every wall now into ``w.wall_gaps`` (:func:`wall_contacts` keeps them as it goes)."""
    for i in range(k.n_balls):
        for wall in range(N_WALLS):
            w.wall_gaps[N_WALLS * i + wall] = wall_gap(s.position[i], k.radius[i], wall, k, w)


@njit(cache=True)
def pair_values(i: int, j: int, k: Constants) -> tuple[float, float, float, float, float]:
    """E*, G* (Pa), R* (m) and m* (kg) of balls i and j (MODEL.md §12.3), and the share of their contacts' heat that
    goes to ball i (by effusivity, MODEL.md §12.4)."""
    youngs, poisson = k.youngs_modulus, k.poisson_ratio
    return (
        contact.effective_modulus(youngs[i], poisson[i], youngs[j], poisson[j]),
        contact.effective_shear_modulus(youngs[i], poisson[i], youngs[j], poisson[j]),
        k.radius[i] * k.radius[j] / (k.radius[i] + k.radius[j]),
        k.mass[i] * k.mass[j] / (k.mass[i] + k.mass[j]),
        k.effusivity[i] / (k.effusivity[i] + k.effusivity[j]),
    )


@njit(cache=True, inline="always")
def bodies(slot: int, k: Constants, s: State) -> tuple[int, int, int]:
    """The ball of a contact slot, the other ball (−1 for a wall) and the wall (−1 for a pair)."""
    walls = N_WALLS * k.n_balls
    if slot < walls:
        return slot // N_WALLS, -1, slot % N_WALLS
    entry = slot - walls
    return s.neighbours.first_ball[entry], s.neighbours.second_ball[entry], -1


@njit(cache=True, inline="always")
def _response(
    slot: int,
    overlap: float,
    relative_spin: np.ndarray,
    modulus: float,
    shear_modulus: float,
    radius: float,
    mass: float,
    beta_e: float,
    friction: float,
    dt: float,
    k: Constants,
    s: State,
    w: Scratch,
) -> None:
    """Normal, tangential and rolling response of a contact (MODEL.md §12.3) into ``w``'s arrays of ``slot``, with
    the damping ratio ``beta_e`` and Coulomb coefficient ``friction`` of its pair of bodies.

    ``w.normal`` points into ball i; ``w.point_velocity`` is i's contact point's velocity relative to the
    other body's. Updates the tangential spring and the running contact's record in place.
    """
    c = s.contacts
    normal, relative = w.normal, w.point_velocity
    approach = dot(relative, normal)
    # A contact that began inside this step starts with an unstretched spring: it did not exist for the
    # step's earlier part, which in free flight can be far longer than a contact step.
    stretching = dt if c.active[slot] else 0.0
    elastic = contact.hertz_force(overlap, modulus, radius)
    damping = contact.damping_coefficient(overlap, mass, radius, modulus, beta_e)
    magnitude = contact.contact_force(elastic, damping, -approach, k.no_tension)
    w.elastic_energy[slot] = contact.elastic_energy(overlap, modulus, radius)
    spring = c.spring[slot]
    length = norm(spring)
    along = dot(spring, normal)
    for axis in range(3):  # the spring turns with the tangent plane, keeping its length
        spring[axis] -= along * normal[axis]
    turned = norm(spring)
    if turned > 0.0:
        scaled_into(spring, length / turned, spring)
    stiffness = contact.tangential_stiffness(shear_modulus, radius, overlap)
    damping_t = contact.tangential_damping(beta_e, stiffness, mass)
    pressing = max(magnitude, 0.0)
    limit = friction * pressing
    c.slip_loss[slot] = 0.0
    for axis in range(3):
        sliding = relative[axis] - approach * normal[axis]
        spring[axis] += sliding * stretching
        w.normal_force[slot, axis] = magnitude * normal[axis]
        w.tangential_force[slot, axis] = -stiffness * spring[axis] - damping_t * sliding
    size = norm(w.tangential_force[slot])
    if size > limit:
        # The force is scaled down to the Coulomb limit, and the spring with it (so that without a damper the
        # spring alone gives the limit): its end slips by the part of the stretch it loses, and sliding
        # dissipates μF_n⁺·|slip|. Holding the whole force in the spring instead would stretch it absurdly
        # where k_t is tiny, in a contact's first step, when the damper gives most of the trial force.
        ratio = limit / size
        c.slip_loss[slot] = limit * (1.0 - ratio) * norm(spring)
        scaled_into(w.tangential_force[slot], ratio, w.tangential_force[slot])
        scaled_into(spring, ratio, spring)
    w.stiffness[slot] = stiffness
    w.stretch[slot] = dot(spring, spring)
    spin = norm(relative_spin)
    for axis in range(3):
        w.rolling_torque[slot, axis] = (
            -k.rolling_friction * radius * pressing * relative_spin[axis] / spin if spin > 0 else 0.0
        )
    c.period[slot] = contact.contact_period(mass, radius, modulus, shear_modulus, overlap, approach)
    if not c.active[slot]:
        c.impact_period[slot] = c.period[slot]
    c.release[slot] = overlap / approach if approach > 0.0 else math.inf
    c.peak_force[slot] = max(c.peak_force[slot], abs(magnitude))
    c.max_overlap[slot] = max(c.max_overlap[slot], overlap)


@njit(cache=True, inline="always")
def _touch(slot: int, t: float, s: State, w: Scratch) -> None:
    """A contact begins in ``slot`` at ``t``: start its record from the approach velocities."""
    c = s.contacts
    approach = dot(w.point_velocity, w.normal)
    c.started[slot] = t
    c.normal_speed_in[slot] = -approach
    c.tangential_speed_in[slot] = math.sqrt(max(dot(w.point_velocity, w.point_velocity) - approach * approach, 0.0))
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
    cross_into(s.spin[ball], w.lever, out)
    for axis in range(3):
        out[axis] += s.velocity[ball, axis]


@njit(cache=True, inline="always")
def _engage(
    slot: int,
    t: float,
    overlap: float,
    modulus: float,
    shear_modulus: float,
    radius: float,
    mass: float,
    ball_radius: float,
    dt: float,
    k: Constants,
    s: State,
    w: Scratch,
    live: int,
) -> int:
    """A touching slot (ball pair or wall): start its record if it is new, its response with these effective
    values and its pair's restitution and friction, the tangential force's torque on ball i (of radius
    ``ball_radius``); returns the live-slot count."""
    if not s.contacts.active[slot]:
        _touch(slot, t, s, w)
    pair = slot >= N_WALLS * k.n_balls
    beta_e, friction = (k.pair_beta_e, k.pair_friction) if pair else (k.beta_e, k.friction)
    _response(slot, overlap, w.relative_spin, modulus, shear_modulus, radius, mass, beta_e, friction, dt, k, s, w)
    scaled_into(w.normal, -ball_radius, w.lever)
    cross_into(w.lever, w.tangential_force[slot], w.lever_torque_i[slot])
    w.touching[slot] = True
    w.live[live] = slot
    return live + 1


@njit(cache=True, inline="always")
def pair_contacts(t: float, dt: float, k: Constants, s: State, w: Scratch, live: int) -> tuple[int, float]:
    """Responses of the touching pairs of the neighbour list; returns the live-slot count and the deepest overlap
    (m)."""
    nb = s.neighbours
    walls = N_WALLS * k.n_balls
    deepest = 0.0
    for entry in range(nb.entries[0]):
        i, j = nb.first_ball[entry], nb.second_ball[entry]
        slot = walls + entry
        centres = distance(s.position[i], s.position[j])
        overlap = k.radius[i] + k.radius[j] - centres
        if overlap <= 0.0:
            live = _release_if_touching(slot, s, w, live)
            continue
        deepest = max(deepest, overlap)
        for axis in range(3):
            w.normal[axis] = (s.position[i, axis] - s.position[j, axis]) / centres
        _contact_point_velocity(i, -k.radius[i], s, w, w.point_velocity)
        _contact_point_velocity(j, k.radius[j], s, w, w.other_velocity)
        difference_into(w.point_velocity, w.other_velocity, w.point_velocity)
        difference_into(s.spin[i], s.spin[j], w.relative_spin)
        modulus, shear_modulus, radius, mass, _ = pair_values(i, j, k)
        live = _engage(slot, t, overlap, modulus, shear_modulus, radius, mass, k.radius[i], dt, k, s, w, live)
        scaled_into(w.lever_torque_i[slot], k.radius[j] / k.radius[i], w.lever_torque_j[slot])
        w.wall_velocity[slot, :] = 0.0
    return live, deepest


@njit(cache=True, inline="always")
def wall_contacts(t: float, dt: float, k: Constants, s: State, w: Scratch, live: int) -> tuple[int, float]:
    """Responses of the balls touching the vial's walls; returns the live-slot count and the deepest overlap."""
    n = k.n_balls
    deepest = 0.0
    for i in range(n):
        for wall in range(N_WALLS):
            slot = N_WALLS * i + wall
            w.wall_gaps[slot] = wall_gap(s.position[i], k.radius[i], wall, k, w)
            overlap = -w.wall_gaps[slot]
            if overlap <= 0.0:
                live = _release_if_touching(slot, s, w, live)
                continue
            deepest = max(deepest, overlap)
            # The vial's velocity at the contact point c = r − R·n: ṙ_v + Ω × (c − r_v).
            for axis in range(3):
                w.lever[axis] = s.position[i, axis] - k.radius[i] * w.normal[axis] - w.coordinates[axis]
            cross_into(w.angular, w.lever, w.other_velocity)
            for axis in range(3):
                w.wall_velocity[slot, axis] = w.rates[axis] + w.other_velocity[axis]
            _contact_point_velocity(i, -k.radius[i], s, w, w.point_velocity)
            difference_into(w.point_velocity, w.wall_velocity[slot], w.point_velocity)
            difference_into(s.spin[i], w.angular, w.relative_spin)
            live = _engage(
                slot,
                t,
                overlap,
                k.wall_modulus[i],
                k.wall_shear_modulus[i],
                k.wall_radius[i, wall],
                k.mass[i],
                k.radius[i],
                dt,
                k,
                s,
                w,
                live,
            )
            w.lever_torque_j[slot, :] = 0.0
    return live, deepest


@njit(cache=True, inline="always")
def sum_forces(live: int, k: Constants, s: State, w: Scratch) -> None:
    """The new contact forces and torques on every ball (gravity apart)."""
    s.force[:, :] = 0.0
    s.torque[:, :] = 0.0
    for index in range(live):
        slot = w.live[index]
        i, j, _ = bodies(slot, k, s)
        for axis in range(3):
            force = w.normal_force[slot, axis] + w.tangential_force[slot, axis]
            s.force[i, axis] += force
            s.torque[i, axis] += w.lever_torque_i[slot, axis] + w.rolling_torque[slot, axis]
            if j >= 0:
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
def settle(slot: int, t: float, dt: float, k: Constants, s: State, w: Scratch, records: np.ndarray, count: int) -> int:
    """Book the step's work of the contact in ``slot`` by channel, turn it into heat, keep the new forces,
    and close the contact's record if it ended. Returns the record count."""
    c = s.contacts
    i, j, wall = bodies(slot, k, s)
    pair = j >= 0
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
    share = pair_values(i, j, k)[4] if pair else k.lam
    other = j if pair else k.n_balls
    s.totals[WORK_VIAL] += vial
    s.totals[HEAT_GENERATED] += heat
    kept = heat - _deposit(int(pair), channels, k, s)
    for node, part in ((i, share * kept), (other, (1.0 - share) * kept)):
        s.pending_heat[node] += part
        s.heat_into[node] += part
    copy_into(w.normal_force[slot], c.normal_force[slot])
    copy_into(w.tangential_force[slot], c.tangential_force[slot])
    copy_into(w.lever_torque_i[slot], c.lever_torque_i[slot])
    copy_into(w.lever_torque_j[slot], c.lever_torque_j[slot])
    copy_into(w.rolling_torque[slot], c.rolling_torque[slot])
    copy_into(w.wall_velocity[slot], c.wall_velocity[slot])
    c.elastic_energy[slot] = w.elastic_energy[slot]
    c.stiffness[slot] = w.stiffness[slot]
    c.stretch[slot] = w.stretch[slot]
    c.active[slot] = w.touching[slot]
    if w.touching[slot]:
        return count
    row = records[count]
    row[0], row[1], row[2] = c.started[slot], i, j if pair else -1 - wall
    row[3], row[4] = c.normal_speed_in[slot], c.tangential_speed_in[slot]
    for channel in range(4):
        row[5 + channel] = c.dissipated[slot, channel]
    row[9], row[10], row[11] = c.peak_force[slot], c.max_overlap[slot], t - c.started[slot]
    total = k.eta * (c.dissipated[slot, 0] + c.dissipated[slot, 1] + c.dissipated[slot, 2] + c.dissipated[slot, 3])
    deposited = _deposited(int(pair), c.dissipated[slot], k)
    row[12], row[13] = share * (total - deposited), (1.0 - share) * (total - deposited)
    row[14] = _conduct(slot, i, j, wall, row[11], k, s)
    row[15] = deposited
    c.spring[slot, :] = 0.0
    return count + 1


@njit(cache=True, inline="always")
def _deposit_share(kind: int, channels: Any, deposit: int, k: Constants) -> float:
    """The heat (J) of ``channels``' dissipation (J, in HEAT_CHANNELS order) of a contact of ``kind`` (0: a wall, 1:
    a pair) that ``deposit`` takes for its node, neither of the two bodies (``network.deposits``: the powder)."""
    part = 0.0
    for channel in range(4):
        part += k.eta * channels[channel] * k.deposit_shares[kind, channel, deposit]
    return part


@njit(cache=True, inline="always")
def _deposited(kind: int, channels: Any, k: Constants) -> float:
    """What all deposits take of a contact's heat (J, :func:`_deposit_share`)."""
    deposited = 0.0
    for deposit in range(k.deposit_count):
        deposited += _deposit_share(kind, channels, deposit, k)
    return deposited


@njit(cache=True, inline="always")
def _deposit(kind: int, channels: Any, k: Constants, s: State) -> float:
    """Put each deposit's share of a step's heat (:func:`_deposit_share`) into its node; their sum (J)."""
    deposited = 0.0
    for deposit in range(k.deposit_count):
        part = _deposit_share(kind, channels, deposit, k)
        node = k.deposit_nodes[deposit]
        s.pending_heat[node] += part
        s.heat_into[node] += part
        deposited += part
    return deposited


@njit(cache=True, inline="always")
def _conduct(slot: int, i: int, j: int, wall: int, duration: float, k: Constants, s: State) -> float:
    """The heat per kelvin (J/K) the contact that ended in ``slot`` conducted between ball ``i`` and ball ``j``
    (or ``wall`` of the vial, ``j`` = −1) over its ``duration`` (MODEL.md §13.1), gathered for the thermal network;
    returned for its record. Counted when the contact ends, so that a lasting one adds all its conduction at once."""
    if j >= 0:
        radius, effusivity, conductivity = pair_values(i, j, k)[2], k.effusivity[j], k.conductivity[j]
    else:
        radius, effusivity, conductivity = k.wall_radius[i, wall], k.vial_effusivity, k.vial_conductivity
    contact_radius = heat_paths.hertz_contact_radius(radius, s.contacts.max_overlap[slot])
    conducted = heat_paths.contact_conduction(
        contact_radius, duration, k.effusivity[i], effusivity, k.conductivity[i], conductivity
    )
    _add_conduction(kernel.contact_drive(i, j, k.n_balls), conducted, s)
    if j >= 0:  # a pair's conduction counts for its two balls
        _add_conduction(kernel.contact_drive(j, i, k.n_balls), conducted, s)
    return conducted


@njit(cache=True, inline="always")
def _add_conduction(drive: int, conducted: float, s: State) -> None:
    s.pending_drives[drive] += conducted
    s.drive_integrals[drive] += conducted


@njit(cache=True)
def _copy_slot(source: Contacts, a: int, target: Contacts, b: int) -> None:
    """Contact memory of slot ``a`` of ``source`` into slot ``b`` of ``target``."""
    target.active[b] = source.active[a]
    for field_from, field_to in (
        (source.normal_force, target.normal_force),
        (source.tangential_force, target.tangential_force),
        (source.lever_torque_i, target.lever_torque_i),
        (source.lever_torque_j, target.lever_torque_j),
        (source.rolling_torque, target.rolling_torque),
        (source.wall_velocity, target.wall_velocity),
        (source.spring, target.spring),
    ):
        copy_into(field_from[a], field_to[b])
    for scalar_from, scalar_to in (
        (source.elastic_energy, target.elastic_energy),
        (source.stiffness, target.stiffness),
        (source.stretch, target.stretch),
        (source.slip_loss, target.slip_loss),
        (source.period, target.period),
        (source.impact_period, target.impact_period),
        (source.release, target.release),
        (source.started, target.started),
        (source.normal_speed_in, target.normal_speed_in),
        (source.tangential_speed_in, target.tangential_speed_in),
        (source.peak_force, target.peak_force),
        (source.max_overlap, target.max_overlap),
    ):
        scalar_to[b] = scalar_from[a]
    for channel in range(source.dissipated.shape[1]):
        target.dissipated[b, channel] = source.dissipated[a, channel]


@njit(cache=True)
def _clear_slot(c: Contacts, slot: int) -> None:
    """A slot no contact holds: what a step reads of a slot that did not touch at its start (forces, stored energies,
    spring) at zero."""
    c.active[slot] = False
    for vectors in (
        c.normal_force,
        c.tangential_force,
        c.lever_torque_i,
        c.lever_torque_j,
        c.rolling_torque,
        c.wall_velocity,
        c.spring,
    ):
        vectors[slot, :] = 0.0
    c.elastic_energy[slot] = 0.0
    c.stiffness[slot] = 0.0
    c.stretch[slot] = 0.0


@njit(cache=True)
def rebuild_neighbours(k: Constants, s: State, centre: np.ndarray) -> bool:
    """Build the neighbour list anew at the balls' positions and carry each touching pair's contact to its new entry
    (every touching pair is listed again: it lies within r_i + r_j); False if the list cannot hold the pairs."""
    nb, c = s.neighbours, s.contacts
    walls = N_WALLS * k.n_balls
    carried = 0
    for entry in range(nb.entries[0]):
        if c.active[walls + entry]:
            _copy_slot(c, walls + entry, nb.carried, carried)
            nb.carried_first[carried], nb.carried_second[carried] = nb.first_ball[entry], nb.second_ball[entry]
            carried += 1
            _clear_slot(c, walls + entry)
    if not neighbours.build(k, s.position, centre, nb):
        return False
    for index in range(carried):
        entry = neighbours.entry_of(nb, nb.carried_first[index], nb.carried_second[index])
        if entry < 0:
            return False
        _copy_slot(nb.carried, index, c, walls + entry)
    return True
