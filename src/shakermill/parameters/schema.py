"""Validated, immutable run parameters with the canonical keys of MODEL.md section 9.

Every numeric field is SI. Users may give strings with units ("25 mm"); they are
converted by :mod:`shakermill.units` before validation, so a ``Parameters``
object only ever holds floats in SI.

Presets are plain mappings from key to :class:`Cited` values, so that every
default carries its source (the PyBaMM habit of parameter sets with citations).
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import numbers
import tomllib
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Mapping

import annotated_types
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from shakermill.parameters import materials
from shakermill.parameters.kinematic_models import ASSUMED_DEFAULTS, MAX_MOTION_HARMONIC, MAX_SWING_ANGLE, arc_angle
from shakermill.parameters.units import UnitError, to_si
from shakermill.support.limits import (
    MAX_FULL_RESOLUTION_PERIODS,
    MAX_RECORD_WINDOWS,
    MAX_RECORDED_SECONDS,
    MAX_SAMPLES,
    QUOTED_LENGTH,
    quoted,
)
from shakermill.support.presenters import present

if TYPE_CHECKING:
    import numpy

PAPER = "Son 2025, Mathematics 13, 446"


class ParameterError(ValueError):
    """Bad user input: one line naming the key and what is allowed."""


def _quantity(unit: str, description: str, **bounds: float) -> Any:
    return Field(json_schema_extra={"unit": unit, "description": description}, **bounds)


def _count(description: str, **bounds: int) -> Any:
    return Field(json_schema_extra={"unit": "", "description": description}, strict=True, **bounds)


def _material_name(of: str, keys: str) -> Any:
    return Field(
        json_schema_extra={
            "unit": "",
            "description": f"material of {of} from `shakermill materials`: fills {keys} unless they are set with it or "
            "later; '': none",
        }
    )


def _per_ball(scalar_key: str) -> Any:
    return Field(
        max_length=MAX_BALLS,
        json_schema_extra={"unit": "", "per_ball": scalar_key, "description": f"per-ball {scalar_key} (engine = 'dem')"},
    )


# The most balls of the 'dem' engine and harmonics of a user-given vial motion.
MAX_BALLS = 50
# No packing of equal spheres fills more of space than π/√18 (Kepler's conjecture, proved by Hales), let
# alone a vial, whose walls leave gaps: the bound of ``fill``.
DENSEST_PACKING = math.pi / math.sqrt(18.0)
MAX_HARMONICS = 60
MOTION_COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
# Translations of a vial beyond half a metre describe no mill.
MAX_MOTION_TRANSLATION = 0.5
Harmonic = tuple[
    Literal["x", "y", "z", "roll", "pitch", "yaw"],
    Annotated[int, annotated_types.Ge(0), annotated_types.Le(MAX_MOTION_HARMONIC)],
    float,
    float,
]


# Every key has hard bounds: a value outside them is refused with one line naming the key and its range.
# They are wide enough for any real mill (PLAUSIBLE_RANGES warns about the merely unusual inside them)
# and tight enough that the model and its integrator stay meaningful and finish; the comment above each
# field says why its bounds are where they are. Lower bounds of 0 that stay open are physical (no
# negative length), except where a small value makes the run misbehave.
LONGEST_RUN_S = 1e6
# The explicit integrator's steps follow the fastest thermal time constant: ~0.7 steps per time constant
# and simulated second, so 0.1 ms costs ~25 million steps a simulated hour, ten times the mechanics'
# own. The default's fastest node, the air, takes 0.1 s.
MIN_THERMAL_TIME_CONSTANT_S = 1e-4
Window = tuple[
    # A window may start anywhere in the longest run; its length is capped with the others' (MAX_RECORDED_SECONDS).
    Annotated[float, annotated_types.Ge(0), annotated_types.Le(LONGEST_RUN_S)],
    Annotated[float, annotated_types.Gt(0), annotated_types.Le(MAX_RECORDED_SECONDS)],
]


class Parameters(BaseModel):
    """One run of the one-ball shaker-mill model (MODEL.md sections 1–9)."""

    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True, allow_inf_nan=False)

    # Geometry and drive (MODEL.md section 1)
    # 25 µm: the finest beads of bead mills (50 µm across); 0.1 m: larger than any milling ball (~50 mm).
    ball_radius: float = _quantity("m", "milling ball radius R", ge=2.5e-5, le=0.1)
    # 1 mm to 1 m: from micro-vials to twice the largest vibratory mill's vessel.
    vial_length: float = _quantity("m", "inner length of the vial l_v", ge=1e-3, le=1.0)
    vial_diameter: float = _quantity("m", "inner diameter of the vial d_v", ge=1e-3, le=1.0)
    # Open at 0: a vanishing stroke is a resting wall, the analytic test of a single impact. 0.5 m: five
    # times the longest stroke of a shaker mill.
    amplitude: float = _quantity(
        "m", "vial oscillation amplitude X_v (kinematics = 'mixer-mill-arc': along the arc, at the jar's centre)", gt=0, le=0.5
    )
    # 1 rad/s (0.16 Hz): thirty times slower than any mill. 1e4 rad/s (1.6 kHz): beyond acoustic mixers
    # (60 Hz), high enough that 1060 typed for rpm is warned about, not refused; the step count grows with ω.
    omega: float = _quantity("rad/s", "vial angular frequency ω", ge=1.0, le=1e4)
    # One turn either way: every phase has an equal one inside, and larger ones only cost precision in sin(ωt + φ).
    phase: float = _quantity("rad", "vial phase φ at t = 0", ge=-2 * math.pi, le=2 * math.pi)
    # Materials (Table 2). A named material fills in the keys below (with_materials); '' leaves them as they are.
    ball_material: str = _material_name(
        "the balls", "ball_density, ball_youngs_modulus, ball_poisson_ratio, ball_heat_capacity, ball_conductivity"
    )
    vial_material: str = _material_name("the vial", "vial_density, vial_youngs_modulus, vial_poisson_ratio, vial_heat_capacity")
    # 500 kg/m³: below every solid milling medium (polyethylene ~950); 25 000: above osmium (22 590), the
    # densest element. A ball of 1e-6 kg/m³ has no heat capacity and made a run take hours.
    ball_density: float = _quantity("kg/m^3", "ball density ρ_b", ge=500.0, le=25_000.0)
    vial_density: float = _quantity("kg/m^3", "vial density ρ_v", ge=500.0, le=25_000.0)
    # 0.1 MPa: softer than rubber; such contacts overlap past what the integrator allows and the run stops
    # with its status. 1.2 TPa: diamond, the stiffest solid.
    ball_youngs_modulus: float = _quantity("Pa", "ball Young's modulus E_b", ge=1e5, le=1.2e12)
    vial_youngs_modulus: float = _quantity("Pa", "vial Young's modulus E_v", ge=1e5, le=1.2e12)
    # Dense solids lie in 0-0.5 (diamond 0.07, steel 0.3, rubber 0.5); -0.5 leaves room for auxetic
    # materials. As ν -> -1 the shear modulus, and the Rayleigh time that bounds contact steps, vanish.
    ball_poisson_ratio: float = _quantity("", "ball Poisson ratio ν_b", ge=-0.5, lt=0.5)
    vial_poisson_ratio: float = _quantity("", "vial Poisson ratio ν_v", ge=-0.5, lt=0.5)
    # 50 J/(kg·K): below the heaviest metals (lead, tungsten, gold ~130); 5000: above polymers (~2000)
    # and water (4186).
    ball_heat_capacity: float = _quantity("J/(kg*K)", "ball specific heat c_b", ge=50.0, le=5000.0)
    vial_heat_capacity: float = _quantity("J/(kg*K)", "vial specific heat c_v", ge=50.0, le=5000.0)
    # 1 g: less steel than one 19-mm end face 0.5 mm thick; 1e-12 kg made the vial's time constant a
    # nanosecond and a run take hours. 100 kg: a heavy vial with its clamp, many times over.
    vial_mass: float = _quantity("kg", "thermally active vial mass m_v", ge=1e-3, le=100.0)
    # Air (Table 3); the bounds cover the gases mills are filled with, from a rough vacuum to high pressure.
    # 0.01 kg/m³ (~10 mbar of air): below it the gas is no continuum for Whitaker's correlation and the
    # air node's time constant falls under a millisecond. 200: nitrogen at ~170 bar.
    air_density: float = _quantity("kg/m^3", "air density ρ_a", ge=0.01, le=200.0)
    # Gases at 0 °C: hydrogen 8.4e-6 to neon 3e-5 Pa·s, with room either way.
    air_viscosity_ref: float = _quantity("Pa*s", "air viscosity μ_r at the reference temperature", ge=1e-6, le=1e-4)
    # The reference of Sutherland's law: 50-2000 K covers every tabulated reference point.
    air_reference_temperature: float = _quantity(
        "K", "reference temperature θ_r of Sutherland's law", ge=50.0, le=2000.0
    )
    # Gases: xenon 0.005 to hydrogen 0.18 W/(m·K).
    air_conductivity: float = _quantity("W/(m*K)", "air thermal conductivity k_a", ge=1e-3, le=1.0)
    # Gases: xenon 158 to hydrogen 14 300 J/(kg·K).
    air_cp: float = _quantity("J/(kg*K)", "air specific heat at constant pressure c_p,a", ge=100.0, le=20_000.0)
    # An ideal gas has 1 < γ <= 5/3 (monatomic).
    air_heat_capacity_ratio: float = _quantity("", "c_p/c_v of air", gt=1, le=5 / 3)
    # Sutherland constants of gases: hydrogen 72 K, air 111, carbon dioxide 240; 1000 leaves room.
    sutherland: float = _quantity("K", "Sutherland constant S", ge=0, le=1000.0)
    # 0 switches the exchange off; 1e4 W/(m²·K) is liquid cooling, far above gas convection (5-250).
    h_inner: float = _quantity("W/(m^2*K)", "vial-to-inner-air convection coefficient h_i", ge=0, le=1e4)
    h_outer: float = _quantity("W/(m^2*K)", "vial-to-surroundings convection coefficient h_o", ge=0, le=1e4)
    # 10 m²: the whole surface of a vial of 1 m, the largest allowed.
    inner_area: float = _quantity("m^2", "vial surface exchanging heat with the inner air A_i", gt=0, le=10.0)
    outer_area: float = _quantity("m^2", "vial surface exchanging heat with the surroundings A_o", gt=0, le=10.0)
    # Collision and heat generation (Table 4)
    # A perfectly plastic contact (0) has no damping ratio. Towards 0 the ball chatters on the face and a
    # run takes more steps (20 times at 0.05, 40 at 1e-6), but it stays correct and finishes.
    restitution: float = _quantity("", "coefficient of restitution e", gt=0, le=1)
    eta: float = _quantity("", "fraction η of dissipated power turned into heat", ge=0, le=1)
    lam: float = _quantity("", "fraction λ of the heat that goes to the ball", ge=0, le=1)
    # β scales Whitaker's correlation, defensible within 0.1-3 (calibrate.DEFENSIBLE_RANGES); 100 leaves
    # room for any hand tuning, and β = 1e12 made the ball's time constant a nanosecond.
    beta: float = _quantity("", "convection calibration factor β", ge=0, le=100.0)
    # Run (Table 4 and assumptions)
    # A microsecond: less than one contact step. 1e6 s (11.6 days): longer than any milling run (~100 h);
    # the stored samples are capped too (MAX_SAMPLES), and full-resolution runs by their drive periods.
    duration: float = _quantity("s", "simulated time", ge=1e-6, le=LONGEST_RUN_S)
    # 50 K: below liquid-nitrogen cryomilling (77 K). 1000 K: a vial in a furnace at 700 °C.
    ambient_temperature: float = _quantity("K", "temperature of the surroundings θ_amb", ge=50.0, le=1000.0)
    initial_temperature: float = _quantity("K", "initial temperature θ_0 of ball, vial and air", ge=50.0, le=1000.0)
    # Up to 4000 K: tungsten, the most refractory ball material, melts at 3695 K.
    ball_temperature_limit: float = _quantity(
        "K", "highest physical ball temperature: a run that exceeds it ends with a non-ok status", ge=50.0, le=4000.0
    )
    # Half the longest vial; the ball must also start inside this vial (checked below).
    ball_position: float = _quantity("m", "initial ball centre, relative to the vial centre", ge=-0.5, le=0.5)
    # A 100-g ball at 1000 m/s; faster starts only end in an overlap the integrator refuses.
    ball_momentum: float = _quantity("kg*m/s", "initial ball momentum", ge=-100.0, le=100.0)
    # Numerics (MODEL.md section 7)
    # The method is third order: rtol 1e-8 costs ~40 times the default's steps, and the contact step limit
    # bounds the error below that anyway. Above 0.1 the error control no longer resolves a contact.
    rtol: float = _quantity("", "relative tolerance of the integrator", ge=1e-8, le=0.1)
    # 1e-12: far below every scale of the motion (the single-impact tests use it); the upper bounds are
    # where the tolerance would exceed the quantity itself (a ball radius, a ball's momentum, a kelvin).
    atol_position: float = _quantity("m", "absolute tolerance on the ball position", ge=1e-12, le=1e-3)
    atol_momentum: float = _quantity("kg*m/s", "absolute tolerance on the ball momentum", ge=1e-12, le=1e-2)
    atol_temperature: float = _quantity("K", "absolute tolerance on temperatures", ge=1e-12, le=1.0)
    # The sample count duration/output_interval is capped as well (MAX_SAMPLES).
    output_interval: float = _quantity("s", "sampling interval of the stored time series", ge=1e-6, le=LONGEST_RUN_S)
    energy_projection: bool = Field(
        strict=True,
        json_schema_extra={"description": "enforce the mechanical energy balance of each contact step by projection"},
    )
    # Budget of one run (shakermill.budget): beyond either limit it stops with a non-ok status, keeping its results
    max_wall_time: float = _quantity(
        "s", "wall-clock budget of one run, its mechanics phase, fall-back and attractor probe included", gt=0,
        le=LONGEST_RUN_S,  # a budget beyond the longest simulated run is no budget
    )
    max_steps: int = Field(
        gt=0,
        le=10**12,  # at ~0.5 µs a step, about a week of computing

        json_schema_extra={"unit": "", "description": "step budget of one run: accepted integrator steps, all its integrations together"},
    )
    # Solver choice (full resolution, or the multiscale averaged solver)
    solver: Literal["full", "averaged"] = Field(
        json_schema_extra={"description": "'full': every impact for the whole run; 'averaged': mechanics until its statistics converge, then the slow thermal network"}
    )
    # Any target is safe: one that is never reached ends at averaging_max_time, and the run falls back.
    averaging_rel_error: float = _quantity(
        "", "averaged solver: target relative standard error of the averages", gt=0, lt=1
    )
    # The several balls' motion is chaotic: its means converge as 1/√T, and 1e-3 would take ~15 min of mechanics.
    dem_averaging_rel_error: float = _quantity(
        "",
        "averaged solver of the 'dem' engine: target relative standard error of the total heat power, the mean "
        "Whitaker term and each ball's own means",
        gt=0,
        lt=1,
    )
    # 10 000 periods (~10 min) per batch: already past any averaging_max_time worth waiting for.
    averaging_batch_periods: int = _count("averaged solver: drive periods per batch of the batch-means estimate", ge=1, le=10_000)
    averaging_min_batches: int = _count("averaged solver: fewest batches after the transient", ge=4, le=10_000)
    # An hour of mechanics costs what a full-resolution hour does; averaging converges in ~20 s.
    averaging_max_time: float = _quantity("s", "averaged solver: longest mechanics window before giving up", gt=0, le=3600.0)
    averaging_fallback: Literal["full", "fail"] = Field(
        json_schema_extra={"description": "averaged solver: what to do when averaging is not valid"}
    )
    # Each start costs a settled run at every point of a scan; 100 cover the gap far more densely than
    # the basins found so far need (the default 8 finds them).
    attractor_starts: int = _count(
        "initial states settled to find coexisting attractors (bifurcation, sweeps, averaged solver); "
        "1: only the configured start",
        ge=1,
        le=100,
    )
    # Model options (MODEL.md sections 2-4: the alternatives the spec allows)
    model: Literal["three_node", "ball_only"] = Field(
        json_schema_extra={
            "description": "'three_node': ball, vial and air (this paper); 'ball_only': air held at ambient and no vial "
            "reservoir, the author's 2023 predecessor"
        }
    )
    no_tension: bool = Field(strict=True, json_schema_extra={"description": "clip the contact force at zero (no adhesion)"})
    heat_model: Literal["relative", "paper"] = Field(
        json_schema_extra={"description": "'relative': η·c·ζ̇² (default); 'paper': η·|F_d·v| as printed"}
    )
    convection_velocity: Literal["auto", "ball", "relative"] = Field(
        json_schema_extra={
            "description": "velocity in Re: the ball's ('ball', as the paper) or relative to the vial, which carries "
            "the air ('relative'); 'auto': 'ball' for the 1-D engine, 'relative' for 'dem' (MODEL.md §12.5)"
        }
    )
    # Several balls in three dimensions (MODEL.md section 12): keys of the 'dem' engine; the 1-D engine ignores them
    engine: Literal["1d", "dem"] = Field(
        json_schema_extra={
            "description": "'1d': one ball on the vial's axis (MODEL.md sections 1-7); 'dem': n_balls spheres in three "
            "dimensions with friction and rotation (section 12)"
        }
    )
    # 50 balls of the smallest radius still fit any vial the bounds allow; the pair search is O(N²).
    n_balls: int = _count("number of balls (engine = 'dem'; the 1-D engine has one)", ge=1, le=MAX_BALLS)
    fill: float = _quantity(
        "",
        "fraction of the vial's inner volume the balls take (engine = 'dem'): > 0 sets n_balls = max(1, "
        "round(fill·V_vial/V_ball)) equal balls; 0: n_balls as given",
        ge=0,
        le=DENSEST_PACKING,
    )
    # Each ball's own radius and material, in ball order; empty: every ball takes the scalar key's value.
    ball_radii: tuple[float, ...] = _per_ball("ball_radius")
    ball_densities: tuple[float, ...] = _per_ball("ball_density")
    ball_youngs_moduli: tuple[float, ...] = _per_ball("ball_youngs_modulus")
    ball_poisson_ratios: tuple[float, ...] = _per_ball("ball_poisson_ratio")
    ball_heat_capacities: tuple[float, ...] = _per_ball("ball_heat_capacity")
    ball_conductivities: tuple[float, ...] = _per_ball("ball_conductivity")
    ball_materials: tuple[str, ...] = Field(
        max_length=MAX_BALLS,
        json_schema_extra={
            "unit": "",
            "description": "per-ball material (engine = 'dem'): fills the per-ball lists of density, Young's modulus, "
            "Poisson ratio, heat capacity and conductivity unless they are set with it or later",
        },
    )
    # Only the ratio of two balls' effusivities √(kρc) matters (the split of ball-ball heat, MODEL.md §12.4):
    # from aerogel-like 0.01 to diamond's 2000 W/(m·K).
    ball_conductivity: float = _quantity("W/(m*K)", "ball thermal conductivity k_b", ge=0.01, le=2000.0)
    gravity: bool = Field(
        strict=True, json_schema_extra={"description": "gravity 9.81 m/s² downward, the vial axis horizontal (engine = 'dem')"}
    )
    # Coulomb coefficients of dry solids stay below ~1.5; 5 leaves room for rough or adhesive pairs.
    friction: float = _quantity("", "Coulomb friction coefficient μ of every contact (engine = 'dem')", ge=0, le=5.0)
    rolling_friction: float = _quantity("", "rolling resistance coefficient μ_r (engine = 'dem')", ge=0, le=1.0)
    kinematics: Literal["axial", "fourier", "spex8000m", "mixer-mill-arc"] = Field(
        json_schema_extra={
            "description": "vial motion of the 'dem' engine (parameters/kinematic_models.py): 'axial' (amplitude, "
            "omega, phase: the 1-D drive), 'fourier' (the harmonics in motion), 'spex8000m' (the clamp's figure of "
            "eight: amplitude, lateral_amplitude, yaw_amplitude) or 'mixer-mill-arc' (a jar swung on a horizontal "
            "arc: amplitude along the arc, swing_radius)"
        }
    )
    # The SPEX clamp's lateral motion and yaw (kinematics = 'spex8000m'); 0 leaves either out. Half a metre,
    # as any translation of a vial; a quarter turn, far beyond the few degrees a clamp turns.
    lateral_amplitude: float = _quantity(
        "m", "kinematics = 'spex8000m': lateral amplitude Y of the vial's centre, y = Y sin 2θ", ge=0, le=MAX_MOTION_TRANSLATION
    )
    yaw_amplitude: float = _quantity(
        "rad", "kinematics = 'spex8000m': yaw amplitude Ψ about the vertical, yaw = Ψ sin θ", ge=0, le=0.5 * math.pi
    )
    # 1 mm to 1 m: from a jar turning about a pivot next to it to an arm longer than any mill.
    swing_radius: float = _quantity(
        "m", "kinematics = 'mixer-mill-arc': radius R of the jar centre's arc about the vertical pivot", ge=1e-3, le=1.0
    )
    motion: tuple[Harmonic, ...] = Field(
        max_length=MAX_HARMONICS,
        json_schema_extra={
            "unit": "m or rad",
            "description": "kinematics = 'fourier': (coordinate, k, cos, sin) terms of the vial's translations x, y, z "
            "(m) and angles roll, pitch, yaw (rad) in the harmonics k of ωt + φ",
        },
    )
    # The step inside a contact as a fraction of the smallest Rayleigh time, or of a slow contact's own period over
    # 9.5 where that is longer (engines/dem/model.py, RAYLEIGH_TIMES_PER_PERIOD); 0.9 is the 1-D engine's bound.
    contact_step_fraction: float = _quantity(
        "", "contact step of the 'dem' engine as a fraction of the smallest Rayleigh time", ge=1e-3, le=0.9
    )
    # A free-flight step never lets a contact begin inside it; this caps it further (1 s: no cap in practice).
    max_flight_step: float = _quantity("s", "longest step of the 'dem' engine in free flight", ge=1e-7, le=1.0)
    record_windows: tuple[Window, ...] = Field(
        max_length=MAX_RECORD_WINDOWS,
        json_schema_extra={"unit": "s", "description": "(start, length) windows stored at full resolution"},
    )

    @model_validator(mode="after")
    def _ball_fits_vial(self) -> "Parameters":
        diameter = 2.0 * self.ball_radius
        if diameter >= self.vial_length:
            raise ValueError(
                f"ball_radius: a ball of diameter {diameter * 1e3:g} mm does not fit a vial of length "
                f"{self.vial_length * 1e3:g} mm; allowed ball_radius < vial_length/2 = {self.vial_length / 2:g} m"
            )
        if diameter > self.vial_diameter:
            raise ValueError(
                f"ball_radius: a ball of diameter {diameter * 1e3:g} mm does not fit a vial of diameter "
                f"{self.vial_diameter * 1e3:g} mm; allowed ball_radius <= vial_diameter/2 = {self.vial_diameter / 2:g} m"
            )
        half_gap = self.vial_length / 2.0 - self.ball_radius
        if abs(self.ball_position) >= half_gap:
            raise ValueError(
                f"ball_position: the ball must start inside the vial, allowed |ball_position| < {half_gap:g} m"
            )
        return self

    @model_validator(mode="after")
    def _fill_sets_the_balls(self) -> "Parameters":
        """``fill`` > 0 makes n_balls equal balls (:func:`balls_for_fill`); an n_balls that says otherwise is refused.

        A key, not a sweep axis of its own: a run, a configuration file and a sweep point all take it, and the
        count it makes follows the ball and vial of that very run (a sweep over fill × ball_radius needs no
        table of counts). It cannot disagree with n_balls unnoticed: a layer that sets fill replaces the
        n_balls of the layers below it (:func:`layered`), and an n_balls set beside it or above it must match.
        """
        if self.fill == 0:
            return self
        if self.engine != "dem":
            raise ValueError("fill: sets the number of balls of the 'dem' engine; allowed fill = 0 with engine = '1d', or set engine = 'dem'")
        listed = next((key for key in ("ball_materials", *PER_BALL_KEYS) if getattr(self, key)), None)
        if listed is not None:
            raise ValueError(f"fill: makes equal balls, and {listed} gives each ball its own value; allowed fill = 0 with per-ball lists")
        wanted = balls_for_fill(self.fill, self.ball_radius, self.vial_length, self.vial_diameter)
        if wanted > MAX_BALLS:
            raise ValueError(
                f"fill: {self.fill:g} of this vial is {wanted} balls of radius {self.ball_radius * 1e3:g} mm; allowed fill "
                f"< {self._fill_below(MAX_BALLS):.3g} here (at most {MAX_BALLS} balls)"
            )
        if self.n_balls != wanted:
            raise ValueError(
                f"n_balls: {self.n_balls} contradicts fill = {self.fill:g}, which makes {wanted} balls of radius "
                f"{self.ball_radius * 1e3:g} mm in this vial; allowed n_balls = {wanted}, or fill = 0 to give n_balls alone"
            )
        return self

    def _fill_below(self, count: int) -> float:
        """The fill at which :func:`balls_for_fill` rounds up to ``count`` + 1 balls of ``ball_radius``."""
        return (count + 0.5) * _ball_volume(self.ball_radius) / self.vial_volume

    @model_validator(mode="after")
    def _balls_of_the_dem_engine(self) -> "Parameters":
        if self.engine == "1d" and self.n_balls > 1:
            raise ValueError(
                "n_balls: the 1-D engine moves one ball; allowed n_balls = 1 with engine = '1d', or set engine = 'dem'"
            )
        if self.engine == "1d" and self.kinematics != "axial":
            raise ValueError(
                f"kinematics: the 1-D engine moves the vial along its axis, not as {self.kinematics!r}; allowed 'axial' "
                "with engine = '1d', or set engine = 'dem'"
            )
        # The materials first: their per-ball lists are as long as they are.
        if self.ball_materials and len(self.ball_materials) != self.n_balls:
            raise ValueError(
                f"ball_materials: {len(self.ball_materials)} names for n_balls = {self.n_balls}; allowed an empty list "
                f"or exactly {self.n_balls} names"
            )
        for key in PER_BALL_KEYS:
            _check_per_ball(key, getattr(self, key), self.n_balls)
        if self.kinematics == "fourier" and not self.motion:
            raise ValueError("motion: kinematics = 'fourier' needs at least one harmonic; allowed (coordinate, k, cos, sin) terms")
        _check_motion(self.motion)
        if self.kinematics == "mixer-mill-arc" and arc_angle(self.amplitude, self.swing_radius) > MAX_SWING_ANGLE:
            raise ValueError(
                f"amplitude: an arc of {self.amplitude * 1e3:g} mm on a swing radius of {self.swing_radius * 1e3:g} mm "
                f"turns the jar by {arc_angle(self.amplitude, self.swing_radius):.3g} rad; allowed amplitude <= "
                f"swing_radius·π/2 = {self.swing_radius * MAX_SWING_ANGLE:.4g} m with kinematics = 'mixer-mill-arc'"
            )
        if self.engine == "dem":
            if self.model == "ball_only":
                raise ValueError("model: the 'dem' engine has a node per ball, the vial and the air; allowed 'three_node' with engine = 'dem'")
            self._check_balls_fit()
        return self

    def _check_balls_fit(self) -> None:
        radii = self.ball_values("ball_radius")
        largest = max(radii)
        if 2.0 * largest >= self.vial_diameter:
            key = "ball_radii" if self.ball_radii else "ball_radius"
            raise ValueError(
                f"{key}: a ball of diameter {2e3 * largest:g} mm does not move in a bore of {self.vial_diameter * 1e3:g} mm; "
                f"allowed radii < vial_diameter/2 = {self.vial_diameter / 2:g} m"
            )
        if self.n_balls > 1 and self.initial_positions() is None:
            if self.fill > 0:
                self._refuse_fill_that_does_not_fit()
            raise ValueError(
                f"n_balls: {self.n_balls} balls (radius up to {largest * 1e3:g} mm) do not fit side by side in a vial of "
                f"{self.vial_diameter * 1e3:g} mm x {self.vial_length * 1e3:g} mm; allowed fewer balls, smaller ones or a "
                "larger vial_diameter"
            )

    def _refuse_fill_that_does_not_fit(self) -> None:
        import numpy as np

        from shakermill.parameters.packing import packed

        fitting = len(packed(np.full(self.n_balls, self.ball_radius), self.vial_length, self.vial_diameter))
        raise ValueError(
            f"fill: {self.fill:g} of the vial is {self.n_balls} balls of radius {self.ball_radius * 1e3:g} mm, and "
            f"{fitting} fit side by side in {self.vial_diameter * 1e3:g} mm x {self.vial_length * 1e3:g} mm; allowed fill "
            f"< {self._fill_below(fitting):.3g} for these balls and this vial"
        )

    @property
    def relative_convection(self) -> bool:
        """Whether Re takes the ball's speed relative to the vial (MODEL.md §§4, 12.5)."""
        if self.convection_velocity == "auto":
            return self.engine == "dem"
        return self.convection_velocity == "relative"

    def ball_values(self, scalar_key: str) -> tuple[float, ...]:
        """Each ball's value of ``scalar_key`` (e.g. 'ball_radius'): its per-ball list, or the scalar for all."""
        values = getattr(self, PER_BALL_KEY_OF[scalar_key])
        return tuple(values) if values else (getattr(self, scalar_key),) * self.n_balls

    def initial_positions(self) -> "numpy.ndarray | None":
        """Ball centres (n_balls, 3) in the vial frame at t = 0 (m): one ball at ``ball_position`` on the axis,
        several filled in from the bottom (:mod:`shakermill.parameters.packing`); None if they do not fit."""
        import numpy as np

        from shakermill.parameters.packing import placement

        if self.n_balls == 1:
            return np.array([[self.ball_position, 0.0, 0.0]])
        return placement(np.array(self.ball_values("ball_radius")), self.vial_length, self.vial_diameter)

    @model_validator(mode="after")
    def _stored_data_fits_in_memory(self) -> "Parameters":
        samples = self.duration / self.output_interval
        if samples > MAX_SAMPLES:
            raise ValueError(
                f"output_interval: {self.output_interval:g} s over duration = {self.duration:g} s makes {samples:.3g} "
                f"samples; allowed output_interval >= duration/{MAX_SAMPLES:,} = {self.duration / MAX_SAMPLES:.4g} s"
            )
        recorded = sum(min(length, max(0.0, self.duration - start)) for start, length in self.record_windows)
        if recorded > MAX_RECORDED_SECONDS:
            raise ValueError(
                f"record_windows: they hold {recorded:g} s of the run at full resolution; allowed at most "
                f"{MAX_RECORDED_SECONDS:g} s in all (sample longer stretches with output_interval)"
            )
        periods = self.duration * self.omega / (2.0 * math.pi)
        if self.solver == "full" and periods > MAX_FULL_RESOLUTION_PERIODS:
            longest = MAX_FULL_RESOLUTION_PERIODS * 2.0 * math.pi / self.omega
            raise ValueError(
                f"duration: {self.duration:g} s at omega = {self.omega:g} rad/s is {periods:.3g} drive periods, and the "
                f"full solver keeps every impact; allowed duration <= {longest:.4g} s here "
                f"({MAX_FULL_RESOLUTION_PERIODS:,} periods), or solver = 'averaged' for longer runs"
            )
        return self

    @model_validator(mode="after")
    def _thermal_network_is_not_stiff(self) -> "Parameters":
        for node, (time_constant, keys) in self.thermal_time_constants_at_rest.items():
            if time_constant < MIN_THERMAL_TIME_CONSTANT_S:
                raise ValueError(
                    f"{', '.join(keys)}: the {node}'s thermal time constant is {time_constant:.3g} s with these values "
                    f"(ball at rest; motion only shortens it); allowed >= {MIN_THERMAL_TIME_CONSTANT_S:g} s, or the "
                    "integrator's steps shrink with it and a run takes hours"
                )
        return self

    # Derived geometry used by more than one module (MODEL.md sections 1 and 6)
    @property
    def ball_mass(self) -> float:
        """m_b = ρ_b·4/3·π R³ (kg)."""
        return self.ball_density * 4.0 / 3.0 * math.pi * self.ball_radius**3

    @property
    def end_face_area(self) -> float:
        """2·π·d_v²/4: both circular end faces (m²), MODEL.md section 1; the paper's A_i = A_o."""
        return end_faces_area(self.vial_diameter)

    @property
    def vial_volume(self) -> float:
        """π d_v²/4·l_v: the vial's inner volume (m³)."""
        return _vial_volume(self.vial_length, self.vial_diameter)

    @property
    def balls_volume(self) -> float:
        """Σ 4/3·π R³ over every ball of the 'dem' engine, or the one ball of the 1-D engine (m³)."""
        radii = self.ball_values("ball_radius") if self.engine == "dem" else (self.ball_radius,)
        return sum(_ball_volume(radius) for radius in radii)

    @property
    def fill_fraction(self) -> float:
        """The fraction of the vial's inner volume the balls take (dimensionless): what ``fill`` asks, as achieved
        by a whole number of balls."""
        return self.balls_volume / self.vial_volume

    @property
    def air_mass(self) -> float:
        """m_a = ρ_a·(π d_v²/4·l_v − Σ 4/3·π R³) (kg), MODEL.md section 6 (every ball of the 'dem' engine)."""
        return self.air_density * (self.vial_volume - self.balls_volume)

    @property
    def air_heat_capacity(self) -> float:
        """c_a = c_p,a/γ: the trapped air is heated at constant volume (J/(kg·K))."""
        return self.air_cp / self.air_heat_capacity_ratio

    @property
    def thermal_time_constants_at_rest(self) -> dict[str, tuple[float, tuple[str, ...]]]:
        """Heat capacity over conductance of each node that evolves (s), and the keys that set it.

        The ball's convection is taken at rest (Nu = 2, h = k_a/R): its motion raises h, so these are
        upper bounds of what a run sees.
        """
        ball_conductance = 4.0 * math.pi * self.ball_radius * self.beta * self.air_conductivity
        ball = self.ball_mass * self.ball_heat_capacity / ball_conductance if ball_conductance > 0 else math.inf
        constants = {"ball": (ball, ("ball_density", "ball_radius", "ball_heat_capacity", "beta", "air_conductivity"))}
        if self.model == "ball_only":
            return constants
        inner, outer = self.h_inner * self.inner_area, self.h_outer * self.outer_area
        vial = self.vial_mass * self.vial_heat_capacity / (inner + outer) if inner + outer > 0 else math.inf
        air_capacity = self.air_mass * self.air_heat_capacity
        air = air_capacity / (inner + ball_conductance) if inner + ball_conductance > 0 else math.inf
        constants["vial"] = (vial, ("vial_mass", "vial_heat_capacity", "h_inner", "inner_area", "h_outer", "outer_area"))
        constants["air"] = (air, ("air_density", "vial_length", "vial_diameter", "h_inner", "inner_area"))
        return constants

    def _repr_html_(self) -> str:
        return present("parameters html", self)

    def replace(self, **changes: Any) -> "Parameters":
        """A new validated ``Parameters`` with ``changes`` applied (values may carry units)."""
        current = self.model_dump()
        if self.fill > 0 and "fill" not in changes:
            # fill made n_balls: it makes it again for the changed ball or vial.
            del current["n_balls"]
        return build_parameters(current, changes)


FIELD_NAMES: tuple[str, ...] = tuple(Parameters.model_fields)
# The per-ball list keys and the scalar key each one refines.
PER_BALL_KEY_OF = {
    str((field.json_schema_extra or {})["per_ball"]): key
    for key, field in Parameters.model_fields.items()
    if "per_ball" in (field.json_schema_extra or {})
}
PER_BALL_KEYS = tuple(PER_BALL_KEY_OF.values())
MATERIAL_KEYS = ("ball_material", "vial_material", "ball_materials")


def _check_per_ball(key: str, values: tuple[float, ...], n_balls: int) -> None:
    if values and len(values) != n_balls:
        raise ValueError(
            f"{key}: {len(values)} values for n_balls = {n_balls}; allowed an empty list or exactly {n_balls} values"
        )
    scalar = next(name for name, per_ball in PER_BALL_KEY_OF.items() if per_ball == key)
    for number, value in enumerate(values, start=1):
        if not bounds(scalar).contains(value):
            raise ValueError(f"{key}: value {number} ({value:g}) is out of range; allowed {allowed_range(scalar)}")


def _check_motion(motion: tuple[tuple[str, int, float, float], ...]) -> None:
    """The summed harmonic amplitudes of each coordinate stay within a metre's half and a half turn."""
    for coordinate in MOTION_COORDINATES:
        amplitude = sum(abs(a) + abs(b) for name, _, a, b in motion if name == coordinate)
        limit, unit = (math.pi, "rad") if coordinate in ("roll", "pitch", "yaw") else (MAX_MOTION_TRANSLATION, "m")
        if amplitude > limit:
            raise ValueError(
                f"motion: the harmonics of {coordinate} add up to {amplitude:g} {unit}; allowed at most {limit:g} {unit}"
            )


def field_unit(key: str) -> str:
    extra = Parameters.model_fields[key].json_schema_extra or {}
    return str(extra.get("unit", ""))


def field_description(key: str) -> str:
    extra = Parameters.model_fields[key].json_schema_extra or {}
    return str(extra.get("description", ""))


@dataclass(frozen=True)
class Bounds:
    """The hard bounds of a numeric key in its SI unit; ``str`` gives them in interval notation."""

    low: float
    high: float
    low_open: bool
    high_open: bool

    def __str__(self) -> str:
        return f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}{')' if self.high_open else ']'}"

    def contains(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below


def bounds(key: str) -> Bounds:
    """The hard bounds of the numeric ``key``, from its field's constraints."""
    low, high, low_open, high_open = -math.inf, math.inf, True, True
    for constraint in Parameters.model_fields[key].metadata:
        if isinstance(constraint, annotated_types.Gt):
            low, low_open = constraint.gt, True
        elif isinstance(constraint, annotated_types.Ge):
            low, low_open = constraint.ge, False
        elif isinstance(constraint, annotated_types.Lt):
            high, high_open = constraint.lt, True
        elif isinstance(constraint, annotated_types.Le):
            high, high_open = constraint.le, False
    return Bounds(float(low), float(high), low_open, high_open)


def allowed_range(key: str) -> str:
    """Human-readable allowed values of ``key`` from its field constraints, e.g. '(0, 1]'."""
    field = Parameters.model_fields[key]
    choices = typing.get_args(field.annotation) if typing.get_origin(field.annotation) is Literal else ()
    if choices:
        return "one of " + ", ".join(repr(choice) for choice in choices)
    if field.annotation is bool:
        return "true or false"
    if key == "record_windows":
        return (
            f"at most {MAX_RECORD_WINDOWS} (start, length) pairs in s, start in [0, {LONGEST_RUN_S:g}], length > 0, "
            f"{MAX_RECORDED_SECONDS:g} s of the run in all"
        )
    if key in PER_BALL_KEYS:
        scalar = next(name for name, per_ball in PER_BALL_KEY_OF.items() if per_ball == key)
        return f"an empty list or n_balls values, each in {allowed_range(scalar)}"
    if key == "ball_materials":
        return f"an empty list or n_balls names, each {materials.allowed_names()}"
    if key in MATERIAL_KEYS:
        return f"'' (none) or {materials.allowed_names()}"
    if key == "motion":
        return (
            f"at most {MAX_HARMONICS} (coordinate, k, cos, sin) terms: coordinate one of {', '.join(MOTION_COORDINATES)}, "
            f"k in [0, {MAX_MOTION_HARMONIC}], translations in m, angles in rad"
        )
    if field.annotation is int:
        return f"a whole number in {bounds(key)}"
    return f"{bounds(key)} {field_unit(key)}".rstrip()


def _ball_volume(radius: float) -> float:
    return 4.0 / 3.0 * math.pi * radius**3


def _vial_volume(vial_length: float, vial_diameter: float) -> float:
    return math.pi * vial_diameter**2 / 4.0 * vial_length


def balls_for_fill(fill: float, ball_radius: float, vial_length: float, vial_diameter: float) -> int:
    """How many equal balls of ``ball_radius`` (m) take ``fill`` of a vial's inner volume (m, m; fill
    dimensionless): n = max(1, round(fill·V_vial/V_ball)), V_vial = π d_v²/4·l_v, halves rounded up."""
    balls = fill * _vial_volume(vial_length, vial_diameter) / _ball_volume(ball_radius)
    return max(1, math.floor(balls + 0.5))


def layered(lower: Mapping[str, Any], upper: Mapping[str, Any]) -> dict[str, Any]:
    """``upper``'s values over ``lower``'s. A fill > 0 in ``upper`` sets the number of balls itself, so it
    replaces ``lower``'s n_balls; an n_balls in ``upper`` stays, and must agree with it."""
    merged = {**lower, **upper}
    if "n_balls" not in upper and "fill" in upper and _coerce("fill", upper["fill"]) > 0:
        merged.pop("n_balls", None)
    return merged


def _with_balls_of_fill(values: dict[str, Any]) -> dict[str, Any]:
    """SI ``values`` with the n_balls their fill > 0 makes, where no layer gave n_balls (:func:`layered`)."""
    if "n_balls" in values or not values.get("fill", 0) > 0:
        return values
    geometry = [values.get(key) for key in ("ball_radius", "vial_length", "vial_diameter")]
    # A missing or non-positive length gets its own error, as does a count beyond MAX_BALLS: fill's, which
    # names fill, rather than n_balls' bounds.
    count = balls_for_fill(values["fill"], *geometry) if all(isinstance(v, float) and v > 0 for v in geometry) else 1
    return {**values, "n_balls": min(count, MAX_BALLS)}


def end_faces_area(vial_diameter: float) -> float:
    """Area of the two circular end faces of a vial of inner diameter ``vial_diameter`` (m²)."""
    return 2.0 * math.pi * vial_diameter**2 / 4.0


@dataclass(frozen=True)
class Cited:
    """A preset value with where it comes from."""

    value: Any
    source: str


@dataclass(frozen=True)
class Preset:
    """A named parameter set. ``fitted`` names the keys a calibration set, ``provenance`` says how."""

    name: str
    description: str
    values: Mapping[str, Cited]
    fitted: tuple[str, ...] = ()
    provenance: Mapping[str, Any] = dataclasses.field(default_factory=dict)


SPEX_8000M = Preset(
    name="spex8000m",
    description="SPEX 8000M Mixer/Mill, one 12.7 mm steel ball, as in Son 2025 (published parameters).",
    values={
        "ball_radius": Cited(6.35e-3, f"{PAPER}, Table 1"),
        "vial_length": Cited(58e-3, f"{PAPER}, Table 1"),
        "vial_diameter": Cited(19e-3, f"{PAPER}, Table 1 (A_i = A_o = 567.06 mm² = 2·π·d_v²/4)"),
        "amplitude": Cited(25e-3, f"{PAPER}, Table 1 (X_v)"),
        "omega": Cited(111.0, "assumption: not stated (range 90-130 rad/s); ~1060 cycles/min, the SPEX 8000M on 60 Hz mains"),
        "phase": Cited(0.0, "assumption"),
        "ball_density": Cited(7800.0, f"{PAPER}, Table 2"),
        "vial_density": Cited(7800.0, f"{PAPER}, Table 2"),
        "ball_youngs_modulus": Cited(200e9, f"{PAPER}, Table 2"),
        "vial_youngs_modulus": Cited(200e9, f"{PAPER}, Table 2"),
        "ball_poisson_ratio": Cited(0.3, f"{PAPER}, Table 2"),
        "vial_poisson_ratio": Cited(0.3, f"{PAPER}, Table 2"),
        "ball_heat_capacity": Cited(461.0, f"{PAPER}, Table 2"),
        "vial_heat_capacity": Cited(461.0, f"{PAPER}, Table 2"),
        "vial_mass": Cited(
            0.05,
            "assumption: not printed in the paper; the steel near the two end faces that exchanges heat with the "
            "inside and outside air. It sets the time constant, not the steady state; calibration fits it",
        ),
        "air_density": Cited(1.225, f"{PAPER}, Table 3"),
        "air_viscosity_ref": Cited(1.716e-5, f"{PAPER}, Table 3 (at 273.15 K)"),
        "air_reference_temperature": Cited(273.15, f"{PAPER}, Table 3 footnote (0 °C)"),
        "air_conductivity": Cited(0.0241, f"{PAPER}, Table 3"),
        "air_cp": Cited(1003.5, f"{PAPER}, Table 3"),
        "air_heat_capacity_ratio": Cited(1.4, "assumption: diatomic ideal gas; c_a = c_p,a/1.4 (MODEL.md section 6)"),
        "sutherland": Cited(111.0, f"{PAPER}, Table 3"),
        "h_inner": Cited(200.0, f"{PAPER}, Table 3"),
        "h_outer": Cited(45.0, f"{PAPER}, Table 3"),
        "inner_area": Cited(end_faces_area(19e-3), f"{PAPER}, Table 1 (A_i = 567.06 mm²: the two end faces, MODEL.md §1)"),
        "outer_area": Cited(
            end_faces_area(19e-3),
            f"{PAPER}, Table 1 (A_o = 567.06 mm²: the two end faces only; a real vial also loses heat through its "
            "side, MODEL.md §11)",
        ),
        "restitution": Cited(0.7, f"{PAPER}, Table 4 (e)"),
        "eta": Cited(0.9, f"{PAPER}, Table 4 (η)"),
        "lam": Cited(0.368, f"{PAPER}, Table 4 (λ)"),
        "beta": Cited(0.3, f"{PAPER}, Table 4 (β, tuned by hand by the author)"),
        "duration": Cited(3600.0, f"{PAPER}, Table 4 (60 min)"),
        "ambient_temperature": Cited(293.15, f"{PAPER}, Table 3 footnote (ambient 20 °C)"),
        "initial_temperature": Cited(293.15, f"assumption: θ̇_0 of {PAPER} Table 5 implies θ_0 = 20 °C"),
        "ball_temperature_limit": Cited(
            1673.15, "assumption: carbon and bearing steels begin to melt near 1400 °C; above it the model does not hold"
        ),
        "ball_position": Cited(0.0, "assumption: ball starts at the vial centre"),
        "ball_momentum": Cited(0.0, "assumption: ball starts at rest"),
        "rtol": Cited(1e-3, "MATLAB ode23 default RelTol, as used by the paper"),
        "atol_position": Cited(1e-6, "MATLAB ode23 default AbsTol (1e-6, in SI)"),
        "atol_momentum": Cited(1e-6, "MATLAB ode23 default AbsTol (1e-6, in SI)"),
        "atol_temperature": Cited(1e-6, "MATLAB ode23 default AbsTol (1e-6, in SI)"),
        "output_interval": Cited(1.0, "assumption: 1 s sampling of the stored time series"),
        "solver": Cited("full", "full resolution, as the paper"),
        "averaging_rel_error": Cited(1e-3, "numerical choice: ±0.1 % on the mean heat rate, ~0.1 K on a 100 K rise"),
        "dem_averaging_rel_error": Cited(
            1e-2, "numerical choice: ±1 % on each ball's mean heat rate (~0.3 K on a 30 K rise) in ~40 s of mechanics"
        ),
        "averaging_batch_periods": Cited(16, "numerical choice: batches of 16 drive periods (~0.9 s)"),
        "averaging_min_batches": Cited(10, "numerical choice: the usual minimum for batch means"),
        "averaging_max_time": Cited(120.0, "numerical choice: 2 simulated minutes of mechanics at most"),
        "averaging_fallback": Cited("full", "numerical choice: fall back to full resolution and say so"),
        "attractor_starts": Cited(
            8,
            "numerical choice: the configured start and 7 spread over the free gap, at rest or at the vial's peak "
            "speed; ~0.02 s of mechanics each",
        ),
        "energy_projection": Cited(True, "numerical choice: projection method (Hairer, Lubich & Wanner 2006, §IV.4)"),
        "max_wall_time": Cited(
            3600.0,
            "numerical choice: an hour; the default 60-min run takes ~3 s, the same at rtol 1e-6 ~20 s, and 10⁹ steps "
            "(max_steps) ~10-20 min",
        ),
        "max_steps": Cited(
            1_000_000_000,
            "numerical choice: ~290 simulated hours at the defaults (3.4 million steps an hour), ~30 h at rtol 1e-6; "
            "beyond it the steps are tiny (a stiff node or an extreme drive)",
        ),
        "model": Cited("three_node", f"{PAPER}: ball, vial and inner air as three lumped reservoirs"),
        "no_tension": Cited(False, "MODEL.md section 2: the total force is not clipped by default"),
        "heat_model": Cited("relative", "MODEL.md section 3: frame-invariant dissipation c·ζ̇²"),
        "convection_velocity": Cited(
            "auto",
            f"{PAPER}, section 3.3 (Re from the ball's velocity) for the 1-D engine; relative to the vial for 'dem' "
            "(MODEL.md section 12.5)",
        ),
        "engine": Cited("1d", f"{PAPER}: one ball on the vial's axis"),
        "n_balls": Cited(1, f"{PAPER}: one ball"),
        "fill": Cited(0.0, "unused: n_balls gives the number of balls"),
        **{key: Cited("", "no material: the keys' own values (the paper's steel)") for key in ("ball_material", "vial_material")},
        "ball_materials": Cited((), "every ball takes ball_material, or the scalar keys' values"),
        **{key: Cited((), "every ball takes the scalar key's value") for key in PER_BALL_KEYS},
        "ball_conductivity": Cited(
            46.6, "AISI 52100 bearing steel at room temperature (ASM data sheet); only ratios between balls matter"
        ),
        "gravity": Cited(True, "MODEL.md section 12.1: 9.81 m/s² downward, the vial axis horizontal (engine = 'dem')"),
        "friction": Cited(
            0.3,
            "assumption: a common choice for dry steel-on-steel contacts in DEM mill studies; not measured for SPEX "
            "media (docs/notes/dem-references.md, section 3), so results should be checked against it",
        ),
        "rolling_friction": Cited(0.0, "MODEL.md section 12.3: no rolling resistance by default"),
        "kinematics": Cited("axial", f"{PAPER}: the vial moves along its axis (MODEL.md section 12.2)"),
        "motion": Cited((), "used only with kinematics = 'fourier'"),
        **{key: Cited(value, source) for key, (value, source) in ASSUMED_DEFAULTS.items()},
        "contact_step_fraction": Cited(
            0.05,
            "numerical choice: restitution within 1e-3, the 1-D limit's heat power within 0.25 % of the converged "
            "value, five balls' within the ~1 % their statistics resolve (benchmarks/README.md, dem engine)",
        ),
        "max_flight_step": Cited(1e-4, "numerical choice: ~1/60 of a drive period, so the wall's motion is resolved"),
        "record_windows": Cited(
            ((0.0, 1.0), (600.0, 0.1)),
            f"the windows of {PAPER} Fig. 4 (first second) and Fig. 5b (100 ms at 10 min)",
        ),
    },
)

def _coerce_material(key: str, value: Any) -> str | tuple[str, ...]:
    """Canonical material names from a name or alias ('' or None: none), or for ``ball_materials`` from
    "wc, zirconia" (the command line) or a list (TOML, Python)."""
    if key != "ball_materials":
        return "" if value is None or not str(value).strip() else _material_named(key, value)
    items = [item for item in value.split(",") if item.strip()] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)):
        raise ParameterError(
            f"{key}: expected a list of material names, one per ball, got {quoted(value)}; allowed {allowed_range(key)}"
        )
    return tuple(_material_named(key, item) for item in items)


def _material_named(key: str, name: Any) -> str:
    try:
        return materials.material(name).name
    except materials.UnknownMaterial as exc:
        raise ParameterError(f"{key}: {exc}") from None


def material_citations(layer: Mapping[str, Any]) -> dict[str, Cited]:
    """The keys that the materials named in ``layer`` stand for, each with the material's value and source."""
    cited: dict[str, Cited] = {}
    for key, prefix in (("ball_material", "ball_"), ("vial_material", "vial_")):
        name = _coerce_material(key, layer.get(key, ""))
        if name:
            found = materials.material(name)
            for prop in materials.FILLED:
                if prefix + prop in Parameters.model_fields:
                    value = getattr(found, prop)
                    cited[prefix + prop] = Cited(value.value, f"material {name}: {value.source}")
    per_ball = [materials.material(name) for name in _coerce_material("ball_materials", layer.get("ball_materials", ()))]
    for prop in materials.FILLED if per_ball else ():
        sources = dict.fromkeys(f"{found.name}: {getattr(found, prop).source}" for found in per_ball)
        values = tuple(getattr(found, prop).value for found in per_ball)
        cited[PER_BALL_KEY_OF[f"ball_{prop}"]] = Cited(values, f"ball_materials: {'; '.join(sources)}")
    return cited


def with_materials(layer: Mapping[str, Any]) -> dict[str, Any]:
    """``layer`` (a preset, a file, the ``--set`` overrides, a sweep point) with the values its materials fill in.

    A key that ``layer`` sets itself wins over its material, and a later layer wins over both: each layer is
    completed on its own before the layers are merged, so ``--set ball_material=wc`` replaces the preset's
    steel density, while a file's ``ball_density`` beside its ``ball_material`` is kept.
    """
    return {**{key: cited.value for key, cited in material_citations(layer).items()}, **layer}


def takes_names(key: str) -> bool:
    """Whether ``key`` takes one name: a material or one of an option's choices."""
    annotation = Parameters.model_fields[key].annotation
    return annotation is str or typing.get_origin(annotation) is Literal


def checked_name(key: str, value: Any) -> str:
    """``value`` of a key that :func:`takes_names`, checked: its canonical name (a material's alias resolved)."""
    if key in MATERIAL_KEYS:
        return str(_coerce_material(key, value))
    if value not in typing.get_args(Parameters.model_fields[key].annotation):
        raise ParameterError(f"{key}: {quoted(value)} is not allowed; allowed {allowed_range(key)}")
    return str(value)


# Presets other than the paper's ship as TOML files next to this module: a base preset, the values that
# differ and a [provenance] table: for a calibration, the fit (command, targets, residuals, date, version);
# for a hand-made preset, [provenance.sources], the source of each value it sets.
PRESET_FOLDER = Path(__file__).parent / "presets"


def load_preset_file(path: Path, known: Mapping[str, Preset]) -> Preset:
    """A preset from a calibration TOML file, on top of the preset it names as its base."""
    with path.open("rb") as handle:
        data = tomllib.load(handle)
    provenance = dict(data.pop("provenance", {}))
    base = known[data.pop("preset")]
    fitted = tuple(provenance.get("fitted", ()))
    sources = provenance.get("sources", {})
    note = f"fitted by calibration ({path.name}, [provenance])"
    values = {**base.values, **material_citations(data)}
    for key, value in data.items():
        source = note if key in fitted else sources.get(key, f"set in {path.name}")
        values[key] = Cited(tuple(map(tuple, value)) if key == "record_windows" else value, source)
    return Preset(
        name=path.stem,
        description=str(provenance.get("description", f"{base.name} with values from {path.name}")),
        values=values,
        fitted=fitted,
        provenance=provenance,
    )


def load_presets(folder: Path, built_in: Preset) -> dict[str, Preset]:
    """The built-in preset and every TOML file of ``folder``, each loaded after the preset it builds on."""
    presets = {built_in.name: built_in}
    waiting = {path.stem: path for path in sorted(folder.glob("*.toml"))}
    bases = {name: _base_of(path) for name, path in waiting.items()}
    while waiting:
        ready = [name for name in waiting if bases[name] in presets]
        if not ready:
            raise ValueError(f"presets {', '.join(sorted(waiting))} build on presets that do not exist or on each other")
        for name in ready:
            presets[name] = load_preset_file(waiting.pop(name), presets)
    return presets


def _base_of(path: Path) -> str:
    with path.open("rb") as handle:
        return str(tomllib.load(handle).get("preset", ""))


PRESETS: dict[str, Preset] = load_presets(PRESET_FOLDER, SPEX_8000M)
DEFAULT_PRESET = SPEX_8000M.name


def preset_values(name: str) -> dict[str, Any]:
    if name not in PRESETS:
        raise ParameterError(f"preset: unknown preset {name!r}; available: {', '.join(sorted(PRESETS))}")
    return {key: cited.value for key, cited in PRESETS[name].values.items()}


def check_known_keys(keys: list[str] | tuple[str, ...], *, extra_allowed: tuple[str, ...] = ()) -> None:
    """Raise :class:`ParameterError` with a did-you-mean suggestion for the first unknown key."""
    known = FIELD_NAMES + extra_allowed
    for key in keys:
        if key not in known:
            # A key longer than any known one is no typo of one; it is quoted short so the line stays readable.
            close = difflib.get_close_matches(key, known, n=1) if len(key) <= QUOTED_LENGTH else []
            hint = f"; did you mean {close[0]!r}?" if close else "; `shakermill keys` lists the allowed keys"
            shown = key if len(key) <= QUOTED_LENGTH else quoted(key)
            raise ParameterError(f"{shown}: unknown parameter{hint}")


# Guards against unit slips. Bare numbers are SI, but people give temperatures in °C, lengths in mm and
# frequencies in rpm or Hz: a bare temperature below this many kelvin is almost surely °C, and is refused.
BARE_TEMPERATURE_MINIMUM = 200.0
USER_TEMPERATURE_KEYS = ("ambient_temperature", "initial_temperature", "ball_temperature_limit")


@dataclass(frozen=True)
class PlausibleRange:
    """Values real mills and laboratories use, in the key's SI unit, and the units people slip into."""

    low: float
    high: float
    users: str
    likely_units: tuple[str, ...]


PLAUSIBLE_RANGES: dict[str, PlausibleRange] = {
    # Mixer mills shake at 3-35 Hz (3 Hz = 18.8 rad/s), planetary mills turn at up to ~1100 rpm of the sun wheel.
    "omega": PlausibleRange(18.0, 400.0, "shaker and planetary mills", ("rpm", "Hz")),
    "amplitude": PlausibleRange(1e-3, 0.1, "shaker mills", ("mm",)),
    "ball_radius": PlausibleRange(2.5e-4, 0.05, "milling balls", ("mm",)),
    "vial_length": PlausibleRange(5e-3, 0.5, "milling vials", ("mm",)),
    "vial_diameter": PlausibleRange(5e-3, 0.5, "milling vials", ("mm",)),
    "ambient_temperature": PlausibleRange(250.0, 330.0, "laboratories", ("degC",)),
    "initial_temperature": PlausibleRange(250.0, 400.0, "laboratories", ("degC",)),
}


def unit_slip(key: str, value: float) -> str | None:
    """Why ``value`` (SI) of ``key`` looks like a unit slip, naming the unit likely meant; None if plausible."""
    plausible = PLAUSIBLE_RANGES.get(key)
    if plausible is None or plausible.low <= value <= plausible.high:
        return None
    unit = field_unit(key)
    meant = next((alt for alt in plausible.likely_units if _plausible_in(alt, value, key)), None)
    hint = f"; did you mean {value:g} {meant}? Write {key}='{value:g} {meant}'" if meant else ""
    return (
        f"{key} = {value:g} {unit} is outside what {plausible.users} use "
        f"({plausible.low:g} to {plausible.high:g} {unit}); bare numbers are SI{hint}"
    )


def _plausible_in(unit: str, value: float, key: str) -> bool:
    """Whether ``value`` read in ``unit`` is plausible for ``key`` (1e308 Hz is no frequency at all)."""
    plausible = PLAUSIBLE_RANGES[key]
    try:
        return plausible.low <= to_si(f"{value:g} {unit}", field_unit(key), key=key) <= plausible.high
    except UnitError:
        return False


def unit_slip_warnings(params: Parameters) -> list[str]:
    """One line per value outside :data:`PLAUSIBLE_RANGES` (see :func:`unit_slip`)."""
    return [line for key in PLAUSIBLE_RANGES if (line := unit_slip(key, getattr(params, key))) is not None]


def _is_bare_number(value: Any) -> bool:
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    try:
        float(str(value).strip())
    except ValueError:
        return False
    return True


def _coerce(key: str, value: Any) -> Any:
    """Convert a user value for ``key`` to SI (strings with units) or to the option's type.

    Raises :class:`ParameterError` naming the key and its allowed values.
    """
    annotation = Parameters.model_fields[key].annotation
    try:
        if annotation is float:
            return _coerce_quantity(key, value)
        if annotation is int:
            return whole_number(key, value)
        if annotation is bool:
            return _coerce_switch(key, value)
        if key == "record_windows":
            return _coerce_windows(value)
        if key in PER_BALL_KEYS:
            return _coerce_per_ball(key, value)
        if key == "motion":
            return _coerce_motion(value)
        if key in MATERIAL_KEYS:
            return _coerce_material(key, value)
    except UnitError as exc:
        raise ParameterError(f"{exc}; allowed {allowed_range(key)}") from None
    return value  # one of a few names: the model checks it


def _coerce_quantity(key: str, value: Any) -> float:
    number = to_si(value, field_unit(key), key=key)
    if key in USER_TEMPERATURE_KEYS and _is_bare_number(value) and number < BARE_TEMPERATURE_MINIMUM:
        raise ParameterError(
            f"{key}: a bare {number:g} is read as {number:g} K ({number - 273.15:.2f} °C); bare temperatures below "
            f"{BARE_TEMPERATURE_MINIMUM:g} are refused: write '{number:g} degC' or '{number + 273.15:g} K'"
        )
    return number


def whole_number(key: str, value: Any) -> int:
    """``value`` of a count key as an int; :class:`UnitError` for anything else."""
    # A TOML `true` is not 1, and 2.5 starts are not 2.
    if isinstance(value, bool):
        raise UnitError(f"{key}: expected a whole number, got {value!r}")
    if isinstance(value, numbers.Integral):
        return int(value)
    number = to_si(value, "", key=key)
    if not number.is_integer():
        raise UnitError(f"{key}: expected a whole number, got {quoted(value)}")
    return int(number)


def _coerce_switch(key: str, value: Any) -> bool:
    if isinstance(value, bool):
        return value
    lowered = value.strip().lower() if isinstance(value, str) else None
    if lowered in {"true", "1", "yes", "on"}:
        return True
    if lowered in {"false", "0", "no", "off"}:
        return False
    raise UnitError(f"{key}: expected true or false, got {quoted(value)}")


def _coerce_windows(value: Any) -> tuple[tuple[float, float], ...]:
    """Windows from "0:1,600:0.1" (the command line; "" means none) or from (start, length) pairs (TOML, Python)."""
    if isinstance(value, str):
        pairs: Any = [item.split(":") for item in value.split(",") if item.strip()]
    elif isinstance(value, (list, tuple)):
        pairs = value
    else:
        raise UnitError(f"record_windows: expected (start, length) pairs, got {quoted(value)}")
    if len(pairs) > MAX_RECORD_WINDOWS:
        raise UnitError(f"record_windows: {len(pairs)} windows are too many")
    return tuple(_window(pair) for pair in pairs)


def _window(pair: Any) -> tuple[float, float]:
    if not isinstance(pair, (list, tuple)) or len(pair) != 2:
        raise UnitError(f"record_windows: expected START:LENGTH (or [start, length]) in seconds, got {quoted(pair)}")
    start, length = (to_si(item, "s", key="record_windows") for item in pair)
    return start, length


def _coerce_per_ball(key: str, value: Any) -> tuple[float, ...]:
    """Per-ball values from "6 mm, 5 mm" (the command line; "" means none) or a list (TOML, Python)."""
    items = [item for item in value.split(",") if item.strip()] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)):
        raise UnitError(f"{key}: expected a list of values, one per ball, got {quoted(value)}")
    scalar = next(name for name, per_ball in PER_BALL_KEY_OF.items() if per_ball == key)
    return tuple(to_si(item, field_unit(scalar), key=key) for item in items)


def _coerce_motion(value: Any) -> tuple[tuple[str, int, float, float], ...]:
    """Harmonics from "x:1:0:25 mm, yaw:2:0.1:0" (the command line) or (coordinate, k, cos, sin) lists (TOML)."""
    terms: Any = [item.split(":") for item in value.split(",") if item.strip()] if isinstance(value, str) else value
    if not isinstance(terms, (list, tuple)):
        raise UnitError(f"motion: expected (coordinate, k, cos, sin) terms, got {quoted(value)}")
    return tuple(_harmonic(term) for term in terms)


def _harmonic(term: Any) -> tuple[str, int, float, float]:
    if not isinstance(term, (list, tuple)) or len(term) != 4 or str(term[0]).strip() not in MOTION_COORDINATES:
        raise UnitError(
            f"motion: expected COORDINATE:K:COS:SIN with a coordinate of {', '.join(MOTION_COORDINATES)}, got {quoted(term)}"
        )
    coordinate = str(term[0]).strip()
    unit = "rad" if coordinate in ("roll", "pitch", "yaw") else "m"
    harmonic = whole_number("motion", term[1])
    return coordinate, harmonic, to_si(term[2], unit, key="motion"), to_si(term[3], unit, key="motion")


RANGE_ERRORS = frozenset({"greater_than", "greater_than_equal", "less_than", "less_than_equal"})


def _shown_value(value: Any) -> str:
    """A float as short as it reads back exactly (1e+12, not 1000000000000.0); anything else quoted short."""
    if isinstance(value, float) and float(f"{value:g}") == value:
        return f"{value:g}"
    return quoted(value)


def _one_line(error: ValidationError) -> str:
    first = error.errors()[0]
    location = first.get("loc") or ()
    key = str(location[0]) if location else ""
    if key not in Parameters.model_fields:
        return str(first["msg"]).removeprefix("Value error, ")
    value = _shown_value(first.get("input"))
    message = str(first["msg"])
    problem = f"{value} is out of range" if first.get("type") in RANGE_ERRORS else f"{message[:1].lower()}{message[1:]} (got {value})"
    return f"{key}: {problem}; allowed {allowed_range(key)}"


def build_parameters(base: Mapping[str, Any], overrides: Mapping[str, Any] | None = None) -> Parameters:
    """Validate ``base`` updated with ``overrides`` (:func:`layered`) into :class:`Parameters`, each completed
    by its materials first (:func:`with_materials`); a fill > 0 makes n_balls where neither layer above it does.

    Raises :class:`ParameterError` with one line that names the offending key.
    """
    merged = layered(with_materials(base), with_materials(overrides or {}))
    check_known_keys(list(merged))
    coerced = _with_balls_of_fill({key: _coerce(key, value) for key, value in merged.items()})
    missing = [key for key in FIELD_NAMES if key not in coerced]
    if missing:
        raise ParameterError(f"{missing[0]}: no value given and no preset supplies one")
    try:
        return Parameters(**coerced)
    except ValidationError as exc:
        raise ParameterError(_with_unit_hint(_one_line(exc), coerced)) from None


def _with_unit_hint(message: str, values: Mapping[str, Any]) -> str:
    """``message`` about a key, with the unit slip behind it when there is one.

    A ball of 6.35 m does not fit the vial: the geometry error alone would hide the slip.
    """
    key = message.partition(":")[0]
    slip = unit_slip(key, values[key]) if key in PLAUSIBLE_RANGES else None
    return message if slip is None else f"{message} ({slip})"


def default_parameters(preset: str = DEFAULT_PRESET, **overrides: Any) -> Parameters:
    """The parameters of ``preset`` with keyword ``overrides`` (values may carry units)."""
    return build_parameters(preset_values(preset), overrides)
