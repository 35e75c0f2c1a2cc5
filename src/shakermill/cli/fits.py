"""``shakermill calibrate``: free keys fitted to a measured curve or targets (``validate`` is in :mod:`validating`)."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.table import Table
from rich.text import Text

from shakermill.cli.common import (
    EXIT_FAILED_RUN,
    EXIT_INTERRUPTED,
    PROGRESS_DELAY_S,
    ConfigArgument,
    FullResolutionOption,
    JsonOption,
    PresetOption,
    SchedulerOption,
    SchedulerTimeoutOption,
    SettingsOption,
    add_plain_row,
    fail,
    nothing_written_when_a_run_is_stopped,
    nothing_written_when_interrupted,
    number,
    progress_bar,
    scheduler_timeout_of,
    stdout_console,
    timestamped_folder,
    user_errors,
    writing,
)
from shakermill.parameters.defaults import DEFAULT_FREE, DEFAULT_FREE_BY_NETWORK, DEM_DEFAULT_FREE, TARGET_KEYS
from shakermill.parameters.errors import ParameterError
from shakermill.support.atomic import check_writable_place

if TYPE_CHECKING:
    from shakermill.studies.calibration.calibrate import Calibration


WithAssumedOption = Annotated[
    bool,
    typer.Option(
        "--with-assumed",
        help="Also free the preset's assumed inputs that move the mechanics (friction, "
        "restitution, λ, the clamp's motion, ...), their stated ranges as priors: a Bayesian fit on emulators "
        "of the runs, with posterior-predictive intervals (MODEL.md §14.1; minutes).",
    ),
]
# The mechanical runs of --with-assumed per set of conditions, where --members does not say.
JOINT_MEMBERS = 32
MembersOption = Annotated[
    int | None,
    typer.Option(
        "--members",
        "-n",
        show_default=str(JOINT_MEMBERS),
        help="With --with-assumed: mechanical runs per set of conditions, a power of two.",
    ),
]
RunsOption = Annotated[
    Path | None,
    typer.Option(
        "--runs",
        metavar="DIR",
        show_default="results/calibrate-<timestamp>",
        help="With --with-assumed: the folder its mechanical runs are stored in as they finish; re-run into it to "
        "resume after Ctrl-C.",
    ),
]
WorkersOption = Annotated[
    int | None,
    typer.Option(
        "--workers", "-w", show_default="one per core", help="With --with-assumed: local worker processes of its runs."
    ),
]
PosteriorOption = Annotated[
    bool | None,
    typer.Option(
        "--posterior/--no-posterior",
        show_default="--posterior",
        help="Sample the posterior of the fitted keys where an evaluation is "
        "the thermal network alone (engine 'dem': ~2400 evaluations, a few minutes); without it, the "
        "standard errors are linear.",
    ),
]


def calibrate(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    target: Annotated[
        list[str] | None,
        typer.Option("--target", "-t", metavar="NAME=VALUE", help=f"A target: {', '.join(TARGET_KEYS)}."),
    ] = None,
    curve: Annotated[
        list[str] | None,
        typer.Option(
            "--curve",
            metavar="CSV[:KEY=VALUE,...]",
            help="A measured curve to fit: CSV with time_s (or time_min) and ball_C or vial_C, and the settings of its "
            "run that differ (e.g. curves.csv:n_balls=5); repeat for several curves, each of its own node and "
            "conditions (default, without --target: the experiment's curve 48 - 28 exp(-t/16.7 min) over 0-60 min).",
        ),
    ] = None,
    free: Annotated[
        list[str] | None,
        typer.Option(
            "--free",
            "-f",
            metavar="KEY[,KEY]",
            help="Keys to fit (default: those of the run's network that it reads: 'paper' "
            f"{','.join(DEFAULT_FREE)}, with "
            f"engine = 'dem' {','.join(DEM_DEFAULT_FREE)}; 'mill-head' "
            f"{','.join(DEFAULT_FREE_BY_NETWORK['mill-head'])}).",
        ),
    ] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Write the fitted preset TOML here.")] = None,
    full_resolution: FullResolutionOption = False,
    json_output: JsonOption = False,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace the preset file if it exists.")] = False,
    with_assumed: WithAssumedOption = False,
    members: MembersOption = None,
    posterior: PosteriorOption = None,
    runs: RunsOption = None,
    workers: WorkersOption = None,
    scheduler: SchedulerOption = None,
    scheduler_timeout: SchedulerTimeoutOption = None,
) -> None:
    """Fit free parameters to measured curves (the experiment's by default) and/or Table 5 targets by bounded least
    squares; with --with-assumed, over every uncertain input by Bayesian inference."""
    from shakermill.io.runs import to_jsonable
    from shakermill.parameters.config import load_config, values_beyond_preset
    from shakermill.studies.calibration.calibrate import calibrate as fit_parameters
    from shakermill.studies.calibration.calibrate import default_free, parse_free, parse_targets
    from shakermill.studies.measured import curve_from_option

    with user_errors():
        # The fit evaluates with its own solver, not the one the parameters name.
        reader = "full" if full_resolution else "averaged"
        run_config = load_config(config, preset=preset, overrides=settings or [], reader=reader)
        targets = parse_targets(target or [])
        free_keys = parse_free(free or [], default_free(run_config.params))
        measured = [curve_from_option(item) for item in curve or ()]
        if out is not None:
            # Checked before the fit, which takes a while.
            check_preset_target(out, overwrite)
        if with_assumed:
            if posterior is False:
                raise ParameterError(
                    "no-posterior: a calibration --with-assumed is its posterior (emcee on emulators of its runs); "
                    "allowed --no-posterior without --with-assumed"
                )
            calibrate_over_assumed(
                run_config,
                free_keys,
                targets,
                measured,
                JOINT_MEMBERS if members is None else members,
                full_resolution,
                out,
                json_output,
                Runs(runs, workers, scheduler, scheduler_timeout_of(scheduler, scheduler_timeout)),
            )
            return
        check_no_runs(runs, workers, scheduler, members, scheduler_timeout)
        with (
            nothing_written_when_interrupted("the fit starts again from the beginning"),
            nothing_written_when_a_run_is_stopped("the fit"),
            progress_bar(
                "calibrate", "{task.fields[doing]}", None, delay_s=PROGRESS_DELAY_S, doing="starting"
            ) as update,
        ):
            calibration = fit_parameters(
                run_config.params,
                free_keys,
                targets,
                measured,
                full_resolution=full_resolution,
                sample_posterior=posterior is not False,
                **fit_progress(update),
                on_start=lambda: announce(
                    run_config.params, free_keys, bool(free), [item.note for item in measured if item.note]
                ),
            )
    # A fit that missed its targets, or left its keys undetermined (values any others would match as well), has no
    # values a preset should carry.
    written = out if out is not None and calibration.success else None
    if written is not None:
        beyond = values_beyond_preset(run_config.params, run_config.preset)
        write_fitted_preset(calibration, written, run_config.preset, free_keys, targets, beyond)
    if json_output:
        typer.echo(
            json.dumps(
                to_jsonable({**calibration.as_dict(), "output": str(written) if written else None}),
                sort_keys=True,
                allow_nan=False,
            )
        )
    else:
        print_calibration(calibration, free_keys, targets, written)
    if not calibration.success:
        verdict = "could not determine its keys" if calibration.status == "undetermined" else "did not meet its targets"
        unwritten = f" (nothing written to {out})" if out is not None else ""
        typer.echo(f"error: calibration {verdict}{unwritten}: {calibration.message}", err=True)
        raise typer.Exit(EXIT_FAILED_RUN)


def fit_progress(update: Callable[..., None]) -> dict[str, Callable[..., None]]:
    """The progress callbacks of a fit (``calibrate``'s keywords) that say what it is doing through ``update``: the
    mechanics it measures once, its evaluations with their RMS from the curves, then the posterior's, of how many."""
    # The fit's evaluations so far, and where the posterior's began with how many to come.
    count = {"done": 0, "posterior_from": -1, "posterior": 0}

    def evaluated(done: int, rms: float | None) -> None:
        count["done"] = done
        if count["posterior_from"] >= 0:
            doing = (
                f"sampling the posterior: {done - count['posterior_from']} of ~{count['posterior']} model evaluations"
            )
        else:
            doing = f"{done} model evaluations, the last {number(rms, '.3g')} K RMS from the curves"
        update(done, doing=doing)

    def measuring(done: float, total: float) -> None:
        update(
            done,
            doing=f"measuring the mechanics once for every evaluation: {done:.4g} s simulated (converged "
            f"means end it, at most {total:.4g} s)",
        )

    return {
        "progress": evaluated,
        "mechanics_progress": measuring,
        "on_posterior": lambda total: count.update(posterior_from=count["done"], posterior=total),
    }


@dataclass(frozen=True)
class Runs:
    """Where ``calibrate --with-assumed`` keeps its runs (``--runs``) and where they run (``--workers``,
    ``--scheduler`` and how long to wait for it)."""

    folder: Path | None
    workers: int | None
    scheduler: str | None
    scheduler_timeout: float


def check_no_runs(
    runs: Path | None, workers: int | None, scheduler: str | None, members: int | None, timeout: float | None
) -> None:
    """A fit of the network alone runs no design of runs: their options are refused in one line."""
    options = (
        ("runs", runs),
        ("workers", workers),
        ("scheduler", scheduler),
        ("scheduler-timeout", timeout),
        ("members", members),
    )
    given = [name for name, value in options if value is not None]
    if given:
        raise ParameterError(
            f"{given[0]}: a fit of the network alone measures the mechanics once and runs no design of runs; "
            f"allowed --{given[0]} with --with-assumed"
        )


def calibrate_over_assumed(
    run_config: Any,
    free_keys: Sequence[str],
    targets: Mapping[str, float],
    curves: Sequence[Any],
    members: int,
    full_resolution: bool,
    out: Path | None,
    json_output: bool,
    runs: Runs,
) -> None:
    """``calibrate --with-assumed``: the posterior of the network's free keys and the preset's assumed inputs given the
    curves, printed, and the preset of its medians written where it is reliable. Its runs are stored in
    ``runs.folder`` as they finish: after Ctrl-C the same command into it computes only the others."""
    from shakermill.parameters.config import config_preset
    from shakermill.studies.calibration.joint import calibrate_jointly
    from shakermill.studies.ensembles.ensemble import check_members
    from shakermill.studies.measured import experiment_curve
    from shakermill.studies.sweeps.executor import Execution, RunsInterrupted

    if targets:
        raise ParameterError(
            "target: a calibration --with-assumed fits measured rises; allowed --curve (a Table 5 "
            "target is a summary of a curve, not a measurement)"
        )
    if full_resolution:
        raise ParameterError(
            "full-resolution: a calibration --with-assumed runs the averaged solver on a design of "
            "runs; allowed without --full-resolution"
        )
    check_members(members)
    execution = Execution(
        runs.workers,
        runs.scheduler,
        runs.scheduler_timeout,
        announce=lambda line: typer.echo(f"calibrate: {line}", err=True),
    )
    folder = runs.folder if runs.folder is not None else timestamped_folder("calibrate")
    params = run_config.params.replace(solver="averaged", attractor_starts=1)
    curves = list(curves) or [experiment_curve()]
    sets = len({tuple(item.conditions) for item in curves} | {()})
    said = (
        f"calibrate: fitting {', '.join(free_keys)} and the assumed inputs of {run_config.preset} over {members} "
        f"mechanical runs per set of conditions ({sets}), then emcee on their emulators; the runs are kept in {folder}"
    )
    resume = f"re-run the same command with --runs {folder}"
    try:
        with (
            nothing_written_when_a_run_is_stopped("the fit"),
            progress_bar(
                "fitting", "{task.completed}/{task.total} runs", members * sets, lines_when_piped=True
            ) as update,
        ):
            joint = calibrate_jointly(
                config_preset(run_config),
                params,
                free_keys,
                curves,
                members,
                progress=lambda done, total: update(done, total=total),
                on_start=lambda: typer.echo(said, err=True),
                runs=folder,
                execution=execution,
                say=lambda line: typer.echo(f"calibrate: {line}", err=True),
            )
    except RunsInterrupted as stopped:
        fail(
            f"interrupted; kept {stopped.kept} of the {stopped.total} runs of a set of conditions in {folder}; "
            f"{resume} to compute the others",
            EXIT_INTERRUPTED,
        )
    except KeyboardInterrupt:
        fail(
            f"interrupted; nothing was written but the runs, kept in {folder}; {resume} to fit from them",
            EXIT_INTERRUPTED,
        )
    report_joint(joint, run_config, out, json_output, folder)


def report_joint(joint: Any, run_config: Any, out: Path | None, json_output: bool, folder: Path) -> None:
    """A joint calibration's preset written to ``out`` where it is reliable, then its report; an unreliable one says
    why and exits 1."""
    from shakermill.io.runs import to_jsonable
    from shakermill.parameters.config import values_beyond_preset
    from shakermill.studies.calibration.joint import write_joint_preset

    # An unreliable posterior (an emulator that misses runs it did not see, or a chain too short) has no medians a
    # preset should carry, as a network fit that missed its targets has none.
    written = out if out is not None and not joint.problems else None
    if written is not None:
        command = "shakermill calibrate " + " ".join(sys.argv[2:])
        with writing(written, "the preset"):
            write_joint_preset(
                joint,
                written,
                base_preset=run_config.preset,
                command=command,
                settings=values_beyond_preset(run_config.params, run_config.preset),
            )
    if json_output:
        typer.echo(
            json.dumps(
                to_jsonable({**joint.as_dict(), "output": str(written) if written else None}),
                sort_keys=True,
                allow_nan=False,
            )
        )
    else:
        print_joint(joint, written)
    if joint.problems:
        unwritten = f" (nothing written to {out})" if out is not None else ""
        typer.echo(
            f"error: calibration over every uncertain input is unreliable{unwritten}: {'; '.join(joint.problems)}; "
            f"more --members (the runs in {folder} are kept and reused) make a better emulator",
            err=True,
        )
        raise typer.Exit(EXIT_FAILED_RUN)


def print_joint(joint: Any, out: Path | None) -> None:
    """Each freed input's prior and posterior, each measured point against its posterior-predictive interval, and the
    run's end with its interval."""
    console = stdout_console()
    table = Table("input", "prior", "posterior 5 %", "median", "95 %", title="calibration over every uncertain input")
    quantiles = joint.posterior.quantiles()
    for item in joint.posterior.inputs:
        low, middle, high = quantiles[item.key]
        add_plain_row(
            table, item.key, f"{item.shown_range()} {item.distribution}", f"{low:.3g}", f"{middle:.3g}", f"{high:.3g}"
        )
    console.print(table)
    points = Table("measured", "rise [K]", "posterior-predictive 90 % [K]", "inside?", title="the fitted points")
    for item in joint.fitted:
        add_plain_row(
            points,
            item.observable.label,
            f"{item.measured_K:.3g}",
            f"{item.quantiles[0]:.3g} to {item.quantiles[2]:.3g}",
            "yes" if item.inside else "no",
        )
    console.print(points)
    for item in joint.predictions:
        console.print(
            Text(
                f"predicted: {item.observable.label} {item.quantiles[1]:.3g} K "
                f"(90 %: {item.quantiles[0]:.3g} to {item.quantiles[2]:.3g} K)"
            )
        )
    console.print(Text(f"{joint.status}: {joint.message}"))
    if out is not None:
        console.print(
            Text(f"preset written to {out}; `shakermill uncertainty {out}` carries its posterior into any run")
        )


def announce(params: Any, free_keys: Sequence[str], chosen: bool, notes: Sequence[str]) -> None:
    """What a fit says once its inputs are all accepted: the keys it moves and, where they are the default set, which
    keys of that set it left out; then how its curves were read."""
    from shakermill.studies.calibration.calibrate import unstarted_defaults

    line = f"calibrate: fitting {', '.join(free_keys)}"
    if not chosen:
        line += f", the default free set of the {params.thermal_model!r} network for this run (--free to choose)"
        unstarted = unstarted_defaults(params)
        if unstarted:
            one = len(unstarted) == 1
            line += (
                f"; {', '.join(unstarted)} start{'s' if one else ''} at 0 and {'is' if one else 'are'} left out: "
                f"set a positive start (--set KEY=VALUE) to fit {'it' if one else 'them'}"
            )
    for said in (line, *(f"note: {note}" for note in notes)):
        typer.echo(said, err=True)


def check_preset_target(out: Path, overwrite: bool) -> None:
    """Raise ParameterError when the fitted preset cannot be written to ``out``."""
    if out.exists() and out.is_dir():
        raise ParameterError(f"out: {out} is a folder; give a .toml file name")
    if out.exists() and not overwrite:
        raise ParameterError(f"out: {out} exists; choose another --out, or add --overwrite to replace it")
    check_writable_place(out)


def write_fitted_preset(
    calibration: Calibration,
    out: Path,
    base_preset: str,
    free_keys: Sequence[str],
    targets: Mapping[str, float],
    settings: Mapping[str, Any],
) -> None:
    """Write the fitted preset TOML, saying in it which command fitted which keys to what, under which settings."""
    from shakermill.studies.calibration.fitted_preset import write_preset

    command = "shakermill calibrate " + " ".join(sys.argv[2:])
    fitted_to = [*targets, *([calibration.curve_source] if calibration.curve_source else [])]
    description = (
        f"{base_preset} with {', '.join(free_keys)} fitted to {', '.join(fitted_to)}; "
        f"{', '.join(calibration.predictions)} are predictions"
    )
    with writing(out, "the preset"):
        write_preset(
            calibration, out, base_preset=base_preset, command=command, description=description, settings=settings
        )


# A prediction whose standard error exceeds this share of its size (a temperature's rise from the start) is one
# the data do not support: shown as such, not as a number.
SUPPORTED_SHARE = 0.5


def prediction_table(calibration: Calibration) -> Table:
    """What the fitted model says of what was not fitted, each with its standard error from the keys' covariance; a
    value the data do not support (an error beyond SUPPORTED_SHARE of its size) is named so."""
    from shakermill.engines.records import kelvin_to_celsius

    start_C = kelvin_to_celsius(calibration.params.initial_temperature)
    table = Table("not fitted, predicted", "value", "std. error", title="what the fitted model predicts")
    for key, value in calibration.predictions.items():
        stderr = calibration.prediction_stderr.get(key, math.nan)
        size = abs(value - start_C) if key.endswith("_C") else abs(value)
        shown = number(value, ".4g")
        if stderr > SUPPORTED_SHARE * size:
            shown = f"not determined by the data ({shown})"
        add_plain_row(table, key, shown, number(stderr, ".2g"))
    return table


def print_calibration(
    calibration: Calibration, free_keys: Sequence[str], targets: Mapping[str, float], out: Path | None
) -> None:
    """The fitted parameters, what the fitted model predicts, the residuals of the targets and of the curve."""
    from shakermill.studies.calibration.identifiability import LOOSE_LOG_ERROR

    console = stdout_console()
    ranges = calibration.posterior_ranges
    posterior_column = ["90 % of the posterior"] if ranges else []
    table = Table(
        "parameter", "start", "fitted", "std. error", *posterior_column, "physically defensible?", title="calibration"
    )
    for key in free_keys:
        posterior = [f"{ranges[key][0]:.3g} to {ranges[key][1]:.3g}"] if ranges else []
        stderr = calibration.parameter_stderr[key]
        # A linear error beyond the value itself says the data leave the key undetermined, not how far it may move.
        shown = "undetermined" if stderr > LOOSE_LOG_ERROR * calibration.fitted[key] else number(stderr, ".3g")
        add_plain_row(
            table,
            key,
            f"{calibration.start[key]:.6g}",
            f"{calibration.fitted[key]:.6g}",
            shown,
            *posterior,
            calibration.defensible[key],
        )
    console.print(table)
    if not ranges:
        console.print(
            Text(
                "no posterior sampled (--no-posterior, or each of its thousands of evaluations would rerun "
                "the engine's mechanics): the standard errors are linear"
            )
        )
    if calibration.status == "undetermined":
        console.print(
            Text(
                "no predictions: the data do not determine the fitted keys, so they do not support what the "
                "model would say of anything else"
            )
        )
    else:
        console.print(prediction_table(calibration))
    if targets:
        residuals = Table("target", "wanted", "achieved", "residual", *[f"∂ln/∂ln {key}" for key in free_keys])
        for key, wanted in targets.items():
            sensitivities = [f"{calibration.sensitivities[key][name]:+.3f}" for name in free_keys]
            add_plain_row(
                residuals,
                key,
                f"{wanted:g}",
                f"{calibration.achieved[key]:.6g}",
                f"{100 * calibration.relative_residuals[key]:+.3f} %",
                *sensitivities,
            )
        console.print(residuals)
    if calibration.curve_rms_K is not None:
        console.print(Text(f"curve ({calibration.curve_source}): RMS residual {calibration.curve_rms_K:.3g} K"))
        for label, values in calibration.sensitivities.items():
            if label not in targets:
                console.print(
                    Text(
                        f"d {label} / d ln(key), K: "
                        + ", ".join(f"{key} {value:+.3g}" for key, value in values.items())
                    )
                )
    console.print(
        Text(f"{calibration.evaluations} model evaluations ({calibration.solver} solver): {calibration.message}")
    )
    if out is not None:
        console.print(Text(f"preset written to {out}; use it with `shakermill run {out}`"))
