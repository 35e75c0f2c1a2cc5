"""Predictions held against what was not fitted (MODEL.md §10, §12): the five-ball experiment, and what the
third dimension, gravity and friction change on the one-ball case.

The calibrated three-dimensional preset was fitted to the one-ball curve only. The five-ball experiment of
Takacs & McHenry (2006), as Son (2025, section 4) quotes it, is the first number the model meets that no
fit has seen: the ball's and the vial's temperature rise after one hour, and their ratio.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from shakermill.parameters.defaults import HIT_SPEED
from shakermill.parameters.keys import Parameters
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.parameters.presets import PRESETS, default_parameters
from shakermill.solvers.simulate import thermal_variants
from shakermill.solvers.summary import Summary
from shakermill.studies.measured import relative_error
from shakermill.studies.validation.kinematics import (
    DEFAULT_FACTORS,
    KinematicSensitivity,
    kinematic_sensitivity,
    measured,
)

HELD_OUT_PRESET = "spex8000m-3d-calibrated"
FIVE_BALLS = 5
FIVE_BALL_SOURCE = (
    "Takacs & McHenry 2006 (J. Mater. Sci. 41, 5246) as quoted by Son 2025, section 4: five balls, one hour"
)
# The experiment's rises after one hour (K) and their ratio, as that source gives them ("21 °C / 46 °C").
FIVE_BALL_BALL_RISE_K, FIVE_BALL_VIAL_RISE_K, FIVE_BALL_RATIO = 46.0, 21.0, 0.46


@dataclass(frozen=True)
class HeldOutRow:
    key: str
    label: str
    unit: str
    experiment: float
    predicted: float

    @property
    def relative_error(self) -> float:
        return relative_error(self.predicted, self.experiment)


@dataclass(frozen=True)
class HeldOutPrediction:
    """The calibrated preset with five balls, nothing refitted, against the five-ball experiment."""

    preset: str
    fitted: tuple[str, ...]
    fitted_to: str
    rows: tuple[HeldOutRow, ...]
    summary: Summary

    @property
    def statement(self) -> str:
        errors = "; ".join(f"{row.label} off by {100 * row.relative_error:+.0f} %" for row in self.rows)
        return (
            f"{self.preset}: {', '.join(self.fitted)} fitted to {self.fitted_to} (one ball) only; with {FIVE_BALLS} "
            "balls "
            f"nothing was refitted, so every number here is a prediction: {errors}."
        )


def five_ball_rows(summary: Summary) -> tuple[HeldOutRow, ...]:
    """The rises after one hour of the balls' mean and of the vial, and their ratio, beside the experiment."""
    start = summary.initial_temperature_C
    return (
        HeldOutRow(
            "ball_rise_C",
            "ball temperature rise after 1 h",
            "K",
            FIVE_BALL_BALL_RISE_K,
            summary.ball_C - start,
        ),
        HeldOutRow(
            "vial_rise_C",
            "vial temperature rise after 1 h",
            "K",
            FIVE_BALL_VIAL_RISE_K,
            summary.vial_C - start,
        ),
        HeldOutRow("vial_ball_ratio", "vial/ball rise ratio after 1 h", "", FIVE_BALL_RATIO, summary.vial_ball_ratio),
    )


def five_ball_parameters(overrides: Mapping[str, Any] | None = None) -> Parameters:
    """:data:`HELD_OUT_PRESET` with five balls for the experiment's hour, averaged unless ``overrides`` say
    otherwise."""
    settings = {
        "solver": "averaged",
        "record_windows": (),
        "duration": 3600.0,
        **(overrides or {}),
        "n_balls": FIVE_BALLS,
    }
    return default_parameters(HELD_OUT_PRESET, **settings)


def five_ball_prediction(overrides: Mapping[str, Any] | None = None) -> HeldOutPrediction:
    """Run :func:`five_ball_parameters` and compare the rises with the experiment."""
    preset = PRESETS[HELD_OUT_PRESET]
    params = five_ball_parameters(overrides)
    # Through thermal_variants: the validation matrix has measured these mechanics already (one thermal model apart).
    result = thermal_variants(params)(params)
    fitted_to = str(preset.provenance.get("curve", "the one-ball experiment"))
    return HeldOutPrediction(HELD_OUT_PRESET, preset.fitted, fitted_to, five_ball_rows(result.summary), result.summary)


# The one-ball case, from the paper's model to the real mill, one change at a time.
@dataclass(frozen=True)
class EngineCase:
    label: str
    preset: str
    settings: Mapping[str, Any] = field(default_factory=dict)


ENGINE_CASES: tuple[EngineCase, ...] = (
    EngineCase("1-D (the paper's model)", "spex8000m"),
    EngineCase(
        "3-D, its 1-D limit (axial, no gravity, no friction, Ø19 mm)",
        "spex8000m",
        {"engine": "dem", "gravity": False, "friction": 0.0},
    ),
    EngineCase("3-D, axial, gravity and friction, Ø19 mm", "spex8000m", {"engine": "dem"}),
    EngineCase("3-D, axial, gravity and friction, Ø38 mm vial", "spex8000m-3d", {"kinematics": "axial"}),
    EngineCase("3-D, SPEX figure-eight, Ø38 mm vial", "spex8000m-3d"),
)
COMPARED_KEYS: tuple[tuple[str, str, str], ...] = (
    ("heat_power_W", "heat power", "W"),
    ("hit_rate_hz", f"hits (≥ {HIT_SPEED:g} m/s)", "1/s"),
    ("mean_hit_speed_m_s", "mean hit speed", "m/s"),
    ("max_impact_speed_m_s", "fastest impact", "m/s"),
    ("impact_rate_hz", "contacts, chatter included", "1/s"),
)


@dataclass(frozen=True)
class EngineComparison:
    cases: tuple[EngineCase, ...]
    values: tuple[dict[str, float], ...]  # per case, COMPARED_KEYS' values

    def change(self, key: str, case: int) -> float:
        """Relative change of ``key`` in ``case`` against the 1-D model."""
        return relative_error(self.values[case][key], self.values[0][key])


def engine_comparison(
    cases: tuple[EngineCase, ...] = ENGINE_CASES,
    overrides: Mapping[str, Any] | None = None,
    progress: Callable[[int], None] | None = None,
) -> EngineComparison:
    """Heat power, hit rate and impact speeds of one ball for each case, with the averaged solver's means of
    the settled motion (``overrides`` apply to every case)."""
    values = []
    for index, case in enumerate(cases):
        settings = {"solver": "averaged", "record_windows": (), **case.settings, **(overrides or {})}
        values.append(measured(default_parameters(case.preset, **settings), [key for key, _, _ in COMPARED_KEYS]))
        if progress is not None:
            progress(index + 1)
    return EngineComparison(cases, tuple(values))


# What the five-ball prediction is made of and what it predicts, each against the assumed amplitudes.
SENSITIVITY_MEASURES = ("heat_power_W", "hit_rate_hz", "mean_hit_speed_m_s", "ball_C", "vial_C")


def five_ball_sensitivity(
    overrides: Mapping[str, Any] | None = None, progress: Callable[[int, int], None] | None = None
) -> KinematicSensitivity:
    """How the five-ball prediction moves when each assumed amplitude of the SPEX motion is halved or raised by half."""
    return kinematic_sensitivity(five_ball_parameters(overrides), measures=SENSITIVITY_MEASURES, progress=progress)


@dataclass(frozen=True)
class HeldOutStudies:
    """The five-ball prediction, the engines on one ball and the sensitivity to the assumed SPEX motion."""

    prediction: HeldOutPrediction
    comparison: EngineComparison
    sensitivity: KinematicSensitivity

    def as_dict(self) -> dict[str, Any]:
        prediction, comparison = self.prediction, self.comparison
        return {
            "five_balls": {
                "preset": prediction.preset,
                "source": FIVE_BALL_SOURCE,
                "fitted_parameters": list(prediction.fitted),
                "fitted_to": prediction.fitted_to,
                "statement": prediction.statement,
                "rows": {
                    row.key: {
                        "label": row.label,
                        "unit": row.unit,
                        "experiment": row.experiment,
                        "predicted": row.predicted,
                        "relative_error": row.relative_error,
                    }
                    for row in prediction.rows
                },
            },
            "engine_comparison": {
                "units": {key: unit for key, _, unit in COMPARED_KEYS},
                "cases": [{"label": case.label, **values} for case, values in zip(comparison.cases, comparison.values)],
            },
            "kinematic_sensitivity": self.sensitivity.as_dict(),
        }


def held_out_steps() -> int:
    """The runs of :func:`held_out_studies`: the prediction, the engines' cases, the sensitivity's baseline and its
    factors of each assumed amplitude."""
    assumed = KINEMATIC_MODELS[five_ball_parameters().kinematics].assumed
    return 1 + len(ENGINE_CASES) + 1 + len(DEFAULT_FACTORS) * len(assumed)


def held_out_studies(progress: Callable[[int, int], None] | None = None) -> HeldOutStudies:
    """All three; ``progress(done, total)`` counts their runs."""
    total = held_out_steps()
    show = progress if progress is not None else (lambda done, total: None)
    prediction = five_ball_prediction()
    show(1, total)
    comparison = engine_comparison(ENGINE_CASES, progress=lambda done: show(1 + done, total))
    sensitivity = five_ball_sensitivity(progress=lambda done, _: show(1 + len(ENGINE_CASES) + done, total))
    return HeldOutStudies(prediction, comparison, sensitivity)
