"""``shakermill validate``: this model against the experiment and the paper, and the tables it prints."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.table import Table
from rich.text import Text

from shakermill.cli.common import (
    JsonOption,
    add_plain_row,
    fail,
    nothing_written_when_a_run_is_stopped,
    nothing_written_when_interrupted,
    number,
    progress_bar,
    stdout_console,
    user_errors,
    writing,
)
from shakermill.support.atomic import check_writable_place

if TYPE_CHECKING:
    pass


def validate(
    full: Annotated[
        bool,
        typer.Option(
            "--full",
            help="Everything (~30 min on two cores): Table 5 at full resolution, the matrix's "
            "experiments of one ball, the structure study, the engines' one-ball comparison and the "
            "sensitivity to the assumed SPEX kinematics, and both SPEX experiments fitted over every uncertain input, "
            "each predicting the other. Without it, a quick validation (~2.5 min on two cores).",
        ),
    ] = False,
    solver: Annotated[
        str | None,
        typer.Option(
            "--solver",
            show_default="averaged; full with --full",
            help="Solver of the Table 5 runs: 'full' (as the paper) or 'averaged' (seconds instead of a minute).",
        ),
    ] = None,
    study: Annotated[
        bool, typer.Option(help="Also fit several free sets to the experiment's curve and say which follow it (~15 s).")
    ] = True,
    three_d: Annotated[
        bool,
        typer.Option(
            "--three-d/--no-three-d",
            help="Also the held-out five-ball prediction of the calibrated 3-D preset, the one-ball comparison of "
            "the engines and the sensitivity to the assumed SPEX kinematics (averaged solver, a few minutes).",
        ),
    ] = True,
    json_output: JsonOption = False,
    html: Annotated[
        Path | None,
        typer.Option(
            "--report",
            metavar="FILE",
            help="Also write the validation matrix, its figure, the structure study "
            "and the held-out prediction as one self-contained HTML page.",
        ),
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace the --report file if it exists.")] = False,
) -> None:
    """Paper Table 5 and the experiment's curve side by side: the paper's model, this model with published and
    calibrated parameters, which free sets of a calibration can follow the curve, and (3-D) the validation matrix of
    the thermal models against the five-ball experiment no fit has seen and the empty mill; with --full also the
    one-ball experiments, the structures that follow the one-ball curve, the held-out studies, and each SPEX
    experiment fitted over every uncertain input predicting the other."""
    from shakermill.io.runs import to_jsonable
    from shakermill.studies.validation.report import SOLVERS, validation_report

    solver = solver if solver is not None else "full" if full else "averaged"
    if solver not in SOLVERS:
        fail(f"--solver: {solver!r} is not allowed; allowed: one of {', '.join(map(repr, SOLVERS))}")
    if html is not None:
        if not three_d:
            fail("report: the page holds the three-dimensional studies; allowed --report with --three-d (the default)")
        check_report_target(html, overwrite)
    typer.echo(
        f"validate: {'everything (--full), ~30 min' if full else 'quick, ~2.5 min; --full for everything (~30 min)'}; "
        f"Table 5 with the {solver} solver" + (", then the 3-D validation matrix" if three_d else ""),
        err=True,
    )
    with (
        nothing_written_when_interrupted("validate prints and writes once every run has ended"),
        nothing_written_when_a_run_is_stopped("validate"),
        progress_bar("validation", "{task.completed}/{task.total} steps", None, lines_when_piped=True) as update,
    ):
        report = validation_report(
            solver, study, three_d, progress=lambda done, total: update(done, total=total), everything=full
        )
    # Printed before the page is written: a page that cannot be written loses nothing the study found.
    if json_output:
        typer.echo(json.dumps(to_jsonable(report.as_dict()), sort_keys=True, allow_nan=False))
    else:
        print_report(report)
        if three_d and not full:
            from shakermill.views.validation_page import QUICK_NOTE

            stdout_console().print(Text(QUICK_NOTE))
    if html is not None:
        from shakermill.views.validation_page import save_validation_page

        with writing(html, "the validation report"):
            save_validation_page(report, html)
        typer.echo(f"validation report written to {html}", err=True)


def print_report(report: Any) -> None:
    """The tables of ``validate`` on the terminal."""
    from shakermill.studies.measured import TABLE5

    console = stdout_console()
    console.print(validation_table(report.runs))
    for run in report.runs:
        console.print(Text(run.statement))
    console.print(Text(f"The experiment's ratio is for five balls: {TABLE5[-1].experiment_note}."))
    if report.outcomes:
        console.print(free_set_table(report.outcomes))
    if report.matrix is not None:
        print_matrix(console, report.matrix)
    if report.structures:
        print_structures(console, report.structures)
    for comparison in report.powder:
        print_powder(console, comparison)
    if report.held_out is not None:
        print_held_out(console, report.held_out)
    if report.cross is not None:
        print_cross(console, report.cross)


def print_cross(console: Console, cross: Any) -> None:
    """Both directions of the SPEX experiments, each fitted over every uncertain input, plainly inside or not."""
    from shakermill.views.validation_page import CROSS_HEADERS, CROSS_TITLE, cross_rows, cross_statement

    table = Table(*CROSS_HEADERS, title=CROSS_TITLE)
    for row in cross_rows(cross):
        add_plain_row(table, *row)
    console.print(table)
    console.print(Text(cross_statement(cross)))


def print_matrix(console: Console, matrix: Any) -> None:
    """Each thermal model's calibrated preset against each experiment: the rise measured and predicted (K), with the
    prediction's 90 % interval, its error and whether the measurement lies inside; then what each experiment is and
    what each prediction would falsify."""
    from shakermill.views.validation_page import MATRIX_HEADERS, matrix_rows

    table = Table(*MATRIX_HEADERS, title="Validation matrix: rises above the start")
    for row in matrix_rows(matrix):
        add_plain_row(table, *row)
    console.print(table)
    for experiment in matrix.experiments:
        console.print(
            Text(
                f"{experiment.name}: {experiment.title}. Source: {experiment.source}. Measured: "
                f"{experiment.how_measured}."
            )
        )
        if experiment.falsifies:
            console.print(Text(f"  It falsifies: {experiment.falsifies}."))


def print_structures(console: Console, outcomes: Sequence[Any]) -> None:
    """Each network structure fitted to the one-ball curve, whether it meets the bar of a physical fit, and what it
    predicts for five balls, nothing refitted."""
    from shakermill.views.validation_page import structure_headers, structure_rows, structure_verdict

    table = Table(
        *structure_headers(),
        title="Which structure follows the one-ball curve with physical couplings, and what it then predicts",
    )
    for row in structure_rows(outcomes):
        add_plain_row(table, *row)
    console.print(table)
    console.print(Text(structure_verdict(outcomes)))


def check_report_target(target: Path, overwrite: bool) -> None:
    """Before a long study: a --report that names a folder, or a file without --overwrite, is refused now."""
    if target.is_dir():
        fail(f"{target}: a folder; give the report a file name")
    if target.exists() and not overwrite:
        fail(f"{target}: exists; choose another --report, or add --overwrite to replace it")
    with user_errors():
        check_writable_place(target, "--report")


def print_powder(console: Console, comparison: Any) -> None:
    from shakermill.views.validation_page import POWDER_HEADERS, powder_rows, powder_statement

    table = Table(*POWDER_HEADERS, title=comparison.title)
    for row in powder_rows(comparison):
        add_plain_row(table, *row)
    console.print(table)
    console.print(Text(powder_statement(comparison)))


def print_held_out(console: Console, held_out: Any) -> None:
    from shakermill.studies.validation.held_out import COMPARED_KEYS, FIVE_BALL_SOURCE
    from shakermill.views.validation_page import HELD_OUT_HEADERS, held_out_rows

    prediction, comparison, sensitivity = held_out.prediction, held_out.comparison, held_out.sensitivity
    table = Table(*HELD_OUT_HEADERS, title=f"Held out: five balls ({FIVE_BALL_SOURCE})")
    for row in held_out_rows(prediction):
        add_plain_row(table, *row)
    console.print(table)
    console.print(Text(prediction.statement))
    table = Table(
        "one ball",
        *(f"{label} [{unit}]" for _, label, unit in COMPARED_KEYS),
        title="One ball: what the third dimension, gravity and friction change",
    )
    for index, case in enumerate(comparison.cases):
        cells = [
            f"{values:.3g}" + ("" if index == 0 else f" ({100 * comparison.change(key, index):+.0f} %)")
            for key, values in ((key, comparison.values[index][key]) for key, _, _ in COMPARED_KEYS)
        ]
        add_plain_row(table, case.label, *cells)
    console.print(table)
    console.print(sensitivity_table(sensitivity))


def sensitivity_table(sensitivity: Any) -> Table:
    """Each assumed amplitude halved and raised by half: the measures' relative changes against the baseline."""
    measures = list(sensitivity.baseline)
    table = Table(
        "assumed key × factor",
        "value (SI)",
        *measures,
        title=f"Sensitivity to the assumed {sensitivity.kinematics} motion (five balls)",
    )
    add_plain_row(table, "baseline", "", *(f"{sensitivity.baseline[name]:.4g}" for name in measures))
    for row in sensitivity.rows:
        # A temperature's relative change depends on where its scale starts: in kelvin it says more.
        changes = (
            f"{row.measures[name] - sensitivity.baseline[name]:+.1f} K"
            if name.endswith("_C")
            else f"{100 * row.relative_change[name]:+.1f} %"
            for name in measures
        )
        add_plain_row(table, f"{row.key} × {row.factor:g}", f"{row.value:.4g}", *changes)
    return table


def validation_table(runs: Sequence[Any]) -> Table:
    from shakermill.studies.measured import EXPERIMENT, TABLE5

    table = Table("quantity", "unit", "experiment", "paper's model", title=f"Table 5 ({EXPERIMENT})")
    for run in runs:
        table.add_column(f"{run.preset}", justify="right")
        table.add_column("vs exp.", justify="right")
    for index, entry in enumerate(TABLE5):
        cells = [entry.label, entry.unit, f"{entry.experiment:g}", f"{entry.paper_model:g}"]
        for run in runs:
            row = run.rows[index]
            cells += [f"{row.value:.4g} ({row.role})", f"{100 * row.error_vs_experiment:+.2f} %"]
        add_plain_row(table, *cells)
    # The experiment's exponential plateau is its own estimate of the steady state; the paper gives none.
    steady = ["ball steady state (MODEL.md §11)", "°C", f"{TABLE5[0].experiment:g}", "n/a"]
    for run in runs:
        value = run.summary.number("ball_steady_C")
        steady += [f"{value:.4g} (predicted)", f"{100 * (value - TABLE5[0].experiment) / TABLE5[0].experiment:+.2f} %"]
    add_plain_row(table, *steady)
    deviation = ["RMS deviation from the experiment's curve, 0–60 min", "K", "0", "n/a"]
    for run in runs:
        deviation += [f"{run.curve_rms_K:.3g}", ""]
    add_plain_row(table, *deviation)
    return table


def free_set_table(outcomes: Sequence[Any]) -> Table:
    table = Table(
        "free keys",
        "fitted values",
        "RMS K",
        "vial/ball ratio (exp. 0.46)",
        "verdict",
        title="Which free sets can follow the experiment's curve (fits within physically defensible ranges)",
    )
    for outcome in outcomes:
        calibration = outcome.calibration
        fitted = ", ".join(f"{key} {value:.3g}" for key, value in calibration.fitted.items())
        ratio = calibration.predictions.get("vial_ball_ratio", math.nan)
        add_plain_row(
            table,
            ", ".join(outcome.free),
            fitted,
            number(calibration.curve_rms_K, ".2f"),
            number(ratio, ".3f"),
            outcome.verdict,
        )
    return table
