"""What ``shakermill validate`` finds, as cells for the terminal's tables and as one self-contained HTML page
(``validate --report``): the validation matrix with a figure of every prediction against its measurement, the
structure study, and the held-out five-ball prediction."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from shakermill.support.version import __version__
from shakermill.views.html import check_page_target, figure_html, paragraph, section, table, write_page
from shakermill.views.notebook import esc

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from shakermill.studies.validation.cross_prediction import CrossPrediction
    from shakermill.studies.validation.held_out import HeldOutPrediction
    from shakermill.studies.validation.matrix import StructureOutcome, ValidationMatrix
    from shakermill.studies.validation.powder import PowderComparison
    from shakermill.studies.validation.report import ValidationReport

MATRIX_HEADERS = (
    "preset (thermal model)",
    "experiment",
    "node",
    "t [min]",
    "role",
    "measured [K]",
    "predicted [K]",
    "90 % interval [K]",
    "error",
    "inside?",
)
MATRIX_NUMERIC = (3, 5, 6, 7, 8)


def matrix_rows(matrix: ValidationMatrix) -> list[tuple[str, ...]]:
    """One row of text per preset × point: the rise measured and predicted (K), the 90 % interval, the error."""
    rows: list[tuple[str, ...]] = []
    for row in matrix.rows:
        measured = row.point.rise_K
        rows.append(
            (
                f"{row.preset} ({row.thermal_model})",
                row.experiment.name,
                row.point.node,
                f"{row.point.time_s / 60:g}",
                row.role,
                "—" if measured is None else f"{measured:.3g}",
                f"{row.predicted_K:.3g}",
                "—" if math.isnan(row.low_K) else f"{row.low_K:.3g} to {row.high_K:.3g}",
                "—" if measured is None else f"{100 * row.error:+.0f} %",
                {None: "—", True: "yes", False: "no"}[row.inside],
            )
        )
    return rows


def structure_headers() -> tuple[str, ...]:
    from shakermill.studies.validation.held_out import FIVE_BALL_BALL_RISE_K, FIVE_BALL_VIAL_RISE_K

    return (
        "structure (free keys)",
        "fitted",
        "one-ball RMS [K]",
        "on a range edge",
        "paths computed",
        "meets the bar",
        f"5 balls: ball [K] (exp. {FIVE_BALL_BALL_RISE_K:g})",
        f"vial [K] (exp. {FIVE_BALL_VIAL_RISE_K:g})",
    )


def structure_rows(outcomes: Sequence[StructureOutcome]) -> list[tuple[str, ...]]:
    """Each structure fitted to the one-ball curve: its fit, whether it meets the bar, its five-ball prediction."""
    from shakermill.studies.measured import relative_error
    from shakermill.studies.validation.held_out import FIVE_BALL_BALL_RISE_K, FIVE_BALL_VIAL_RISE_K

    def against(rise: float, measured: float) -> str:
        return f"{rise:.3g} ({100 * relative_error(rise, measured):+.0f} %)"

    return [
        (
            outcome.structure.label,
            ", ".join(f"{key} {value:.3g}" for key, value in outcome.fitted.items()),
            f"{outcome.curve_rms_K:.2f}",
            ", ".join(outcome.edges) or "none",
            "yes" if outcome.structure.physical else "no",
            "yes" if outcome.meets_point_7 else "no",
            against(outcome.ball_rise_K, FIVE_BALL_BALL_RISE_K),
            against(outcome.vial_rise_K, FIVE_BALL_VIAL_RISE_K),
        )
        for outcome in outcomes
    ]


HELD_OUT_HEADERS = ("quantity", "unit", "experiment", "predicted", "error")


def held_out_rows(prediction: HeldOutPrediction) -> list[tuple[str, ...]]:
    """The five balls held out: each quantity measured and predicted, and the error."""
    return [
        (row.label, row.unit, f"{row.experiment:g}", f"{row.predicted:.3g}", f"{100 * row.relative_error:+.0f} %")
        for row in prediction.rows
    ]


POWDER_HEADERS = ("quantity", "unit", "without powder", "with powder", "measured without", "measured with")


def powder_rows(comparison: PowderComparison) -> list[tuple[str, ...]]:
    """Each quantity predicted without and with the powder, beside what was measured ('' where nothing was)."""
    return [
        (
            row.label,
            row.unit,
            *(f"{value:.3g}" if math.isfinite(value) else "—" for value in (row.without, row.with_powder)),
            *(f"{value:g}" if math.isfinite(value) else "" for value in (row.measured_without, row.measured_with)),
        )
        for row in comparison.rows
    ]


def powder_statement(comparison: PowderComparison) -> str:
    """What the comparison ran and whether the vial came out warmer with powder, as the published ordering has it."""
    vial = comparison.vial_row
    ordering = "warmer" if comparison.vial_warmer_with_powder else "NOT warmer"
    measured = vial.measured_with - vial.measured_without
    published = f" (measured: {measured:+.3g} K)" if math.isfinite(measured) and measured != 0 else ""
    return (
        f"{comparison.preset} with {1e3 * comparison.powder_kg:g} g of powder (the preset's assumed powder values: "
        f"`shakermill keys powder`): the vial is {ordering} with powder than without, by "
        f"{vial.with_powder - vial.without:+.3g} K{published}. Source: {comparison.source}."
    )


def structure_verdict(outcomes: Sequence[StructureOutcome]) -> str:
    from shakermill.studies.validation.matrix import FOLLOWS_CURVE_K

    meeting = [outcome.structure.label for outcome in outcomes if outcome.meets_point_7]
    return (
        f"The bar: the one-ball curve within {FOLLOWS_CURVE_K:g} K RMS, every free key strictly inside its range, "
        "every "
        "computed path at its correlation's value. "
        + (f"Met by: {', '.join(meeting)}." if meeting else "No structure meets it.")
    )


def matrix_figure(matrix: ValidationMatrix) -> Figure:
    """Every predicted rise with its 90 % interval beside its measurement, one row per experiment's point."""
    from shakermill.views.figures.common import new_figure

    points = list(dict.fromkeys((row.experiment.name, row.point.node, row.point.time_s) for row in matrix.rows))
    presets = list(dict.fromkeys(row.preset for row in matrix.rows))
    roles: dict[tuple[str, str, float], list[str]] = {}
    for row in matrix.rows:
        # A preset fitted to another curve gives the same point another role: the label names each.
        point_roles = roles.setdefault((row.experiment.name, row.point.node, row.point.time_s), [])
        if row.role not in point_roles:
            point_roles.append(row.role)
    figure, (axes,) = new_figure(height=1.0 + 0.45 * len(points) * max(1, len(presets)) / 2, width=10.0)
    offsets = {
        preset: 0.3 * (index - (len(presets) - 1) / 2) / max(1, len(presets)) for index, preset in enumerate(presets)
    }
    for preset in presets:
        rows = [row for row in matrix.rows if row.preset == preset]
        y = [points.index((row.experiment.name, row.point.node, row.point.time_s)) + offsets[preset] for row in rows]
        predicted = [row.predicted_K for row in rows]
        spread = [
            [max(0.0, row.predicted_K - row.low_K) if math.isfinite(row.low_K) else 0.0 for row in rows],
            [max(0.0, row.high_K - row.predicted_K) if math.isfinite(row.high_K) else 0.0 for row in rows],
        ]
        axes.errorbar(predicted, y, xerr=spread, fmt="o", capsize=3, label=f"{preset} (predicted, 90 %)")
    rises = {(row.experiment.name, row.point.node, row.point.time_s): row.point.rise_K for row in matrix.rows}
    measured = [(index, rises[point]) for index, point in enumerate(points) if rises[point] is not None]
    if measured:
        axes.plot(
            [rise for _, rise in measured], [index for index, _ in measured], "k*", markersize=11, label="measured"
        )
    axes.set_yticks(
        range(len(points)),
        [f"{name}: {node}, {time / 60:g} min ({' / '.join(roles[name, node, time])})" for name, node, time in points],
    )
    axes.invert_yaxis()
    axes.set_xlabel("rise above the start [K]")
    axes.set_title("Each calibrated preset against each experiment")
    axes.grid(axis="x", alpha=0.3)
    axes.legend(loc="best", fontsize="small")
    return figure


CROSS_HEADERS = (
    "fitted on",
    "predicted",
    "measured [K]",
    "predicted median [K]",
    "90 % interval [K]",
    "inside?",
    "prior alone: 90 % [K]",
)
CROSS_TITLE = "Both directions: fitted over every uncertain input on one SPEX experiment, the other predicted"


def cross_rows(cross: CrossPrediction) -> list[tuple[str, ...]]:
    """Each direction's predictions of the other experiment's measured points, beside what the prior alone says."""
    rows: list[tuple[str, ...]] = []
    for direction in cross.directions:
        for prediction, prior in zip(direction.predictions, direction.prior_predictions, strict=True):
            low, median, high = prediction.quantiles
            rows.append(
                (
                    direction.fitted_on.name,
                    f"{direction.predicted.name}: {prediction.observable.label}",
                    f"{prediction.measured_K:.3g}",
                    f"{median:.3g}",
                    f"{low:.3g} to {high:.3g}",
                    "yes" if prediction.inside else "no",
                    f"{prior.quantiles[0]:.3g} to {prior.quantiles[2]:.3g}",
                )
            )
    return rows


def cross_statement(cross: CrossPrediction) -> str:
    """The verdicts, what was freed and how, and how well the emulators predict runs they did not see."""
    from shakermill.studies.calibration.observables import ASSUMED_MEASUREMENT_SD_K

    verdicts = "; ".join(
        direction.verdict + (f" (unreliable: {'; '.join(direction.problems)})" if direction.problems else "")
        for direction in cross.directions
    )
    q2 = ", ".join(
        f"{experiment} {name} {value:.2f}"
        for experiment, emulator in cross.emulators.items()
        for name, value in emulator.q2.items()
    )
    freed = sorted({item.key for emulator in cross.emulators.values() for item in emulator.inputs})
    return (
        f"{verdicts[0].upper()}{verdicts[1:]}. Each fit starts from {cross.preset} and frees {', '.join(freed)} over "
        "their "
        f"stated ranges (the priors; pair keys only where two balls meet), the measurements with a standard "
        f"deviation of {ASSUMED_MEASUREMENT_SD_K:g} K (assumed: no source states one); the posterior by "
        f"emcee on Gaussian-process emulators of the runs, whose Q² on runs they did not see is {q2}."
    )


QUICK_NOTE = (
    "A quick validation: the matrix holds the experiments of five balls and of none. `shakermill validate "
    "--full` adds those of one ball, the structure study, the engines' one-ball comparison and the "
    "sensitivity to the assumed SPEX kinematics and both SPEX experiments fitted over every uncertain input, each "
    "predicting the other (~30 min on two cores)."
)


def render_validation_page(report: ValidationReport) -> str:
    """The whole page: the matrix, its figure and its experiments, the structures, the five balls held out."""
    from shakermill.views.report import STYLE

    sections = [
        "<h1>shakermill validation: the thermal networks in three dimensions</h1>",
        paragraph(
            "Every run on this page uses the averaged solver; the mechanics of each experiment's conditions "
            "are measured once and shared by the thermal networks.",
            "note",
        ),
    ]
    if not report.everything:
        sections.append(paragraph(QUICK_NOTE, "status failed"))
    if report.matrix is not None:
        experiments = [
            paragraph(
                f"{experiment.name}: {experiment.title}. Source: {experiment.source}. Measured: "
                f"{experiment.how_measured}."
                + (f" It falsifies: {experiment.falsifies}." if experiment.falsifies else "")
            )
            for experiment in report.matrix.experiments
        ]
        sections.append(
            section(
                "Validation matrix: rises above the start",
                table(MATRIX_HEADERS, matrix_rows(report.matrix), numeric=MATRIX_NUMERIC),
                figure_html(
                    matrix_figure(report.matrix),
                    "Each prediction (points, bars: 90 % interval from the fit's "
                    "uncertainty and the averaging error) against the measurement (stars).",
                    1,
                ),
                *experiments,
            )
        )
    if report.structures:
        sections.append(
            section(
                "Which structure follows the one-ball curve with physical couplings, and what it then predicts",
                table(structure_headers(), structure_rows(report.structures), numeric=(2, 6, 7)),
                paragraph(structure_verdict(report.structures), "statement"),
            )
        )
    if report.held_out is not None:
        prediction = report.held_out.prediction
        sections.append(
            section(
                "Held out: five balls",
                table(HELD_OUT_HEADERS, held_out_rows(prediction), numeric=(2, 3, 4)),
                paragraph(prediction.statement, "statement"),
            )
        )
    for comparison in report.powder:
        sections.append(
            section(
                comparison.title,
                table(POWDER_HEADERS, powder_rows(comparison), numeric=(2, 3, 4, 5)),
                paragraph(powder_statement(comparison), "statement"),
            )
        )
    if report.cross is not None:
        sections.append(
            section(
                CROSS_TITLE,
                table(CROSS_HEADERS, cross_rows(report.cross), numeric=(2, 3, 4, 6)),
                paragraph(cross_statement(report.cross), "statement"),
            )
        )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>shakermill validation</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
        + "\n".join(sections)
        + f'\n<p class="note">Written by shakermill {esc(__version__)}.</p>\n</body>\n</html>\n'
    )


def save_validation_page(report: ValidationReport, target: Path) -> Path:
    check_page_target(target)
    return write_page(target, render_validation_page(report))
