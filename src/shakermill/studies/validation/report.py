"""Everything ``shakermill validate`` reports, composed: the paper's Table 5 and the experiment's curve against this
model with published and calibrated parameters (:mod:`validation`), which free sets of a calibration can follow the
curve (:func:`calibrate.free_set_study`), and the three-dimensional studies held against what no fit has seen
(:mod:`held_out`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from shakermill.parameters.config import load_config
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.keys import Parameters
from shakermill.studies.calibration.calibrate import FREE_SET_STUDY, FreeSetOutcome, free_set_study
from shakermill.studies.measured import EXPERIMENT, TABLE5
from shakermill.studies.validation.cross_prediction import CrossPrediction, cross_prediction
from shakermill.studies.validation.held_out import HeldOutStudies, held_out_steps, held_out_studies
from shakermill.studies.validation.matrix import (
    STRUCTURES,
    THERMAL_MODEL_PRESETS,
    Experiment,
    StructureOutcome,
    ValidationMatrix,
    load_experiments,
    structure_study,
    validation_matrix,
)
from shakermill.studies.validation.powder import POWDER_STEPS, PowderComparison, powder_studies
from shakermill.studies.validation.table5 import VALIDATION_PRESETS, ValidationRun, validate

SOLVERS = ("full", "averaged")


@dataclass(frozen=True)
class ValidationReport:
    """The runs of the presets against Table 5, the free-set study (empty when not asked) and the held-out
    studies (None when not asked)."""

    solver: str
    runs: tuple[ValidationRun, ...]
    outcomes: tuple[FreeSetOutcome, ...]
    held_out: HeldOutStudies | None
    matrix: ValidationMatrix | None = None
    structures: tuple[StructureOutcome, ...] = ()
    # False for the quick validation: the matrix holds only the experiments of quick_experiments.
    everything: bool = True
    # Fitted over every uncertain input on one SPEX experiment, the other predicted (--full only).
    cross: CrossPrediction | None = None
    # Five SPEX balls and a planetary mill, each without and with powder (with the 3-D studies).
    powder: tuple[PowderComparison, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        """The JSON object of ``validate --json``."""
        return {
            "experiment_source": EXPERIMENT,
            "solver": self.solver,
            "full": self.everything,
            "ran": {
                "table5": True,
                "free_set_study": bool(self.outcomes),
                "validation_matrix": self.matrix is not None,
                "experiments": []
                if self.matrix is None
                else [experiment.name for experiment in self.matrix.experiments],
                "structure_study": bool(self.structures),
                "held_out": self.held_out is not None,
                "cross_prediction": self.cross is not None,
                "powder": bool(self.powder),
            },
            "quantities": {
                entry.key: {
                    "label": entry.label,
                    "unit": entry.unit,
                    "experiment": entry.experiment,
                    "paper_model": entry.paper_model,
                }
                for entry in TABLE5
            },
            "runs": {run.preset: _run_entry(run) for run in self.runs},
            "free_set_study": [_outcome_entry(outcome) for outcome in self.outcomes],
            **(self.held_out.as_dict() if self.held_out is not None else {}),
            **({"validation_matrix": self.matrix.as_dict()} if self.matrix is not None else {}),
            **({"structure_study": [outcome.as_dict() for outcome in self.structures]} if self.structures else {}),
            **({"cross_prediction": self.cross.as_dict()} if self.cross is not None else {}),
            **({"powder": [comparison.as_dict() for comparison in self.powder]} if self.powder else {}),
        }


def _run_entry(run: ValidationRun) -> dict[str, Any]:
    return {
        "fitted_parameters": list(run.fitted),
        "statement": run.statement,
        "values": {row.quantity.key: row.value for row in run.rows},
        "relative_error_vs_experiment": {row.quantity.key: row.error_vs_experiment for row in run.rows},
        "role": {row.quantity.key: row.role for row in run.rows},
        "curve_rms_K": run.curve_rms_K,
        "ball_steady_C": run.summary.ball_steady_C,
        "slowest_time_constant_min": run.summary.slowest_time_constant_min,
    }


def _outcome_entry(outcome: FreeSetOutcome) -> dict[str, Any]:
    return {
        "free": list(outcome.free),
        "fitted": outcome.calibration.fitted,
        "curve_rms_K": outcome.calibration.curve_rms_K,
        "follows_curve": outcome.follows_curve,
        "at_edges": outcome.calibration.at_bounds,
        "predictions": outcome.calibration.predictions,
        "verdict": outcome.verdict,
    }


def preset_parameters(name: str) -> Parameters:
    """The parameters of preset ``name`` without record windows."""
    return load_config(preset=name, overrides=["record_windows="]).params


def validation_report(
    solver: str,
    study: bool = True,
    three_d: bool = True,
    progress: Callable[[int, int], None] | None = None,
    everything: bool = True,
) -> ValidationReport:
    """Validate with ``solver`` ('full' or 'averaged'); with ``study`` the free-set study of the default preset, with
    ``three_d`` the validation matrix of the thermal models (``progress(done, total)`` counts its runs) and, with
    ``everything``, its experiments of one ball, the structure study, the held-out studies and both directions of
    the SPEX experiments fitted over every uncertain input (:func:`cross_prediction`); without, only the
    experiments that run in minutes (:func:`quick_experiments`)."""
    show = progress if progress is not None else (lambda done, total: None)
    experiments = load_experiments() if everything else quick_experiments(load_experiments())
    # Every step counted, Table 5's runs and the free-set fits first: minutes pass before the 3-D studies begin.
    first = len(VALIDATION_PRESETS) + (len(FREE_SET_STUDY) if study else 0)
    pairs = len(experiments) * len(THERMAL_MODEL_PRESETS) + POWDER_STEPS if three_d else 0
    runs = tuple(validate(solver, lambda done: show(done, first + pairs)))

    def fitted(done: int) -> None:
        show(len(VALIDATION_PRESETS) + done, first + pairs)

    outcomes = tuple(free_set_study(preset_parameters(DEFAULT_PRESET), progress=fitted)) if study else ()
    if not three_d:
        return ValidationReport(solver, runs, outcomes, None, everything=False)
    matrix = validation_matrix(
        experiments=experiments, progress=lambda done, total: show(first + done, first + total + POWDER_STEPS)
    )
    done_matrix = first + pairs - POWDER_STEPS
    powder = powder_studies(progress=lambda done, total: show(done_matrix + done, first + pairs))
    if not everything:
        return ValidationReport(solver, runs, outcomes, None, matrix, everything=False, powder=powder)
    before = first + pairs
    structures = structure_study(progress=lambda done, total: show(before + done, before + total))
    before += len(STRUCTURES)
    held_out = held_out_studies(lambda done, total: show(before + done, before + total))
    before += held_out_steps()
    cross = cross_prediction(progress=lambda done, total: show(before + done, before + total))
    return ValidationReport(solver, runs, outcomes, held_out, matrix, structures, cross=cross, powder=powder)


def quick_experiments(experiments: Sequence[Experiment]) -> tuple[Experiment, ...]:
    """The experiments of more balls than one, or none: a lone ball rolling in the SPEX's figure of eight takes its
    averaged mechanics ~5 min to converge on two cores, five balls ~1 min, an empty mill nothing."""
    return tuple(experiment for experiment in experiments if experiment.conditions.get("n_balls", 1) != 1)
