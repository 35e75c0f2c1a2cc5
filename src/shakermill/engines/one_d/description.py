"""What the 1-D engine is (MODEL.md sections 1-7): its description for the layers above, its status codes and its
impact columns. Plain data: reading it loads no compiled code."""

from __future__ import annotations

from shakermill.engines.interface import EngineDescription
from shakermill.engines.status import BUDGET_EXCEEDED, NOT_FINITE, OVERLAP_TOO_LARGE, REACHED_STOP
from shakermill.parameters.engine_keys import ONE_DIMENSIONAL

# Status codes of the compiled loop (negative: failure).
STEP_UNDERFLOW = -3
# Checked between compiled calls (Integrator.advance), not in the loop: the size of the record windows.
WINDOWS_FULL = -7
# Every step inside a record window is kept: ~1000 rows a simulated second at the defaults (35 min of
# windows fit, 4 min at rtol 1e-6), but tiny steps would fill memory and disk (a vacuum vial,
# air_density = 1e-8, takes 1.7e8 steps a second). 2·10⁶ rows are ~220 MB, in memory and in windows.nc.
MAX_WINDOW_POINTS = 2_000_000

STATUS_MESSAGES = {
    REACHED_STOP: "The solver reached the end of the integration interval.",
    NOT_FINITE: "The state became NaN or infinite.",
    OVERLAP_TOO_LARGE: (
        "The contact overlap exceeded the allowed fraction of the ball radius: the materials are too soft for "
        "this impact speed (check ball_youngs_modulus and vial_youngs_modulus), or the step control failed."
    ),
    STEP_UNDERFLOW: "The step size fell below the resolution of the time variable.",
    BUDGET_EXCEEDED: "The run used up its budget (max_wall_time or max_steps).",
    WINDOWS_FULL: (
        f"The record windows filled the {MAX_WINDOW_POINTS:,} points (~220 MB) a run keeps of them: the steps "
        "inside them are tiny. Shorten record_windows, or leave it empty, to run on."
    ),
}

IMPACT_UNITS = {
    "time": "s",
    "wall": "",
    "impact_speed": "m/s",
    "rebound_speed": "m/s",
    "dissipated_energy": "J",
    "heat_generated": "J",
    "max_overlap": "m",
    "peak_force": "N",
    "duration": "s",
    "heat_to_ball": "J",
    "heat_to_vial": "J",
}

DESCRIPTION = EngineDescription(
    keys=ONE_DIMENSIONAL,
    channels=("normal",),
    impact_units=IMPACT_UNITS,
    impact_target="wall",
    read_back=("time", "x", "p", "theta_ball", "theta_vial", "theta_air"),
    motion=("x", "p", "velocity"),
    per_ball=(),
    averaged_flows=("work_vial", "dissipated", "heat_generated", "velocity_term_integral"),
    heat_variables=("heat_generated",),
    term_variables=("velocity_term_integral",),
    status_messages=STATUS_MESSAGES,
    averaging_error_key="averaging_rel_error",
    attractor_starts=True,
)
