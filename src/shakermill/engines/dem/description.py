"""What the 'dem' engine is (MODEL.md section 12): its description for the layers above, its status messages,
its dissipation channels and its impact columns. Plain data: reading it loads no compiled code."""

from __future__ import annotations

from shakermill.engines.interface import EngineDescription
from shakermill.engines.records import HERTZ_SCALE
from shakermill.engines.status import NOT_FINITE, OVERLAP_TOO_LARGE, REACHED_STOP
from shakermill.parameters.engine_keys import THREE_DIMENSIONAL

CHANNELS = ("normal", "tangential", "sliding", "rolling")
# The neighbour list could not hold the pairs near each other (engines/dem/neighbours.py): only balls far deeper in
# each other than OVERLAP_TOO_LARGE allows, which stops a run first, could make it.
NEIGHBOURS_FULL = -5

STATUS_MESSAGES = {
    REACHED_STOP: "The engine reached the end of the integration interval.",
    NOT_FINITE: "The state became NaN or infinite.",
    OVERLAP_TOO_LARGE: (
        "A contact overlap exceeded 5 % of the smallest ball radius: the materials are too soft for these impact "
        "speeds, or contact_step_fraction is too large."
    ),
    NEIGHBOURS_FULL: (
        "The neighbour list could not hold the pairs of balls near each other: balls overlap far more than a step "
        "allows."
    ),
}

IMPACT_UNITS = {
    "time": "s",
    "ball": "",
    "target": "",
    "other_ball": "",
    "impact_speed": "m/s",
    "tangential_speed": "m/s",
    **{f"dissipated_{name}": "J" for name in CHANNELS},
    "dissipated_energy": "J",
    "heat_generated": "J",
    "heat_to_ball": "J",
    "heat_to_other": "J",
    "heat_to_deposits": "J",
    "peak_force": "N",
    "max_overlap": "m",
    "duration": "s",
    "conduction": "J/K",
    HERTZ_SCALE: "s",
}

DESCRIPTION = EngineDescription(
    keys=THREE_DIMENSIONAL,
    channels=CHANNELS,
    impact_units=IMPACT_UNITS,
    impact_target="target",
    per_ball=(
        "theta_balls",
        "theta_balls_C",
        "heat_into_balls",
        "velocity_term_integrals",
        "position",
        "velocity",
        "angular_velocity",
    ),
    read_back=("time", "position", "velocity", "theta_ball", "theta_balls", "theta_vial", "theta_air"),
    motion=("position", "velocity", "angular_velocity"),
    averaged_flows=(
        "work_vial",
        "heat_generated",
        "heat_into_balls",
        "heat_into_nodes",
        "velocity_term_integrals",
        "velocity_term_integral",
        "contact_conduction",
    ),
    heat_variables=("heat_into_balls", "heat_into_nodes"),
    term_variables=("velocity_term_integrals",),
    status_messages=STATUS_MESSAGES,
    averaging_error_key="dem_averaging_rel_error",
    attractor_starts=False,
    conduction_variables=("contact_conduction",),
    contact_step_guard=True,
)
