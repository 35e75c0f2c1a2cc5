"""A planetary mill (Fritsch Pulverisette, Retsch PM type): a jar on a sun wheel turning at omega, spinning at
speed_ratio relative to it."""

from __future__ import annotations

import math

from shakermill.parameters.motions import KinematicModel, Term


def planetary_terms(revolution_radius: float, speed_ratio: float, jar_tilt: float) -> tuple[Term, ...]:
    """A planetary mill's jar: its centre on a circle of radius R_p about the vertical sun axis, turned by the sun
    wheel at ω (θ = ωt + φ), and the jar spinning about its own axis at k·ω relative to the wheel.

    x = R_p cos θ, y = R_p sin θ; yaw = θ (the wheel), pitch = −π/2 + τ (the jar's axis, the vial frame's x,
    stands up, its top leaning away from the sun axis by the tilt τ), roll = kθ (the jar about its axis). With
    τ = 0 the jar turns in the lab at (1 + k)ω: the ratio k is the jar's speed relative to the wheel, as the
    manufacturers' "1 : −2" (a Retsch PM 100's jar turns twice, the other way, for each turn of the sun wheel).
    The angles grow in time: they are steady rates, the k = 0 sine slot (physics/kinematics.py).
    """
    return (
        ("x", 1, revolution_radius, 0.0),
        ("y", 1, 0.0, revolution_radius),
        ("yaw", 0, 0.0, 1.0),
        ("pitch", 0, -0.5 * math.pi + jar_tilt, 0.0),
        ("roll", 0, 0.0, speed_ratio),
    )


MOTION = KinematicModel(
    "planetary",
    "planetary mill (Fritsch Pulverisette, Retsch PM type): a jar on a sun wheel turning at omega, spinning at "
    "speed_ratio relative to it",
    planetary_terms,
    axis_upright=True,
)
