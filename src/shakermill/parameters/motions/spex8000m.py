"""The SPEX 8000M clamp's figure of eight: an axial stroke, a lateral motion at twice the drive's frequency and a
yaw about the vertical.

No source reachable here gives the clamp's lateral amplitude, yaw or their phases (docs/notes/dem-references.md,
section 2.3): those values are stated assumptions, each a key of its own so that it can be swept
(``studies.kinematics.kinematic_sensitivity``)."""

from __future__ import annotations

from shakermill.parameters.motions import KinematicModel, Term


def spex_terms(amplitude: float, lateral_amplitude: float, yaw_amplitude: float) -> tuple[Term, ...]:
    """The SPEX 8000M clamp's figure of eight: x = X_v sin θ, y = Y sin 2θ, yaw = Ψ sin θ.

    Phases (assumptions, no published value found): y = Y sin 2θ makes the centre's path a figure of
    eight (Gerono's lemniscate) that crosses itself at mid-stroke, where the vial moves fastest, and
    reaches its lateral extremes at x = ±X_v/√2; an arc-like clamp (cos 2θ) would trace a crescent
    instead, which is not what the SPEX literature describes. The yaw is in phase with the stroke, as a
    vial carried on a curved path turns with it (yaw = x/ρ for an arc of radius ρ), so the vial's ends
    trace figures of eight of slightly unequal lobes. Zero amplitudes leave out their terms: with both
    zero the motion is ``axial`` term for term.
    """
    terms = (("x", 1, 0.0, amplitude), ("y", 2, 0.0, lateral_amplitude), ("yaw", 1, 0.0, yaw_amplitude))
    return tuple(term for term in terms if term[3] != 0.0)


MOTION = KinematicModel(
    "spex8000m",
    "SPEX 8000M clamp: axial stroke, lateral motion at twice the frequency, yaw about the vertical",
    spex_terms,
    assumed=("lateral_amplitude", "yaw_amplitude"),
)
