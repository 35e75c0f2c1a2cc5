"""The ``shakermill`` command line: parse, call the library, write files. No physics here.

Exit codes: 0 success; 1 the run ended with a failed status: the integrator
stopped early, the run used up its budget (``max_wall_time``, ``max_steps``) or
its results cannot be trusted (the run folder is still written); 2 bad input
(one ``error: ...`` line on stderr, no traceback); 130 interrupted by the user
(partial results are written).

A progress bar is drawn on stderr once a run has taken a second, and only when
stderr is a terminal, so pipes and logs stay clean.
"""

from __future__ import annotations

import gc
import json
import math
import sys
import time
from contextlib import contextmanager
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Callable, Iterator, Mapping, NoReturn, Sequence

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text
from typer.core import TyperGroup

# Only light modules here: `shakermill --help` and the listing commands must not wait for NumPy, Numba,
# pandas, xarray, SciPy or Matplotlib. Each command imports what it uses.
from shakermill.engines.budget import BudgetExceeded
from shakermill.parameters.config import load_config
from shakermill.parameters.defaults import (
    ANIMATION_FILE,
    ANIMATION_FRAMES,
    DEFAULT_FREE,
    DEFAULT_SCHEDULER_TIMEOUT_S,
    DEM_DEFAULT_FREE,
    HIT_SPEED,
    MOST_ANIMATION_FRAMES,
    PNG_DPI,
    REPORT_FILE,
)
from shakermill.parameters.schema import (
    DEFAULT_PRESET,
    FIELD_NAMES,
    PRESETS,
    ParameterError,
    allowed_range,
    field_description,
    field_unit,
    preset_values,
    unit_slip_warnings,
)
from shakermill.studies.validation import EXPERIMENT, TABLE5, TARGET_KEYS, Curve
from shakermill.studies.validation import validate as run_validation
from shakermill.support.atomic import StorageError, check_writable_place
from shakermill.support.limits import MAX_BIFURCATION_VALUES
from shakermill.support.version import __version__

if TYPE_CHECKING:
    import pandas as pd

    from shakermill.io.runs import RunData
    from shakermill.parameters.schema import Parameters
    from shakermill.solvers.result import Result
    from shakermill.studies.calibrate import Calibration

EXIT_FAILED_RUN = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130
# A run's or a fit's progress bar appears once it has taken this long (s): quick ones end without a flicker.
PROGRESS_DELAY_S = 1.0
FIGURES_FOLDER = "figures"
PIPED_TABLE_WIDTH = 160
DEFAULT_RESULTS_FOLDER = Path("results")

class OneLineUsageErrors(TyperGroup):
    """typer's command group, with its own usage errors (an unknown option or command, a value of the
    wrong type or outside an option's range) as one ``error:`` line and exit code 2, like every other
    bad input: typer draws them in a box over several lines, which scripts and logs read badly."""

    def main(self, args: Sequence[str] | None = None, *rest: Any, standalone_mode: bool = True, **extra: Any) -> Any:
        arguments = sys.argv[1:] if args is None else list(args)
        if not standalone_mode or not arguments:  # no arguments: typer shows the help, as it should
            return super().main(args, *rest, standalone_mode=standalone_mode, **extra)
        try:
            outcome = super().main(arguments, *rest, standalone_mode=False, **extra)
        except typer.Abort:
            # Outside Click's handling now: typer.Exit (what _fail raises) would not be caught.
            _echo_error("aborted")
            sys.exit(EXIT_FAILED_RUN)
        except Exception as exc:
            # Click's usage errors, told by what they carry: typer vendors Click and exports none of its classes.
            if getattr(exc, "exit_code", None) != EXIT_USAGE or not hasattr(exc, "format_message"):
                raise
            _echo_error(exc.format_message())
            sys.exit(EXIT_USAGE)
        sys.exit(outcome if isinstance(outcome, int) else 0)


app = typer.Typer(
    cls=OneLineUsageErrors,
    name="shakermill",
    help="Simulate a high-energy shaker mill (SPEX 8000M type): ball motion, impacts and temperatures.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def main() -> None:
    """Entry point of the ``shakermill`` console script."""
    try:
        app()
    finally:
        # Everything is written by now. Tearing down NumPy, SciPy, Numba and pandas at exit collects
        # every object they made, about 0.4 s of a short run; frozen objects are left to the OS instead.
        gc.freeze()


def _version(show: bool) -> None:
    if show:
        typer.echo(f"shakermill {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
) -> None:
    """Simulate a high-energy shaker mill (SPEX 8000M type): ball motion, impacts and temperatures."""


def _stdout_console() -> Console:
    # Piped into a file, tables are read later at any width; 80 columns would wrap every source citation.
    console = Console()
    return console if console.is_terminal else Console(width=PIPED_TABLE_WIDTH)


def _add_plain_row(table: Table, *cells: str) -> None:
    # Plain text: values such as "[0, 1]" or "[start ≥ 0, ...]" would otherwise be parsed as rich markup.
    table.add_row(*(Text(cell) for cell in cells))


def _echo_error(message: str) -> None:
    # typer.echo, not rich: rich would wrap a long message over several lines and read "[...]" as markup.
    typer.echo(f"error: {' '.join(message.splitlines())}", err=True)


def _fail(message: str, code: int = EXIT_USAGE) -> NoReturn:
    _echo_error(message)
    raise typer.Exit(code)


@contextmanager
def _user_errors() -> Iterator[None]:
    """Turn bad input into one ``error:`` line and exit code 2."""
    try:
        yield
    except (ParameterError, StorageError) as exc:
        _fail(str(exc))


@contextmanager
def _nothing_written_when_interrupted(what: str) -> Iterator[None]:
    """Ctrl-C before anything was written: one line and exit code 130."""
    try:
        yield
    except KeyboardInterrupt:
        _fail(f"interrupted; nothing was written ({what})", EXIT_INTERRUPTED)


@contextmanager
def _writing(target: Path, what: str) -> Iterator[None]:
    """A write that fails (a full or read-only disk, a path under a file): one ``error:`` line and exit code 2."""
    try:
        yield
    except OSError as exc:
        _fail(f"{target}: cannot write {what} ({exc.strerror or exc})")


@contextmanager
def _nothing_written_when_a_run_is_stopped(what: str) -> Iterator[None]:
    """A run of a scan or fit used up its budget: one line and exit code 1, as a failed run."""
    try:
        yield
    except BudgetExceeded as exc:
        _fail(f"{what} stopped, nothing was written: {exc}", EXIT_FAILED_RUN)


# Options shared by several commands, declared once.
ConfigArgument = Annotated[
    Path | None,
    typer.Argument(metavar="CONFIG", help="TOML file with canonical keys (and optionally preset = NAME)."),
]
PresetOption = Annotated[
    str | None, typer.Option("--preset", "-p", show_default=DEFAULT_PRESET, help="Preset to start from.")
]
SettingsOption = Annotated[
    list[str] | None,
    typer.Option("--set", "-s", metavar="KEY=VALUE", help="Override one key, units allowed: --set ball_radius='5 mm'."),
]
JsonOption = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout, nothing else.")]
OverwriteOption = Annotated[
    bool, typer.Option("--overwrite", help="Replace what --out holds (never a folder that shakermill did not write).")
]
FullResolutionOption = Annotated[
    bool, typer.Option("--full-resolution", help="Use the full-resolution solver (default: averaged).")
]


@app.command()
def run(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", show_default="results/run-<timestamp>", help="Run folder to write."),
    ] = None,
    json_output: JsonOption = False,
    no_plots: Annotated[bool, typer.Option("--no-plots", help="Do not draw the figures.")] = False,
    overwrite: OverwriteOption = False,
) -> None:
    """Run one simulation and write its run folder (data, summary, configuration, figures)."""
    from shakermill.io.runs import check_target, to_jsonable
    from shakermill.solvers.result import INTERRUPTED

    overrides = settings or []
    with _user_errors():
        run_config = load_config(config, preset=preset, overrides=overrides)
        target = out if out is not None else timestamped_folder("run")
        check_target(target, overwrite=overwrite)
    # Unit slips are said before a possibly long run, the rest once it is known.
    said_first = unit_slip_warnings(run_config.params)
    echo_warnings(said_first)
    # A full-resolution run keeps what it computed when interrupted; the averaged solver has nothing to keep.
    with _nothing_written_when_interrupted("the averaged solver keeps no part of a run"):
        result = simulate_with_progress(run_config.params)
    if result.status != INTERRUPTED:
        # An interrupted run is short by choice: its warnings (run length, steady state) stay in summary.json.
        echo_warnings([line for line in result.warnings if line not in said_first])
    provenance = {"command": "shakermill run", "config_file": str(config) if config else None, "overrides": overrides}
    target = _write(result, target, run_config.preset, provenance, with_figures=not no_plots, overwrite=overwrite)
    if json_output:
        summary = to_jsonable({**result.summary, "output_dir": str(target)})
        typer.echo(json.dumps(summary, sort_keys=True, allow_nan=False))
    else:
        _stdout_console().print(summary_table(result, target))
    _exit_for_status(result, target)


def echo_warnings(warnings: Sequence[str]) -> None:
    """One ``warning: ...`` line on stderr each (stdout stays clean for ``--json``)."""
    for warning in warnings:
        typer.echo(f"warning: {' '.join(warning.splitlines())}", err=True)


@contextmanager
def _warnings_as_lines() -> Iterator[None]:
    """The library's warnings (an unreadable point file) as ``warning: ...`` lines, like a run's own."""
    import warnings

    with warnings.catch_warnings():
        warnings.showwarning = lambda message, *_: echo_warnings([str(message)])
        yield


def timestamped_folder(kind: str) -> Path:
    """``results/<kind>-<local timestamp>``, with a counter if one started in the same second."""
    stem = f"{kind}-{datetime.now():%Y%m%d-%H%M%S}"
    candidate = DEFAULT_RESULTS_FOLDER / stem
    counter = 1
    while candidate.exists():
        candidate = DEFAULT_RESULTS_FOLDER / f"{stem}-{counter}"
        counter += 1
    return candidate


def simulate_with_progress(params: Parameters) -> Result:
    """``simulate``, with a transient progress bar on stderr once the run takes a while, when stderr is a terminal.

    The bar counts the simulated seconds of each phase in turn: the averaged solver's mechanics (out of
    averaging_max_time), the whole duration, then its attractor probe (all starts together).
    """
    from shakermill.solvers.simulate import simulate

    counter = "{task.completed:.5g}/{task.total:.5g} s simulated"
    with _progress_bar("simulating", counter, params.duration, delay_s=PROGRESS_DELAY_S) as update:
        return simulate(params, progress=None if update is None else lambda done, total: update(done, total=total))


@contextmanager
def _progress_bar(
    verb: str, counter: str, total: float | None, delay_s: float = 0.0, **fields: Any
) -> Iterator[Callable[..., None] | None]:
    """``update(completed, **fields)`` of a transient progress bar with an ETA on stderr; None when stderr is not a terminal.

    The bar shows from the first update ``delay_s`` seconds after the start, or at once without a delay.
    Pipes and logs stay clean: a bar redrawn many times a second would fill them.
    """
    console = Console(stderr=True)
    if not console.is_terminal:
        yield None
        return
    columns = (TextColumn(verb), BarColumn(), TextColumn(counter), TimeRemainingColumn())
    bar = Progress(*columns, console=console, transient=True)
    task = bar.add_task(verb, total=total, **fields)
    shown_from = time.monotonic() + delay_s

    def show_when_due() -> None:
        if not bar.live.is_started and time.monotonic() >= shown_from:
            bar.start()

    def update(completed: float, **updates: Any) -> None:
        bar.update(task, completed=completed, **updates)
        show_when_due()

    show_when_due()
    try:
        yield update
    finally:
        if bar.live.is_started:
            bar.stop()


def _write(
    result: Result, target: Path, preset: str, provenance: dict[str, Any], *, with_figures: bool, overwrite: bool
) -> Path:
    """Write the run folder (with figures unless told not to); return its absolute path."""
    from shakermill.io.runs import write_run

    def add_figures(folder: Path) -> None:
        from shakermill.views.figures import plot_run

        plot_run(result, folder / FIGURES_FOLDER)

    try:
        with _user_errors(), _writing(target, "the run folder"):
            return write_run(
                result, target, preset=preset, extra_provenance=provenance, add_files=add_figures if with_figures else None,
                overwrite=overwrite,
            )
    except KeyboardInterrupt:
        _fail(f"interrupted while writing {target}; no partial folder was left there", EXIT_INTERRUPTED)


def _exit_for_status(result: Result, target: Path) -> None:
    from shakermill.solvers.result import INTERRUPTED

    if result.status == INTERRUPTED:
        typer.echo(f"interrupted: {result.message} Partial results in {target}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED)
    if not result.success:
        typer.echo(f"error: {result.message} Results so far in {target}", err=True)
        raise typer.Exit(EXIT_FAILED_RUN)


def _number(value: Any, spec: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    return format(value, spec)


def _radii_mm(params: Parameters) -> str:
    """The ball radius in mm, or each ball's where they differ."""
    radii = sorted(set(params.ball_values("ball_radius")))
    return ", ".join(_number(radius * 1e3, ".4g") for radius in radii)


def summary_table(result: Result, target: Path) -> Table:
    """The human summary of a run: fitted and final temperatures, impacts, power, numerics."""
    s = result.summary
    table = Table(title="shakermill run", show_header=True)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    table.add_column("unit")
    fit_window = f"0–{_number(s['simulated_s'] / 60.0, '.4g')} min"
    # The 'dem' engine's ball temperatures, steady state and fit are the balls' means; its own rows say more.
    ball = "balls' mean" if s.get("engine") == "dem" else "ball"
    rows = [
        ("status", s["message"] if not result.success else "ok", ""),
        ("solver", s["solver"], ""),
        ("drive ω", f"{_number(s['omega_rad_s'], '.4g')} rad/s = {_number(s['omega_hz'], '.4g')} Hz = {_number(s['omega_rpm'], '.0f')}", "rpm"),
        ("amplitude; ball radius", f"{_number(s['amplitude_mm'], '.4g')}; {_radii_mm(result.params)}", "mm"),
        ("ambient; initial temperature", f"{_number(s['ambient_temperature_C'], '.4g')}; {_number(s['initial_temperature_C'], '.4g')}", "°C"),
        ("simulated time", _number(s["simulated_s"], ".6g"), "s"),
        (f"{ball} steady state", _number(s["ball_steady_C"], ".2f"), "°C"),
        ("vial; air steady state", f"{_number(s['vial_steady_C'], '.2f')}; {_number(s['air_steady_C'], '.2f')}", "°C"),
        ("slowest time constant", _number(s["slowest_time_constant_min"], ".1f"), "min"),
        (f"{ball} θ∞ of the exponential fitted over {fit_window}", _number(s["theta_inf_C"], ".2f"), "°C"),
        ("τ of that fit", _number(s["tau_min"], ".2f"), "min"),
        ("initial heating rate θ̇₀ of that fit", _number(s["rate0_C_per_min"], ".3f"), "°C/min"),
        (f"{ball} at the end", _number(s["ball_C"], ".2f"), "°C"),
        ("vial at the end", _number(s["vial_C"], ".2f"), "°C"),
        ("air at the end", _number(s["air_C"], ".2f"), "°C"),
        ("vial/ball increment ratio", _number(s["vial_ball_ratio"], ".3f"), ""),
        *several_ball_rows(s),
        ("impacts", _number(s["impacts"], "d"), ""),
        ("impact rate", _number(s["impact_rate_hz"], ".2f"), "Hz"),
        ("mean impact speed", _number(s["mean_impact_speed_m_s"], ".3f"), "m/s"),
        (f"hits ≥ {HIT_SPEED:g} m/s: rate; mean speed", f"{_number(s['hit_rate_hz'], '.2f')} Hz; {_number(s['mean_hit_speed_m_s'], '.3f')}", "m/s"),
        ("heat generated", _number(s["heat_power_W"], ".3f"), "W"),
        ("steps (rejected)", f"{s['steps']} ({s['rejected_steps']})", ""),
        ("wall time", _number(s["wall_time_s"], ".2f"), "s"),
        ("energy audit residual", _number(s["energy_audit_residual"], ".2e"), "relative"),
        ("output folder", str(target), ""),
    ]
    for row in rows:
        _add_plain_row(table, *row)
    return table


# Up to this many balls the run table gives each ball's temperature; beyond, the coolest and the hottest.
EACH_BALL_UP_TO = 6


def several_ball_rows(s: Mapping[str, Any]) -> list[tuple[str, str, str]]:
    """The run table's rows of the 'dem' engine (none for 1-D): balls, their temperatures at the end and
    steady states, impacts on the walls and between balls, heat by dissipation channel."""
    if s.get("engine") != "dem":
        return []
    from shakermill.engines.dem.model import CHANNELS

    rows = [("engine; balls; fill of the vial", f"dem; {s['n_balls']}; {_number(s.get('fill_fraction'), '.3f')}", "")]
    for key, what in (("ball_temperatures_C", "at the end"), ("balls_steady_C", "steady state")):
        values = [value for value in s.get(key) or () if value is not None]
        if not values:
            continue
        if len(values) <= EACH_BALL_UP_TO:
            rows.append((f"each ball {what} (ball 0; 1; …)", "; ".join(_number(value, ".2f") for value in values), "°C"))
        else:
            rows.append((f"balls {what}: coolest; hottest", f"{_number(min(values), '.2f')}; {_number(max(values), '.2f')}", "°C"))
    rows.append(("impacts on the walls; between balls", f"{s['wall_impacts']}; {s['ball_ball_impacts']}", ""))
    heat = [s.get(f"heat_{channel}_W") for channel in CHANNELS]
    if any(value is not None for value in heat):
        # The averaged solver has no split by channel: its heat comes from the thermal network's means.
        rows.append((f"heat by channel: {'; '.join(CHANNELS)}", "; ".join(_number(value, ".3g") for value in heat), "W"))
    return rows


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


@app.command("compare-solvers")
def compare_solvers(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    json_output: JsonOption = False,
) -> None:
    """Run the same configuration with the full and the averaged solver; print both, the differences and the speed ratio."""
    from shakermill.io.runs import to_jsonable

    with _user_errors():
        params = load_config(config, preset=preset, overrides=settings or []).params
        # The full solver has limits of its own (the drive periods it keeps every impact of).
        full_params, averaged_params = params.replace(solver="full"), params.replace(solver="averaged")
    with _nothing_written_when_interrupted("compare-solvers writes no files"):
        full = _uninterrupted(simulate_with_progress(full_params))
        averaged = _uninterrupted(simulate_with_progress(averaged_params))
    rows = [
        (label, unit, full.summary[key], averaged.summary[key], averaged.summary[key] - full.summary[key])
        for key, label, unit in COMPARED_QUANTITIES
    ]
    speed_ratio = full.wall_time / averaged.wall_time if averaged.wall_time > 0 else math.inf
    if json_output:
        payload = {
            "full": {key: full.summary[key] for key, _, _ in COMPARED_QUANTITIES},
            "averaged": {key: averaged.summary[key] for key, _, _ in COMPARED_QUANTITIES},
            "averaged_solver_used": averaged.solver,
            "averaged_message": averaged.message,
            "speed_ratio": speed_ratio,
        }
        typer.echo(json.dumps(to_jsonable(payload), sort_keys=True, allow_nan=False))
    else:
        table = Table("quantity", "full", "averaged", "averaged − full", "unit", title="full vs averaged solver")
        for label, unit, full_value, averaged_value, difference in rows:
            _add_plain_row(table, label, _number(full_value, ".4g"), _number(averaged_value, ".4g"), _number(difference, "+.3g"), unit)
        console = _stdout_console()
        console.print(table)
        console.print(Text(f"averaged solver: {averaged.message}"))
        console.print(Text(f"speed ratio full/averaged: {speed_ratio:.0f}x"))
    for result in (full, averaged):
        if not result.success:
            typer.echo(f"error: the {result.params.solver} run did not finish cleanly: {result.message}", err=True)
            raise typer.Exit(EXIT_FAILED_RUN)


def _uninterrupted(result: Result) -> Result:
    """``result``, unless Ctrl-C cut it short: a comparison with part of a run means nothing."""
    from shakermill.solvers.result import INTERRUPTED

    if result.status == INTERRUPTED:
        raise KeyboardInterrupt
    return result


# The vial's size plays no part in a lone impact, only its material: a vial of the largest usual size (0.5 m) lets
# any ball of the allowed radii be set without resizing the vial too. The user's own settings come after.
IMPACT_VIAL = ["vial_length=0.5 m", "vial_diameter=0.5 m"]
IMPACT_ROWS = (
    ("normal_restitution", "normal restitution", 1.0, ".6f", ""),
    ("tangential_velocity_out_m_s", "tangential velocity of the centre after", 1.0, ".6g", "m/s"),
    ("angular_velocity_rad_s", "angular velocity after (about n × t)", 1.0, ".6g", "rad/s"),
    ("contact_time_s", "contact time", 1e6, ".5g", "µs"),
    ("max_overlap_m", "largest overlap", 1e6, ".5g", "µm"),
    ("max_normal_force_N", "largest normal force", 1.0, ".5g", "N"),
    ("dissipated_J", "dissipated", 1.0, ".4g", "J"),
    ("dissipated_normal_J", "  by normal damping", 1.0, ".4g", "J"),
    ("dissipated_tangential_J", "  by tangential damping", 1.0, ".4g", "J"),
    ("dissipated_sliding_J", "  by sliding", 1.0, ".4g", "J"),
    ("dissipated_rolling_J", "  by rolling resistance", 1.0, ".4g", "J"),
)


@app.command()
def impact(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    speed: Annotated[
        float, typer.Option("--speed", help="Speed of the incoming ball relative to its target, m/s.")
    ] = ...,
    angle: Annotated[
        float, typer.Option("--angle", help="Angle between the incoming velocity and the normal, degrees (0: head-on).")
    ] = 0.0,
    target: Annotated[
        str, typer.Option("--target", help="'wall': the vial's end face at rest; 'ball': an identical ball at rest.")
    ] = "wall",
    spin: Annotated[
        float,
        typer.Option(
            "--spin", help="Angular velocity of the incoming ball about the normal to the plane of incidence, rad/s."
        ),
    ] = 0.0,
    json_output: JsonOption = False,
) -> None:
    """One impact on its own, through the 'dem' engine: restitution, rebound, spin, contact time, peak force and
    the dissipated energy by channel. Materials, restitution, friction and the contact step come from --set."""
    from shakermill.studies.impact import single_impact

    with _user_errors(), _nothing_written_when_interrupted("impact writes no files"):
        params = load_config(config, preset=preset, overrides=[*IMPACT_VIAL, *(settings or [])]).params
        echo_warnings(unit_slip_warnings(params))
        outcome = single_impact(params, speed, angle, target, spin).as_dict()
    if json_output:
        typer.echo(json.dumps(outcome, allow_nan=False))
        return
    table = Table("quantity", "value", "unit", title=f"one impact: {speed:g} m/s at {angle:g}° on a {target} at rest")
    for key, label, scale, spec, unit in IMPACT_ROWS:
        _add_plain_row(table, label, _number(scale * outcome[key], spec), unit)
    _stdout_console().print(table)


@app.command()
def presets(
    name: Annotated[str | None, typer.Argument(help="Show every value of this preset with its source.")] = None,
) -> None:
    """List the presets, or show one preset's values, units and sources."""
    console = _stdout_console()
    if name is None:
        table = Table("preset", "description", title="presets")
        for preset in PRESETS.values():
            marker = " (default)" if preset.name == DEFAULT_PRESET else ""
            _add_plain_row(table, preset.name + marker, preset.description)
        console.print(table)
        return
    with _user_errors():
        preset_values(name)  # validates the name with the library's one-line message
    preset = PRESETS[name]
    table = Table("key", "value", "source", title=f"{preset.name}: {preset.description}")
    for key, cited in preset.values.items():
        _add_plain_row(table, key, format_value(key, cited.value), cited.source)
    console.print(table)


# The library's table: property, header with its unit, scale from SI.
MATERIAL_COLUMNS = (
    ("density", "ρ (kg/m³)", 1.0),
    ("youngs_modulus", "E (GPa)", 1e-9),
    ("poisson_ratio", "ν", 1.0),
    ("heat_capacity", "c (J/(kg·K))", 1.0),
    ("conductivity", "k (W/(m·K))", 1.0),
    ("restitution", "e (range, not applied)", 1.0),
    ("friction", "μ (range, not applied)", 1.0),
)


@app.command("materials")
def materials_command(
    name: Annotated[str | None, typer.Argument(help="Show every value of this material with its unit and source.")] = None,
    json_output: JsonOption = False,
) -> None:
    """List the materials library, or show one material's values, units and sources. Select one with
    --set ball_material=NAME (or vial_material, or ball_materials per ball); its restitution and friction are
    shown, never applied."""
    from shakermill.parameters.materials import UnknownMaterial, library, material

    try:
        chosen = [material(name)] if name is not None else list(library().values())
    except UnknownMaterial as exc:
        _fail(str(exc))
    if json_output:
        described = [found.as_dict() for found in chosen]
        typer.echo(json.dumps(described[0] if name is not None else {"materials": described}, allow_nan=False))
        return
    _stdout_console().print(material_table(chosen[0]) if name is not None else materials_table(chosen))


def _material_value(value: float | tuple[float, float], scale: float = 1.0) -> str:
    return f"{value[0]:g}-{value[1]:g}" if isinstance(value, tuple) else f"{value * scale:g}"


def materials_table(chosen: Sequence[Any]) -> Table:
    table = Table("material", *(header for _, header, _ in MATERIAL_COLUMNS), title="materials (room temperature)")
    for found in chosen:
        _add_plain_row(table, found.name, *(_material_value(getattr(found, key).value, scale) for key, _, scale in MATERIAL_COLUMNS))
    table.caption = "`shakermill materials NAME`: every value's source; restitution and friction are shown, not applied"
    return table


def material_table(found: Any) -> Table:
    from shakermill.parameters.materials import PROPERTIES

    table = Table("property", "value", "unit (SI)", "source", title=f"{found.name}: {found.description}")
    for key, sourced in found.properties().items():
        _add_plain_row(table, PROPERTIES[key][1], _material_value(sourced.value), sourced.unit, sourced.source)
    aliases = f"aliases: {', '.join(found.aliases)}; " if found.aliases else ""
    table.caption = f"{aliases}select with --set ball_material={found.name} (or vial_material, ball_materials)"
    return table


@app.command()
def keys() -> None:
    """List the canonical parameter keys with unit, allowed values, default and description."""
    defaults = preset_values(DEFAULT_PRESET)
    table = Table("key", "allowed (SI)", f"default ({DEFAULT_PRESET})", "description", title="parameter keys")
    for key in FIELD_NAMES:
        default = format_value(key, defaults[key]) if key in defaults else ""
        _add_plain_row(table, key, allowed_range(key), default, field_description(key))
    _stdout_console().print(table)


def _load_run_or_fail(folder: Path) -> RunData:
    """The run folder at ``folder``, or one ``error:`` line and exit code 2."""
    from shakermill.io.runs import load_run

    with _user_errors():
        return load_run(folder)


@app.command()
def plot(
    folder: Annotated[
        Path, typer.Argument(metavar="RUN_DIR|SWEEP_DIR", help="A run folder (`shakermill run`) or a sweep folder (`shakermill sweep`).")
    ],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", show_default="DIR/figures", help="Folder for the figures.")
    ] = None,
    impacts: Annotated[
        bool, typer.Option("--impacts", help="Run folder: only the impact statistics (speed, energy, rate, phase).")
    ] = False,
    contour: Annotated[
        list[str] | None,
        typer.Option("--contour", metavar="COLUMN=VALUE", help="Sweep folder: draw this level on every map, e.g. theta_inf_C=60."),
    ] = None,
    dpi: Annotated[int, typer.Option("--dpi", min=30, max=600, help="Resolution of the PNG files.")] = PNG_DPI,
    window: Annotated[
        int | None,
        typer.Option("--window", min=0, show_default="0", help="Run folder: the record window (index in record_windows, from 0) of the ball's motion, the balls' paths and the animation."),
    ] = None,
    animate: Annotated[
        bool, typer.Option("--animate", help=f"Run folder of the dem engine: also write {ANIMATION_FILE}, the balls over --window in the vial's side view.")
    ] = False,
    frames: Annotated[
        int, typer.Option("--frames", min=2, max=MOST_ANIMATION_FRAMES, help="Frames of the animation (24 a second).")
    ] = ANIMATION_FRAMES,
) -> None:
    """Draw the figures of a run folder (paper Figs. 4, 5a, 5b, impact statistics; for the dem engine the balls'
    paths and heat by channel, and with --animate a GIF) or of a sweep folder (maps or lines)."""
    from shakermill.studies.sweep import is_sweep_folder
    from shakermill.views.figures import plot_figures

    target = out if out is not None else folder / FIGURES_FOLDER
    if is_sweep_folder(folder):
        for given, option in ((impacts, "--impacts"), (animate, "--animate"), (window is not None, "--window")):
            if given:
                _fail(f"{option}: a sweep folder has no impacts or motion of its own; plot one run (sweep --keep-runs writes them)")
        figures = _sweep_figures(folder, contour or [])
        with _writing(target, "the figures"):
            paths = plot_figures(figures, target, dpi=dpi)
    else:
        if contour:
            _fail("--contour: contours are drawn on the maps of a sweep folder, not on a run")
        paths = _plot_run_folder(folder, target, dpi, impacts=impacts, window=window, frames=frames if animate else None)
    typer.echo(f"{len(paths)} files written to {target}")


def _sweep_figures(folder: Path, contour: Sequence[str]) -> dict[str, Any]:
    """The maps or lines of a sweep folder, with the ``--contour`` levels; a note for each level never reached."""
    from shakermill.studies.sweep import load_sweep
    from shakermill.views.figures import contour_notes, parse_contour, sweep_context, sweep_figures

    with _user_errors():
        data = load_sweep(folder)
        numeric = list(data.table.select_dtypes("number").columns)
        levels = [parse_contour(spec, numeric) for spec in contour]
        figures = sweep_figures(data.table, data.keys, levels, context=sweep_context(data.manifest, data.keys))
    for note in contour_notes(data.table, levels):
        typer.echo(f"note: {note}; no contour drawn", err=True)
    return figures


def _plot_run_folder(
    folder: Path, target: Path, dpi: int, *, impacts: bool, window: int | None, frames: int | None
) -> list[Path]:
    """The figures of a run folder, and its animation of ``frames`` frames unless None; the files written."""
    from shakermill.views.figures import check_window, impact_figures, plot_figures, run_figures, write_animation

    run_data = _load_run_or_fail(folder)
    if frames is not None and run_data.params.engine != "dem":
        _fail("--animate: the animation shows the balls of a run of the dem engine (--set engine=dem); this run is 1-D")
    with _user_errors():
        if window is not None:
            check_window(run_data.params, window)
        written = []
        # First: a window without motion to animate is refused before any figure is written.
        if frames is not None:
            with _writing(target, "the animation"):
                written.append(write_animation(run_data, target / ANIMATION_FILE, window=window or 0, frames=frames))
        figures = impact_figures(run_data) if impacts else run_figures(run_data, impacts=True, window=window or 0)
    with _writing(target, "the figures"):
        return plot_figures(figures, target, dpi=dpi) + written


@app.command()
def report(
    run_dir: Annotated[Path, typer.Argument(metavar="RUN_DIR", help="A run folder written by `shakermill run`.")],
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", metavar="FILE", show_default=f"RUN_DIR/{REPORT_FILE}", help="HTML file to write."),
    ] = None,
    compare: Annotated[
        Path | None,
        typer.Option("--compare", metavar="OTHER_RUN_DIR", help="Add a side-by-side comparison with this run folder."),
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace the report file if it exists.")] = False,
) -> None:
    """Write one self-contained HTML report of a run folder (figures embedded, no external resources)."""
    from shakermill.views.report import save_report

    run_data = _load_run_or_fail(run_dir)
    other = _load_run_or_fail(compare) if compare is not None else None
    target = out if out is not None else run_dir / REPORT_FILE
    if target.is_file() and not overwrite:
        _fail(f"{target}: exists; choose another --out, or add --overwrite to replace it")
    with _writing(target, "the report"):
        save_report(run_data, target, other)
    typer.echo(f"report written to {target}")


SWEEP_PREVIEW_ROWS = 20
SWEEP_PREVIEW_COLUMNS = (
    ("regime", "regime", ""),
    ("ball_steady_C", "steady", "°C"),
    ("theta_inf_C", "θ∞ (fit)", "°C"),
    ("tau_min", "τ (fit)", "min"),
    ("impact_rate_hz", "impact rate", "Hz"),
    ("heat_power_W", "heat", "W"),
    ("mean_impact_speed_m_s", "mean speed", "m/s"),
)


@app.command()
def sweep(
    config: ConfigArgument = None,
    grid: Annotated[
        list[str] | None,
        typer.Option(
            "--grid", "-g", metavar="KEY=START:STOP:N",
            help="N equally spaced values of a numeric key, units allowed (amplitude=20mm:30mm:6), or names "
            "(ball_material=steel,zirconia); several grids combine as a product.",
        ),
    ] = None,
    points: Annotated[
        Path | None,
        typer.Option("--points", metavar="FILE.csv", help="Explicit points: a header of keys, one point per row (combined with --grid as a product)."),
    ] = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", show_default="results/sweep-<timestamp>", help="Sweep folder; re-run into it to resume.")
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", "-w", show_default="one per core", help="Local worker processes.")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", metavar="ADDRESS", help="Run on this Dask distributed scheduler (tcp://host:8786).")
    ] = None,
    scheduler_timeout: Annotated[
        float, typer.Option("--scheduler-timeout", min=0.1, max=86400.0, metavar="SECONDS", help="Give up connecting to the scheduler after this long.")
    ] = DEFAULT_SCHEDULER_TIMEOUT_S,
    keep_runs: Annotated[bool, typer.Option("--keep-runs", help="Also write each point's run folder under DIR/runs.")] = False,
    full_resolution: FullResolutionOption = False,
    json_output: JsonOption = False,
) -> None:
    """Run one simulation per point of a grid or a list; write one table (Parquet and CSV) of their summaries."""
    from shakermill.studies.sweep import SweepFailed, is_sweep_folder, plan_sweep
    from shakermill.studies.sweep import sweep as run_sweep
    from shakermill.studies.sweep import sweep_parameters

    with _user_errors():
        run_config = sweep_parameters(config, preset=preset, overrides=settings or [], full_resolution=full_resolution)
        plan = plan_sweep(grid or [], points)
    target = out if out is not None else timestamped_folder("sweep")
    try:
        counter = "{task.completed}/{task.total} points · {task.fields[running]} running · {task.fields[failed]} failed"
        with _user_errors(), _warnings_as_lines(), _progress_bar("sweep", counter, len(plan.points), running=0, failed=0) as update:
            progress = None if update is None else lambda state: update(state.done, running=state.running, failed=state.failed)
            table = run_sweep(
                run_config.params, plan, target, workers=workers, scheduler=scheduler,
                keep_runs=keep_runs, progress=progress, preset=run_config.preset, scheduler_timeout=scheduler_timeout,
            )
    except SweepFailed as exc:
        # Said below like any failed point, after the table's preview.
        table = exc.table
    except KeyboardInterrupt:
        _fail(f"interrupted; the finished points are stored in {target}; re-run with --out {target} to finish", EXIT_INTERRUPTED)
    except OSError as exc:
        resume = f"; re-run with --out {target} to finish" if is_sweep_folder(target) else ""
        _fail(f"{target}: cannot write the sweep ({exc.strerror or exc}){resume}")
    report_sweep(table, plan.keys, target, json_output)


def report_sweep(table: pd.DataFrame, keys: Sequence[str], target: Path, json_output: bool) -> None:
    """Print the sweep's table (a preview, or where it is as JSON); exit with EXIT_FAILED_RUN if a point failed."""
    from shakermill.studies.sweep import TABLE_CSV, TABLE_PARQUET, failed_points

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
        _stdout_console().print(sweep_preview(table, keys, target))
    if not failed.empty:
        first = failed.iloc[0]
        typer.echo(
            f"error: {len(failed)} of {len(table)} points failed (first: {first['point_id']}: {first['error']}); "
            f"see the error column of {target / TABLE_CSV}",
            err=True,
        )
        raise typer.Exit(EXIT_FAILED_RUN)


def sweep_preview(table: pd.DataFrame, keys: Sequence[str], target: Path) -> Table:
    """The first rows of a sweep table: swept values, regime and the main results."""
    import pandas as pd

    from shakermill.studies.sweep import TABLE_CSV, TABLE_PARQUET, failed_points

    preview = Table(title=f"shakermill sweep: {len(table)} points, {len(failed_points(table))} failed")
    for key in keys:
        preview.add_column(f"{key} ({field_unit(key)})" if field_unit(key) else key, justify="right")
    for _, label, unit in SWEEP_PREVIEW_COLUMNS:
        preview.add_column(f"{label} ({unit})" if unit else label, justify="right")
    for _, row in table.head(SWEEP_PREVIEW_ROWS).iterrows():
        values = [_cell(row[key], ".4g") for key in keys]
        if pd.notna(row["error"]):
            results = ["failed", *([""] * (len(SWEEP_PREVIEW_COLUMNS) - 1))]
        else:
            results = [_cell(row.get(column), ".4g") for column, _, _ in SWEEP_PREVIEW_COLUMNS]
        _add_plain_row(preview, *values, *results)
    more = len(table) - SWEEP_PREVIEW_ROWS
    preview.caption = (f"{more} more rows; " if more > 0 else "") + f"table: {target / TABLE_PARQUET} and {TABLE_CSV}"
    return preview


def _cell(value: Any, spec: str) -> str:
    import pandas as pd

    if value is None or (not isinstance(value, str) and pd.isna(value)):
        return "n/a"
    return value if isinstance(value, str) else _number(value, spec)


@app.command()
def bifurcation(
    config: ConfigArgument = None,
    grid: Annotated[
        str, typer.Option("--grid", "-g", metavar="KEY=START:STOP:N", help="The scanned key and its values.")
    ] = "omega=90:130:200",
    preset: PresetOption = None,
    settings: SettingsOption = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", show_default="results/bifurcation-<timestamp>", help="Folder for tables and figure.")
    ] = None,
    full_resolution: Annotated[
        bool, typer.Option("--full-resolution", help="Settle with the full-resolution solver (default: averaged).")
    ] = False,
    dpi: Annotated[int, typer.Option("--dpi", min=30, max=600, help="Resolution of the PNG file.")] = PNG_DPI,
    overwrite: OverwriteOption = False,
) -> None:
    """Scan one key, record the impact phases of the settled motion, classify each run and draw the bifurcation diagram."""
    from shakermill.io.runs import check_target, write_folder
    from shakermill.studies.bifurcation import BIFURCATION_FIGURE, BIFURCATION_FOLDER
    from shakermill.studies.bifurcation import bifurcation as regime_scan
    from shakermill.studies.bifurcation import write_bifurcation
    from shakermill.studies.sweep import parse_grid, sweep_parameters
    from shakermill.views.figures import bifurcation_figure, plot_figures, sweep_context

    with _user_errors():
        run_config = sweep_parameters(config, preset=preset, overrides=settings or [], full_resolution=full_resolution)
        _require_one_dimensional_engine(run_config.params, "bifurcation settles the one ball's attractors")
        key, values = parse_grid(grid, most=MAX_BIFURCATION_VALUES)
        # Checked before the scan: a value out of range would otherwise stop it midway.
        for value in (values[0], values[-1]):
            run_config.params.replace(**{key: float(value)})
    target = out if out is not None else timestamped_folder("bifurcation")
    with _user_errors():
        check_target(target, overwrite=overwrite, kind=BIFURCATION_FOLDER)
    with _nothing_written_when_interrupted("a scan is quick to repeat"), _nothing_written_when_a_run_is_stopped(
        "the scan"
    ), _progress_bar("scanning", "{task.completed}/{task.total} runs", len(values)) as update:
        scan = regime_scan(run_config.params, values, key, progress=None if update is None else lambda done, _total: update(done))

    def fill(folder: Path) -> None:
        write_bifurcation(scan, folder)
        context = sweep_context({"preset": run_config.preset, "base": run_config.params.model_dump()}, (key,))
        figure = bifurcation_figure(scan.phases, scan.attractors, key, context=context)
        plot_figures({BIFURCATION_FIGURE: figure}, folder, dpi=dpi)

    with _user_errors(), _writing(target, "the results"):
        written = write_folder(target, fill, overwrite=overwrite, kind=BIFURCATION_FOLDER)
    counts = scan.regimes["regime"].value_counts()
    table = Table("regime", "runs", f"{key} ({field_unit(key)})", title=f"bifurcation scan over {key}: {len(values)} runs")
    for label, count in counts.items():
        inside = scan.regimes.loc[scan.regimes["regime"] == label, key]
        _add_plain_row(table, str(label), str(count), f"{inside.min():.5g} – {inside.max():.5g}")
    console = _stdout_console()
    console.print(table)
    console.print(coexisting_attractors_table(scan.attractors, key, run_config.params.attractor_starts))
    console.print(Text(f"{len(list(written.iterdir()))} files written to {target}"))


def _require_one_dimensional_engine(params: Parameters, why: str) -> None:
    if params.engine != "1d":
        raise ParameterError(f"engine: {why}; allowed engine = '1d' here (got {params.engine!r})")


COEXISTING_PREVIEW_ROWS = 20


def coexisting_attractors_table(attractors: pd.DataFrame, key: str, starts: int) -> Table | Text:
    """The values with more than one attractor: each attractor's regime, basin fraction and heat power."""
    counts = attractors.groupby(key, sort=False)["attractor"].transform("size")
    several = attractors[counts > 1]
    values = several[key].unique()
    if not len(values):
        return Text(f"coexisting attractors: none; all {starts} starts reach one attractor at each of {attractors[key].nunique()} values")
    unit = field_unit(key)
    table = Table(
        f"{key} ({unit})" if unit else key, "attractor", "regime", "basin fraction", "heat power (W)", "impact rate (Hz)",
        title=f"coexisting attractors ({starts} starts per value): at {len(values)} of {attractors[key].nunique()} values",
    )
    for _, row in several[several[key].isin(values[:COEXISTING_PREVIEW_ROWS])].iterrows():
        _add_plain_row(
            table, f"{row[key]:.5g}", str(row["attractor"]), str(row["regime"]), f"{row['basin_fraction']:.2f}",
            f"{row['heat_power_W']:.4g}", f"{row['impact_rate_hz']:.4g}",
        )
    more = len(values) - COEXISTING_PREVIEW_ROWS
    table.caption = (f"{more} more values; " if more > 0 else "") + "all attractors: bifurcation_attractors.csv"
    return table


def format_value(key: str, value: Any) -> str:
    """A preset value with its unit, e.g. '0.00635 m', 'true', '[0, 1], [600, 0.1] s'."""
    unit = field_unit(key)
    if isinstance(value, bool):
        return str(value).lower()
    if key == "record_windows":
        pairs = ", ".join(f"[{start:g}, {length:g}]" for start, length in value)
        return f"{pairs} {unit}" if pairs else "none"
    if isinstance(value, (int, float)):
        return f"{value:g} {unit}".rstrip()
    return str(value)


@app.command()
def validate(
    solver: Annotated[
        str, typer.Option("--solver", help="'full' (default, as the paper) or 'averaged' (seconds instead of minutes).")
    ] = "full",
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
) -> None:
    """Paper Table 5 and the experiment's curve side by side: the paper's model, this model with published and
    calibrated parameters, which free sets of a calibration can follow the curve, and (3-D) the five-ball
    experiment that no fit has seen."""
    from shakermill.io.runs import to_jsonable
    from shakermill.studies.calibrate import free_set_study

    if solver not in ("full", "averaged"):
        _fail(f"solver: {solver!r} is not allowed; allowed: one of 'full', 'averaged'")
    runs = run_validation(solver)
    outcomes = free_set_study(preset_parameters(DEFAULT_PRESET)) if study else []
    held_out = _held_out_studies() if three_d else None
    if json_output:
        payload = {**validation_payload(runs, outcomes, solver), **(held_out_payload(*held_out) if held_out else {})}
        typer.echo(json.dumps(to_jsonable(payload), sort_keys=True, allow_nan=False))
        return
    console = _stdout_console()
    console.print(validation_table(runs))
    for run in runs:
        console.print(Text(run.statement))
    console.print(Text(f"The experiment's ratio is for five balls: {TABLE5[-1].experiment_note}."))
    if outcomes:
        console.print(free_set_table(outcomes))
    if held_out:
        print_held_out(console, *held_out)


def _held_out_studies() -> tuple[Any, Any, Any]:
    """The five-ball prediction, the engines on one ball and the kinematic sensitivity, with one progress bar."""
    from shakermill.studies.held_out import ENGINE_CASES, engine_comparison, five_ball_prediction, five_ball_sensitivity

    total = 1 + len(ENGINE_CASES) + 5
    with _progress_bar("3-D validation", "{task.completed}/{task.total} runs", total) as update:
        show = update or (lambda done: None)
        prediction = five_ball_prediction()
        show(1)
        comparison = engine_comparison(ENGINE_CASES, progress=lambda done: show(1 + done))
        sensitivity = five_ball_sensitivity(progress=lambda done, _: show(1 + len(ENGINE_CASES) + done))
    return prediction, comparison, sensitivity


def held_out_payload(prediction: Any, comparison: Any, sensitivity: Any) -> dict[str, Any]:
    from shakermill.studies.held_out import COMPARED_KEYS, FIVE_BALL_SOURCE

    return {
        "five_balls": {
            "preset": prediction.preset,
            "source": FIVE_BALL_SOURCE,
            "fitted_parameters": list(prediction.fitted),
            "fitted_to": prediction.fitted_to,
            "statement": prediction.statement,
            "rows": {
                row.key: {"label": row.label, "unit": row.unit, "experiment": row.experiment, "predicted": row.predicted,
                          "relative_error": row.relative_error}
                for row in prediction.rows
            },
        },
        "engine_comparison": {
            "units": {key: unit for key, _, unit in COMPARED_KEYS},
            "cases": [{"label": case.label, **values} for case, values in zip(comparison.cases, comparison.values)],
        },
        "kinematic_sensitivity": sensitivity.as_dict(),
    }


def print_held_out(console: Console, prediction: Any, comparison: Any, sensitivity: Any) -> None:
    from shakermill.studies.held_out import COMPARED_KEYS, FIVE_BALL_SOURCE

    table = Table("quantity", "unit", "experiment", "predicted", "error", title=f"Held out: five balls ({FIVE_BALL_SOURCE})")
    for row in prediction.rows:
        _add_plain_row(table, row.label, row.unit, f"{row.experiment:g}", f"{row.predicted:.3g}", f"{100 * row.relative_error:+.0f} %")
    console.print(table)
    console.print(Text(prediction.statement))
    table = Table("one ball", *(f"{label} [{unit}]" for _, label, unit in COMPARED_KEYS), title="One ball: what the third dimension, gravity and friction change")
    for index, case in enumerate(comparison.cases):
        cells = [
            f"{values:.3g}" + ("" if index == 0 else f" ({100 * comparison.change(key, index):+.0f} %)")
            for key, values in ((key, comparison.values[index][key]) for key, _, _ in COMPARED_KEYS)
        ]
        _add_plain_row(table, case.label, *cells)
    console.print(table)
    console.print(sensitivity_table(sensitivity))


def sensitivity_table(sensitivity: Any) -> Table:
    """Each assumed amplitude halved and raised by half: the measures' relative changes against the baseline."""
    measures = list(sensitivity.baseline)
    table = Table("assumed key × factor", "value (SI)", *measures, title=f"Sensitivity to the assumed {sensitivity.kinematics} motion (five balls)")
    _add_plain_row(table, "baseline", "", *(f"{sensitivity.baseline[name]:.4g}" for name in measures))
    for row in sensitivity.rows:
        # A temperature's relative change depends on where its scale starts: in kelvin it says more.
        changes = (
            f"{row.measures[name] - sensitivity.baseline[name]:+.1f} K" if name.endswith("_C") else f"{100 * row.relative_change[name]:+.1f} %"
            for name in measures
        )
        _add_plain_row(table, f"{row.key} × {row.factor:g}", f"{row.value:.4g}", *changes)
    return table


def preset_parameters(name: str) -> Parameters:
    return load_config(preset=name, overrides=["record_windows="]).params


def validation_payload(runs: Sequence[Any], outcomes: Sequence[Any], solver: str) -> dict[str, Any]:
    return {
        "experiment_source": EXPERIMENT,
        "solver": solver,
        "quantities": {
            entry.key: {"label": entry.label, "unit": entry.unit, "experiment": entry.experiment, "paper_model": entry.paper_model}
            for entry in TABLE5
        },
        "runs": {
            run.preset: {
                "fitted_parameters": list(run.fitted),
                "statement": run.statement,
                "values": {row.quantity.key: row.value for row in run.rows},
                "relative_error_vs_experiment": {row.quantity.key: row.error_vs_experiment for row in run.rows},
                "role": {row.quantity.key: row.role for row in run.rows},
                "curve_rms_K": run.curve_rms_K,
                "ball_steady_C": run.summary["ball_steady_C"],
                "slowest_time_constant_min": run.summary["slowest_time_constant_min"],
            }
            for run in runs
        },
        "free_set_study": [
            {
                "free": list(outcome.free),
                "fitted": outcome.calibration.fitted,
                "curve_rms_K": outcome.calibration.curve_rms_K,
                "follows_curve": outcome.follows_curve,
                "at_edges": outcome.calibration.at_bounds,
                "predictions": outcome.calibration.predictions,
                "verdict": outcome.verdict,
            }
            for outcome in outcomes
        ],
    }


def validation_table(runs: Sequence[Any]) -> Table:
    table = Table("quantity", "unit", "experiment", "paper's model", title=f"Table 5 ({EXPERIMENT})")
    for run in runs:
        table.add_column(f"{run.preset}", justify="right")
        table.add_column("vs exp.", justify="right")
    for index, entry in enumerate(TABLE5):
        cells = [entry.label, entry.unit, f"{entry.experiment:g}", f"{entry.paper_model:g}"]
        for run in runs:
            row = run.rows[index]
            cells += [f"{row.value:.4g} ({row.role})", f"{100 * row.error_vs_experiment:+.2f} %"]
        _add_plain_row(table, *cells)
    # The experiment's exponential plateau is its own estimate of the steady state; the paper gives none.
    steady = ["ball steady state (MODEL.md §11)", "°C", f"{TABLE5[0].experiment:g}", "n/a"]
    for run in runs:
        value = run.summary["ball_steady_C"]
        steady += [f"{value:.4g} (predicted)", f"{100 * (value - TABLE5[0].experiment) / TABLE5[0].experiment:+.2f} %"]
    _add_plain_row(table, *steady)
    deviation = ["RMS deviation from the experiment's curve, 0–60 min", "K", "0", "n/a"]
    for run in runs:
        deviation += [f"{run.curve_rms_K:.3g}", ""]
    _add_plain_row(table, *deviation)
    return table


def free_set_table(outcomes: Sequence[Any]) -> Table:
    table = Table(
        "free keys", "fitted values", "RMS K", "vial/ball ratio (exp. 0.46)", "verdict",
        title="Which free sets can follow the experiment's curve (fits within physically defensible ranges)",
    )
    for outcome in outcomes:
        calibration = outcome.calibration
        fitted = ", ".join(f"{key} {value:.3g}" for key, value in calibration.fitted.items())
        ratio = calibration.predictions.get("vial_ball_ratio", math.nan)
        _add_plain_row(table, ", ".join(outcome.free), fitted, _number(calibration.curve_rms_K, ".2f"), _number(ratio, ".3f"), outcome.verdict)
    return table


@app.command()
def calibrate(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    target: Annotated[
        list[str] | None,
        typer.Option("--target", "-t", metavar="NAME=VALUE", help=f"A target: {', '.join(TARGET_KEYS)}."),
    ] = None,
    curve: Annotated[
        Path | None,
        typer.Option(
            "--curve",
            help="CSV with time_s (or time_min) and ball_C columns to fit (default, without --target: the "
            "experiment's curve 48 - 28 exp(-t/16.7 min) over 0-60 min).",
        ),
    ] = None,
    free: Annotated[
        list[str] | None,
        typer.Option("--free", "-f", metavar="KEY[,KEY]", help=f"Keys to fit (default: {','.join(DEFAULT_FREE)}; engine = 'dem': {','.join(DEM_DEFAULT_FREE)})."),
    ] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Write the fitted preset TOML here.")] = None,
    full_resolution: FullResolutionOption = False,
    json_output: JsonOption = False,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace the preset file if it exists.")] = False,
) -> None:
    """Fit free parameters to a measured curve (the experiment's by default) and/or Table 5 targets by bounded least squares."""
    from shakermill.io.runs import to_jsonable
    from shakermill.studies.calibrate import calibrate as fit_parameters
    from shakermill.studies.calibrate import default_free, parse_free, parse_targets

    with _user_errors():
        run_config = load_config(config, preset=preset, overrides=settings or [])
        targets = parse_targets(target or [])
        free_keys = parse_free(free or [], default_free(run_config.params))
        measured = Curve.from_csv(curve) if curve is not None else None
        if out is not None:
            # Checked before the fit, which takes a while.
            check_preset_target(out, overwrite)
        with _nothing_written_when_interrupted("the fit starts again from the beginning"), _nothing_written_when_a_run_is_stopped(
            "the fit"
        ), _progress_bar("fitting", "{task.completed} model evaluations", None, delay_s=PROGRESS_DELAY_S) as update:
            calibration = fit_parameters(
                run_config.params, free_keys, targets, measured, full_resolution=full_resolution, progress=update
            )
    if out is not None:
        write_fitted_preset(calibration, out, run_config.preset, free_keys, targets)
    if json_output:
        typer.echo(json.dumps(to_jsonable({**calibration.as_dict(), "output": str(out) if out else None}), sort_keys=True, allow_nan=False))
    else:
        print_calibration(calibration, free_keys, targets, out)
    if not calibration.success:
        typer.echo(f"error: calibration did not meet its targets: {calibration.message}", err=True)
        raise typer.Exit(EXIT_FAILED_RUN)


def check_preset_target(out: Path, overwrite: bool) -> None:
    """Raise ParameterError when the fitted preset cannot be written to ``out``."""
    if out.exists() and out.is_dir():
        raise ParameterError(f"out: {out} is a folder; give a .toml file name")
    if out.exists() and not overwrite:
        raise ParameterError(f"out: {out} exists; choose another --out, or add --overwrite to replace it")
    check_writable_place(out)


def write_fitted_preset(
    calibration: Calibration, out: Path, base_preset: str, free_keys: Sequence[str], targets: Mapping[str, float]
) -> None:
    """Write the fitted preset TOML, saying in it which command fitted which keys to what."""
    from shakermill.studies.calibrate import write_preset

    command = "shakermill calibrate " + " ".join(sys.argv[2:])
    fitted_to = [*targets, *([calibration.curve_source] if calibration.curve_source else [])]
    description = (
        f"{base_preset} with {', '.join(free_keys)} fitted to {', '.join(fitted_to)}; "
        f"{', '.join(calibration.predictions)} are predictions"
    )
    with _writing(out, "the preset"):
        write_preset(calibration, out, base_preset=base_preset, command=command, description=description)


def print_calibration(
    calibration: Calibration, free_keys: Sequence[str], targets: Mapping[str, float], out: Path | None
) -> None:
    """The fitted parameters, what the fitted model predicts, the residuals of the targets and of the curve."""
    console = _stdout_console()
    table = Table("parameter", "start", "fitted", "std. error", "physically defensible?", title="calibration")
    for key in free_keys:
        _add_plain_row(
            table, key, f"{calibration.start[key]:.6g}", f"{calibration.fitted[key]:.6g}",
            _number(calibration.parameter_stderr[key], ".3g"), calibration.defensible[key],
        )
    console.print(table)
    predictions = Table("not fitted, predicted", "value", title="what the fitted model predicts")
    for key, value in calibration.predictions.items():
        _add_plain_row(predictions, key, _number(value, ".4g"))
    console.print(predictions)
    if targets:
        residuals = Table("target", "wanted", "achieved", "residual", *[f"∂ln/∂ln {key}" for key in free_keys])
        for key, wanted in targets.items():
            sensitivities = [f"{calibration.sensitivities[key][name]:+.3f}" for name in free_keys]
            _add_plain_row(
                residuals, key, f"{wanted:g}", f"{calibration.achieved[key]:.6g}",
                f"{100 * calibration.relative_residuals[key]:+.3f} %", *sensitivities,
            )
        console.print(residuals)
    if calibration.curve_rms_K is not None:
        console.print(Text(f"curve ({calibration.curve_source}): RMS residual {calibration.curve_rms_K:.3g} K"))
        for label, values in calibration.sensitivities.items():
            if label not in targets:
                console.print(Text(f"d {label} / d ln(key), K: " + ", ".join(f"{key} {value:+.3g}" for key, value in values.items())))
    console.print(Text(f"{calibration.evaluations} model evaluations ({calibration.solver} solver): {calibration.message}"))
    if out is not None:
        console.print(Text(f"preset written to {out}; use it with `shakermill run {out}`"))


if __name__ == "__main__":
    main()
