"""A horizontal mixer mill (Retsch MM400 type): the jar swings on a horizontal arc about a vertical pivot.

No source reachable here gives the swing radius or the stroke of a Retsch MM400 (docs/notes/dem-references.md,
section 2.4): both are stated assumptions, keys of their own so that they can be swept."""

from __future__ import annotations

import math
from typing import Any

from shakermill.parameters.motions import MAX_MOTION_HARMONIC, KinematicModel, Term

# The arc's Bessel series: terms smaller than this fraction of the swing radius are dropped. Within the
# widest swing allowed they fall below it before MAX_MOTION_HARMONIC (2R·J_20(π/2) ≈ 6e-21 R).
ARC_TRUNCATION = 1e-12
# A quarter turn either way: a mixer mill swings its jars through a few degrees; beyond a right angle
# the jar's axis would point along the arm.
MAX_SWING_ANGLE = 0.5 * math.pi


def arc_angle(amplitude: float, swing_radius: float) -> float:
    """The swing's angular amplitude α = s/R (rad) of an arc of amplitude s (m, at the jar's centre) on radius R."""
    return amplitude / swing_radius


def arc_terms(amplitude: float, swing_radius: float) -> tuple[Term, ...]:
    """A jar swung on a horizontal arc of radius R about a vertical pivot, φ(t) = α sin θ, α = amplitude/R.

    The pivot is at (0, R, 0); the jar's centre, at rest at the origin with its axis along x (the tangent
    of the arc), is at (R sin φ, R(1 − cos φ), 0) and the jar turns with the arm, yaw = φ. Exact Fourier
    series (Jacobi–Anger): x = 2R Σ_{k≥0} J_{2k+1}(α) sin((2k+1)θ),
    y = R(1 − J_0(α)) − 2R Σ_{k≥1} J_{2k}(α) cos(2kθ), truncated where 2R|J_n(α)| < ARC_TRUNCATION·R.
    """
    # SciPy is imported here, not at start-up: these terms are needed by a run of this motion alone.
    from scipy.special import jv

    alpha = arc_angle(amplitude, swing_radius)
    terms: list[Term] = [("y", 0, swing_radius * (1.0 - float(jv(0, alpha))), 0.0), ("yaw", 1, 0.0, alpha)]
    for n in range(1, MAX_MOTION_HARMONIC + 1):
        coefficient = 2.0 * swing_radius * float(jv(n, alpha))
        if abs(coefficient) < ARC_TRUNCATION * swing_radius:
            break
        terms.append(("x", n, 0.0, coefficient) if n % 2 else ("y", n, -coefficient, 0.0))
    return tuple(terms)


def check_swing(values: Any) -> None:
    """The arc turns the jar at most a quarter turn."""
    angle = arc_angle(values.amplitude, values.swing_radius)
    if angle > MAX_SWING_ANGLE:
        raise ValueError(
            f"amplitude: an arc of {values.amplitude * 1e3:g} mm on a swing radius of {values.swing_radius * 1e3:g} "
            f"mm turns the jar by {angle:.3g} rad; allowed amplitude <= swing_radius·π/2 = "
            f"{values.swing_radius * MAX_SWING_ANGLE:.4g} m with kinematics = 'mixer-mill-arc'"
        )


MOTION = KinematicModel(
    "mixer-mill-arc",
    "horizontal mixer mill (Retsch MM400 type): the jar swings on a horizontal arc about a vertical pivot",
    arc_terms,
    assumed=("amplitude", "swing_radius"),
    check=check_swing,
)
