"""``shakermill run``, ``compare-solvers`` and ``impact``: one simulation and its run folder, the two solvers side by
side, one impact on its own."""

from __future__ import annotations

import json
import math
import re
import shutil
from collections.abc import Iterator, Sequence
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import typer
from rich.table import Table
from rich.text import Text

from shakermill.cli.common import (
    EXIT_FAILED_RUN,
    EXIT_INTERRUPTED,
    ConfigArgument,
    JsonOption,
    OverwriteOption,
    PresetOption,
    SchedulerTimeoutOption,
    SettingsOption,
    add_plain_row,
    echo_notes,
    echo_warnings,
    nothing_written_when_interrupted,
    number,
    scheduler_timeout_of,
    simulate_with_progress,
    stdout_console,
    timestamped_folder,
    user_errors,
    writing,
)
from shakermill.engines.budget import interrupts_held
from shakermill.parameters.defaults import HIT_SPEED

if TYPE_CHECKING:
    from shakermill.parameters.keys import Parameters
    from shakermill.solvers.result import Result
    from shakermill.solvers.summary import Summary
    from shakermill.solvers.summary_sections import Charge

FIGURES_FOLDER = "figures"


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
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            metavar="ADDRESS",
            help="Advance an averaged run's replicas after the first on this Dask scheduler (tcp://host:8786).",
        ),
    ] = None,
    scheduler_timeout: SchedulerTimeoutOption = None,
) -> None:
    """Run one simulation and write its run folder (data, summary, configuration, figures)."""
    from shakermill.io.runs import check_target, import_writers, to_jsonable
    from shakermill.parameters.config import load_config
    from shakermill.parameters.keys import unit_slip_warnings
    from shakermill.solvers.result import INTERRUPTED
    from shakermill.solvers.simulate import preflight
    from shakermill.solvers.summary_versions import SCHEMA_VERSION, VERSION_KEY

    overrides = settings or []
    with user_errors():
        run_config = load_config(config, preset=preset, overrides=overrides)
        target = out if out is not None else timestamped_folder("run")
        check_target(target, overwrite=overwrite)
        preflight(run_config.params)
        cluster = cluster_for_replicas(run_config.params, scheduler, scheduler_timeout_of(scheduler, scheduler_timeout))
    import_writers()
    # Unit slips and the solver's choice are said before a possibly long run, the rest once it is known.
    said_first = unit_slip_warnings(run_config.params)
    echo_warnings(said_first)
    said_notes = solver_choice(run_config.params)
    echo_notes([*run_config.notes, *said_notes])
    # A run returns what it computed when interrupted; Ctrl-C in the thermal network leaves none.
    with nothing_written_when_interrupted("the run had no results to keep yet"), cluster:
        result = simulate_with_progress(run_config.params)
    refitted = tuple(run_config.provenance.get("fitted", ()))
    stopped = result.status == INTERRUPTED or not preset_findings_added(result, run_config.preset, refitted)
    provenance = {"command": "shakermill run", "config_file": str(config) if config else None, "overrides": overrides}
    # What was computed is written whole: a Ctrl-C meanwhile takes effect once it is.
    with interrupts_held(deliver=False) as held:
        target = _write(result, target, run_config.preset, provenance, overwrite=overwrite)
    finished = not stopped and not held
    if finished:
        # An interrupted run is short by choice: its warnings (steady state, fit) stay in summary.json, unsaid.
        echo_warnings([line for line in result.summary.warnings if line not in said_first])
        # After a Ctrl-C the figures are left to `plot`, so that it exits within a second.
        finished = no_plots or _draw_figures(result, target)
    if json_output:
        typer.echo(
            json.dumps(
                to_jsonable({VERSION_KEY: SCHEMA_VERSION, **result.summary.flat(), "output_dir": str(target)}),
                sort_keys=True,
                allow_nan=False,
            )
        )
    elif finished:
        console = stdout_console()
        console.print(summary_table(result, target))
        console.print(Text(answer_text(result.summary, run_config.preset, said=said_notes)))
    if not finished:
        _exit_interrupted(result, target)
    _exit_for_status(result, target)


def cluster_for_replicas(params: Parameters, scheduler: str | None, timeout: float) -> AbstractContextManager[None]:
    """Where the replicas of an averaged run after its first advance: on the Dask scheduler at ``scheduler``
    (solvers/replicas.py), or here. A scheduler a run would not use is refused in one line."""
    from contextlib import nullcontext

    from shakermill.parameters.errors import ParameterError
    from shakermill.solvers.averaged import full_resolution_instead, replica_count
    from shakermill.studies.sweeps.backends import connect

    if scheduler is None:
        return nullcontext()
    replicas = replica_count(params)
    if params.solver != "averaged" or full_resolution_instead(params) is not None or replicas < 2:
        key = params.engine_keys.replicas_key
        wanted = f"{key} >= 2" if key else "an engine with replicas (engine = 'dem', dem_replicas >= 2)"
        raise ParameterError(
            f"--scheduler: this run sends nothing to a cluster (solver = {params.solver!r}, {replicas} "
            "replica); allowed "
            f"with solver = 'averaged' and {wanted}"
        )
    return _sending_replicas(connect(scheduler, timeout))


@contextmanager
def _sending_replicas(client: Any) -> Iterator[None]:
    from shakermill.solvers.replicas import replicas_on

    with client, replicas_on(client):
        yield


def solver_choice(params: Parameters) -> list[str]:
    """The sentence that says an averaged run is run at full resolution from the start, and why (none otherwise)."""
    from shakermill.solvers.averaged import full_resolution_instead

    reason = full_resolution_instead(params)
    return [] if reason is None else [reason]


def preset_findings_added(result: Result, preset: str | None, refitted: Sequence[str] = ()) -> bool:
    """:func:`with_preset_findings`; False when Ctrl-C stopped it (the run is then written without them)."""
    try:
        with_preset_findings(result, preset, refitted)
    except KeyboardInterrupt:
        return False
    return True


def with_preset_findings(result: Result, preset: str | None, refitted: Sequence[str] = ()) -> None:
    """Add to the summary of any preset's run what its validation found where it failed or is missing
    (``validation_caveat``, said of the preset as shipped where the configuration ``refitted`` keys), and of a
    calibrated preset's run the 90 % intervals of its headline temperatures (``studies.calibration.intervals``),
    which carry the calibration's uncertainty and the averaging error."""
    from shakermill.parameters.presets import PRESETS
    from shakermill.studies.calibration.intervals import intervals, uncertainty_of

    known = PRESETS.get(preset) if preset is not None else None
    caveat = known.caveat_for(result.params.model_dump(), refitted) if known is not None else None
    uncertainty = uncertainty_of(known) if known is not None else None
    found = intervals(result, uncertainty) if uncertainty is not None else None
    result.summary = result.summary.with_findings(
        validation_caveat=caveat or None, intervals=found.as_summary() if found is not None else None
    )


def answer_text(summary: Summary, preset: str | None, said: Sequence[str] = ()) -> str:
    """The run's answer under its table: the report's sentences with the run's notes (but those ``said`` before the
    run), then the preset's caveat."""
    from shakermill.parameters.presets import PRESETS
    from shakermill.views.notebook import answer_sentences

    known = PRESETS.get(preset) if preset is not None else None
    unsaid = summary.updated(notes=[note for note in summary.notes if note not in said])
    text = " ".join(answer_sentences(unsaid, preset, fitted=known is None or bool(known.fitted)))
    caveat = summary.validation_caveat
    return text + (f"\nCaveat ({preset}): {caveat}" if caveat else "")


def _write(result: Result, target: Path, preset: str, provenance: dict[str, Any], *, overwrite: bool) -> Path:
    """Write the run folder's data and status; return its absolute path."""
    from shakermill.io.runs import write_run

    with user_errors(), writing(target, "the run folder"):
        return write_run(result, target, preset=preset, extra_provenance=provenance, overwrite=overwrite)


def _draw_figures(result: Result, target: Path) -> bool:
    """Draw the figures into the written run folder, whole or not at all (they are drawn in a hidden sibling and
    renamed into place); False when Ctrl-C stops them."""
    from shakermill.support.atomic import partial_path
    from shakermill.views.figures.run import plot_run

    folder = target / FIGURES_FOLDER
    drawing = partial_path(folder)
    try:
        with writing(folder, "the figures"):
            plot_run(result, drawing)
            drawing.rename(folder)
    except KeyboardInterrupt:
        return False
    finally:
        shutil.rmtree(drawing, ignore_errors=True)
    return True


def _exit_interrupted(result: Result, target: Path) -> NoReturn:
    """One line for Ctrl-C, once the data and status are written, and exit code 130."""
    from shakermill.solvers.result import INTERRUPTED

    what = result.message if result.status == INTERRUPTED else "Interrupted by the user after the run had finished."
    typer.echo(
        f"interrupted: {what} Data and status written to {target}; draw its figures with: shakermill plot {target}",
        err=True,
    )
    raise typer.Exit(EXIT_INTERRUPTED)


def _exit_for_status(result: Result, target: Path) -> None:
    if not result.success:
        typer.echo(f"error: {result.message} Results so far in {target}", err=True)
        raise typer.Exit(EXIT_FAILED_RUN)


def _radii_mm(params: Parameters) -> str:
    """The ball radius in mm, or each ball's where they differ; "none" in an empty mill."""
    radii = sorted(set(params.ball_values("ball_radius")))
    return ", ".join(number(radius * 1e3, ".4g") for radius in radii) or "none"


def summary_table(result: Result, target: Path) -> Table:
    """The human summary of a run: fitted and final temperatures, impacts, power, numerics."""
    s = result.summary
    table = Table(title="shakermill run", show_header=True)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    table.add_column("unit")
    fit_window = f"0–{number(s.simulated_s / 60.0, '.4g')} min"
    description = result.description
    # With several balls the temperatures, steady state and fit are the balls' means; their own rows say more.
    ball = "balls' mean" if description.several_balls else "ball"
    rows = [
        ("status", s.message if not result.success else "ok", ""),
        ("solver", s.solver, ""),
        (
            "drive ω",
            f"{number(s.omega_rad_s, '.4g')} rad/s = {number(s.omega_hz, '.4g')} Hz = {number(s.omega_rpm, '.0f')}",
            "rpm",
        ),
        _size_row(result),
        (
            "ambient; initial temperature",
            f"{number(s.ambient_temperature_C, '.4g')}; {number(s.initial_temperature_C, '.4g')}",
            "°C",
        ),
        ("simulated time", number(s.simulated_s, ".6g"), "s"),
        (f"{ball} steady state", number(s.ball_steady_C, ".2f"), "°C"),
        ("vial; air steady state", f"{number(s.vial_steady_C, '.2f')}; {number(s.air_steady_C, '.2f')}", "°C"),
        ("slowest time constant", number(s.slowest_time_constant_min, ".1f"), "min"),
        *_fit_rows(result, ball, fit_window),
        (f"{ball} at the end", number(s.ball_C, ".2f"), "°C"),
        ("vial at the end", number(s.vial_C, ".2f"), "°C"),
        ("air at the end", number(s.air_C, ".2f"), "°C"),
        ("vial/ball increment ratio", number(s.vial_ball_ratio, ".3f"), ""),
        *interval_rows(s),
        *(several_ball_rows(s, description.channels) if description.several_balls else ()),
        *heat_path_rows(s),
        ("impacts", number(s.impacts.count, "d"), ""),
        ("impact rate", number(s.impacts.rate_hz, ".2f"), "Hz"),
        ("mean impact speed", number(s.impacts.mean_speed_m_s, ".3f"), "m/s"),
        (
            f"hits ≥ {HIT_SPEED:g} m/s: rate; mean speed",
            f"{number(s.impacts.hit_rate_hz, '.2f')} Hz; {number(s.impacts.mean_hit_speed_m_s, '.3f')}",
            "m/s",
        ),
        ("heat generated", number(s.heat_power_W, ".3f"), "W"),
        ("steps (rejected)", f"{s.steps} ({s.rejected_steps})", ""),
        ("wall time", number(s.wall_time_s, ".2f"), "s"),
        ("energy audit residual", number(s.energy_audit_residual, ".2e"), "relative"),
        ("output folder", str(target), ""),
    ]
    for row in rows:
        add_plain_row(table, *row)
    return table


def _size_row(result: Result) -> tuple[str, str, str]:
    """The vial's amplitude where its motion reads one (a planetary jar's does not) and the balls' radii (mm)."""
    from shakermill.parameters.engine_keys import reader_of

    radii = _radii_mm(result.params)
    if reader_of(result.params).not_read("amplitude") is not None:
        return ("ball radius", radii, "mm")
    return ("amplitude; ball radius", f"{number(result.summary.amplitude_mm, '.4g')}; {radii}", "mm")


def _fit_rows(result: Result, ball: str, fit_window: str) -> list[tuple[str, str, str]]:
    """The exponential fitted to the balls' heating, or one row saying why a run shorter than the network's slowest
    time constant has none worth reading."""
    from shakermill.solvers.result import shorter_than_its_network

    s = result.summary
    if shorter_than_its_network(result):
        return [
            (
                "exponential fit",
                f"none: the run is shorter than the slowest time constant "
                f"({number(s.slowest_time_constant_min, '.1f')} min)",
                "",
            )
        ]
    return [
        (f"{ball} θ∞ of the exponential fitted over {fit_window}", number(s.theta_inf_C, ".2f"), "°C"),
        ("τ of that fit", number(s.tau_min, ".2f"), "min"),
        ("initial heating rate θ̇₀ of that fit", number(s.rate0_C_per_min, ".3f"), "°C/min"),
    ]


def interval_rows(s: Summary) -> list[tuple[str, str, str]]:
    """The temperatures of the nodes only some networks have (the holder of thermal_model = 'mill-head', ...) and the
    90 % intervals of a calibrated preset's run."""
    rows = [
        (f"{node} at the end; steady state", f"{number(end, '.2f')}; {number(steady, '.2f')}", "°C")
        for node, (end, steady) in s.further_nodes().items()
    ]
    found = s.intervals
    if found is None:
        return rows
    for label, low, high in (
        ("ball at the end", found.ball_C_low, found.ball_C_high),
        ("vial at the end", found.vial_C_low, found.vial_C_high),
        ("ball steady state", found.ball_steady_C_low, found.ball_steady_C_high),
        ("vial steady state", found.vial_steady_C_low, found.vial_steady_C_high),
    ):
        rows.append((f"  90 % interval, {label}", f"{number(low, '.1f')} to {number(high, '.1f')}", "°C"))
    return rows


def heat_path_rows(s: Summary) -> list[tuple[str, str, str]]:
    """Each heat path's mean flow over the run, the balls' like paths summed (``ball 2 → air`` counts in
    ``balls → air``)."""
    totals: dict[str, float] = {}
    several = s.charge is not None and s.charge.n_balls > 1
    for name, value in s.heat_paths_W.items():
        general = re.sub(r"ball \d+", "balls", name) if several else name
        totals[general] = totals.get(general, 0.0) + (0.0 if math.isnan(value) else value)
    rows = [(f"heat path {name}", number(value, ".3g"), "W") for name, value in totals.items()]
    if s.drive_heat_W:
        rows.append(("drive heat into the holder", number(s.drive_heat_W, ".3g"), "W"))
    return rows


# Up to this many balls the run table gives each ball's temperature; beyond, the coolest and the hottest.
EACH_BALL_UP_TO = 6


def several_ball_rows(s: Summary, channels: Sequence[str]) -> list[tuple[str, str, str]]:
    """The run table's rows of an engine of several balls: balls, their temperatures at the end and steady states,
    impacts on the walls and between balls, heat by dissipation channel (``channels``); none for an engine of one."""
    charge = s.charge
    if charge is None:
        return []
    rows = [
        (
            "engine; balls; fill of the vial",
            f"{charge.engine}; {charge.n_balls}; {number(charge.fill_fraction, '.3f')}",
            "",
        )
    ]
    steady = s.steady.each_ball_C if s.steady is not None else None
    for each, what in ((s.temperatures.each_ball_C, "at the end"), (steady, "steady state")):
        values = [value for value in each or () if not math.isnan(value)]
        if not values:
            continue
        if len(values) <= EACH_BALL_UP_TO:
            rows.append((f"each ball {what} (ball 0; 1; …)", "; ".join(number(value, ".2f") for value in values), "°C"))
        else:
            rows.append(
                (f"balls {what}: coolest; hottest", f"{number(min(values), '.2f')}; {number(max(values), '.2f')}", "°C")
            )
    rows.append(("impacts on the walls; between balls", f"{s.impacts.on_walls}; {s.impacts.between_balls}", ""))
    # Kwade's ½·m*·v_n² beside the energy dissipated, and how much of the dissipation neither describes.
    rows.append(
        (
            "contact records; touches (< touch_speed, not impacts)",
            f"{number(s.impacts.records_hz, '.4g')}; {number(s.impacts.touches_hz, '.4g')}",
            "Hz",
        )
    )
    rows.append(
        (
            "stress energy dissipated per impact: median; p90",
            f"{number(s.stress_energy_median_J, '.3g')}; {number(s.stress_energy_p90_J, '.3g')}",
            "J",
        )
    )
    rows.append(
        (
            "... energy-weighted: median; p90",
            f"{number(s.stress_energy_weighted_median_J, '.3g')}; {number(s.stress_energy_weighted_p90_J, '.3g')}",
            "J",
        )
    )
    rows.append(
        (
            "½·m*·v_n² at contact (Kwade): median; p90",
            f"{number(s.stress_energy_kinetic_median_J, '.3g')}; {number(s.stress_energy_kinetic_p90_J, '.3g')}",
            "J",
        )
    )
    share = s.stress_lasting_share
    rows.append(
        (
            "dissipation in lasting contacts (not in the medians)",
            number(100 * share, ".3g"),
            "%",
        )
    )
    rows.extend(regime_rows(charge))
    heat = [s.heat_by_channel_W.get(channel) for channel in channels]
    if any(value is not None for value in heat):
        # The averaged solver has no split by channel: its heat comes from the thermal network's means.
        rows.append((f"heat by channel: {'; '.join(channels)}", "; ".join(number(value, ".3g") for value in heat), "W"))
    return rows


def regime_rows(charge: Charge) -> list[tuple[str, str, str]]:
    """The run table's rows of the regime of a charge's settled motion and, for an intermittent one, how it
    switches."""
    from shakermill.analysis.regime import INTERMITTENT  # NumPy with it: not on the path of --help

    rows = []
    if charge.regime is not None:
        rows.append(
            (
                f"motion from {number(charge.regime_from_s, '.3g')} s (pack: lasting contacts, under one impact "
                "> 1 m/s a ball and turn; else active)",
                f"{charge.regime}, {number(charge.regime_fast_impact_rate_hz, '.4g')} impacts > 1 m/s a second, "
                f"{number(100 * charge.regime_lasting_share, '.3g')} % in lasting contacts",
                "",
            )
        )
    if charge.regime == INTERMITTENT:
        rows.append(
            (
                "intermittent: share of the time active (%); time between switches (s)",
                f"{number(100 * charge.regime_active_share, '.3g')}; {number(charge.regime_switch_interval_s, '.3g')}",
                "",
            )
        )
    return rows


def compare_solvers(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    json_output: JsonOption = False,
) -> None:
    """Run the same configuration with the full and the averaged solver; print both, the differences and the
    speed ratio."""
    from shakermill.io.runs import to_jsonable
    from shakermill.parameters.config import load_config
    from shakermill.studies.validation.compare import compare_solvers as compare

    with user_errors(), nothing_written_when_interrupted("compare-solvers writes no files"):
        # Both solvers run: a key of the averaged one is read.
        params = load_config(config, preset=preset, overrides=settings or [], reader="averaged").params
        comparison = compare(params, simulate_with_progress)
    if json_output:
        typer.echo(json.dumps(to_jsonable(comparison.as_dict()), sort_keys=True, allow_nan=False))
    else:
        table = Table("quantity", "full", "averaged", "averaged − full", "unit", title="full vs averaged solver")
        for label, unit, full_value, averaged_value, difference in comparison.rows():
            add_plain_row(
                table, label, number(full_value, ".4g"), number(averaged_value, ".4g"), number(difference, "+.3g"), unit
            )
        console = stdout_console()
        console.print(table)
        console.print(Text(f"averaged solver: {comparison.averaged.message}"))
        console.print(Text(f"speed ratio full/averaged: {comparison.speed_ratio:.0f}x"))
    for result in (comparison.full, comparison.averaged):
        if not result.success:
            typer.echo(f"error: the {result.params.solver} run did not finish cleanly: {result.message}", err=True)
            raise typer.Exit(EXIT_FAILED_RUN)


# The vial's size plays no part in a lone impact, only its material: a vial of the largest usual size (0.5 m) lets
# any ball of the allowed radii be set without resizing the vial too. Its heat is not computed either, so the paper's
# network, which has no outside to hold that bore, stands in for a preset's 'mill-head' one. The user's own settings
# come after.
IMPACT_VIAL = ["vial_length=0.5 m", "vial_diameter=0.5 m", "thermal_model=paper"]
IMPACT_VIAL_KEYS = frozenset(setting.partition("=")[0] for setting in IMPACT_VIAL)
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


def impact(
    config: ConfigArgument = None,
    preset: PresetOption = None,
    settings: SettingsOption = None,
    *,
    # Required: an option without a default (keyword-only, after the arguments that have one).
    speed: Annotated[float, typer.Option("--speed", help="Speed of the incoming ball relative to its target, m/s.")],
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
    from shakermill.parameters.config import load_config, parse_overrides
    from shakermill.parameters.errors import ParameterError
    from shakermill.parameters.keys import unit_slip_warnings
    from shakermill.solvers.impact import check_keys_read, check_reads, single_impact

    with user_errors(), nothing_written_when_interrupted("impact writes no files"):
        asked = parse_overrides(settings or [])
        # Before the parameters are built: a fill would make balls for the impact's own large vial.
        check_keys_read(asked, target)
        # A lone impact reads the keys its own way (solvers/impact.py), whatever engine the preset names.
        run_config = load_config(config, preset=preset, overrides=[*IMPACT_VIAL, *(settings or [])], reader=None)
        if run_config.assumed_tables:
            raise ParameterError(
                f"{run_config.source}: [assumed]: a lone impact varies no input; ranges of inputs apply to "
                "uncertainty and calibrate --with-assumed"
            )
        params = run_config.params
        # The impact's own vial is the command's, not the user's: only what the user set is checked.
        check_reads([key for key in run_config.explicit if key not in IMPACT_VIAL_KEYS or key in asked], params, target)
        echo_warnings(unit_slip_warnings(params))
        outcome = single_impact(params, speed, angle, target, spin).as_dict()
    if json_output:
        typer.echo(json.dumps(outcome, allow_nan=False))
        return
    table = Table("quantity", "value", "unit", title=f"one impact: {speed:g} m/s at {angle:g}° on a {target} at rest")
    for key, label, scale, spec, unit in IMPACT_ROWS:
        add_plain_row(table, label, number(scale * outcome[key], spec), unit)
    stdout_console().print(table)
