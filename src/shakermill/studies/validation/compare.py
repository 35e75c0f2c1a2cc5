"""The full and the averaged solver on the same configuration: both summaries side by side, their differences and
the speed ratio (``shakermill compare-solvers``)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.keys import Parameters
from shakermill.solvers.result import INTERRUPTED, Result

# (summary key, quantity, unit) compared.
COMPARED_QUANTITIES = (
    ("ball_steady_C", "ball steady state", "°C"),
    ("slowest_time_constant_min", "slowest time constant", "min"),
    ("theta_inf_C", "ball θ∞ of the exponential fitted over the run", "°C"),
    ("tau_min", "τ of that fit", "min"),
    ("rate0_C_per_min", "initial heating rate θ̇₀ of that fit", "°C/min"),
    ("ball_C", "ball at the end", "°C"),
    ("vial_C", "vial at the end", "°C"),
    ("air_C", "air at the end", "°C"),
    ("vial_ball_ratio", "vial/ball increment ratio", ""),
    ("heat_power_W", "heat generated", "W"),
    ("impact_rate_hz", "impact rate", "Hz"),
    ("mean_impact_speed_m_s", "mean impact speed", "m/s"),
    ("wall_time_s", "wall time", "s"),
)


@dataclass(frozen=True)
class SolverComparison:
    """The two runs of one configuration."""

    full: Result
    averaged: Result

    @property
    def speed_ratio(self) -> float:
        """Wall time of the full run over the averaged one's."""
        return self.full.wall_time / self.averaged.wall_time if self.averaged.wall_time > 0 else math.inf

    def rows(self) -> list[tuple[str, str, Any, Any, Any]]:
        """(quantity, unit, full, averaged, averaged − full) of each compared quantity."""
        full, averaged = self.full.summary, self.averaged.summary
        return [
            (label, unit, full.value(key), averaged.value(key), averaged.number(key) - full.number(key))
            for key, label, unit in COMPARED_QUANTITIES
        ]

    def as_dict(self) -> dict[str, Any]:
        return {
            "full": {key: self.full.summary.value(key) for key, _, _ in COMPARED_QUANTITIES},
            "averaged": {key: self.averaged.summary.value(key) for key, _, _ in COMPARED_QUANTITIES},
            "averaged_solver_used": self.averaged.solver,
            "averaged_message": self.averaged.message,
            "speed_ratio": self.speed_ratio,
        }


def compare_solvers(params: Parameters, simulate: Callable[[Parameters], Result]) -> SolverComparison:
    """Run ``params`` with the full and with the averaged solver through ``simulate``. Ctrl-C raises
    ``KeyboardInterrupt`` even where a run returned cut short: a comparison with part of a run means nothing."""
    # The full solver has limits of its own (the drive periods it keeps every impact of): checked before either runs.
    full_params, averaged_params = params.replace(solver="full"), params.replace(solver="averaged")
    runs = []
    for variant in (full_params, averaged_params):
        result = simulate(variant)
        if result.status == INTERRUPTED:
            raise KeyboardInterrupt
        runs.append(result)
    return SolverComparison(*runs)
