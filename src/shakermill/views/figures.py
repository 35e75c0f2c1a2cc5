"""Figures of a run, as PNG and SVG: the paper's Figs. 4, 5a and 5b, and the impact statistics.

The paper's figures (Son 2025, section 4): ``ball_motion`` is Fig. 4 (position
and momentum over the first recorded window, the first second by default),
``temperatures`` is Fig. 5a (ball, vial and air with the ball's fitted
exponential) and ``ball_heating_zoom`` is Fig. 5b (100 ms at 10 min: heating at
each impact, convective cooling between). The impact figures are this
package's own: histograms of impact speed and dissipated energy per impact, and
the impacts per second at each end face.

A run of the 'dem' engine (several balls in three dimensions, MODEL.md §12) has no ball on the axis to
draw as in Fig. 4: its paths are drawn in the vial frame instead (``trajectories``,
:mod:`shakermill.views.trajectories`), its temperature figures have a line per ball, ``heat_by_channel``
splits the heat by dissipation channel and contact, and the impact figures tell the end faces, the side
wall and the other balls apart.

Matplotlib is imported inside the functions, so that importing :mod:`shakermill`
stays fast. Figures are drawn on the Agg canvas directly, without pyplot: that
needs no display and leaves the backend of an interactive session untouched.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Protocol, Sequence

import numpy as np
import pandas as pd
import xarray as xr

from shakermill.analysis.fit import ExponentialFit
from shakermill.engines.dem.model import CHANNELS
from shakermill.parameters.defaults import ANIMATION_FRAMES, FIGURE_FORMATS, PNG_DPI
from shakermill.parameters.schema import ParameterError, Parameters
from shakermill.physics import kinematics
from shakermill.solvers.result import BALL_TEMPERATURES
from shakermill.support.atomic import remove_abandoned_writes, write_bytes_atomically, write_files_atomically
from shakermill.views.trajectories import ANIMATION_DPI, animation_gif, ball_colours, trajectory_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

# Figure names (file stems): the paper's Figs. 5a, 4, 5b, and this package's impact statistics.
PAPER_FIGURES = ("temperatures", "ball_motion", "ball_heating_zoom")
# The same for the 'dem' engine: Fig. 5a and 5b with a line per ball, the paths in the vial frame, the heat by channel.
SEVERAL_BALL_FIGURES = ("temperatures", "trajectories", "heat_by_channel", "ball_heating_zoom")
IMPACT_FIGURES = ("impact_speed_histogram", "impact_energy_histogram", "impacts_per_second", "impact_phase_histogram")
KELVIN_OFFSET = 273.15
# The paper's Fig. 5b zooms into the heating at 10 min; the window starting nearest to it is shown.
HEATING_ZOOM_TIME = 600.0
MIN_POINTS_TO_PLOT = 2
# Columns of a legend under a figure (one entry per ball, the vial and the air).
LEGEND_COLUMNS = 6
DRIVE_CURVE_POINTS = 2000


class RunLike(Protocol):
    """What the figures need: a :class:`shakermill.simulate.Result` or a :class:`shakermill.storage.RunData`."""

    @property
    def params(self) -> Parameters: ...

    @property
    def timeseries(self) -> xr.Dataset: ...

    @property
    def windows(self) -> xr.Dataset: ...

    @property
    def impacts(self) -> pd.DataFrame: ...

    @property
    def ball_fit(self) -> ExponentialFit: ...

    @property
    def summary(self) -> dict[str, Any]: ...


def plot_run(run: RunLike, out_dir: Path | str, *, impacts: bool = False, dpi: int = PNG_DPI) -> list[Path]:
    """Write the paper's figures of ``run`` (and the impact figures if asked) into ``out_dir``; return the files."""
    return plot_figures(run_figures(run, impacts=impacts), out_dir, dpi=dpi)


def run_figures(run: RunLike, *, impacts: bool = False, window: int = 0) -> dict[str, Figure]:
    """The figures of ``run`` by name: those of :func:`main_figure_names` its data allow, then the impact
    figures; the motion (``ball_motion``, ``trajectories``) is drawn over record window ``window``."""
    figures = paper_figures(run, window=window)
    if impacts:
        figures.update(impact_figures(run))
    return figures


def several_balls(params: Parameters) -> bool:
    """Whether a run is the 'dem' engine's (MODEL.md §12), whose figures differ from the paper's."""
    return params.engine == "dem"


def main_figure_names(params: Parameters) -> tuple[str, ...]:
    """The figures a run of ``params`` gets besides the impact statistics, where its data allow them."""
    return SEVERAL_BALL_FIGURES if several_balls(params) else PAPER_FIGURES


def check_window(params: Parameters, window: int) -> None:
    """:class:`ParameterError` unless ``window`` is the index of one of the run's record windows."""
    count = len(params.record_windows)
    if not 0 <= window < count:
        allowed = f"0 to {count - 1}" if count else "none: the run has no record_windows"
        raise ParameterError(f"window {window}: not one of the run's record windows; allowed {allowed}")


def run_context(run: RunLike) -> str:
    """"spex8000m, 60 min, averaged solver": what a figure of ``run`` shows, for its title.

    The preset is known for a stored run (:class:`shakermill.storage.RunData`), not for a bare Result.
    """
    minutes = run.summary.get("simulated_s", run.params.duration) / 60.0
    parts = [getattr(run, "preset", None), f"{minutes:.3g} min", f"{run.params.solver} solver"]
    return ", ".join(part for part in parts if part)


def averaging_window_note(run: RunLike) -> str:
    """For the averaged solver, which keeps the impacts of its averaging window only: that window; else empty."""
    window = run.summary.get("averaging_window_s")
    if run.params.solver != "averaged" or window is None:
        return ""
    return f"impacts of the {window:.3g} s averaging window only"


def add_context(figure: Figure, *lines: str) -> Figure:
    """``lines`` (the empty ones skipped) under the figure's title: its suptitle, else its first axes' title."""
    text = "\n".join(line for line in lines if line)
    if not text:
        return figure
    if figure.get_suptitle():
        figure.suptitle(f"{figure.get_suptitle()}\n{text}")
    else:
        axis = figure.axes[0]
        axis.set_title(f"{axis.get_title()}\n{text}")
    return figure


def paper_figures(run: RunLike, *, window: int = 0) -> dict[str, Figure]:
    """Fig. 5a always; Fig. 4 (over record window ``window``) and Fig. 5b only when their record windows
    hold enough points. A 'dem' run gets :data:`SEVERAL_BALL_FIGURES` instead, by the same rules."""
    figures = _paper_figures(run, window)
    context = run_context(run)
    return {name: add_context(figure, context) for name, figure in figures.items()}


def _paper_figures(run: RunLike, window: int) -> dict[str, Figure]:
    params = run.params
    balls = several_balls(params)
    figures = {"temperatures": temperature_figure(run)}
    motion = window_data(run, window)
    if motion is not None:
        name, draw = ("trajectories", trajectory_figure) if balls else ("ball_motion", motion_figure)
        figures[name] = draw(params, motion, params.record_windows[window])
    if balls:
        figures["heat_by_channel"] = heat_by_channel_figure(run)
    zoom_index = heating_zoom_window(params)
    zoom = window_data(run, zoom_index) if zoom_index is not None else None
    if zoom is not None:
        zoom_start = params.record_windows[zoom_index][0]
        figures["ball_heating_zoom"] = heating_zoom_figure(run, zoom, zoom_start)
    return figures


def write_animation(
    run: RunLike, target: Path | str, *, window: int = 0, frames: int = ANIMATION_FRAMES, dpi: int = ANIMATION_DPI
) -> Path:
    """Write the GIF of the balls of a 'dem' run over record window ``window`` (:func:`animation_gif`) to
    ``target``, atomically; :class:`ParameterError` for a 1-D run or a window without points."""
    params = run.params
    if not several_balls(params):
        raise ParameterError("animate: the animation shows the balls of a 'dem' run; this run is 1-D (engine = '1d')")
    check_window(params, window)
    motion = window_data(run, window)
    if motion is None:
        start, length = params.record_windows[window]
        raise ParameterError(
            f"window {window}: the record window from {start:g} s ({length:g} s long) holds no stored motion; the "
            "run, or the averaged solver's mechanics, ended before it"
        )
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_abandoned_writes(target.parent)
    return write_bytes_atomically(target, animation_gif(params, motion, frames=frames, dpi=dpi))


def save_figure(figure: Figure, stem: Path, *, dpi: int = PNG_DPI) -> list[Path]:
    """Save ``figure`` as ``stem.png`` and ``stem.svg``, drawn in memory and written atomically."""
    files = {}
    for fmt in FIGURE_FORMATS:
        buffer = io.BytesIO()
        figure.savefig(buffer, format=fmt, dpi=dpi, bbox_inches="tight")
        files[stem.with_suffix(f".{fmt}")] = buffer.getbuffer()
    return write_files_atomically(files)


def _new_figure(rows: int = 1, height: float = 4.5, columns: int = 1, width: float = 7.5) -> tuple[Figure, list]:
    """A figure of ``rows`` × ``columns`` axes, listed row by row; the rows of one column share their time axis."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(rows, columns, sharex=columns == 1, squeeze=False)
    return figure, list(axes.flat)


def to_celsius(kelvin: np.ndarray) -> np.ndarray:
    return np.asarray(kelvin) - KELVIN_OFFSET


def temperature_figure(run: RunLike) -> Figure:
    """Paper Fig. 5a: ball (each ball of a 'dem' run), vial and air temperatures in °C against minutes, with
    the fitted exponential of the ball (of the balls' mean) and its steady state."""
    figure, (axis,) = _new_figure()
    series = run.timeseries
    minutes = series["time"].values / 60.0
    bodies = [
        axis.plot(minutes, to_celsius(kelvin), color=colour, label=label)[0]
        for kelvin, label, colour in temperature_lines(run.params, series)
    ]
    balls = several_balls(run.params)
    fit = run.ball_fit
    window = f"0–{minutes[-1]:.3g} min"
    if math.isfinite(fit.theta_inf) and math.isfinite(fit.tau):
        fitted = "balls' mean, exponential fitted" if balls else f"ball, exponential fitted over {window}"
        axis.plot(minutes, to_celsius(fit.evaluate(series["time"].values)), "k--", lw=1, label=fitted)
    steady = run.summary.get("ball_steady_C")
    if steady is not None and math.isfinite(steady):
        # The fit's θ∞ is a property of the window; the steady state is where the ball really settles.
        axis.axhline(steady, color="tab:red", ls=":", lw=1, label=steady_label(run.summary, balls))
        low, high = axis.get_ylim()
        axis.set_ylim(low, max(high, steady + 0.05 * (steady - low)))
    axis.text(
        0.98, 0.55, f"exponential fitted over {window}:\n{_fit_text(fit)}", transform=axis.transAxes, ha="right",
        va="bottom", bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.85},
    )
    axis.set_xlabel("time (min)")
    axis.set_ylabel("temperature (°C)")
    named = f"the {run.params.n_balls} balls" if balls else "ball"
    axis.set_title(f"Temperatures of {named}, vial and inner air (cf. paper Fig. 5a)")
    if balls:
        legend_below(figure, bodies)
        lines = [line for line in axis.get_lines() if line not in bodies]
        if lines:
            axis.legend(handles=lines, loc="lower right", fontsize="small")
    else:
        axis.legend(loc="lower right")
    axis.grid(alpha=0.3)
    return figure


def steady_label(summary: Mapping[str, Any], balls: bool) -> str:
    """The legend of the steady-state line: the ball's, or the balls' mean with the range of the balls'."""
    steady = summary["ball_steady_C"]
    if not balls:
        return f"ball steady state {steady:.1f} °C (MODEL.md §11)"
    each = [value for value in summary.get("balls_steady_C") or () if value is not None]
    spread = f" (each {min(each):.1f}–{max(each):.1f} °C)" if each else ""
    return f"balls' mean steady state {steady:.1f} °C{spread}"


def legend_below(figure: Figure, lines: Sequence[Any]) -> None:
    """A legend of ``lines`` under the figure: a line per ball would cover the curves inside the axes."""
    figure.legend(handles=lines, loc="outside lower center", ncols=min(len(lines), LEGEND_COLUMNS), fontsize="small")


def model_of(params: Parameters) -> str:
    """The thermal model of a run; parameters from before the model option existed are three-node runs."""
    return str(getattr(params, "model", "three_node"))


def temperature_curves(params: Parameters) -> tuple[tuple[str, str, str], ...]:
    """(variable, legend label, colour) of the temperatures to draw; ``ball_only`` holds vial and air at ambient."""
    ball = ("theta_ball", "ball", "tab:red")
    if model_of(params) == "ball_only":
        return ball, ("theta_air", "vial and air (held at ambient: ball_only model)", "tab:green")
    return ball, ("theta_vial", "vial", "tab:blue"), ("theta_air", "air", "tab:green")


def temperature_lines(params: Parameters, series: xr.Dataset) -> list[tuple[np.ndarray, str, Any]]:
    """(temperatures in K, legend label, colour) of each line of the temperature figure: the ball, vial and
    air of :func:`temperature_curves`, or for a 'dem' run each ball (numbered as in the run's files), vial and air."""
    if not several_balls(params):
        return [(series[name].values, label, colour) for name, label, colour in temperature_curves(params)]
    balls = series[BALL_TEMPERATURES].transpose("time", "ball").values
    lines: list[tuple[np.ndarray, str, Any]] = [
        (balls[:, ball], f"ball {ball}", colour) for ball, colour in enumerate(ball_colours(balls.shape[1]))
    ]
    return lines + [(series["theta_vial"].values, "vial", "tab:blue"), (series["theta_air"].values, "air", "tab:green")]


def _fit_text(fit: ExponentialFit) -> str:
    if not (math.isfinite(fit.theta_inf) and math.isfinite(fit.tau)):
        return "exponential fit: not determined"
    return (
        f"θ∞ = {fit.theta_inf - KELVIN_OFFSET:.2f} °C\n"
        f"τ = {fit.tau / 60.0:.2f} min\n"
        f"θ̇₀ = {fit.initial_rate * 60.0:.3f} °C/min"
    )


def window_data(run: RunLike, index: int) -> xr.Dataset | None:
    """The points of record window ``index``, or None when it has too few to plot."""
    windows = run.params.record_windows
    if index >= len(windows):
        return None
    start, length = windows[index]
    times = run.windows["time"].values
    selected = run.windows.isel(time=np.flatnonzero((times >= start) & (times <= start + length)))
    return selected if selected.sizes["time"] >= MIN_POINTS_TO_PLOT else None


def heating_zoom_window(params: Parameters) -> int | None:
    """Index of the record window that starts nearest to 10 min (None without windows)."""
    if not params.record_windows:
        return None
    starts = [start for start, _ in params.record_windows]
    return int(np.argmin([abs(start - HEATING_ZOOM_TIME) for start in starts]))


def motion_figure(
    params: Parameters, window: xr.Dataset, record_window: tuple[float, float] | None = None
) -> Figure:
    """Paper Fig. 4: ball centre (with its positions at contact with either end face) and ball momentum.

    ``record_window`` (start, length) in s sets the time axis; without it the stored points do. The
    last stored step usually ends before the window does, the next step landing after it.
    """
    figure, (position_axis, momentum_axis) = _new_figure(rows=2, height=6.0)
    time = window["time"].values
    start, end = (record_window[0], sum(record_window)) if record_window else (time[0], time[-1])
    # Step points are sparse in flight, where the ball moves in straight lines but the vial does not:
    # the end faces are drawn on a grid of their own.
    drive_time = np.linspace(start, end, DRIVE_CURVE_POINTS)
    vial = np.array([kinematics.vial_position(t, params.amplitude, params.omega, params.phase) for t in drive_time])
    # The ball touches an end face (at x_v ± l_v/2) when its centre is one radius away from it.
    reach = params.vial_length / 2.0 - params.ball_radius
    position_axis.plot(time, window["x"].values * 1e3, color="tab:red", label="ball centre")
    contact_label = "ball centre at contact with an end face"
    position_axis.plot(drive_time, (vial - reach) * 1e3, color="0.4", lw=1, label=contact_label)
    position_axis.plot(drive_time, (vial + reach) * 1e3, color="0.4", lw=1)
    position_axis.set_ylabel("position (mm)")
    figure.suptitle(f"Ball position and momentum, t = {start:g}–{end:g} s (cf. paper Fig. 4a, 4b)")
    # Above the axes: inside, it would hide the turning points at the end faces.
    position_axis.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=2, fontsize="small", frameon=False)
    momentum_axis.plot(time, window["p"].values, color="tab:purple")
    momentum_axis.set_ylabel("momentum (kg·m/s)")
    momentum_axis.set_xlabel("time (s)")
    for axis in (position_axis, momentum_axis):
        axis.grid(alpha=0.3)
    return figure


def heating_zoom_figure(run: RunLike, window: xr.Dataset, start: float) -> Figure:
    """Paper Fig. 5b: ball temperature in °C (each ball's for a 'dem' run) in the window starting at
    ``start`` (s), impacts marked.

    Each impact heats the ball in a few tens of microseconds; convection cools it between impacts.
    """
    figure, (axis,) = _new_figure()
    time = window["time"].values
    balls = several_balls(run.params)
    if balls:
        temperatures = window[BALL_TEMPERATURES].transpose("time", "ball").values
        for ball, colour in enumerate(ball_colours(temperatures.shape[1])):
            axis.plot((time - start) * 1e3, to_celsius(temperatures[:, ball]), color=colour, lw=1.2, label=f"ball {ball}")
        legend_below(figure, axis.get_lines())
    else:
        axis.plot((time - start) * 1e3, to_celsius(window["theta_ball"].values), color="tab:red", lw=1.2)
    impact_times = run.impacts["time"].to_numpy()
    inside = impact_times[(impact_times >= start) & (impact_times <= time[-1])]
    for impact_time in inside:
        axis.axvline((impact_time - start) * 1e3, color="0.6", lw=0.6, ls=":")
    axis.ticklabel_format(axis="y", useOffset=False)
    axis.set_xlabel(f"time after t = {start:g} s (ms)")
    axis.set_ylabel("ball temperature (°C)")
    heated = "Heating of each ball" if balls else "Ball heating"
    axis.set_title(f"{heated} at each of {len(inside)} impacts (dotted), cooling between (cf. paper Fig. 5b)")
    axis.grid(alpha=0.3)
    return figure


def impact_span(run: RunLike) -> float:
    """The seconds the impact table covers: the whole run, or the averaged solver's averaging window.

    The summary's impact rate is the table's impacts over that span, whichever solver wrote it.
    """
    rate = run.summary.get("impact_rate_hz")
    if rate is None or not rate > 0.0:
        return float(run.summary.get("simulated_s", run.params.duration))
    return len(run.impacts) / float(rate)


def heat_by_channel_figure(run: RunLike) -> Figure:
    """A 'dem' run's heat as mean power (W): made in each dissipation channel (MODEL.md §12.4), stacked by
    what was hit (left, from the impact table), and received by each ball and the vial (right, from the
    sampled history)."""
    figure, (made, received) = _new_figure(height=4.2, columns=2, width=11.0)
    impacts = run.impacts
    kinds, categories = impact_kinds(impacts)
    span = impact_span(run)
    positions = np.arange(len(CHANNELS))
    total = np.zeros(len(CHANNELS))
    for kind, label, colour in categories:
        hit = impacts[kinds == kind]
        power = run.params.eta * np.array([hit[f"dissipated_{channel}"].sum() for channel in CHANNELS]) / span
        made.bar(positions, power, bottom=total, color=colour, label=f"{label} ({power.sum():.3g} W)")
        total += power
    for position, value in zip(positions, total):
        made.annotate(f"{value:.3g} W", (position, value), xytext=(0, 2), textcoords="offset points", ha="center", va="bottom")
    made.set_xticks(positions, CHANNELS)
    made.set_xlabel("dissipation channel")
    made.set_ylabel("heat generated, mean power (W)")
    covered = averaging_window_note(run)
    made.set_title(f"made in each channel, by what was hit: {total.sum():.3g} W" + (f"\n({covered})" if covered else ""))
    made.legend(loc="upper right", fontsize="small")
    _heat_received(received, run)
    figure.suptitle("Heat of the impacts, as mean power")
    for axis in (made, received):
        axis.set_ylim(0.0, axis.get_ylim()[1] * 1.15)  # room for the numbers on the bars
        axis.grid(alpha=0.3, axis="y")
    return figure


def _heat_received(axis: object, run: RunLike) -> None:
    """Bars of the mean heat power into each ball (numbered as in the run's files) and into the vial."""
    series = run.timeseries
    seconds = float(series["time"].values[-1]) or math.nan
    balls = series["heat_into_balls"].transpose("time", "ball").values[-1] / seconds
    powers = [*balls, float(series["heat_into_vial"].values[-1]) / seconds]
    names = [str(ball) for ball in range(balls.size)] + ["vial"]
    axis.bar(range(len(powers)), powers, color=[*ball_colours(balls.size), "tab:blue"])  # type: ignore[attr-defined]
    axis.set_xticks(range(len(powers)), names)  # type: ignore[attr-defined]
    axis.set_xlabel("ball (numbered as in the run's files), and the vial")  # type: ignore[attr-defined]
    axis.set_ylabel("heat received, mean power (W)")  # type: ignore[attr-defined]
    axis.set_title(f"received by each ball and the vial: {sum(powers):.3g} W")  # type: ignore[attr-defined]


WALLS = (("left", "left end face", "tab:blue"), ("right", "right end face", "tab:orange"))
# What a ball of the 'dem' engine hits (its impact table's column ``target``).
TARGETS = (*WALLS, ("side", "side wall", "tab:green"), ("ball", "another ball", "tab:purple"))
HISTOGRAM_BINS = 60
HISTOGRAM_HEADROOM = 1.35
# Impacts per second are counted in bins of at least a second (a few drive periods), at most this many bins.
RATE_BINS = 120
MIN_RATE_BIN_S = 1.0
# Beyond this span the rate is plotted against minutes, as the temperatures are.
MINUTES_AXIS_FROM_S = 300.0


def impact_figures(run: RunLike) -> dict[str, Figure]:
    """Histograms of impact speed and dissipated energy, impacts per second at each wall, and (1-D) the
    impact phases; none without impacts."""
    impacts = run.impacts
    if impacts.empty:
        return {}
    balls = several_balls(run.params)
    speed = "normal impact speed relative to what is hit" if balls else "impact speed relative to the end face"
    figures = {
        "impact_speed_histogram": impact_histogram_figure(impacts, "impact_speed", 1.0, speed, "m/s"),
        "impact_energy_histogram": impact_histogram_figure(
            impacts, "dissipated_energy", 1e3, "energy dissipated per impact", "mJ"
        ),
        "impacts_per_second": impact_rate_figure(impacts),
    }
    if not balls:
        # Regimes are sequences of end faces hit at fixed drive phases: a notion of one ball on the axis.
        figures["impact_phase_histogram"] = impact_phase_figure(run)
    context, window = run_context(run), averaging_window_note(run)
    return {name: add_context(figure, context, window) for name, figure in figures.items()}


def impact_kinds(impacts: pd.DataFrame) -> tuple[np.ndarray, tuple[tuple[str, str, str], ...]]:
    """What each impact hit, and the kinds to tell apart as (name, label, colour): the end faces of a 1-D
    run (column ``wall``), or the end faces, the side wall and another ball of a 'dem' run (``target``)."""
    if "target" in impacts:
        return impacts["target"].to_numpy(), TARGETS
    return impacts["wall"].to_numpy(), WALLS


def impact_histogram_figure(impacts: pd.DataFrame, column: str, scale: float, quantity: str, unit: str) -> Figure:
    """Histogram of ``column`` × ``scale`` (in ``unit``), stacked by what was hit (:func:`impact_kinds`), with the
    mean and maximum in a box."""
    figure, (axis,) = _new_figure(height=4.0)
    values = impacts[column].to_numpy() * scale
    edges = np.histogram_bin_edges(values, bins=HISTOGRAM_BINS)
    _stacked_by_kind(axis, values, *impact_kinds(impacts), edges)
    axis.text(
        0.98, 0.96, f"mean {values.mean():.3g} {unit}\nmax {values.max():.3g} {unit}",
        transform=axis.transAxes, ha="right", va="top",
        bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.85},
    )
    # Headroom above the highest bar for the legend and the statistics box.
    axis.set_ylim(0.0, axis.get_ylim()[1] * HISTOGRAM_HEADROOM)
    axis.set_xlabel(f"{quantity} ({unit})")
    axis.set_ylabel("impacts per bin (count)")
    axis.set_title(f"Distribution of the {quantity} ({len(values)} impacts)")
    axis.legend(loc="upper left")
    axis.grid(alpha=0.3)
    return figure


def _stacked_by_kind(
    axis: object, values: np.ndarray, kinds: np.ndarray, categories: Sequence[tuple[str, str, str]], edges: np.ndarray
) -> None:
    """A histogram of ``values`` stacked by what was hit (``categories``: :func:`impact_kinds`), each labelled with its count."""
    parts = [values[kinds == kind] for kind, _, _ in categories]
    axis.hist(  # type: ignore[attr-defined]
        parts,
        bins=edges,
        stacked=True,
        color=[colour for _, _, colour in categories],
        label=[f"{label} ({len(part)})" for (_, label, _), part in zip(categories, parts)],
    )


def rate_bin_edges(first_impact: float, last_impact: float) -> np.ndarray:
    """Equal bins from the first to the last impact: at least :data:`MIN_RATE_BIN_S` wide, :data:`RATE_BINS` at most.

    The averaged solver keeps only the impacts after its start-up transient, so the bins start at the
    first impact, not at t = 0.
    """
    span = max(last_impact - first_impact, MIN_RATE_BIN_S)
    bins = int(min(RATE_BINS, max(1.0, span // MIN_RATE_BIN_S)))
    return np.linspace(first_impact, first_impact + span, bins + 1)


def impact_rate_figure(impacts: pd.DataFrame) -> Figure:
    """Impacts per second on each kind of target (:func:`impact_kinds`) against time, counted in the bins of
    :func:`rate_bin_edges`."""
    figure, (axis,) = _new_figure(height=4.0)
    times = impacts["time"].to_numpy()
    edges = rate_bin_edges(float(times.min()), float(times.max()))
    width = edges[1] - edges[0]
    in_minutes = edges[-1] >= MINUTES_AXIS_FROM_S
    time_scale = 60.0 if in_minutes else 1.0
    kinds, categories = impact_kinds(impacts)
    for kind, label, colour in categories:
        counts, _ = np.histogram(times[kinds == kind], bins=edges)
        rates = counts / width
        legend = f"{label} (mean {rates.mean():.3g}/s)"
        # No baseline: the vertical edges down to zero at both ends would read as a drop in the rate.
        axis.stairs(rates, edges / time_scale, baseline=None, color=colour, lw=1.5, label=legend)
    axis.set_ylim(bottom=0.0)
    axis.set_xlabel("time (min)" if in_minutes else "time (s)")
    axis.set_ylabel("impacts per second (1/s)")
    where = "at each end face" if categories == WALLS else "on each wall and between balls"
    axis.set_title(f"Impacts per second {where} (bins of {width:.3g} s)")
    axis.legend(loc="best")
    axis.grid(alpha=0.3)
    return figure


PHASE_BINS = 72  # 5° bins


def impact_phase_figure(run: RunLike) -> Figure:
    """Distribution of the drive phase ωt + φ (mod 2π) at the impacts of the settled motion, by end face.

    A periodic motion hits at a few sharp phases; an irregular one spreads them. The start-up
    transient is left out (the second half of a full run; the averaged solver's impacts are settled).
    """
    from shakermill.analysis.regime import classify_impacts, impact_phases, settled_run_impacts

    settled = settled_run_impacts(run)
    params = run.params
    phases = impact_phases(settled, params.omega, params.phase)
    regime, _ = classify_impacts(settled, params.omega, params.phase)
    figure, (axis,) = _new_figure(height=4.0)
    edges = np.linspace(0.0, 2 * math.pi, PHASE_BINS + 1)
    _stacked_by_kind(axis, phases.phase, phases.wall, WALLS, edges)
    _radian_ticks(axis.xaxis)
    axis.set_xlim(0.0, 2 * math.pi)
    axis.set_ylim(0.0, axis.get_ylim()[1] * HISTOGRAM_HEADROOM)
    axis.set_xlabel("drive phase at impact, ωt + φ mod 2π (rad)")
    axis.set_ylabel("impacts per 5° bin (count)")
    axis.set_title(f"Impact phases of the settled motion ({len(settled['time'])} impacts, {regime})")
    axis.legend(loc="upper left")
    axis.grid(alpha=0.3)
    return figure


def _radian_ticks(axis: object) -> None:
    ticks = np.arange(5) * math.pi / 2
    axis.set_ticks(ticks, ["0", "π/2", "π", "3π/2", "2π"])  # type: ignore[attr-defined]


def comparison_temperature_figure(runs: dict[str, RunLike]) -> Figure:
    """Ball (solid) and vial (dashed) temperatures in °C of up to four runs, labelled by the keys of ``runs``.

    The vial of a ``ball_only`` run is held at ambient and is left out.
    """
    figure, (axis,) = _new_figure()
    for (label, run), colour in zip(runs.items(), ("tab:red", "tab:blue", "tab:green", "tab:purple")):
        minutes = run.timeseries["time"].values / 60.0
        axis.plot(minutes, to_celsius(run.timeseries["theta_ball"].values), color=colour, label=f"{label}: ball")
        if model_of(run.params) != "ball_only":
            vial = to_celsius(run.timeseries["theta_vial"].values)
            axis.plot(minutes, vial, color=colour, ls="--", label=f"{label}: vial")
    axis.set_xlabel("time (min)")
    axis.set_ylabel("temperature (°C)")
    axis.set_title("Ball and vial temperatures of the compared runs")
    axis.legend(loc="upper left", fontsize="small")
    axis.grid(alpha=0.3)
    return figure


def png_bytes(figure: Figure, dpi: int = PNG_DPI) -> bytes:
    """``figure`` rendered as PNG, in memory (for embedding in a report)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    return buffer.getvalue()


# Sweeps and regime maps ------------------------------------------------------------------------------

# (column of the sweep table, quantity, unit) drawn by `shakermill plot SWEEP_DIR`.
SWEEP_QUANTITIES = (
    ("theta_inf_C", "ball θ∞ of the exponential fitted over the run", "°C"),
    ("tau_min", "time constant τ", "min"),
    ("impact_rate_hz", "impact rate", "1/s"),
    ("heat_power_W", "heat generated", "W"),
    ("mean_impact_speed_m_s", "mean impact speed", "m/s"),
    ("ball_steady_C", "ball steady state", "°C"),
)
# Lengths read better in mm: a vial is a few centimetres long.
DISPLAY_UNITS = {"m": (1e3, "mm")}
CONTOUR_STYLE = {"colors": "white", "linewidths": 2.0, "linestyles": "--"}
NOTE_STYLE = {"fontsize": "small", "ha": "left", "va": "bottom", "bbox": {"facecolor": "white", "alpha": 0.85, "edgecolor": "0.6"}}
REGIME_COLOURS = {"no impacts": "0.85", "irregular": "0.25"}
# No red: it marks the failed points.
PERIOD_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")


# Short names of the sweep columns for contour labels ("ball θ∞ = 60 °C"); other columns go by their own name.
SHORT_NAMES = {
    "theta_inf_C": "ball θ∞",
    "tau_min": "τ",
    "impact_rate_hz": "impact rate",
    "heat_power_W": "heat power",
    "mean_impact_speed_m_s": "mean impact speed",
    "ball_steady_C": "ball steady state",
}
# Units of the summary columns by the suffix of their names (theta_inf_C, tau_min, impact_rate_hz, ...).
SUFFIX_UNITS = (("_C", "°C"), ("_K", "K"), ("_min", "min"), ("_hz", "1/s"), ("_W", "W"), ("_m_s", "m/s"), ("_J", "J"), ("_s", "s"))
MISSING_STYLE = {"marker": "x", "color": "tab:red", "s": 40, "zorder": 3}


def contour_label(column: str, level: float) -> str:
    """``("theta_inf_C", 60)`` -> ``"ball θ∞ = 60 °C"``: the quantity's name and unit, not the column's."""
    unit = next((unit for suffix, unit in SUFFIX_UNITS if column.endswith(suffix)), "")
    return f"{SHORT_NAMES.get(column, column)} = {level:g} {unit}".rstrip()


def rpm_axis(axis: object, key: str, which: str = "x") -> None:
    """A second ω axis in rpm (drive cycles per minute, as mills are specified) when ``key`` is omega."""
    if key != "omega":
        return
    to_rpm = 60.0 / (2.0 * math.pi)
    functions = (lambda omega: omega * to_rpm, lambda rpm: rpm / to_rpm)
    if which == "x":
        secondary = axis.secondary_xaxis("top", functions=functions)  # type: ignore[attr-defined]
        secondary.set_xlabel("drive frequency (rpm)")
    else:
        secondary = axis.secondary_yaxis("left", functions=functions)  # type: ignore[attr-defined]
        secondary.set_ylabel("drive frequency (rpm)")
        # Outside the rad/s ticks of the same side, so that the two scales do not overlap.
        secondary.spines["left"].set_position(("outward", 45))


def sweep_context(manifest: Mapping[str, Any], keys: Sequence[str]) -> str:
    """"spex8000m, 60 min, averaged solver" from a sweep's ``sweep.json``; the duration only when it is not swept."""
    base = manifest.get("base", {})
    duration = base.get("duration")
    parts = [
        manifest.get("preset"),
        f"{duration / 60.0:.3g} min" if duration is not None and "duration" not in keys else None,
        f"{base['solver']} solver" if "solver" in base and "solver" not in keys else None,
    ]
    return ", ".join(part for part in parts if part)


def axis_label(key: str) -> str:
    """``"amplitude (mm)"``: the key with the unit its values are drawn in."""
    from shakermill.parameters.schema import field_unit

    unit = DISPLAY_UNITS.get(field_unit(key), (1.0, field_unit(key)))[1]
    return f"{key} ({unit})" if unit else f"{key} (–)"


def display_values(key: str, values: np.ndarray) -> np.ndarray:
    from shakermill.parameters.schema import field_unit

    return np.asarray(values, dtype=float) * DISPLAY_UNITS.get(field_unit(key), (1.0, ""))[0]


@dataclass(frozen=True)
class KeyAxis:
    """Where each value of a swept key lies on an axis, and the tick labels when the values are names."""

    positions: np.ndarray
    names: tuple[str, ...] = ()

    def mark(self, axis: object, which: str = "x") -> None:
        """One tick per name (nothing for numbers, whose ticks matplotlib chooses)."""
        if self.names:
            set_ticks = axis.set_xticks if which == "x" else axis.set_yticks  # type: ignore[attr-defined]
            set_ticks(range(len(self.names)), self.names)


def key_axis(key: str, values: Sequence[Any]) -> KeyAxis:
    """Numbers in their display unit; names (a points file sweeping ``solver`` or ``model``) one tick apart, sorted."""
    try:
        return KeyAxis(display_values(key, np.asarray(values)))
    except ValueError:
        text = [str(value) for value in values]
        names = tuple(sorted(set(text)))
        return KeyAxis(np.array([names.index(value) for value in text], dtype=float), names)


def parse_contour(spec: str, columns: Sequence[str]) -> tuple[str, float]:
    """``"theta_inf_C=60"`` -> ``("theta_inf_C", 60.0)``, the column checked against ``columns``."""
    from shakermill.parameters.schema import ParameterError

    column, separator, level = spec.partition("=")
    column = column.strip()
    if not separator or not column:
        raise ParameterError(f"contour {spec!r}: expected COLUMN=VALUE, for example theta_inf_C=60")
    if column not in columns:
        shown = ", ".join(columns)
        raise ParameterError(f"contour {spec!r}: {column} is not a numeric column of the sweep table; allowed: {shown}")
    try:
        value = float(level)
    except ValueError:
        raise ParameterError(f"contour {spec!r}: {level.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise ParameterError(f"contour {spec!r}: the level must be a finite number")
    return column, value


def sweep_figures(
    table: pd.DataFrame, keys: Sequence[str], contours: Sequence[tuple[str, float]] = (), *, context: str = ""
) -> dict[str, Figure]:
    """Lines (one swept key) or maps (two) of :data:`SWEEP_QUANTITIES` and of the regime, by figure name.

    ``contours`` are (column, level) pairs drawn on every map (on lines: where the column crosses
    the level), so the 60 °C line of θ∞ can be read off the impact-rate map too. Failed points are
    marked with a red x. ``context`` (preset, duration: :func:`sweep_context`) goes under every title.
    Sweeps over more keys are not drawn: their table is the result.
    """
    from shakermill.parameters.schema import ParameterError

    if len(keys) not in (1, 2):
        raise ParameterError(
            f"plot: a sweep over {len(keys)} keys ({', '.join(keys)}) has no map; "
            "1-key sweeps are drawn as lines and 2-key sweeps as maps; read sweep.parquet for the rest"
        )
    # A failed point keeps its place in the grid, with no values: a gap in the line, a blank cell.
    data = table.copy()
    for column in {column for column, _, _ in SWEEP_QUANTITIES} | {column for column, _ in contours}:
        data[column] = _finished_values(table, column)
    notes = contour_notes(table, contours)
    figures = {}
    for column, quantity, unit in SWEEP_QUANTITIES:
        if len(keys) == 1:
            figure = sweep_line_figure(data, keys[0], column, quantity, unit, contours)
        else:
            figure = sweep_map_figure(data, keys, column, quantity, unit, contours)
        if notes:
            # Said on the figure: a map without its 60 °C line would otherwise look like a forgotten option.
            figure.axes[0].text(0.01, 0.01, "\n".join(notes), transform=figure.axes[0].transAxes, **NOTE_STYLE)
        figures[f"sweep_{column}"] = figure
    figures["sweep_regime"] = regime_figure(table, keys)
    return {name: add_context(figure, context) for name, figure in figures.items()}


def contour_notes(table: pd.DataFrame, contours: Sequence[tuple[str, float]]) -> list[str]:
    """One line per contour level that no pair of finished points straddles, so that none is drawn."""
    notes = []
    for column, level in contours:
        values = _finished_values(table, column)
        values = values[np.isfinite(values)]
        if values.size == 0:
            notes.append(f"{column} = {level:g}: no finished point has a value")
        elif not _straddled(values, level):
            side = "above" if values.min() >= level else "below"
            notes.append(
                f"{column} = {level:g} not crossed: {column} is {values.min():.4g} to {values.max():.4g}, {side} it at every point"
            )
    return notes


def _straddled(values: np.ndarray, level: float) -> bool:
    """Whether the finite ``values`` lie on both sides of ``level``: only then is there a contour to draw."""
    finite = values[np.isfinite(values)]
    return finite.size > 0 and finite.min() < level < finite.max()


def _finished_values(table: pd.DataFrame, column: str) -> np.ndarray:
    """``column`` as floats, NaN for the points that failed."""
    return np.where(table["error"].isna(), _numeric(table, column), np.nan)


def _numeric(table: pd.DataFrame, column: str) -> np.ndarray:
    return pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)


def sweep_line_figure(
    table: pd.DataFrame, key: str, column: str, quantity: str, unit: str, contours: Sequence[tuple[str, float]]
) -> Figure:
    figure, (axis,) = _new_figure(height=4.0)
    ordered = table.sort_values(key)
    key_values = key_axis(key, ordered[key].to_numpy())
    x = key_values.positions
    y = _numeric(ordered, column)
    axis.plot(*_broken_at_regime_changes(x, y, _regimes(ordered)), "o-", color="tab:blue", ms=4)
    missing = ~np.isfinite(y)
    if missing.any():
        # At the foot of the axis: a failed point has no value to place it at, but it must not vanish.
        axis.scatter(x[missing], np.zeros(missing.sum()), transform=axis.get_xaxis_transform(), clip_on=False,
                     label=f"failed or no value ({missing.sum()})", **MISSING_STYLE)
    for contour_column, level in contours:
        values = _numeric(ordered, contour_column)
        for crossing in _crossings(x, values, level):
            axis.axvline(crossing, color="0.3", ls="--", lw=1)
        if contour_column == column:
            axis.axhline(level, color="0.3", ls=":", lw=1)
        if len(_crossings(x, values, level)):
            axis.plot([], [], color="0.3", ls="--", lw=1, label=contour_label(contour_column, level))
    if axis.get_legend_handles_labels()[0]:
        axis.legend(loc="best")
    axis.set_xlabel(axis_label(key))
    key_values.mark(axis)
    rpm_axis(axis, key)
    axis.set_ylabel(f"{quantity} ({unit})")
    axis.set_title(f"{quantity} against {key} ({len(ordered)} points; lines break where the regime changes)")
    axis.grid(alpha=0.3)
    return figure


def _regimes(table: pd.DataFrame) -> np.ndarray:
    """The regime of each point ("failed" where it failed); one regime for all in tables without the column."""
    regimes = table["regime"].astype(object) if "regime" in table else pd.Series("", index=table.index, dtype=object)
    return regimes.where(table["error"].isna(), "failed").to_numpy()


def _broken_at_regime_changes(x: np.ndarray, y: np.ndarray, regimes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) with a NaN point between neighbours of different regimes: matplotlib does not join across it.

    A line between a period-1 and a period-2 point would suggest values between them that no motion has.
    """
    changes = np.flatnonzero(regimes[1:] != regimes[:-1]) + 1
    return np.insert(x, changes, np.nan), np.insert(y, changes, np.nan)


def _crossings(x: np.ndarray, values: np.ndarray, level: float) -> np.ndarray:
    """The x at which the piecewise-linear curve through (x, values) crosses ``level``."""
    above = values - level
    found = []
    for i in range(len(x) - 1):
        a, b = above[i], above[i + 1]
        if np.isfinite(a) and np.isfinite(b) and a * b < 0:
            found.append(x[i] + (x[i + 1] - x[i]) * a / (a - b))
        elif a == 0:
            found.append(x[i])
    return np.asarray(found)


def _grid_of(x: np.ndarray, y: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(x values, y values, Z[y, x]) when the points (x, y) form a complete grid, else None."""
    xs, ys = np.unique(x), np.unique(y)
    if len(xs) < 2 or len(ys) < 2 or len(values) != len(xs) * len(ys):
        return None
    grid = np.full((len(ys), len(xs)), np.nan)
    grid[np.searchsorted(ys, y), np.searchsorted(xs, x)] = values
    return xs, ys, grid


def _cell_edges(centres: np.ndarray) -> np.ndarray:
    middle = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - middle[0]], middle, [2 * centres[-1] - middle[-1]]])


def sweep_map_figure(
    table: pd.DataFrame,
    keys: Sequence[str],
    column: str,
    quantity: str,
    unit: str,
    contours: Sequence[tuple[str, float]],
) -> Figure:
    """A heat map over a grid of the two keys (first key across), or coloured points for scattered points."""
    figure, (axis,) = _new_figure(height=5.0)
    x_key, y_key = keys
    x_values, y_values = key_axis(x_key, table[x_key].to_numpy()), key_axis(y_key, table[y_key].to_numpy())
    x_all, y_all = x_values.positions, y_values.positions
    gridded = _grid_of(x_all, y_all, _numeric(table, column)) if not table.empty else None
    if gridded is not None:
        x, y, values = gridded
        mesh = axis.pcolormesh(_cell_edges(x), _cell_edges(y), np.ma.masked_invalid(values), cmap="inferno", shading="flat")
        for contour_column, level in contours:
            _, _, levels = _grid_of(x_all, y_all, _numeric(table, contour_column))  # type: ignore[misc]
            if _straddled(levels, level):
                lines = axis.contour(x, y, levels, levels=[level], **CONTOUR_STYLE)
                axis.clabel(lines, fmt=contour_label(contour_column, level), fontsize="small")
    else:
        # A points file: no cells to fill.
        mesh = axis.scatter(x_all, y_all, c=_numeric(table, column), cmap="inferno", s=60, edgecolors="0.3")
        for contour_column, level in contours:
            levels = _numeric(table, contour_column)
            if len(x_all) >= 3 and _straddled(levels, level):
                lines = axis.tricontour(x_all, y_all, levels, levels=[level], colors="0.3", linestyles="--")
                axis.clabel(lines, fmt=contour_label(contour_column, level), fontsize="small")
    _mark_missing(axis, x_all, y_all, _numeric(table, column))
    x_values.mark(axis)
    y_values.mark(axis, "y")
    figure.colorbar(mesh, ax=axis, label=f"{quantity} ({unit})")
    axis.set_xlabel(axis_label(x_key))
    axis.set_ylabel(axis_label(y_key))
    rpm_axis(axis, x_key)
    rpm_axis(axis, y_key, which="y")
    axis.set_title(f"{quantity} over {x_key} and {y_key} ({len(table)} points)")
    return figure


def _mark_missing(axis: object, x: np.ndarray, y: np.ndarray, values: np.ndarray) -> None:
    """A red x on each point without a value (failed, or NaN), so that a blank cell reads as a missing point."""
    missing = ~np.isfinite(values)
    if missing.any():
        axis.scatter(x[missing], y[missing], label=f"failed or no value ({missing.sum()})", **MISSING_STYLE)  # type: ignore[attr-defined]
        axis.legend(loc="upper left", bbox_to_anchor=(0.0, -0.12), fontsize="small", frameon=False)  # type: ignore[attr-defined]


def regime_figure(table: pd.DataFrame, keys: Sequence[str]) -> Figure:
    """The regime of each point (period-n, irregular, no impacts; failed points open) over the swept keys.

    The regime is the configured start's; points where other starts settle elsewhere are framed.
    """
    figure, (axis,) = _new_figure(height=4.0 if len(keys) == 1 else 5.0)
    x_values = key_axis(keys[0], table[keys[0]].to_numpy())
    y_values = key_axis(keys[1], table[keys[1]].to_numpy()) if len(keys) == 2 else KeyAxis(np.zeros(len(table)))
    x, y = x_values.positions, y_values.positions
    labels = table["regime"].astype(object).where(table["error"].isna(), "failed")
    present = sorted(set(labels), key=_regime_order)
    periods = [label for label in present if label.startswith("period-")]
    for label in present:
        inside = (labels == label).to_numpy()
        if label == "failed":
            axis.scatter(x[inside], y[inside], marker="x", color="tab:red", s=40, label=f"failed ({inside.sum()})")
            continue
        # Colours by rank among the periods present, so that period-4 and period-12 never share one.
        colour = PERIOD_COLOURS[periods.index(label) % len(PERIOD_COLOURS)] if label in periods else REGIME_COLOURS[label]
        axis.scatter(x[inside], y[inside], marker="s", s=70, color=colour, label=f"{label} ({inside.sum()})")
    if "n_attractors" in table:  # sweeps before attractors were probed have no such column
        several = _numeric(table, "n_attractors") > 1
        axis.scatter(
            x[several], y[several], marker="s", s=150, facecolors="none", edgecolors="black", lw=1.2,
            label=f"more than one attractor ({several.sum()})",
        )
    axis.set_xlabel(axis_label(keys[0]))
    x_values.mark(axis)
    rpm_axis(axis, keys[0])
    if len(keys) == 2:
        axis.set_ylabel(axis_label(keys[1]))
        y_values.mark(axis, "y")
        rpm_axis(axis, keys[1], which="y")
    else:
        axis.set_yticks([])
        axis.set_ylabel("regime (–)")
    axis.set_title("Regime of the settled motion (from the impact phases)")
    axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return figure


def _regime_order(label: str) -> tuple[int, int]:
    """period-1, period-2, …, then irregular, no impacts, failed."""
    if label.startswith("period-"):
        return 0, int(label.removeprefix("period-"))
    return 1, ("irregular", "no impacts", "failed").index(label)


# End faces in the bifurcation diagram, where the colour tells the attractors apart.
WALL_MARKERS = (("left", "left end face", "o"), ("right", "right end face", "x"))
# Marker area in the period panel of an attractor reached from every start (pt²).
FULL_BASIN_AREA = 60.0


def bifurcation_figure(phases: pd.DataFrame, attractors: pd.DataFrame, key: str, *, context: str = "") -> Figure:
    """Bifurcation diagram: the drive phase of every settled impact against ``key`` (top) and the period of
    each attractor (bottom), coloured by attractor; attractor 0 is the configured start's at every value."""
    figure, (phase_axis, period_axis) = _new_figure(rows=2, height=7.0)
    labels = sorted(set(attractors["attractor"]) | set(phases["attractor"]))
    for label in labels:
        colour = PERIOD_COLOURS[label % len(PERIOD_COLOURS)]
        for wall, _, marker in WALL_MARKERS:
            inside = (phases["attractor"] == label) & (phases["wall"] == wall)
            x = display_values(key, phases.loc[inside, key].to_numpy())
            phase_axis.scatter(x, phases.loc[inside, "phase"], s=4, marker=marker, color=colour, alpha=0.6, lw=0.6)
    _radian_ticks(phase_axis.yaxis)
    phase_axis.set_ylim(0.0, 2 * math.pi)
    phase_axis.set_ylabel("impact phase ωt + φ mod 2π (rad)")
    # Above the axes: inside, the legend would hide branches near 0 or 2π.
    phase_axis.legend(
        handles=_attractor_handles(labels) + _wall_handles(),
        loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=4, fontsize="small", frameon=False,
    )
    figure.suptitle(f"Bifurcation diagram over {key}: impact phases of every attractor")
    _attractor_periods(period_axis, attractors, key)
    period_axis.set_xlabel(axis_label(key))
    # Between the panels: above the phases it would run into their legend.
    rpm_axis(period_axis, key)
    add_context(figure, context)
    for axis in (phase_axis, period_axis):
        axis.grid(alpha=0.3)
    return figure


def _attractor_periods(axis: object, attractors: pd.DataFrame, key: str) -> None:
    """Period of each attractor, irregular ones above the largest period; marker area ∝ basin fraction."""
    from matplotlib.ticker import MaxNLocator

    periods = pd.to_numeric(attractors["period"], errors="coerce").to_numpy(dtype=float)
    top = np.nanmax(periods, initial=1.0) + 1
    irregular = (attractors["regime"] == "irregular").to_numpy()
    shown = np.where(irregular, top, periods)
    x = display_values(key, attractors[key].to_numpy())
    colours = [PERIOD_COLOURS[label % len(PERIOD_COLOURS)] for label in attractors["attractor"]]
    # Open markers: two attractors of the same period at one value show as concentric rings.
    axis.scatter(x, shown, s=FULL_BASIN_AREA * attractors["basin_fraction"].to_numpy(), facecolors="none", edgecolors=colours)  # type: ignore[attr-defined]
    # Periods are whole numbers: half a period of room either way keeps the ticks on them.
    axis.set_ylim(0.5, np.nanmax(shown, initial=1.0) + 0.5)  # type: ignore[attr-defined]
    ticks = [tick for tick in MaxNLocator(integer=True, min_n_ticks=1).tick_values(1, top - 1) if 1 <= tick < top]
    labels = [f"{tick:g}" for tick in ticks]
    if irregular.any():
        # Irregular motion has no period: its row is named, not numbered, and ruled off from the periods.
        axis.axhline(top - 0.5, color="0.3", lw=1.0, ls="--")  # type: ignore[attr-defined]
        ticks, labels = [*ticks, top], [*labels, "irregular"]
    axis.set_yticks(ticks, labels)  # type: ignore[attr-defined]
    axis.set_ylabel("period n (drive periods)\nmarker area ∝ basin fraction")  # type: ignore[attr-defined]


def _attractor_handles(labels: Sequence[int]) -> list:
    from matplotlib.lines import Line2D

    return [
        Line2D([], [], ls="", marker="s", color=PERIOD_COLOURS[label % len(PERIOD_COLOURS)],
               label="attractor 0 (configured start)" if label == 0 else f"attractor {label}")
        for label in labels
    ]


def _wall_handles() -> list:
    from matplotlib.lines import Line2D

    return [Line2D([], [], ls="", marker=marker, color="0.3", label=name) for _, name, marker in WALL_MARKERS]


def plot_figures(figures: dict[str, Figure], out_dir: Path | str, *, dpi: int = PNG_DPI) -> list[Path]:
    """Save each of ``figures`` as PNG and SVG in ``out_dir``; return the files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    remove_abandoned_writes(out)
    written: list[Path] = []
    for name, figure in figures.items():
        written.extend(save_figure(figure, out / name, dpi=dpi))
    return written
