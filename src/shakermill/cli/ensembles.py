"""``shakermill uncertainty``: an answer over its assumed inputs (MODEL.md §14.1)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from shakermill.cli.common import (
    EXIT_INTERRUPTED,
    ConfigArgument,
    FullResolutionOption,
    JsonOption,
    PresetOption,
    SchedulerOption,
    SchedulerTimeoutOption,
    SettingsOption,
    add_plain_row,
    echo_notes,
    fail,
    progress_bar,
    scheduler_timeout_of,
    stdout_console,
    timestamped_folder,
    user_errors,
    warnings_as_lines,
)

if TYPE_CHECKING:
    from shakermill.studies.ensembles.ensemble import Ensemble

SUMMARY = "summary.json"
REPORT = "report.html"


def uncertainty(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    assume: Annotated[
        list[str] | None,
        typer.Option(
            "--assume",
            metavar="KEY=LOW:HIGH[:DIST]",
            help="Your own range of an input (SI units; DIST uniform or log-uniform), replacing the preset's "
            "or adding one.",
        ),
    ] = None,
    vary: Annotated[
        list[str] | None,
        typer.Option("--vary", metavar="KEY", help="Vary only these inputs (repeat it); the others keep their values."),
    ] = None,
    members: Annotated[int, typer.Option("--members", "-n", help="Members of the design, a power of two.")] = 64,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            show_default="results/uncertainty-<timestamp>",
            help="Ensemble folder; re-run into it to resume.",
        ),
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", "-w", show_default="one per core", help="Local worker processes.")
    ] = None,
    scheduler: SchedulerOption = None,
    scheduler_timeout: SchedulerTimeoutOption = None,
    full_resolution: FullResolutionOption = False,
    json_output: JsonOption = False,
) -> None:
    """Run a quasi-random ensemble over the assumed inputs; print each headline's 5/50/95 % points, the inputs that
    decide it (Sobol' indices) and the motion regimes found."""
    from shakermill.io.runs import ENSEMBLE_KIND, KIND_KEY
    from shakermill.parameters.config import config_preset
    from shakermill.studies.ensembles.ensemble import check_members, ensemble_inputs, run_ensemble
    from shakermill.studies.sweeps.plan import sweep_parameters
    from shakermill.studies.sweeps.sweep import SweepFailed, SweepInterrupted
    from shakermill.support.atomic import write_text_atomically
    from shakermill.views.ensemble_page import save_ensemble_page

    with user_errors():
        check_members(members)
        run_config = sweep_parameters(config, preset=preset, overrides=settings or [], full_resolution=full_resolution)
        inputs, posterior, notes = ensemble_inputs(
            config_preset(run_config), run_config.params, assume or [], vary or [], run_config.explicit
        )
        waits = scheduler_timeout_of(scheduler, scheduler_timeout)
    target = out if out is not None else timestamped_folder("uncertainty")
    try:
        counter = (
            "{task.completed}/{task.total} members · {task.fields[running]} running · {task.fields[failed]} failed"
        )
        # A member takes seconds to minutes: piped, each one finished is a line.
        with (
            user_errors(),
            warnings_as_lines(),
            progress_bar("uncertainty", counter, members, lines_when_piped=True, running=0, failed=0) as update,
        ):
            ensemble = run_ensemble(
                run_config.params,
                inputs,
                target,
                members,
                workers=workers,
                scheduler=scheduler,
                scheduler_timeout=waits,
                preset=run_config.preset,
                posterior=posterior,
                announce=lambda line: typer.echo(f"uncertainty: {line}", err=True),
                # Said once every check has passed: a refused command says one line.
                on_start=lambda: echo_notes(notes),
                progress=lambda state: update(state.done, running=state.running, failed=state.failed),
            )
    except SweepFailed as exc:
        fail(f"every member failed (first: {exc.table['error'].dropna().iloc[0]}); see {target}", 1)
    except (SweepInterrupted, KeyboardInterrupt):
        fail(
            f"interrupted; the members finished are kept in {target}; re-run the same command with --out {target} "
            "to compute the others",
            EXIT_INTERRUPTED,
        )
    title = f"{run_config.preset}: what the answer hangs on"
    payload = {
        KIND_KEY: ENSEMBLE_KIND,
        "preset": run_config.preset,
        "output_dir": str(target.absolute()),
        **ensemble.as_dict(),
    }
    write_text_atomically(target / SUMMARY, json.dumps(payload, indent=1, allow_nan=False) + "\n")
    save_ensemble_page(ensemble, title, target / REPORT)
    if json_output:
        typer.echo(json.dumps(payload, allow_nan=False))
        return
    print_ensemble(ensemble, title, target)


def print_ensemble(ensemble: Ensemble, title: str, target: Path) -> None:
    from shakermill.views.ensemble_page import (
        HEADLINE_HEADERS,
        NO_REGIMES,
        REGIME_HEADERS,
        REGIME_NOTE,
        headline_rows,
        regime_rows,
    )

    console = stdout_console()
    tables: list[tuple[tuple[str, ...], list[tuple[str, ...]], str]] = [
        (HEADLINE_HEADERS, headline_rows(ensemble), title)
    ]
    if ensemble.regimes:
        tables.append((REGIME_HEADERS, regime_rows(ensemble), f"regimes ({REGIME_NOTE})"))
    for headers, rows, caption in tables:
        shown = Table(*headers, title=caption)
        for row in rows:
            add_plain_row(shown, *row)
        console.print(shown)
    if not ensemble.regimes:
        console.print(NO_REGIMES)
    failed = f" ({ensemble.failed} failed, left out)" if ensemble.failed else ""
    console.print(f"{ensemble.members} members{failed}; {target / SUMMARY}, {target / REPORT}, members in {target}")
