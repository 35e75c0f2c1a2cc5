"""The 'dem' engine's own keys (MODEL.md section 12): the vial motion it moves the vial by and gravity, its steps at
contacts and in flight, and its averaged solver's target error and replicas."""

from __future__ import annotations

from typing import Any

from pydantic import field_validator

from shakermill.parameters.fields import choice, count, one_of, quantity, switch
from shakermill.parameters.key_group import KeyGroup, only_with_solver
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.parameters.sources import PAPER


class LabFrame(KeyGroup):
    """The vial's motion in the lab (one of the motions of ``parameters/motions/``) and gravity (MODEL.md
    §§12.1-12.2)."""

    title = "the vial's motion and gravity"

    # One of the motions of parameters/motions/ (kinematic_models.KINEMATIC_MODELS), checked by _known_motion.
    kinematics: str = choice(
        "vial motion of the 'dem' engine (parameters/motions/), with the keys each reads: "
        + ", ".join(f"'{name}' ({', '.join(model.keys)})" for name, model in KINEMATIC_MODELS.items()),
        default="axial",
        source=f"{PAPER}: the vial moves along its axis (MODEL.md section 12.2)",
    )
    gravity: bool = switch(
        "gravity 9.81 m/s² downward, the vial axis horizontal (engine = 'dem')",
        default=True,
        source="MODEL.md section 12.1: 9.81 m/s² downward, the vial axis horizontal (engine = 'dem')",
    )

    @field_validator("kinematics")
    @classmethod
    def _known_motion(cls, name: Any) -> Any:
        return one_of(name, KINEMATIC_MODELS)


class DemStepping(KeyGroup):
    """The 'dem' engine's steps at a contact's start and release and in free flight (MODEL.md §12.6)."""

    title = "the 'dem' engine's steps"

    # The shortest step, at a contact's start and release, as a fraction of the smallest Rayleigh time; an impact
    # steps at 0.4 of this fraction of its own period (engines/dem/model.py, IMPACT_STEP_SCALE); 0.9 is the 1-D
    # engine's bound.
    contact_step_fraction: float = quantity(
        "",
        "contact step of the 'dem' engine as a fraction of the smallest Rayleigh time",
        default=0.025,
        source="numerical choice: restitution within 1e-3 of e for ball-ball and ball-wall impacts at 0.5-5 m/s (at "
        "most 6.4e-4; 0.05 left 1.45e-3), the 1-D limit's heat power within 0.25 % of the converged value, five balls' "
        "within the ~1 % their statistics resolve (benchmarks/README.md, dem engine)",
        ge=1e-3,
        le=0.9,
    )
    # A free-flight step never lets a contact begin inside it; this caps it further (1 s: no cap in practice).
    max_flight_step: float = quantity(
        "s",
        "longest step of the 'dem' engine in free flight",
        default=1e-4,
        source="numerical choice: ~1/60 of a drive period, so the wall's motion is resolved",
        ge=1e-7,
        le=1.0,
    )


class EnduringContacts(KeyGroup):
    """The 'dem' engine's step inside a contact that outlasted two of its periods (rolling, sliding, resting)."""

    title = "enduring contacts"

    # An enduring contact (rolling, sliding or resting, not an impact) steps at this fraction of its own period,
    # within the same 0.9 t_R bound; Verlet is stable below 1/π of a period (engines/dem/model.py, ENDURING_AFTER).
    enduring_step_fraction: float = quantity(
        "",
        "step of the 'dem' engine inside an enduring contact as a fraction of its oscillation period",
        default=0.05,
        source="numerical choice: 20 steps a period of a contact that outlasted two of its periods; heat power and hit "
        "statistics within their statistical errors of finer steps (benchmarks/README.md, enduring contacts)",
        ge=1e-3,
        le=0.1,
    )


class DemAveraging(KeyGroup):
    """The 'dem' engine's target error of the averaged solver and its replicas of the mechanics."""

    title = "the 'dem' engine's averaging"
    rule = only_with_solver("averaged")

    # The several balls' motion is chaotic: its means converge as 1/√T, and 1e-3 would take ~15 min of mechanics.
    dem_averaging_rel_error: float = quantity(
        "",
        "averaged solver of the 'dem' engine: target relative standard error of the total heat power, the mean "
        "Whitaker term and each ball's own means",
        default=1e-2,
        source="numerical choice: ±1 % on each ball's mean heat rate (~0.3 K on a 30 K rise) in ~40 s of mechanics",
        gt=0,
        lt=1,
    )
    # Each replica pays its own start-up transient, so more replicas than cores cost more than they save.
    dem_replicas: int = count(
        "averaged solver of the 'dem' engine: independent replicas of the mechanics, pooled",
        default=1,
        source="numerical choice: one replica, as before replicas existed; set it to the cores a run may use",
        ge=1,
        le=64,
    )


class WhatAnImpactIs(KeyGroup):
    """Which of the 'dem' engine's contact records are impacts (MODEL.md §14.4): its counts, rates, spectra and
    regimes are of impacts so defined; its records keep every contact."""

    title = "what an impact is"

    touch_speed: float = quantity(
        "m/s",
        "a contact that begins with a normal approach slower than this is a touch, not an impact",
        default=0.1,
        source="MODEL.md §14.4: 0.1 m/s, about the speed at which a Hertz impact of hardened steel begins to yield "
        "(Johnson 1985, §11.4; recalled, not re-read), a free fall of 0.5 mm",
        ge=0.0,
        le=10.0,
    )
    chatter_factor: float = quantity(
        "",
        "records of one pair that begin again within this many Hertz durations of their approach are one lasting "
        "contact, its chatter merged; 0 merges none",
        default=2.0,
        source="MODEL.md §14.4: about twice the Hertz contact duration of the approach",
        ge=0.0,
        le=100.0,
    )
