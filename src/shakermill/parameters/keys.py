"""Validated, immutable run parameters with the canonical keys of MODEL.md section 9: every key with its unit,
bounds and description (:class:`Parameters`), and their construction from user values (:func:`build_parameters`).

Every numeric field is SI. Users may give strings with units ("25 mm"); they are converted by :mod:`guards`
before validation, so a ``Parameters`` object only ever holds floats in SI. The checks across keys are in
:mod:`consistency`, the presets with their citations in :mod:`presets`.
"""

from __future__ import annotations

import difflib
import math
import typing
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Literal

import annotated_types
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator
from pydantic_core import PydanticCustomError

from shakermill.parameters import consistency, guards, materials
from shakermill.parameters.bounds import Bounds
from shakermill.parameters.derived import DerivedQuantities
from shakermill.parameters.engine_keys import ENGINE_KEYS, MAX_BALLS
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.fields import (
    LONGEST_RUN_S,
    MAX_HARMONICS,
    MAX_STRESS_THRESHOLDS,
    Harmonic,
    StressThreshold,
    Window,
    choice,
    count,
    material_name,
    per_ball,
    quantity,
)
from shakermill.parameters.geometry import DENSEST_PACKING, balls_for_fill
from shakermill.parameters.kinematic_models import MAX_MOTION_HARMONIC, MAX_MOTION_TRANSLATION, MOTION_COORDINATES
from shakermill.parameters.units import UnitError
from shakermill.support.limits import MAX_RECORD_WINDOWS, MAX_RECORDED_SECONDS, QUOTED_LENGTH, quoted
from shakermill.support.presenters import present

if TYPE_CHECKING:
    pass


# Every key has hard bounds: a value outside them is refused with one line naming the key and its range.
# They are wide enough for any real mill (PLAUSIBLE_RANGES warns about the merely unusual inside them)
# and tight enough that the model and its integrator stay meaningful and finish; the comment above each
# field says why its bounds are where they are. Lower bounds of 0 that stay open are physical (no
# negative length), except where a small value makes the run misbehave.
class Parameters(DerivedQuantities, BaseModel):
    """One run of the one-ball shaker-mill model (MODEL.md sections 1–9)."""

    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True, allow_inf_nan=False)

    # Geometry and drive (MODEL.md section 1)
    # 25 µm: the finest beads of bead mills (50 µm across); 0.1 m: larger than any milling ball (~50 mm).
    ball_radius: float = quantity("m", "milling ball radius R (or give ball_diameter, twice it)", ge=2.5e-5, le=0.1)
    # 1 mm to 1 m: from micro-vials to twice the largest vibratory mill's vessel.
    vial_length: float = quantity("m", "inner length of the vial l_v", ge=1e-3, le=1.0)
    vial_diameter: float = quantity("m", "inner diameter of the vial d_v", ge=1e-3, le=1.0)
    # Open at 0: a vanishing stroke is a resting wall, the analytic test of a single impact. 0.5 m: five
    # times the longest stroke of a shaker mill.
    amplitude: float = quantity(
        "m",
        "vial oscillation amplitude X_v (kinematics = 'mixer-mill-arc': along the arc, at the jar's centre)",
        gt=0,
        le=0.5,
    )
    # 1 rad/s (0.16 Hz): thirty times slower than any mill. 1e4 rad/s (1.6 kHz): beyond acoustic mixers
    # (60 Hz), high enough that 1060 typed for rpm is warned about, not refused; the step count grows with ω.
    omega: float = quantity(
        "rad/s", "vial angular frequency ω (kinematics = 'planetary': the sun wheel's speed)", ge=1.0, le=1e4
    )
    # One turn either way: every phase has an equal one inside, and larger ones only cost precision in sin(ωt + φ).
    phase: float = quantity("rad", "vial phase φ at t = 0", ge=-2 * math.pi, le=2 * math.pi)
    # Materials (Table 2). A named material fills in the keys below (with_materials); '' leaves them as they are.
    ball_material: str = material_name(
        "the balls", "ball_density, ball_youngs_modulus, ball_poisson_ratio, ball_heat_capacity, ball_conductivity"
    )
    vial_material: str = material_name(
        "the vial", "vial_density, vial_youngs_modulus, vial_poisson_ratio, vial_heat_capacity, vial_conductivity"
    )
    # 500 kg/m³: below every solid milling medium (polyethylene ~950); 25 000: above osmium (22 590), the
    # densest element. A ball of 1e-6 kg/m³ has no heat capacity and made a run take hours.
    ball_density: float = quantity("kg/m^3", "ball density ρ_b", ge=500.0, le=25_000.0)
    vial_density: float = quantity("kg/m^3", "vial density ρ_v", ge=500.0, le=25_000.0)
    # 0.1 MPa: softer than rubber; such contacts overlap past what the integrator allows and the run stops
    # with its status. 1.2 TPa: diamond, the stiffest solid.
    ball_youngs_modulus: float = quantity("Pa", "ball Young's modulus E_b", ge=1e5, le=1.2e12)
    vial_youngs_modulus: float = quantity("Pa", "vial Young's modulus E_v", ge=1e5, le=1.2e12)
    # Dense solids lie in 0-0.5 (diamond 0.07, steel 0.3, rubber 0.5); -0.5 leaves room for auxetic
    # materials. As ν -> -1 the shear modulus, and the Rayleigh time that bounds contact steps, vanish.
    ball_poisson_ratio: float = quantity("", "ball Poisson ratio ν_b", ge=-0.5, lt=0.5)
    vial_poisson_ratio: float = quantity("", "vial Poisson ratio ν_v", ge=-0.5, lt=0.5)
    # 50 J/(kg·K): below the heaviest metals (lead, tungsten, gold ~130); 5000: above polymers (~2000)
    # and water (4186).
    ball_heat_capacity: float = quantity("J/(kg*K)", "ball specific heat c_b", ge=50.0, le=5000.0)
    vial_heat_capacity: float = quantity("J/(kg*K)", "vial specific heat c_v", ge=50.0, le=5000.0)
    # 1 g: less steel than one 19-mm end face 0.5 mm thick; 1e-12 kg made the vial's time constant a
    # nanosecond and a run take hours. 100 kg: a heavy vial with its clamp, many times over.
    vial_mass: float = quantity("kg", "thermally active vial mass m_v", ge=1e-3, le=100.0)
    # Air (Table 3); the bounds cover the gases mills are filled with, from a rough vacuum to high pressure.
    # 0.01 kg/m³ (~10 mbar of air): below it the gas is no continuum for Whitaker's correlation and the
    # air node's time constant falls under a millisecond. 200: nitrogen at ~170 bar.
    air_density: float = quantity("kg/m^3", "air density ρ_a", ge=0.01, le=200.0)
    # Gases at 0 °C: hydrogen 8.4e-6 to neon 3e-5 Pa·s, with room either way.
    air_viscosity_ref: float = quantity("Pa*s", "air viscosity μ_r at the reference temperature", ge=1e-6, le=1e-4)
    # The reference of Sutherland's law: 50-2000 K covers every tabulated reference point.
    air_reference_temperature: float = quantity(
        "K", "reference temperature θ_r of Sutherland's law", ge=50.0, le=2000.0
    )
    # Gases: xenon 0.005 to hydrogen 0.18 W/(m·K).
    air_conductivity: float = quantity("W/(m*K)", "air thermal conductivity k_a", ge=1e-3, le=1.0)
    # Gases: xenon 158 to hydrogen 14 300 J/(kg·K).
    air_cp: float = quantity("J/(kg*K)", "air specific heat at constant pressure c_p,a", ge=100.0, le=20_000.0)
    # An ideal gas has 1 < γ <= 5/3 (monatomic).
    air_heat_capacity_ratio: float = quantity("", "c_p/c_v of air", gt=1, le=5 / 3)
    # Sutherland constants of gases: hydrogen 72 K, air 111, carbon dioxide 240; 1000 leaves room.
    sutherland: float = quantity("K", "Sutherland constant S", ge=0, le=1000.0)
    # 0 switches the exchange off; 1e4 W/(m²·K) is liquid cooling, far above gas convection (5-250).
    h_inner: float = quantity("W/(m^2*K)", "vial-to-inner-air convection coefficient h_i", ge=0, le=1e4)
    h_outer: float = quantity("W/(m^2*K)", "vial-to-surroundings convection coefficient h_o", ge=0, le=1e4)
    # 10 m²: the whole surface of a vial of 1 m, the largest allowed.
    inner_area: float = quantity("m^2", "vial surface exchanging heat with the inner air A_i", gt=0, le=10.0)
    outer_area: float = quantity("m^2", "vial surface exchanging heat with the surroundings A_o", gt=0, le=10.0)
    # The thermal network of a real mill (MODEL.md section 13): its structure and the paths beyond the paper's.
    thermal_model: Literal["paper", "mill-head"] = choice(
        "'paper': ball, vial and air, the vial losing h_outer·outer_area to the room (MODEL.md §5); 'mill-head': the "
        "vial's outer convection and radiation at its own speed, conduction through contacts, a clamp warmed "
        "by the drive (§13)"
    )
    # 1 mm to 1 m as the bore; the outside must hold the bore (checked below).
    outer_diameter: float = quantity(
        "m", "outer diameter of the vial D_o (thermal_model = 'mill-head')", ge=1e-3, le=1.0
    )
    outer_length: float = quantity("m", "outer length of the vial L_o (thermal_model = 'mill-head')", ge=1e-3, le=1.0)
    # Polished metal ~0.05, oxidised steel ~0.8, black paint ~0.95.
    emissivity: float = quantity("", "emissivity ε of the vial's outside (thermal_model = 'mill-head')", ge=0, le=1)
    # Gases' 0.005 to diamond's 2000, as the balls'.
    vial_conductivity: float = quantity("W/(m*K)", "vial thermal conductivity k_v", ge=0.01, le=2000.0)
    # Up to ~50 kg of steel in a clamp and mill head; 0 is refused: the node needs a heat capacity. The joint and the
    # loss up to a soldered joint over 10 cm² (0 decouples); the drive's heat up to a mill's whole motor (~0.1-1 kW).
    clamp_heat_capacity: float = quantity(
        "J/K", "heat capacity C_k of the clamp and mill head ('mill-head')", gt=0, le=1e5
    )
    clamp_conductance: float = quantity("W/K", "vial-to-clamp contact conductance G_vk ('mill-head')", ge=0, le=1e3)
    clamp_loss: float = quantity("W/K", "clamp-to-room conductance G_k (thermal_model = 'mill-head')", ge=0, le=1e3)
    drive_heat: float = quantity(
        "W", "heat Q_m the drive puts into the clamp whatever the balls do ('mill-head')", ge=0, le=1e3
    )
    # Powder (engine = 'dem'; MODEL.md §13, engines/thermal/powder.py): up to 1 kg, far beyond a planetary bowl's
    # charge; 0 leaves the network without a powder node. The coefficient spans a loose layer millimetres thick
    # (2k/ℓ with k ~0.05 W/(m·K)) to a thin, compacted one; 0 decouples the layer.
    powder_mass: float = quantity("kg", "mass m_p of powder in the vial (engine = 'dem'); 0: none", ge=0, le=1.0)
    powder_material: str = material_name("the powder", "powder_heat_capacity")
    powder_heat_capacity: float = quantity("J/(kg*K)", "powder specific heat c_p (powder_mass > 0)", ge=50, le=5000)
    powder_heat_share: float = quantity(
        "", "share φ of each contact's heat deposited in the powder between the bodies (powder_mass > 0)", ge=0, le=1
    )
    powder_restitution: float = quantity(
        "", "coefficient of restitution of powder-coated contacts, on the vial and between balls", gt=0, le=1
    )
    powder_contact_coefficient: float = quantity(
        "W/(m^2*K)", "h_p through the powder layer to the vial's wall and the balls it coats", ge=0, le=1e5
    )
    # Collision and heat generation (Table 4)
    # A perfectly plastic contact (0) has no damping ratio. Towards 0 the ball chatters on the face and a
    # run takes more steps (20 times at 0.05, 40 at 1e-6), but it stays correct and finishes.
    restitution: float = quantity(
        "", "coefficient of restitution e of a ball on the vial (every contact of the 1-D engine)", gt=0, le=1
    )
    # Ball-ball and ball-wall contacts are different pairs of bodies, each with its own e and μ (MODEL.md §14.1).
    pair_restitution: float = quantity("", "coefficient of restitution e of two balls (engine = 'dem')", gt=0, le=1)
    eta: float = quantity("", "fraction η of dissipated power turned into heat", ge=0, le=1)
    lam: float = quantity("", "fraction λ of the heat that goes to the ball", ge=0, le=1)
    # β scales Whitaker's correlation, defensible within 0.1-3 (calibrate.DEFENSIBLE_RANGES); 100 leaves
    # room for any hand tuning, and β = 1e12 made the ball's time constant a nanosecond.
    beta: float = quantity("", "convection calibration factor β", ge=0, le=100.0)
    # Run (Table 4 and assumptions)
    # A microsecond: less than one contact step. 1e6 s (11.6 days): longer than any milling run (~100 h);
    # the stored samples are capped too (MAX_SAMPLES), and full-resolution runs by their drive periods.
    duration: float = quantity("s", "simulated time", ge=1e-6, le=LONGEST_RUN_S)
    # 50 K: below liquid-nitrogen cryomilling (77 K). 1000 K: a vial in a furnace at 700 °C.
    ambient_temperature: float = quantity("K", "temperature of the surroundings θ_amb", ge=50.0, le=1000.0)
    initial_temperature: float = quantity("K", "initial temperature θ_0 of ball, vial and air", ge=50.0, le=1000.0)
    # Up to 4000 K: tungsten, the most refractory ball material, melts at 3695 K.
    ball_temperature_limit: float = quantity(
        "K", "highest physical ball temperature: a run that exceeds it ends with a non-ok status", ge=50.0, le=4000.0
    )
    # Half the longest vial; the ball must also start inside this vial (checked below).
    ball_position: float = quantity("m", "initial ball centre, relative to the vial centre", ge=-0.5, le=0.5)
    # A 100-g ball at 1000 m/s; faster starts only end in an overlap the integrator refuses.
    ball_momentum: float = quantity("kg*m/s", "initial ball momentum", ge=-100.0, le=100.0)
    # Numerics (MODEL.md section 7)
    # The method is third order: rtol 1e-8 costs ~40 times the default's steps, and the contact step limit
    # bounds the error below that anyway. Above 0.1 the error control no longer resolves a contact.
    rtol: float = quantity("", "relative tolerance of the integrator", ge=1e-8, le=0.1)
    # 1e-12: far below every scale of the motion (the single-impact tests use it); the upper bounds are
    # where the tolerance would exceed the quantity itself (a ball radius, a ball's momentum, a kelvin).
    atol_position: float = quantity("m", "absolute tolerance on the ball position", ge=1e-12, le=1e-3)
    atol_momentum: float = quantity("kg*m/s", "absolute tolerance on the ball momentum", ge=1e-12, le=1e-2)
    atol_temperature: float = quantity("K", "absolute tolerance on temperatures", ge=1e-12, le=1.0)
    # The sample count duration/output_interval is capped as well (MAX_SAMPLES).
    output_interval: float = quantity("s", "sampling interval of the stored time series", ge=1e-6, le=LONGEST_RUN_S)
    energy_projection: bool = Field(
        strict=True,
        json_schema_extra={"description": "enforce the mechanical energy balance of each contact step by projection"},
    )
    # Budget of one run (shakermill.budget): beyond either limit it stops with a non-ok status, keeping its results
    max_wall_time: float = quantity(
        "s",
        "wall-clock budget of one run, its mechanics phase, fall-back and attractor probe included",
        gt=0,
        le=LONGEST_RUN_S,  # a budget beyond the longest simulated run is no budget
    )
    max_steps: int = Field(
        gt=0,
        le=10**12,  # at ~0.5 µs a step, about a week of computing
        json_schema_extra={
            "unit": "",
            "description": "step budget of one run: accepted integrator steps, all its integrations together",
        },
    )
    # Solver choice (full resolution, or the multiscale averaged solver)
    solver: Literal["full", "averaged"] = choice(
        "'full': every impact for the whole run; 'averaged': mechanics until its statistics converge, then "
        "the slow network"
    )
    # Any target is safe: one that is never reached ends at averaging_max_time, and the run falls back.
    averaging_rel_error: float = quantity(
        "", "averaged solver: target relative standard error of the averages", gt=0, lt=1
    )
    # The several balls' motion is chaotic: its means converge as 1/√T, and 1e-3 would take ~15 min of mechanics.
    dem_averaging_rel_error: float = quantity(
        "",
        "averaged solver of the 'dem' engine: target relative standard error of the total heat power, the mean "
        "Whitaker term and each ball's own means",
        gt=0,
        lt=1,
    )
    # Each replica pays its own start-up transient, so more replicas than cores cost more than they save.
    dem_replicas: int = count(
        "averaged solver of the 'dem' engine: independent replicas of the mechanics, pooled", ge=1, le=64
    )
    # 10 000 periods (~10 min) per batch: already past any averaging_max_time worth waiting for.
    averaging_batch_periods: int = count(
        "averaged solver: drive periods per batch of the batch-means estimate", ge=1, le=10_000
    )
    averaging_min_batches: int = count("averaged solver: fewest batches after the transient", ge=4, le=10_000)
    # An hour of mechanics costs what a full-resolution hour does; averaging converges in ~20 s.
    averaging_max_time: float = quantity(
        "s", "averaged solver: longest mechanics window before giving up", gt=0, le=3600.0
    )
    averaging_fallback: Literal["full", "fail"] = choice("averaged solver: what to do when averaging is not valid")
    # Each start costs a settled run at every point of a scan; 100 cover the gap far more densely than
    # the basins found so far need (the default 8 finds them).
    attractor_starts: int = count(
        "initial states settled to find coexisting attractors (bifurcation, sweeps, averaged solver); "
        "1: only the configured start",
        ge=1,
        le=100,
    )
    # Model options (MODEL.md sections 2-4: the alternatives the spec allows)
    model: Literal["three_node", "ball_only"] = choice(
        "'three_node': ball, vial and air (this paper); 'ball_only': air held at ambient and no vial "
        "reservoir, the author's 2023 predecessor"
    )
    no_tension: bool = Field(
        strict=True, json_schema_extra={"description": "clip the contact force at zero (no adhesion)"}
    )
    heat_model: Literal["relative", "paper"] = choice("'relative': η·c·ζ̇² (default); 'paper': η·|F_d·v| as printed")
    convection_velocity: Literal["auto", "ball", "relative"] = choice(
        "velocity in Re: the ball's ('ball', as the paper) or relative to the vial, which carries "
        "the air ('relative'); 'auto': 'ball' for the 1-D engine, 'relative' for 'dem' (MODEL.md §12.5)"
    )
    # The engine (engine_keys.py; engines/registry.py adds any registered): its name is checked by _known_engine.
    engine: str = choice(
        "'1d': one ball on the vial's axis (MODEL.md sections 1-7); 'dem': n_balls spheres in three "
        "dimensions with friction and rotation (section 12)"
    )
    # 50 balls of the smallest radius still fit any vial the bounds allow; the pair search is O(N²).
    n_balls: int = count(
        "number of balls (engine = 'dem', 0: an empty mill; the 1-D engine has one)", ge=0, le=MAX_BALLS
    )
    fill: float = quantity(
        "",
        "fraction of the vial's inner volume the balls take (engine = 'dem'): > 0 sets n_balls = max(1, "
        "round(fill·V_vial/V_ball)) equal balls; 0: n_balls as given",
        ge=0,
        le=DENSEST_PACKING,
    )
    # Each ball's own radius and material, in ball order; empty: every ball takes the scalar key's value.
    ball_radii: tuple[float, ...] = per_ball("ball_radius")
    ball_densities: tuple[float, ...] = per_ball("ball_density")
    ball_youngs_moduli: tuple[float, ...] = per_ball("ball_youngs_modulus")
    ball_poisson_ratios: tuple[float, ...] = per_ball("ball_poisson_ratio")
    ball_heat_capacities: tuple[float, ...] = per_ball("ball_heat_capacity")
    ball_conductivities: tuple[float, ...] = per_ball("ball_conductivity")
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
    ball_conductivity: float = quantity("W/(m*K)", "ball thermal conductivity k_b", ge=0.01, le=2000.0)
    gravity: bool = Field(
        strict=True,
        json_schema_extra={"description": "gravity 9.81 m/s² downward, the vial axis horizontal (engine = 'dem')"},
    )
    # Coulomb coefficients of dry solids stay below ~1.5; 5 leaves room for rough or adhesive pairs.
    friction: float = quantity(
        "", "Coulomb friction coefficient μ of a ball on the vial (engine = 'dem')", ge=0, le=5.0
    )
    pair_friction: float = quantity("", "Coulomb friction coefficient μ of two balls (engine = 'dem')", ge=0, le=5.0)
    rolling_friction: float = quantity("", "rolling resistance coefficient μ_r (engine = 'dem')", ge=0, le=1.0)
    kinematics: Literal["axial", "fourier", "spex8000m", "mixer-mill-arc", "planetary"] = choice(
        "vial motion of the 'dem' engine (parameters/kinematic_models.py): 'axial' (amplitude, "
        "omega, phase: the 1-D drive), 'fourier' (the harmonics in motion), 'spex8000m' (the clamp's figure of "
        "eight: amplitude, lateral_amplitude, yaw_amplitude), 'mixer-mill-arc' (a jar swung on a horizontal "
        "arc: amplitude along the arc, swing_radius) or 'planetary' (a jar on a sun wheel turning at omega: "
        "revolution_radius, speed_ratio, jar_tilt)"
    )
    # The SPEX clamp's lateral motion and yaw (kinematics = 'spex8000m'); 0 leaves either out. Half a metre,
    # as any translation of a vial; a quarter turn, far beyond the few degrees a clamp turns.
    lateral_amplitude: float = quantity(
        "m",
        "kinematics = 'spex8000m': lateral amplitude Y of the vial's centre, y = Y sin 2θ",
        ge=0,
        le=MAX_MOTION_TRANSLATION,
    )
    yaw_amplitude: float = quantity(
        "rad", "kinematics = 'spex8000m': yaw amplitude Ψ about the vertical, yaw = Ψ sin θ", ge=0, le=0.5 * math.pi
    )
    # 1 mm to 1 m: from a jar turning about a pivot next to it to an arm longer than any mill.
    swing_radius: float = quantity(
        "m", "kinematics = 'mixer-mill-arc': radius R of the jar centre's arc about the vertical pivot", ge=1e-3, le=1.0
    )
    # A planetary jar's sun wheel: from a laboratory mill's ~5 cm to a metre, beyond any production mill's.
    revolution_radius: float = quantity(
        "m", "kinematics = 'planetary': radius R_p of the jar centre's circle about the sun axis", ge=1e-2, le=1.0
    )
    # The jar's speed relative to the sun wheel: mills are built from −3 to −1 (Retsch, Fritsch); ±5 covers any gear.
    speed_ratio: float = quantity(
        "", "kinematics = 'planetary': the jar's spin relative to the sun wheel, k of 1 : k", ge=-5.0, le=5.0
    )
    # Jars stand upright in most mills; tilted ones lean by tens of degrees. Past 60° a jar would lie nearly flat.
    jar_tilt: float = quantity(
        "rad", "kinematics = 'planetary': lean of the jar's top away from the sun axis", ge=0.0, le=math.pi / 3
    )
    motion: tuple[Harmonic, ...] = Field(
        max_length=MAX_HARMONICS,
        json_schema_extra={
            "unit": "m or rad",
            "description": "kinematics = 'fourier': (coordinate, k, cos, sin) terms of the vial's translations x, y, z "
            "(m) and angles roll, pitch, yaw (rad) in the harmonics k of θ = ωt + φ; an angle's sin at k = 0 turns it "
            "steadily by that many radians per radian of θ",
        },
    )
    # The shortest step, at a contact's start and release, as a fraction of the smallest Rayleigh time; an impact
    # steps at 0.4 of this fraction of its own period (engines/dem/model.py, IMPACT_STEP_SCALE); 0.9 is the 1-D
    # engine's bound.
    contact_step_fraction: float = quantity(
        "", "contact step of the 'dem' engine as a fraction of the smallest Rayleigh time", ge=1e-3, le=0.9
    )
    # An enduring contact (rolling, sliding or resting, not an impact) steps at this fraction of its own period,
    # within the same 0.9 t_R bound; Verlet is stable below 1/π of a period (engines/dem/model.py, ENDURING_AFTER).
    enduring_step_fraction: float = quantity(
        "",
        "step of the 'dem' engine inside an enduring contact as a fraction of its oscillation period",
        ge=1e-3,
        le=0.1,
    )
    # A free-flight step never lets a contact begin inside it; this caps it further (1 s: no cap in practice).
    max_flight_step: float = quantity("s", "longest step of the 'dem' engine in free flight", ge=1e-7, le=1.0)
    stress_energy_thresholds: tuple[StressThreshold, ...] = Field(
        max_length=MAX_STRESS_THRESHOLDS,
        json_schema_extra={
            "unit": "J",
            "description": (
                "stress energies above which each run reports the impacts' power (analysis/stress_energy.py)"
            ),
        },
    )
    record_windows: tuple[Window, ...] = Field(
        max_length=MAX_RECORD_WINDOWS,
        json_schema_extra={"unit": "s", "description": "(start, length) windows stored at full resolution"},
    )

    @field_validator("engine")
    @classmethod
    def _known_engine(cls, name: str) -> str:
        if name not in ENGINE_KEYS:
            # Worded as pydantic words a value outside a Literal's choices, as the other options are.
            raise PydanticCustomError(
                "literal_error", "Input should be {expected}", {"expected": " or ".join(map(repr, ENGINE_KEYS))}
            )
        return name

    @model_validator(mode="after")
    def _consistent(self) -> Parameters:
        """The checks across keys (:mod:`consistency`) and of the per-ball values' bounds, in this order: the first
        problem is the one reported."""
        consistency.ball_fits_vial(self)
        consistency.outside_holds_the_bore(self)
        consistency.fill_sets_the_balls(self, PER_BALL_KEYS)
        consistency.engine_takes_the_keys(self)
        for key in PER_BALL_KEYS:
            _check_per_ball(key, getattr(self, key), self.n_balls)
        consistency.motion_is_well_formed(self)
        consistency.balls_fit_side_by_side(self)
        consistency.stored_data_fit_in_memory(self)
        consistency.thermal_network_is_not_stiff(self)
        consistency.thresholds_are_distinct(self)
        return self

    def ball_values(self, scalar_key: str) -> tuple[float, ...]:
        """Each ball's value of ``scalar_key`` (e.g. 'ball_radius'): its per-ball list, or the scalar for all."""
        values = getattr(self, PER_BALL_KEY_OF[scalar_key])
        return tuple(values) if values else (getattr(self, scalar_key),) * self.n_balls

    @property
    def thermal_time_constants_at_rest(self) -> dict[str, tuple[float, tuple[str, ...]]]:
        """Heat capacity over conductance of each node that evolves (s), and the keys that set it
        (:func:`consistency.thermal_time_constants_at_rest`)."""
        return consistency.thermal_time_constants_at_rest(self)

    def _repr_html_(self) -> str:
        return present("parameters html", self)

    def replace(self, **changes: Any) -> Parameters:
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
SCALAR_KEY_OF = {per_ball: scalar for scalar, per_ball in PER_BALL_KEY_OF.items()}
MATERIAL_KEYS = ("ball_material", "vial_material", "powder_material", "ball_materials")


def _check_per_ball(key: str, values: tuple[float, ...], n_balls: int) -> None:
    if values and len(values) != n_balls:
        raise ValueError(
            f"{key}: {len(values)} values for n_balls = {n_balls}; allowed an empty list or exactly {n_balls} values"
        )
    scalar = SCALAR_KEY_OF[key]
    for number, value in enumerate(values, start=1):
        if not bounds(scalar).contains(value):
            shown = _shown_value(value)
            raise ValueError(f"{key}: value {number} ({shown}) is out of range; allowed {allowed_range(scalar, value)}")


def field_unit(key: str) -> str:
    extra = Parameters.model_fields[key].json_schema_extra or {}
    return str(extra.get("unit", ""))


def field_description(key: str) -> str:
    extra = Parameters.model_fields[key].json_schema_extra or {}
    return str(extra.get("description", ""))


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


def allowed_range(key: str, refused: Any = None) -> str:
    """Human-readable allowed values of ``key`` from its field constraints, e.g. '(0, 1]', its bounds in
    enough digits to tell them from the ``refused`` value."""
    field = Parameters.model_fields[key]
    choices = choices_of(key)
    if choices:
        return "one of " + ", ".join(repr(choice) for choice in choices)
    if field.annotation is bool:
        return "true or false"
    if key == "stress_energy_thresholds":
        return f"at most {MAX_STRESS_THRESHOLDS} energies in J, each in [1e-09, 1000]"
    if key == "record_windows":
        return (
            f"at most {MAX_RECORD_WINDOWS} (start, length) pairs in s, start in [0, {LONGEST_RUN_S:g}], length > 0, "
            f"{MAX_RECORDED_SECONDS:g} s of the run in all"
        )
    if key in PER_BALL_KEYS:
        return f"an empty list or n_balls values, each in {allowed_range(SCALAR_KEY_OF[key], refused)}"
    if key in MATERIAL_KEYS:
        return materials.allowed_for(key)
    if key == "motion":
        return (
            f"at most {MAX_HARMONICS} (coordinate, k, cos, sin) terms: coordinate one of "
            f"{', '.join(MOTION_COORDINATES)}, "
            f"k in [0, {MAX_MOTION_HARMONIC}], translations in m, angles in rad"
        )
    shown = bounds(key).shown(refused if isinstance(refused, float) else None)
    if field.annotation is int:
        return f"a whole number in {shown}"
    return f"{shown} {field_unit(key)}".rstrip()


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


def with_materials(layer: Mapping[str, Any]) -> dict[str, Any]:
    """``layer`` (a preset, a file, the ``--set`` overrides, a sweep point) with the values its materials fill in.

    A key that ``layer`` sets itself wins over its material, and a later layer wins over both: each layer is
    completed on its own before the layers are merged, so ``--set ball_material=wc`` replaces the preset's
    steel density, while a file's ``ball_density`` beside its ``ball_material`` is kept.
    """
    return {**{key: value for key, (value, _) in material_sources(layer).items()}, **layer}


def material_sources(layer: Mapping[str, Any]) -> dict[str, tuple[Any, str]]:
    """The keys that the materials named in ``layer`` stand for, each with the material's value and source."""
    single = tuple(key for key in MATERIAL_KEYS if key.endswith("_material"))
    return materials.filled_keys(layer, FIELD_NAMES, PER_BALL_KEY_OF, single)


def choices_of(key: str) -> tuple[str, ...]:
    """The names an option takes (the engines' for ``engine``); () for a key that is no option."""
    if key == "engine":
        return tuple(ENGINE_KEYS)
    annotation = Parameters.model_fields[key].annotation
    return typing.get_args(annotation) if typing.get_origin(annotation) is Literal else ()


def takes_names(key: str) -> bool:
    """Whether ``key`` takes one name: a material or one of an option's choices."""
    annotation = Parameters.model_fields[key].annotation
    return annotation is str or typing.get_origin(annotation) is Literal


def checked_name(key: str, value: Any) -> str:
    """``value`` of a key that :func:`takes_names`, checked: its canonical name (a material's alias resolved)."""
    if key in MATERIAL_KEYS:
        return str(materials.names_in(key, value))
    if value not in choices_of(key):
        raise ParameterError(f"{key}: {quoted(value)} is not allowed; allowed {allowed_range(key)}")
    return str(value)


def check_known_keys(keys: list[str] | tuple[str, ...], *, extra_allowed: tuple[str, ...] = ()) -> None:
    """Raise :class:`ParameterError` with a did-you-mean suggestion for the first unknown key."""
    known = FIELD_NAMES + extra_allowed
    for key in keys:
        if key not in known:
            # A key longer than any known one is no typo of one; it is quoted short so the line stays readable.
            close = difflib.get_close_matches(key, known, n=1) if len(key) <= QUOTED_LENGTH else []
            hint = f"; did you mean {close[0]!r}?" if close else "; `shakermill keys WORD` finds the keys about WORD"
            shown = key if len(key) <= QUOTED_LENGTH else quoted(key)
            raise ParameterError(f"{shown}: unknown parameter{hint}")


def unit_slip(key: str, value: float) -> str | None:
    """Why ``value`` (SI) of ``key`` looks like a unit slip (:func:`guards.unit_slip`); None if plausible."""
    return guards.unit_slip(key, value, field_unit(key))


def unit_slip_warnings(params: Parameters) -> list[str]:
    """One line per value outside :data:`guards.PLAUSIBLE_RANGES` (see :func:`unit_slip`)."""
    return [line for key in guards.PLAUSIBLE_RANGES if (line := unit_slip(key, getattr(params, key))) is not None]


def _coerce(key: str, value: Any) -> Any:
    """Convert a user value for ``key`` to SI (strings with units) or to the option's type.

    Raises :class:`ParameterError` naming the key and its allowed values.
    """
    annotation = Parameters.model_fields[key].annotation
    try:
        if annotation is float:
            return bounds(key).snapped(guards.quantity(key, value, field_unit(key)))
        if annotation is int:
            return guards.whole_number(key, value)
        if annotation is bool:
            return guards.switch(key, value)
        if key == "record_windows":
            return guards.windows(value)
        if key == "stress_energy_thresholds":
            return guards.quantity_list(key, value, "J", "a list of energies")
        if key in PER_BALL_KEYS:
            scalar = SCALAR_KEY_OF[key]
            return tuple(map(bounds(scalar).snapped, guards.per_ball(key, value, field_unit(scalar))))
        if key == "motion":
            return guards.motion(value)
        if key in MATERIAL_KEYS:
            return materials.names_in(key, value)
    except UnitError as exc:
        raise ParameterError(f"{exc}; allowed {allowed_range(key)}") from None
    return value  # one of a few names: the model checks it


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
    problem = (
        f"{value} is out of range"
        if first.get("type") in RANGE_ERRORS
        else f"{message[:1].lower()}{message[1:]} (got {value})"
    )
    return f"{key}: {problem}; allowed {allowed_range(key, first.get('input'))}"


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
    slip = unit_slip(key, values[key]) if key in guards.PLAUSIBLE_RANGES else None
    return message if slip is None else f"{message} ({slip})"
