"""``shakermill sweep`` and ``bifurcation``: many runs over a grid, and the scan of one key with its attractors."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.table import Table
from rich.text import Text

from shakermill.cli.common import (
    EXIT_FAILED_RUN,
    EXIT_INTERRUPTED,
    ConfigArgument,
    FullResolutionOption,
    JsonOption,
    OverwriteOption,
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
    warnings_as_lines,
    writing,
)
from shakermill.parameters.defaults import PNG_DPI
from shakermill.parameters.errors import ParameterError
from shakermill.support.limits import MAX_BIFURCATION_VALUES

if TYPE_CHECKING:
    import pandas as pd


SWEEP_PREVIEW_ROWS = 20


# (column, label, unit): the sweep's regime, then summary keys (their names checked against solvers/summary.py where
# the preview is drawn).
SWEEP_PREVIEW_COLUMNS = (
    ("regime", "regime", ""),
    ("ball_steady_C", "steady", "°C"),
    ("theta_inf_C", "θ∞ (fit)", "°C"),
    ("tau_min", "τ (fit)", "min"),
    ("impact_rate_hz", "impact rate", "Hz"),
    ("heat_power_W", "heat", "W"),
    ("mean_impact_speed_m_s", "mean speed", "m/s"),
)


def sweep(
    config: ConfigArgument = None,
    grid: Annotated[
        list[str] | None,
        typer.Option(
            "--grid",
            "-g",
            metavar="KEY=START:STOP:N",
            help="N equally spaced values of a numeric key, units allowed (amplitude=20mm:30mm:6), or names "
            "(ball_material=steel,zirconia); several grids combine as a product.",
        ),
    ] = None,
    points: Annotated[
        Path | None,
        typer.Option(
            "--points",
            metavar="FILE.csv",
            help="Explicit points: a header of keys, one point per row (combined with --grid as a product).",
        ),
    ] = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out", "-o", show_default="results/sweep-<timestamp>", help="Sweep folder; re-run into it to resume."
        ),
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", "-w", show_default="one per core", help="Local worker processes.")
    ] = None,
    scheduler: SchedulerOption = None,
    scheduler_timeout: SchedulerTimeoutOption = None,
    keep_runs: Annotated[
        bool, typer.Option("--keep-runs", help="Also write each point's run folder under DIR/runs.")
    ] = False,
    full_resolution: FullResolutionOption = False,
    json_output: JsonOption = False,
) -> None:
    """Run one simulation per point of a grid or a list; write one table (Parquet and CSV) of their summaries."""
    from shakermill.studies.sweeps.plan import check_keys_read, plan_sweep, sweep_parameters
    from shakermill.studies.sweeps.storage import is_sweep_folder
    from shakermill.studies.sweeps.sweep import SweepFailed, SweepInterrupted
    from shakermill.studies.sweeps.sweep import sweep as run_sweep

    with user_errors():
        run_config = sweep_parameters(config, preset=preset, overrides=settings or [], full_resolution=full_resolution)
        plan = plan_sweep(grid or [], points)
        check_keys_read(run_config.params, plan)
        waits = scheduler_timeout_of(scheduler, scheduler_timeout)
    target = out if out is not None else timestamped_folder("sweep")
    try:
        counter = "{task.completed}/{task.total} points · {task.fields[running]} running · {task.fields[failed]} failed"
        with (
            user_errors(),
            warnings_as_lines(),
            progress_bar("sweep", counter, len(plan.points), running=0, failed=0) as update,
        ):

            def progress(state: Any) -> None:
                update(state.done, running=state.running, failed=state.failed)

            table = run_sweep(
                run_config.params,
                plan,
                target,
                workers=workers,
                scheduler=scheduler,
                keep_runs=keep_runs,
                progress=progress,
                preset=run_config.preset,
                scheduler_timeout=waits,
                announce=lambda line: typer.echo(f"sweep: {line}", err=True),
            )
    except SweepFailed as exc:
        # Said below like any failed point, after the table's preview.
        table = exc.table
    except SweepInterrupted as exc:
        left = len(exc.table) - exc.kept
        fail(
            f"interrupted; kept {exc.kept} of {len(exc.table)} points in {target}; "
            f"re-run the same command with --out {target} to compute the other {left}",
            EXIT_INTERRUPTED,
        )
    except KeyboardInterrupt:
        # Before the sweep took its folder (or after it finished), there is nothing to resume.
        resume = f"; re-run with --out {target} to finish" if is_sweep_folder(target) else "; no point was computed"
        fail(f"interrupted{resume}", EXIT_INTERRUPTED)
    except OSError as exc:
        resume = f"; re-run with --out {target} to finish" if is_sweep_folder(target) else ""
        fail(f"{target}: cannot write the sweep ({exc.strerror or exc}){resume}")
    report_sweep(table, plan.keys, target, json_output, dict(plan.units))


def report_sweep(
    table: pd.DataFrame, keys: Sequence[str], target: Path, json_output: bool, units: Mapping[str, str]
) -> None:
    """Print the sweep's table (a preview, with the swept values in ``units`` where given, or where it is as JSON);
    exit with EXIT_FAILED_RUN if a point failed."""
    from shakermill.studies.sweeps.storage import TABLE_CSV, TABLE_PARQUET, failed_points

    failed = failed_points(table)
    if json_output:
        payload = {
            "output_dir": str(target.absolute()),
            "points": len(table),
            "failed": len(failed),
            "keys": list(keys),
            "table_parquet": str((target / TABLE_PARQUET).absolute()),
            "table_csv": str((target / TABLE_CSV).absolute()),
        }
        typer.echo(json.dumps(payload, sort_keys=True))
    else:
        stdout_console().print(sweep_preview(table, keys, target, units))
    if not failed.empty:
        first = failed.iloc[0]
        typer.echo(
            f"error: {len(failed)} of {len(table)} points failed (first: {first['point_id']}: {first['error']}); "
            f"see the error column of {target / TABLE_CSV}",
            err=True,
        )
        raise typer.Exit(EXIT_FAILED_RUN)


def sweep_preview(table: pd.DataFrame, keys: Sequence[str], target: Path, units: Mapping[str, str]) -> Table:
    """The first rows of a sweep table: swept values (in ``units`` where given, else SI), regime and the main
    results."""
    import pandas as pd

    from shakermill.solvers.summary import declared_names
    from shakermill.studies.sweeps.storage import TABLE_CSV, TABLE_PARQUET, failed_points

    regime, *summary_columns = (column for column, _, _ in SWEEP_PREVIEW_COLUMNS)
    columns = (regime, *declared_names(summary_columns))

    preview = Table(title=f"shakermill sweep: {len(table)} points, {len(failed_points(table))} failed")
    for key in keys:
        preview.add_column(key_header(key, units.get(key)), justify="right")
    for _, label, unit in SWEEP_PREVIEW_COLUMNS:
        preview.add_column(f"{label} ({unit})" if unit else label, justify="right")
    for _, row in table.head(SWEEP_PREVIEW_ROWS).iterrows():
        values = [_cell(in_unit(row[key], key, units.get(key)), ".4g") for key in keys]
        if pd.notna(row["error"]):
            results = ["failed", *([""] * (len(SWEEP_PREVIEW_COLUMNS) - 1))]
        else:
            results = [_cell(row.get(column), ".4g") for column in columns]
        add_plain_row(preview, *values, *results)
    more = len(table) - SWEEP_PREVIEW_ROWS
    preview.caption = (f"{more} more rows; " if more > 0 else "") + f"table: {target / TABLE_PARQUET} and {TABLE_CSV}"
    return preview


def key_header(key: str, unit: str | None) -> str:
    """'amplitude (mm)': a swept key with the unit its values were written in, else its SI unit."""
    from shakermill.parameters.keys import field_unit

    shown = unit or field_unit(key)
    return f"{key} ({shown})" if shown else key


def in_unit(value: Any, key: str, unit: str | None) -> Any:
    """A swept value (SI) in the ``unit`` it was written in: 5 for the 0.005 m of '5 mm'; as stored without one."""
    from shakermill.parameters.keys import field_unit
    from shakermill.parameters.units import from_si

    return from_si(value, unit, field_unit(key), key=key) if unit else value


def _cell(value: Any, spec: str) -> str:
    import pandas as pd

    if value is None or (not isinstance(value, str) and pd.isna(value)):
        return "n/a"
    return value if isinstance(value, str) else number(value, spec)


def bifurcation(
    config: ConfigArgument = None,
    grid: Annotated[
        str, typer.Option("--grid", "-g", metavar="KEY=START:STOP:N", help="The scanned key and its values.")
    ] = "omega=90:130:200",
    preset: PresetOption = None,
    settings: SettingsOption = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out", "-o", show_default="results/bifurcation-<timestamp>", help="Folder for tables and figure."
        ),
    ] = None,
    full_resolution: Annotated[
        bool, typer.Option("--full-resolution", help="Settle with the full-resolution solver (default: averaged).")
    ] = False,
    dpi: Annotated[int, typer.Option("--dpi", min=30, max=600, help="Resolution of the PNG file.")] = PNG_DPI,
    overwrite: OverwriteOption = False,
) -> None:
    """Scan one key, record the impact phases of the settled motion, classify each run and draw the bifurcation
    diagram."""
    from shakermill.io.runs import check_target, write_folder
    from shakermill.parameters.engine_keys import reader_of
    from shakermill.studies.sweeps.bifurcation import BIFURCATION_FIGURE, BIFURCATION_FOLDER, write_bifurcation
    from shakermill.studies.sweeps.bifurcation import bifurcation as regime_scan
    from shakermill.studies.sweeps.plan import grid_unit, parse_grid, sweep_parameters
    from shakermill.views.figures.common import plot_figures
    from shakermill.views.figures.sweeps import bifurcation_figure, sweep_context

    with user_errors():
        run_config = sweep_parameters(config, preset=preset, overrides=settings or [], full_resolution=full_resolution)
        _require_attractor_starts(run_config.params.engine)
        key, values = parse_grid(grid, most=MAX_BIFURCATION_VALUES)
        unread = reader_of(run_config.params).unread_problem([key], "scanned")
        if unread is not None:
            fail(unread)
        # Checked before the scan: a value out of range would otherwise stop it midway.
        for value in (values[0], values[-1]):
            run_config.params.replace(**{key: float(value)})
    target = out if out is not None else timestamped_folder("bifurcation")
    with user_errors():
        check_target(target, overwrite=overwrite, kind=BIFURCATION_FOLDER)
    with (
        nothing_written_when_interrupted("a scan is quick to repeat"),
        nothing_written_when_a_run_is_stopped("the scan"),
        progress_bar("scanning", "{task.completed}/{task.total} runs", len(values)) as update,
    ):
        scan = regime_scan(
            run_config.params, [float(value) for value in values], key, progress=lambda done, _total: update(done)
        )

    def fill(folder: Path) -> None:
        write_bifurcation(scan, folder)
        context = sweep_context({"preset": run_config.preset, "base": run_config.params.model_dump()}, (key,))
        figure = bifurcation_figure(scan.phases, scan.attractors, key, context=context)
        plot_figures({BIFURCATION_FIGURE: figure}, folder, dpi=dpi)

    with user_errors(), writing(target, "the results"):
        written = write_folder(target, fill, overwrite=overwrite, kind=BIFURCATION_FOLDER)
    counts = scan.regimes["regime"].value_counts()
    unit = grid_unit(grid)
    table = Table("regime", "runs", key_header(key, unit), title=f"bifurcation scan over {key}: {len(values)} runs")
    for label, count in counts.items():
        inside = in_unit(scan.regimes.loc[scan.regimes["regime"] == label, key], key, unit)
        add_plain_row(table, str(label), str(count), f"{inside.min():.5g} – {inside.max():.5g}")
    console = stdout_console()
    console.print(table)
    console.print(coexisting_attractors_table(scan.attractors, key, run_config.params.attractor_starts, unit))
    console.print(Text(f"{len(list(written.iterdir()))} files written to {target}"))


def _require_attractor_starts(engine: str) -> None:
    """A scan settles one ball started on the axis: refused for an engine whose runs do not start so."""
    from shakermill.engines.registry import describe, engine_names

    if not describe(engine).attractor_starts:
        allowed = [repr(name) for name in engine_names() if describe(name).attractor_starts]
        named = f"= {allowed[0]}" if len(allowed) == 1 else f"one of {', '.join(allowed)}"
        raise ParameterError(
            f"engine: bifurcation settles the one ball's attractors; allowed engine {named} here (got {engine!r})"
        )


COEXISTING_PREVIEW_ROWS = 20


def coexisting_attractors_table(attractors: pd.DataFrame, key: str, starts: int, unit: str) -> Table | Text:
    """The values with more than one attractor: each attractor's regime, basin fraction and heat power; the values of
    ``key`` in the ``unit`` its grid was written in, else SI."""
    counts = attractors.groupby(key, sort=False)["attractor"].transform("size")
    several = attractors[counts > 1]
    values = several[key].unique()
    if not len(values):
        return Text(
            f"coexisting attractors: none; all {starts} starts reach one attractor at each of "
            f"{attractors[key].nunique()} values"
        )
    table = Table(
        key_header(key, unit),
        "attractor",
        "regime",
        "basin fraction",
        "heat power (W)",
        "impact rate (Hz)",
        title=(
            f"coexisting attractors ({starts} starts per value): at {len(values)} of {attractors[key].nunique()} values"
        ),
    )
    for _, row in several[several[key].isin(values[:COEXISTING_PREVIEW_ROWS])].iterrows():
        add_plain_row(
            table,
            f"{in_unit(row[key], key, unit):.5g}",
            str(row["attractor"]),
            str(row["regime"]),
            f"{row['basin_fraction']:.2f}",
            f"{row['heat_power_W']:.4g}",
            f"{row['impact_rate_hz']:.4g}",
        )
    more = len(values) - COEXISTING_PREVIEW_ROWS
    table.caption = (f"{more} more values; " if more > 0 else "") + "all attractors: bifurcation_attractors.csv"
    return table
