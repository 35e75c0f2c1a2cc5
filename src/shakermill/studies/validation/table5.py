"""The published comparison (paper Table 5; MODEL.md §10) and this model's numbers beside it: the published and the
calibrated 1-D presets run at the experiment's operating point, each quantity marked fitted or predicted."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from shakermill.parameters.keys import field_unit
from shakermill.studies.measured import (
    EXPERIMENT_OPERATING_POINT,
    OPERATING_POINT_TOLERANCE,
    TABLE5,
    VIAL_KEYS,
    Quantity,
    experiment_curve,
    fitted_quantities,
    relative_error,
)

if TYPE_CHECKING:
    from shakermill.solvers.summary import Summary


@dataclass(frozen=True)
class ComparisonRow:
    quantity: Quantity
    value: float
    fitted: bool  # the value was a calibration target (so agreement is not a prediction)

    @property
    def error_vs_experiment(self) -> float:
        return relative_error(self.value, self.quantity.experiment)

    @property
    def role(self) -> str:
        return "fitted" if self.fitted else "predicted"


def compare(summary: Summary, fitted_keys: tuple[str, ...] = ()) -> list[ComparisonRow]:
    """This model's Table 5 quantities from a run summary, marked fitted or predicted."""
    return [ComparisonRow(entry, summary.number(entry.key), entry.key in fitted_keys) for entry in TABLE5]


VALIDATION_PRESETS = ("spex8000m", "spex8000m-calibrated")


@dataclass(frozen=True)
class ValidationRun:
    preset: str
    fitted: tuple[str, ...]
    rows: list[ComparisonRow]
    summary: Summary
    curve_rms_K: float  # RMS deviation from the experiment's curve over the hour
    fitted_to_curve: bool

    @property
    def statement(self) -> str:
        """One sentence on what was fitted and what was predicted."""
        predicted = [row.quantity.key for row in self.rows if not row.fitted] + ["ball_steady_C"]
        deviation = f"RMS {self.curve_rms_K:.2f} K from the experiment's curve over the hour"
        if not self.fitted:
            return (
                f"{self.preset}: published parameters, nothing fitted; {deviation}; "
                f"{', '.join(predicted)} are predictions."
            )
        targets = [row.quantity.key for row in self.rows if row.fitted]
        through = (
            f"the experiment's curve ({', '.join(targets)} through it)" if self.fitted_to_curve else ", ".join(targets)
        )
        return (
            f"{self.preset}: {', '.join(self.fitted)} fitted to {through}; {deviation}; "
            f"{', '.join(predicted)} predicted."
        )


def validate(solver: str = "full", progress: Callable[[int], None] | None = None) -> list[ValidationRun]:
    """Run the published and the calibrated preset and compare both with Table 5 and the experiment's curve
    (``progress(runs done)`` after each). Ctrl-C raises ``KeyboardInterrupt`` and a spent budget ``BudgetExceeded``: a
    run cut short is no row of Table 5."""
    from shakermill.parameters.presets import PRESETS, default_parameters
    from shakermill.solvers.simulate import simulate_whole

    curve = experiment_curve()
    runs = []
    for name in VALIDATION_PRESETS:
        preset = PRESETS[name]
        result = simulate_whole(default_parameters(name, solver=solver, record_windows=()))
        series = result.timeseries
        runs.append(
            ValidationRun(
                preset=name,
                fitted=preset.fitted,
                rows=compare(result.summary, fitted_quantities(preset.provenance)),
                summary=result.summary,
                curve_rms_K=curve.rms_K(series["time"].values, series["theta_ball"].values),
                fitted_to_curve="curve" in preset.provenance,
            )
        )
        if progress is not None:
            progress(len(runs))
    return runs


def operating_point_mismatches(values: Mapping[str, float], vial: Mapping[str, float]) -> list[str]:
    """The keys of ``values`` (parameters, with the simulated time as ``duration``) off the experiment's operating
    point by more than :data:`OPERATING_POINT_TOLERANCE`, as "omega = 100 rad/s (experiment: 111 rad/s)".

    ``vial`` holds the preset's vial length and diameter: the experiment's vial.
    """
    wanted = {**EXPERIMENT_OPERATING_POINT, **{key: vial[key] for key in VIAL_KEYS}}
    return [
        f"{key} = {values[key]:.4g} {field_unit(key)} (experiment: {target:.4g} {field_unit(key)})"
        for key, target in wanted.items()
        if not math.isclose(values[key], target, rel_tol=OPERATING_POINT_TOLERANCE)
    ]
