"""The checks of a parameter set across its keys, each raising ``ValueError`` with one line that names the key to
change and what is allowed: the ball fits the vial, ``fill`` and the balls agree, the keys suit the engine, the
vial's motion is well formed, the stored data fit in memory and the thermal network is not too stiff to integrate.
``Parameters`` runs them when it is built (``keys.Parameters._consistent``); each reads a parameter set's keys and
derived values alone."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from shakermill.parameters.engine_keys import engine_problem
from shakermill.parameters.geometry import ball_volume, balls_for_fill
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.support.limits import MAX_BALLS, MAX_FULL_RESOLUTION_PERIODS, MAX_RECORDED_SECONDS, MAX_SAMPLES

# The explicit integrator's steps follow the fastest thermal time constant: ~0.7 steps per time constant
# and simulated second, so 0.1 ms costs ~25 million steps a simulated hour, ten times the mechanics'
# own. The default's fastest node, the air, takes 0.1 s.
MIN_THERMAL_TIME_CONSTANT_S = 1e-4


def ball_fits_vial(params: Any) -> None:
    """The ball (the scalar radius) fits the vial and starts inside it."""
    diameter = 2.0 * params.ball_radius
    if diameter >= params.vial_length:
        raise ValueError(
            f"ball_radius: a ball of diameter {diameter * 1e3:g} mm does not fit a vial of length "
            f"{params.vial_length * 1e3:g} mm; allowed ball_radius < vial_length/2 = {params.vial_length / 2:g} m"
        )
    if diameter > params.vial_diameter:
        raise ValueError(
            f"ball_radius: a ball of diameter {diameter * 1e3:g} mm does not fit a vial of diameter "
            f"{params.vial_diameter * 1e3:g} mm; allowed ball_radius <= vial_diameter/2 = {params.vial_diameter / 2:g} "
            "m"
        )
    half_gap = params.vial_length / 2.0 - params.ball_radius
    if abs(params.ball_position) >= half_gap:
        raise ValueError(
            f"ball_position: the ball must start inside the vial, allowed |ball_position| < {half_gap:g} m"
        )


def outside_holds_the_bore(params: Any) -> None:
    """With ``thermal_model = 'mill-head'`` the vial's outside (whose convection it computes) is larger than its bore,
    and the paper's ball-only model, which holds the vial at the room temperature, is not asked for with it."""
    if params.thermal_model != "mill-head":
        return
    for outer, inner in (("outer_diameter", "vial_diameter"), ("outer_length", "vial_length")):
        if getattr(params, outer) <= getattr(params, inner):
            raise ValueError(
                f"{outer}: the vial's outside must be larger than its bore; allowed {outer} > {inner} = "
                f"{getattr(params, inner):g} m"
            )
    if params.model != "three_node":
        raise ValueError(
            "model: thermal_model = 'mill-head' has a vial and a clamp of their own; allowed model = 'three_node'"
        )


def fill_sets_the_balls(params: Any, per_ball_keys: Sequence[str]) -> None:
    """``fill`` > 0 makes n_balls equal balls (:func:`balls_for_fill`); an n_balls that says otherwise is refused.

    A key, not a sweep axis of its own: a run, a configuration file and a sweep point all take it, and the
    count it makes follows the ball and vial of that very run (a sweep over fill × ball_radius needs no
    table of counts). It cannot disagree with n_balls unnoticed: a layer that sets fill replaces the
    n_balls of the layers below it (``keys.layered``), and an n_balls set beside it or above it must match.
    """
    if params.fill == 0:
        return
    problem = engine_problem(params, fill=True)
    if problem is not None:
        raise ValueError(problem)
    listed = next((key for key in ("ball_materials", *per_ball_keys) if getattr(params, key)), None)
    if listed is not None:
        raise ValueError(
            f"fill: makes equal balls, and {listed} gives each ball its own value; allowed fill = 0 with per-ball lists"
        )
    wanted = balls_for_fill(params.fill, params.ball_radius, params.vial_length, params.vial_diameter)
    if wanted > MAX_BALLS:
        raise ValueError(
            f"fill: {params.fill:g} of this vial is {wanted} balls of radius {params.ball_radius * 1e3:g} mm; allowed "
            "fill "
            f"< {_fill_below(params, MAX_BALLS):.3g} here (at most {MAX_BALLS} balls)"
        )
    if params.n_balls != wanted:
        raise ValueError(
            f"n_balls: {params.n_balls} contradicts fill = {params.fill:g}, which makes {wanted} balls of radius "
            f"{params.ball_radius * 1e3:g} mm in this vial; allowed n_balls = {wanted}, or fill = 0 to give n_balls "
            "alone"
        )


def _fill_below(params: Any, count: int) -> float:
    """The fill at which :func:`balls_for_fill` rounds up to ``count`` + 1 balls of ``ball_radius``."""
    return (count + 0.5) * ball_volume(params.ball_radius) / params.vial_volume


def engine_takes_the_keys(params: Any) -> None:
    """The number of balls, the kinematics and the thermal model are the engine's (``engine_keys``); the list of
    per-ball materials is as long as the balls."""
    problem = engine_problem(params)
    if problem is not None:
        raise ValueError(problem)
    # The materials first: their per-ball lists are as long as they are.
    if params.ball_materials and len(params.ball_materials) != params.n_balls:
        raise ValueError(
            f"ball_materials: {len(params.ball_materials)} names for n_balls = {params.n_balls}; allowed an empty list "
            f"or exactly {params.n_balls} names"
        )


def motion_is_well_formed(params: Any) -> None:
    """The run's vial motion checks its keys across what their bounds say (its module's ``check``: a Fourier motion
    has terms within a metre's half and a half turn, a mixer mill's arc turns the jar at most a quarter turn)."""
    KINEMATIC_MODELS[params.kinematics].check(params)


def balls_fit_side_by_side(params: Any) -> None:
    """Every ball moves in the bore, and the balls of an engine of several fit the vial together."""
    if not params.engine_keys.several_balls:
        return
    radii = params.ball_values("ball_radius")
    largest = max(radii, default=0.0)
    if 2.0 * largest >= params.vial_diameter:
        key = "ball_radii" if params.ball_radii else "ball_radius"
        raise ValueError(
            f"{key}: a ball of diameter {2e3 * largest:g} mm does not move in a bore of {params.vial_diameter * 1e3:g} "
            "mm; "
            f"allowed radii < vial_diameter/2 = {params.vial_diameter / 2:g} m"
        )
    if params.n_balls > 1 and params.initial_positions() is None:
        if params.fill > 0:
            _refuse_fill_that_does_not_fit(params)
        raise ValueError(
            f"n_balls: {params.n_balls} balls (radius up to {largest * 1e3:g} mm) do not fit side by side in a vial of "
            f"{params.vial_diameter * 1e3:g} mm x {params.vial_length * 1e3:g} mm; allowed fewer balls, smaller ones "
            "or a "
            "larger vial_diameter"
        )


def _refuse_fill_that_does_not_fit(params: Any) -> None:
    import numpy as np

    from shakermill.parameters.packing import packed

    fitting = len(packed(np.full(params.n_balls, params.ball_radius), params.vial_length, params.vial_diameter))
    raise ValueError(
        f"fill: {params.fill:g} of the vial is {params.n_balls} balls of radius {params.ball_radius * 1e3:g} mm, and "
        f"{fitting} fit side by side in {params.vial_diameter * 1e3:g} mm x {params.vial_length * 1e3:g} mm; allowed "
        "fill "
        f"< {_fill_below(params, fitting):.3g} for these balls and this vial"
    )


def components_are_consistent(params: Any) -> None:
    """Each component's own checks of its keys against the rest of the run (its group's ``check_across``)."""
    from shakermill.parameters.groups import GROUPS

    for group in GROUPS:
        group.check_across(params)


def stored_data_fit_in_memory(params: Any) -> None:
    """The samples, the record windows and a full-resolution run's drive periods stay within the limits."""
    samples = params.duration / params.output_interval
    if samples > MAX_SAMPLES:
        raise ValueError(
            f"output_interval: {params.output_interval:g} s over duration = {params.duration:g} s makes {samples:.3g} "
            f"samples; allowed output_interval >= duration/{MAX_SAMPLES:,} = {params.duration / MAX_SAMPLES:.4g} s"
        )
    recorded = sum(min(length, max(0.0, params.duration - start)) for start, length in params.record_windows)
    if recorded > MAX_RECORDED_SECONDS:
        raise ValueError(
            f"record_windows: they hold {recorded:g} s of the run at full resolution; allowed at most "
            f"{MAX_RECORDED_SECONDS:g} s in all (sample longer stretches with output_interval)"
        )
    periods = params.duration / params.period
    if params.solver == "full" and periods > MAX_FULL_RESOLUTION_PERIODS:
        longest = MAX_FULL_RESOLUTION_PERIODS * params.period
        raise ValueError(
            f"duration: {params.duration:g} s at omega = {params.omega:g} rad/s is {periods:.3g} drive periods, and "
            "the "
            f"full solver keeps every impact; allowed duration <= {longest:.4g} s here "
            f"({MAX_FULL_RESOLUTION_PERIODS:,} periods), or solver = 'averaged' for longer runs"
        )


def thermal_network_is_not_stiff(params: Any) -> None:
    """No node's time constant at rest is below MIN_THERMAL_TIME_CONSTANT_S."""
    for node, (time_constant, keys) in params.thermal_time_constants_at_rest.items():
        if time_constant < MIN_THERMAL_TIME_CONSTANT_S:
            raise ValueError(
                f"{', '.join(keys)}: the {node}'s thermal time constant is {time_constant:.3g} s with these values "
                f"(ball at rest; motion only shortens it); allowed >= {MIN_THERMAL_TIME_CONSTANT_S:g} s, or the "
                "integrator's steps shrink with it and a run takes hours"
            )


def thermal_time_constants_at_rest(params: Any) -> dict[str, tuple[float, tuple[str, ...]]]:
    """Heat capacity over conductance of each node that evolves (s), and the keys that set it.

    The ball's convection is taken at rest (Nu = 2, h = k_a/R): its motion raises h, so these are
    upper bounds of what a run sees.
    """
    ball_conductance = 4.0 * math.pi * params.ball_radius * params.beta * params.air_conductivity
    ball = params.ball_mass * params.ball_heat_capacity / ball_conductance if ball_conductance > 0 else math.inf
    constants: dict[str, tuple[float, tuple[str, ...]]] = {
        "ball": (ball, ("ball_density", "ball_radius", "ball_heat_capacity", "beta", "air_conductivity"))
    }
    if params.model == "ball_only":
        return constants
    inner, outer = params.h_inner * params.inner_area, params.h_outer * params.outer_area
    vial = params.vial_mass * params.vial_heat_capacity / (inner + outer) if inner + outer > 0 else math.inf
    air_capacity = params.air_mass * params.air_heat_capacity
    air = air_capacity / (inner + ball_conductance) if inner + ball_conductance > 0 else math.inf
    constants["vial"] = (vial, ("vial_mass", "vial_heat_capacity", "h_inner", "inner_area", "h_outer", "outer_area"))
    constants["air"] = (air, ("air_density", "vial_length", "vial_diameter", "h_inner", "inner_area"))
    if params.thermal_model == "mill-head":
        # The vial's outer paths are then computed (tens of W/(m²·K)): its joint to the clamp bounds it from below.
        joint = params.clamp_conductance + inner
        constants["vial"] = (
            params.vial_mass * params.vial_heat_capacity / joint if joint > 0 else math.inf,
            ("vial_mass", "vial_heat_capacity", "clamp_conductance", "h_inner", "inner_area"),
        )
        clamp = params.clamp_conductance + params.clamp_loss
        constants["clamp"] = (
            params.clamp_heat_capacity / clamp if clamp > 0 else math.inf,
            ("clamp_heat_capacity", "clamp_conductance", "clamp_loss"),
        )
    return constants


def thresholds_are_distinct(params: Any) -> None:
    """Each stress-energy threshold once: a threshold given twice ("1 mJ" and "0.001 J") would report one result
    under one summary key twice over."""
    thresholds = list(params.stress_energy_thresholds)
    repeated = sorted({value for value in thresholds if thresholds.count(value) > 1})
    if repeated:
        raise ValueError(
            f"stress_energy_thresholds: {repeated[0]!r} J is given {thresholds.count(repeated[0])} times; allowed "
            "distinct energies"
        )
