"""Contacts as events of the 1-D mechanics (MODEL.md §7): where a contact begins within a free-flight step, and
how long steps may be inside a contact.

In flight the ball moves on a straight line and the walls on a sine, so the gap to each wall is known exactly
over a trial step. Its first zero is searched with a curvature bound (|gap''| ≤ X_v·ω²) that rules out a wall
touching and leaving within the step; the step is then shortened to land on the contact onset, so a contact
start is never stepped over. Inside a contact the steps are graded towards both ends of the contact, where the
damping force has a ζ^{1/4} singularity.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from shakermill.engines.one_d.model import LEFT_WALL, NO_WALL, RIGHT_WALL, Constants, gap
from shakermill.physics import kinematics
from shakermill.physics.contact import hertz_contact_time

# Pending intervals of the contact-onset search: one per halving of a step, and a step halves at most
# ~60 times before reaching the resolution of the time variable.
STACK_ROWS = 128
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
# Approach speed (m/s) below which a contact's scales stop shrinking: guards a tangential onset against 0.
SLOWEST_APPROACH = 1e-12
# Relative resolution of the time variable used to stop bisection of a contact onset.
TIME_RESOLUTION = 4.0 * np.finfo(float).eps


@njit(cache=True)
def _gap_rate(t: float, velocity: float, wall: int, k: Constants) -> float:
    """d(gap)/dt in free flight (m/s)."""
    vial_velocity = kinematics.vial_velocity(t, k.amplitude, k.omega, k.phase)
    return velocity - vial_velocity if wall == LEFT_WALL else vial_velocity - velocity


@njit(cache=True)
def _refine_root(
    t: float, x: float, velocity: float, wall: int, k: Constants, a: float, b: float, resolution: float
) -> float:
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
def _first_touch_of_wall(
    t: float, h: float, x: float, velocity: float, wall: int, curvature: float, k: Constants, stack: np.ndarray
) -> float:
    """Earliest s in [0, h] where the free-flight gap to ``wall`` reaches 0, or −1 if none.

    Intervals are examined left to right. One is discarded only when the bound
    gap(s) ≥ min(gap(a), gap(b)) − curvature·(b − a)²/8 proves it free of zeros;
    a sign change is refined once the slope bound |gap'(b)| > curvature·(b − a)
    proves the gap monotone there, so the zero found is the first one.
    ``stack`` is scratch space of at least 2 × 64 rows: each halving leaves one pending interval.
    """
    resolution = TIME_RESOLUTION * max(1.0, abs(t) + h)
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
def rate_into_wall(wall: int, velocity: float, vial_velocity: float) -> float:
    """ζ̇ for ``wall``: positive while the ball and the wall approach (MODEL.md §2)."""
    return vial_velocity - velocity if wall == LEFT_WALL else velocity - vial_velocity


@njit(cache=True)
def shortest_contact_step(speed_in: float, k: Constants) -> float:
    """First and last steps of a contact (s): ONSET_STEP_FRACTION of the Hertz duration at the approach speed."""
    return ONSET_STEP_FRACTION * hertz_contact_time(k.ball_mass, k.radius, k.e_star, max(speed_in, SLOWEST_APPROACH))


@njit(cache=True)
def _separation_step_limit(t: float, x: float, p: float, wall: int, speed_in: float, k: Constants) -> float:
    """Longest contact step that keeps the mesh graded towards the separation (see SEPARATION_GRADING)."""
    vial_velocity = kinematics.vial_velocity(t, k.amplitude, k.omega, k.phase)
    overlap_rate = rate_into_wall(wall, p / k.ball_mass, vial_velocity)
    if overlap_rate >= 0.0:
        return np.inf
    overlap = -gap(t, x, wall, k)
    return max(SEPARATION_GRADING * overlap / -overlap_rate, shortest_contact_step(speed_in, k))


@njit(cache=True)
def bound_step(
    t: float,
    h: float,
    t_stop: float,
    x: float,
    p: float,
    wall: int,
    speed_in: float,
    k: Constants,
    contact_step_limit: float,
    stack: np.ndarray,
) -> tuple[float, int]:
    """The step to try from (t, x, p), at most ``h`` and ending by ``t_stop``, and the wall it ends on.

    In a contact with ``wall`` the step is graded towards the separation. In flight (``wall`` = NO_WALL)
    it is shortened to the first contact onset within it, and the wall it lands on is returned: the flight
    path is exact, so this costs no right-hand-side evaluations, and no trial step runs into a wall.
    """
    h = min(h, t_stop - t)
    if wall != NO_WALL:
        return min(h, contact_step_limit, _separation_step_limit(t, x, p, wall, speed_in, k)), wall
    # Bound on |gap''|: the ball's path is straight, the wall's a sine of amplitude X_v.
    curvature = k.amplitude * k.omega * k.omega
    for candidate in (LEFT_WALL, RIGHT_WALL):
        touch = _first_touch_of_wall(t, h, x, p / k.ball_mass, candidate, curvature, k, stack)
        if touch >= 0.0 and (wall == NO_WALL or touch < h):
            h, wall = touch, candidate
    return h, wall
