"""The figures of a run: the paper's Figs. 4, 5a and 5b, and, for an engine of several balls, their paths and the heat
by dissipation channel (the impact statistics are in :mod:`impacts`).

The paper's figures (Son 2025, section 4): ``ball_motion`` is Fig. 4 (position
and momentum over the first recorded window, the first second by default),
``temperatures`` is Fig. 5a (ball, vial and air with the ball's fitted
exponential) and ``ball_heating_zoom`` is Fig. 5b (100 ms at 10 min: heating at
each impact, convective cooling between). The impact figures are this
package's own: histograms of impact speed and dissipated energy per impact, and
the impacts per second at each end face.

A run of an engine of several balls in three dimensions (the 'dem' engine, MODEL.md §12) has no ball on the axis
to draw as in Fig. 4: its paths are drawn in the vial frame instead (``trajectories``,
:mod:`shakermill.views.trajectories`), its temperature figures have a line per ball, ``heat_by_channel``
splits the heat by dissipation channel and contact, and the impact figures tell the end faces, the side
wall and the other balls apart.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from shakermill.analysis.fit import ExponentialFit
from shakermill.engines.records import BALL_TEMPERATURES, HEAT_INTO_NODES, NODE_NAMES
from shakermill.parameters.defaults import ANIMATION_FRAMES, PNG_DPI
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.physics import kinematics
from shakermill.support.atomic import remove_abandoned_writes, write_bytes_atomically
from shakermill.views.figures.common import (
    KELVIN_OFFSET,
    RunLike,
    add_context,
    averaging_window_note,
    check_window,
    legend_below,
    new_figure,
    plot_figures,
    run_context,
    several_balls,
    to_celsius,
    window_data,
)
from shakermill.views.figures.impacts import impact_figures, impact_kinds, spectrum_figures
from shakermill.views.trajectories import ANIMATION_DPI, animation_gif, ball_colours, trajectory_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from shakermill.solvers.summary import Summary

# Figure names (file stems): the paper's Figs. 5a, 4, 5b, and this package's impact statistics.
PAPER_FIGURES = ("temperatures", "ball_motion", "ball_heating_zoom")
# The same for the 'dem' engine: Fig. 5a and 5b with a line per ball, the paths in the vial frame, the heat by channel.
SEVERAL_BALL_FIGURES = ("temperatures", "trajectories", "heat_by_channel", "ball_heating_zoom")
# The colours of the nodes other than the balls, in the network's order (the vial, the air, then any others).
NODE_COLOURS = ("tab:blue", "tab:green", "tab:purple", "tab:brown", "tab:olive")
# The paper's Fig. 5b zooms into the heating at 10 min; the window starting nearest to it is shown.
HEATING_ZOOM_TIME = 600.0
DRIVE_CURVE_POINTS = 2000


def plot_run(run: RunLike, out_dir: Path | str, *, impacts: bool = False, dpi: int = PNG_DPI) -> list[Path]:
    """Write the paper's figures of ``run`` (and the impact figures if asked) into ``out_dir``; return the files."""
    return plot_figures(run_figures(run, impacts=impacts), out_dir, dpi=dpi)


def run_figures(run: RunLike, *, impacts: bool = False, window: int = 0) -> dict[str, Figure]:
    """The figures of ``run`` by name: those of :func:`main_figure_names` its data allow, then the impact
    figures, or for a run of several balls at least its stress-energy spectrum; the motion (``ball_motion``,
    ``trajectories``) is drawn over record window ``window``."""
    figures = paper_figures(run, window=window)
    if impacts:
        figures.update(impact_figures(run))
    elif several_balls(run.params):
        figures.update(spectrum_figures(run))
    return figures


def main_figure_names(params: Parameters) -> tuple[str, ...]:
    """The figures a run of ``params`` gets besides the impact statistics, where its data allow them."""
    return SEVERAL_BALL_FIGURES if several_balls(params) else PAPER_FIGURES


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
    if params.n_balls == 0:
        return figures  # an empty mill has no motion and no contact to draw
    motion = window_data(run, window)
    if motion is not None:
        name, draw = ("trajectories", trajectory_figure) if balls else ("ball_motion", motion_figure)
        figures[name] = draw(params, motion, params.record_windows[window])
    if balls:
        figures["heat_by_channel"] = heat_by_channel_figure(run)
    zoom_index = heating_zoom_window(params)
    zoom = window_data(run, zoom_index) if zoom_index is not None else None
    if zoom is not None and zoom_index is not None:
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
    if params.n_balls == 0:
        raise ParameterError(
            "animate: the animation shows the balls of a 'dem' run; this run is an empty mill (n_balls = 0)"
        )
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


def temperature_figure(run: RunLike) -> Figure:
    """Paper Fig. 5a: ball (each ball of a 'dem' run), vial and air temperatures in °C against minutes, with
    the fitted exponential of the ball (of the balls' mean) and its steady state."""
    figure, (axis,) = new_figure()
    series = run.timeseries
    minutes = series["time"].values / 60.0
    bodies = [
        axis.plot(minutes, to_celsius(kelvin), color=colour, label=label)[0]
        for kelvin, label, colour in temperature_lines(run.params, series)
    ]
    balls = several_balls(run.params)
    fit = run.ball_fit
    window = f"0–{minutes[-1]:.3g} min"
    describes = run.summary.exponential_fit_describes_run
    if describes and math.isfinite(fit.theta_inf) and math.isfinite(fit.tau):
        fitted = "balls' mean, exponential fitted" if balls else f"ball, exponential fitted over {window}"
        axis.plot(minutes, to_celsius(fit.evaluate(series["time"].values)), "k--", lw=1, label=fitted)
    steady = run.summary.ball_steady_C
    if steady is not None and math.isfinite(steady):
        # The fit's θ∞ is a property of the window; the steady state is where the ball really settles.
        axis.axhline(steady, color="tab:red", ls=":", lw=1, label=steady_label(run.summary, balls))
        low, high = axis.get_ylim()
        axis.set_ylim(low, max(high, steady + 0.05 * (steady - low)))
    if run.params.n_balls:
        slowest = run.summary.slowest_time_constant_min or math.nan
        said = (
            f"exponential fitted over {window}:\n{_fit_text(fit)}"
            if describes
            else f"no exponential: the run ({window}) is shorter\nthan the slowest time constant ({slowest:.3g} min)"
        )
        axis.text(
            0.98,
            0.55,
            said,
            transform=axis.transAxes,
            ha="right",
            va="bottom",
            bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.85},
        )
    axis.set_xlabel("time (min)")
    axis.set_ylabel("temperature (°C)")
    named = f"the {run.params.n_balls} balls" if balls and run.params.n_balls > 1 else "ball"
    axis.set_title(
        f"Temperatures of {named}, vial and inner air (cf. paper Fig. 5a)"
        if run.params.n_balls
        else "Temperatures of an empty mill's vial and inner air (no balls)"
    )
    if balls:
        legend_below(figure, bodies)
        lines = [line for line in axis.get_lines() if line not in bodies]
        if lines:
            axis.legend(handles=lines, loc="lower right", fontsize="small")
    else:
        axis.legend(loc="lower right")
    axis.grid(alpha=0.3)
    return figure


def steady_label(summary: Summary, balls: bool) -> str:
    """The legend of the steady-state line: the ball's, or the balls' mean with the range of the balls'."""
    steady = summary.ball_steady_C
    if not balls:
        return f"ball steady state {steady:.1f} °C (MODEL.md §11)"
    each_ball = summary.steady.each_ball_C if summary.steady is not None else None
    each = [value for value in each_ball or () if math.isfinite(value)]
    spread = f" (each {min(each):.1f}–{max(each):.1f} °C)" if each else ""
    return f"balls' mean steady state {steady:.1f} °C{spread}"


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
    air of :func:`temperature_curves`, or for a 'dem' run each ball (numbered as in the run's files) and every other
    node of its network (the vial, the air, then the holder or the powder where it has them)."""
    if not several_balls(params):
        return [(series[name].values, label, colour) for name, label, colour in temperature_curves(params)]
    balls = series[BALL_TEMPERATURES].transpose("time", "ball").values
    lines: list[tuple[np.ndarray, str, Any]] = [
        (balls[:, ball], f"ball {ball}", colour) for ball, colour in enumerate(ball_colours(balls.shape[1]))
    ]
    nodes = [name.strip() for name in series[HEAT_INTO_NODES].attrs[NODE_NAMES].split(",")]
    return lines + [
        (
            series[f"theta_{name}"].values,
            series[f"theta_{name}"].attrs["long_name"].removesuffix(" temperature"),
            colour,
        )
        for name, colour in zip(nodes, NODE_COLOURS, strict=False)
    ]


def _fit_text(fit: ExponentialFit) -> str:
    if not (math.isfinite(fit.theta_inf) and math.isfinite(fit.tau)):
        return "exponential fit: not determined"
    return (
        f"θ∞ = {fit.theta_inf - KELVIN_OFFSET:.2f} °C\n"
        f"τ = {fit.tau / 60.0:.2f} min\n"
        f"θ̇₀ = {fit.initial_rate * 60.0:.3f} °C/min"
    )


def heating_zoom_window(params: Parameters) -> int | None:
    """Index of the record window that starts nearest to 10 min (None without windows)."""
    if not params.record_windows:
        return None
    starts = [start for start, _ in params.record_windows]
    return int(np.argmin([abs(start - HEATING_ZOOM_TIME) for start in starts]))


def motion_figure(params: Parameters, window: xr.Dataset, record_window: tuple[float, float] | None = None) -> Figure:
    """Paper Fig. 4: ball centre (with its positions at contact with either end face) and ball momentum.

    ``record_window`` (start, length) in s sets the time axis; without it the stored points do. The
    last stored step usually ends before the window does, the next step landing after it.
    """
    figure, (position_axis, momentum_axis) = new_figure(rows=2, height=6.0)
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
    figure, (axis,) = new_figure()
    time = window["time"].values
    balls = several_balls(run.params)
    if balls:
        temperatures = window[BALL_TEMPERATURES].transpose("time", "ball").values
        for ball, colour in enumerate(ball_colours(temperatures.shape[1])):
            axis.plot(
                (time - start) * 1e3, to_celsius(temperatures[:, ball]), color=colour, lw=1.2, label=f"ball {ball}"
            )
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
    """The seconds the impact table covers: the whole run, or the averaged solver's averaging window (the
    summary's ``stress_window_s``; a folder from before the spectrum, the simulated time)."""
    window = run.summary.stress_window_s
    return float(window) if window > 0.0 else float(run.summary.simulated_s)


def heat_by_channel_figure(run: RunLike) -> Figure:
    """The heat of a run of several balls as mean power (W): made in each dissipation channel of its engine
    (MODEL.md §12.4), stacked by what was hit (left, from the impact table), and received by each ball and the
    vial (right, from the sampled history)."""
    channels = run.description.channels
    figure, (made, received) = new_figure(height=4.2, columns=2, width=11.0)
    impacts = run.impacts
    kinds, categories = impact_kinds(impacts)
    span = impact_span(run)
    positions = np.arange(len(channels))
    total = np.zeros(len(channels))
    for kind, label, colour in categories:
        hit = impacts[kinds == kind]
        power = run.params.eta * np.array([hit[f"dissipated_{channel}"].sum() for channel in channels]) / span
        made.bar(positions, power, bottom=total, color=colour, label=f"{label} ({power.sum():.3g} W)")
        total += power
    for position, value in zip(positions, total):
        made.annotate(
            f"{value:.3g} W", (position, value), xytext=(0, 2), textcoords="offset points", ha="center", va="bottom"
        )
    made.set_xticks(positions, channels)
    made.set_xlabel("dissipation channel")
    made.set_ylabel("heat generated, mean power (W)")
    covered = averaging_window_note(run)
    made.set_title(
        f"made in each channel, by what was hit: {total.sum():.3g} W" + (f"\n({covered})" if covered else "")
    )
    made.legend(loc="upper right", fontsize="small")
    _heat_received(received, run)
    figure.suptitle("Heat of the impacts, as mean power")
    for axis in (made, received):
        axis.set_ylim(0.0, axis.get_ylim()[1] * 1.15)  # room for the numbers on the bars
        axis.grid(alpha=0.3, axis="y")
    return figure


def _heat_received(axis: object, run: RunLike) -> None:
    """Bars of the mean heat power into each ball (numbered as in the run's files) and into each other node the
    contacts heat (the vial, the powder): the nodes as the run's files name them."""
    series = run.timeseries
    seconds = float(series["time"].values[-1]) or math.nan
    balls = series["heat_into_balls"].transpose("time", "ball").values[-1] / seconds
    nodes = series[HEAT_INTO_NODES]
    heated = [
        (name.strip(), float(value) / seconds)
        for name, value in zip(nodes.attrs[NODE_NAMES].split(","), nodes.transpose("time", "node").values[-1])
        if value > 0.0
    ]
    powers = [*balls, *(power for _, power in heated)]
    names = [str(ball) for ball in range(balls.size)] + [name for name, _ in heated]
    colours = [*ball_colours(balls.size), *NODE_COLOURS[: len(heated)]]
    axis.bar(range(len(powers)), powers, color=colours)  # type: ignore[attr-defined]
    axis.set_xticks(range(len(powers)), names)  # type: ignore[attr-defined]
    axis.set_xlabel(f"ball (numbered as in the run's files), and {', '.join(names[balls.size :])}")  # type: ignore[attr-defined]
    axis.set_ylabel("heat received, mean power (W)")  # type: ignore[attr-defined]
    axis.set_title(f"received by each node: {sum(powers):.3g} W")  # type: ignore[attr-defined]


def comparison_temperature_figure(runs: dict[str, RunLike]) -> Figure:
    """Ball (solid) and vial (dashed) temperatures in °C of up to four runs, labelled by the keys of ``runs``.

    The vial of a ``ball_only`` run is held at ambient and is left out.
    """
    figure, (axis,) = new_figure()
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
