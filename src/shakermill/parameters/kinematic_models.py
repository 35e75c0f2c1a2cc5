"""Named motions of the vial for the 'dem' engine (MODEL.md section 12.2), as data.

A model is the Fourier terms ``(coordinate, k, cos, sin)`` of the vial's six rigid-body coordinates in
the harmonics k of θ = ωt + φ (translations x, y, z of its centre in m; roll, pitch, yaw about the lab's
x, y, z axes in rad), built from the keys it names. ``engines.dem.model.harmonics_of`` turns them into
the array the compiled stepping evaluates (``physics.kinematics.fourier_coordinates``), so a new mill is
a new entry here, not a new code path. Angles may also turn steadily (a k = 0 term's sine is its rate per
radian of θ), as a planetary mill's do. The lab frame has z up; every model below but the planetary keeps the
vial's axis horizontal, so gravity stays along −z of the vial at rest; a planetary jar stands on its end.

No source reachable here gives the SPEX clamp's lateral amplitude, yaw or their phases, nor the swing
radius or stroke of a Retsch MM400 (docs/notes/dem-references.md, sections 2.3 and 2.4): those values
are stated assumptions, each a key of its own so that it can be swept
(``studies.kinematics.kinematic_sensitivity``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

Term = tuple[str, int, float, float]

# The vial's six rigid-body coordinates: translations of its centre (m) and angles about the lab's axes (rad).
MOTION_COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
# Harmonics beyond the 20th describe no mill (a user's `motion` is held to it too).
MAX_MOTION_HARMONIC = 20
# Translations of a vial beyond half a metre describe no mill.
MAX_MOTION_TRANSLATION = 0.5
# The arc's Bessel series: terms smaller than this fraction of the swing radius are dropped. Within the
# widest swing allowed they fall below it before MAX_MOTION_HARMONIC (2R·J_20(π/2) ≈ 6e-21 R).
ARC_TRUNCATION = 1e-12
# A quarter turn either way: a mixer mill swings its jars through a few degrees; beyond a right angle
# the jar's axis would point along the arm.
MAX_SWING_ANGLE = 0.5 * math.pi


@dataclass(frozen=True)
class KinematicModel:
    """A vial motion: the keys whose values ``terms`` takes, in order, and which of them no source gives."""

    description: str
    keys: tuple[str, ...]
    terms: Callable[..., tuple[Term, ...]]
    assumed: tuple[str, ...] = ()
    # The vial's axis stands up (its frame's x along the lab's z) and the vial is carried across it, as a planetary
    # jar round its sun wheel: the air meets its outside across the axis, not along it as a shaken vial's
    # (engines/thermal/network.py), and the figures name its views as seen with the axis up (views/trajectories.py).
    axis_upright: bool = False


def axial_terms(amplitude: float) -> tuple[Term, ...]:
    """x = X_v sin θ (MODEL.md §1): the 1-D drive."""
    return (("x", 1, 0.0, amplitude),)


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


def given_terms(motion: tuple[Term, ...]) -> tuple[Term, ...]:
    """The user's own terms (key ``motion``)."""
    return motion


KINEMATIC_MODELS: dict[str, KinematicModel] = {
    "axial": KinematicModel("the 1-D drive along the vial's axis (MODEL.md §1)", ("amplitude",), axial_terms),
    "fourier": KinematicModel("the user's Fourier terms in `motion`", ("motion",), given_terms),
    "spex8000m": KinematicModel(
        "SPEX 8000M clamp: axial stroke, lateral motion at twice the frequency, yaw about the vertical",
        ("amplitude", "lateral_amplitude", "yaw_amplitude"),
        spex_terms,
        assumed=("lateral_amplitude", "yaw_amplitude"),
    ),
    "mixer-mill-arc": KinematicModel(
        "horizontal mixer mill (Retsch MM400 type): the jar swings on a horizontal arc about a vertical pivot",
        ("amplitude", "swing_radius"),
        arc_terms,
        assumed=("amplitude", "swing_radius"),
    ),
    "planetary": KinematicModel(
        "planetary mill (Fritsch Pulverisette, Retsch PM type): a jar on a sun wheel turning at omega, spinning at "
        "speed_ratio relative to it",
        ("revolution_radius", "speed_ratio", "jar_tilt"),
        planetary_terms,
        axis_upright=True,
    ),
}


def motion_terms(kinematics: str, values: object) -> tuple[Term, ...]:
    """The Fourier terms of the model ``kinematics``, its keys read (SI) as attributes of ``values`` (a
    ``Parameters``)."""
    model = KINEMATIC_MODELS[kinematics]
    return model.terms(*(getattr(values, key) for key in model.keys))


# Defaults of the assumed amplitudes, with the reasoning behind each (the presets cite these).
NO_SOURCE = "no published value found (docs/notes/dem-references.md §§2.3-2.4)"
ASSUMED_DEFAULTS: dict[str, tuple[float, str]] = {
    # A figure of eight visibly narrower than long: 2Y = 10 mm across a 2X_v = 50 mm stroke (1:5).
    "lateral_amplitude": (
        5e-3,
        "assumption: ±5 mm at twice the drive frequency, a figure of eight 10 mm wide across the 50 mm stroke; "
        f"{NO_SOURCE}",
    ),
    # A clamp carried on a curved path of radius ρ turns by X_v/ρ: ρ ≈ 0.3 m, the size of the mill's
    # housing, gives 25 mm/0.3 m = 0.083 rad.
    "yaw_amplitude": (
        math.radians(5.0),
        "assumption: ±5° (0.0873 rad) in phase with the stroke, X_v/ρ for a curved path of radius ρ ≈ 0.3 m; "
        f"{NO_SOURCE}",
    ),
    # Mixer mills carry their jars on arms of the order of a decimetre (the mill is ~0.4 m wide).
    "swing_radius": (
        0.1,
        "assumption: 100 mm from the vertical pivot to the jar's centre, an arm of the size of a mixer mill's "
        f"housing; {NO_SOURCE}",
    ),
}
