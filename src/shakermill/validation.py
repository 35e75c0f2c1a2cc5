"""The published comparison (paper Table 5; MODEL.md §10) and this model's numbers beside it."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

PAPER = "Son 2025, Mathematics 13, 446"
EXPERIMENT = "Takacs & McHenry 2006 (J. Mater. Sci. 41, 5246), one ball, SPEX 8000"


@dataclass(frozen=True)
class Quantity:
    key: str  # summary key
    label: str
    unit: str
    experiment: float
    paper_model: float
    experiment_note: str = ""


TABLE5: tuple[Quantity, ...] = (
    Quantity("theta_inf_C", "steady-state ball temperature θ∞", "°C", 48.0, 47.89),
    Quantity("tau_min", "time constant τ", "min", 16.7, 16.70),
    Quantity("rate0_C_per_min", "initial heating rate θ̇₀", "°C/min", 1.6766, 1.6702),
    Quantity(
        "vial_ball_ratio",
        "vial/ball temperature increment ratio after 1 h",
        "",
        0.46,
        0.44,
        experiment_note="five balls (vial +21 °C, ball +46 °C); the paper compares its one-ball model with it",
    ),
)

TARGET_KEYS: tuple[str, ...] = tuple(quantity.key for quantity in TABLE5)


def quantity(key: str) -> Quantity:
    for entry in TABLE5:
        if entry.key == key:
            return entry
    raise KeyError(key)


def relative_error(value: float, reference: float) -> float:
    return (value - reference) / reference if reference else math.nan


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


def compare(summary: Mapping[str, float], fitted_keys: tuple[str, ...] = ()) -> list[ComparisonRow]:
    """This model's Table 5 quantities from a run summary, marked fitted or predicted."""
    return [ComparisonRow(entry, float(summary[entry.key]), entry.key in fitted_keys) for entry in TABLE5]


VALIDATION_PRESETS = ("spex8000m", "spex8000m-calibrated")


@dataclass(frozen=True)
class ValidationRun:
    preset: str
    fitted: tuple[str, ...]
    rows: list[ComparisonRow]
    summary: Mapping[str, float]

    @property
    def statement(self) -> str:
        """One sentence on what was fitted and what was predicted."""
        predicted = [row.quantity.key for row in self.rows if not row.fitted]
        if not self.fitted:
            return f"{self.preset}: published parameters, nothing fitted; {', '.join(predicted)} are predictions."
        targets = [row.quantity.key for row in self.rows if row.fitted]
        return (
            f"{self.preset}: {', '.join(self.fitted)} fitted to {', '.join(targets)} of the experiment; "
            f"{', '.join(predicted)} predicted."
        )


def validate(solver: str = "full") -> list[ValidationRun]:
    """Run the published and the calibrated preset and compare both with Table 5."""
    from .params import PRESETS, default_parameters
    from .simulate import simulate

    runs = []
    for name in VALIDATION_PRESETS:
        preset = PRESETS[name]
        targets = tuple(preset.provenance.get("targets", {}))
        result = simulate(default_parameters(name, solver=solver, record_windows=()))
        runs.append(ValidationRun(name, preset.fitted, compare(result.summary, targets), result.summary))
    return runs
