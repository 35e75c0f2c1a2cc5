"""Figures of a run, as PNG and SVG: temperatures, ball motion in the first window, heating zoom.

Matplotlib is imported inside the functions, so that importing :mod:`shakermill`
stays fast. Figures are drawn on the Agg canvas directly, without pyplot: that
needs no display and leaves the backend of an interactive session untouched.
"""

from __future__ import annotations

import math
import os
import secrets
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np
import pandas as pd
import xarray as xr

from . import drive
from .fit import ExponentialFit
from .params import Parameters

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FORMATS = ("png", "svg")
PNG_DPI = 150
KELVIN_OFFSET = 273.15
# The paper's Fig. 5b zooms into the heating at 10 min; the window starting nearest to it is shown.
HEATING_ZOOM_TIME = 600.0
MIN_POINTS_TO_PLOT = 2
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


def plot_run(run: RunLike, out_dir: Path | str) -> list[Path]:
    """Write every figure of ``run`` into ``out_dir`` (created if needed); return the files written."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {"temperatures": temperature_figure(run)}
    first_window = window_data(run, 0)
    if first_window is not None:
        figures["ball_motion"] = motion_figure(run.params, first_window)
    zoom_index = heating_zoom_window(run.params)
    zoom = window_data(run, zoom_index) if zoom_index is not None else None
    if zoom is not None:
        zoom_start = run.params.record_windows[zoom_index][0]
        figures["ball_heating_zoom"] = heating_zoom_figure(run, zoom, zoom_start)
    written: list[Path] = []
    for name, figure in figures.items():
        written.extend(save_figure(figure, out / name))
    return written


def save_figure(figure: Figure, stem: Path) -> list[Path]:
    """Save ``figure`` as ``stem.png`` and ``stem.svg``, each through a temporary file and an atomic rename."""
    paths = []
    for fmt in FORMATS:
        path = stem.with_suffix(f".{fmt}")
        partial = path.with_name(f".{path.name}.partial-{secrets.token_hex(4)}")
        try:
            figure.savefig(partial, format=fmt, dpi=PNG_DPI, bbox_inches="tight")
            os.replace(partial, path)
        finally:
            partial.unlink(missing_ok=True)
        paths.append(path)
    return paths


def _new_figure(rows: int = 1, height: float = 4.5) -> tuple[Figure, list]:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.5, height), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(rows, 1, sharex=True, squeeze=False)
    return figure, list(axes[:, 0])


def to_celsius(kelvin: np.ndarray) -> np.ndarray:
    return np.asarray(kelvin) - KELVIN_OFFSET


def temperature_figure(run: RunLike) -> Figure:
    """Ball, vial and air temperatures in °C against minutes, with the ball's fitted exponential."""
    figure, (axis,) = _new_figure()
    series = run.timeseries
    minutes = series["time"].values / 60.0
    for name, label, colour in (
        ("theta_ball", "ball", "tab:red"),
        ("theta_vial", "vial", "tab:blue"),
        ("theta_air", "air", "tab:green"),
    ):
        axis.plot(minutes, to_celsius(series[name].values), color=colour, label=label)
    fit = run.ball_fit
    if math.isfinite(fit.theta_inf) and math.isfinite(fit.tau):
        axis.plot(minutes, to_celsius(fit.evaluate(series["time"].values)), "k--", lw=1, label="ball, exponential fit")
    axis.text(
        0.98, 0.04, _fit_text(fit), transform=axis.transAxes, ha="right", va="bottom",
        bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.85},
    )
    axis.set_xlabel("time (min)")
    axis.set_ylabel("temperature (°C)")
    axis.set_title("Temperatures of ball, vial and inner air")
    axis.legend(loc="upper left")
    axis.grid(alpha=0.3)
    return figure


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


def motion_figure(params: Parameters, window: xr.Dataset) -> Figure:
    """Ball centre with the centre positions at contact with either end face, and the ball's momentum."""
    figure, (position_axis, momentum_axis) = _new_figure(rows=2, height=6.0)
    time = window["time"].values
    # Step points are sparse in flight, where the ball moves in straight lines but the vial does not:
    # the end faces are drawn on a grid of their own.
    drive_time = np.linspace(time[0], time[-1], DRIVE_CURVE_POINTS)
    vial = np.array([drive.vial_position(t, params.amplitude, params.omega, params.phase) for t in drive_time])
    # The ball touches an end face (at x_v ± l_v/2) when its centre is one radius away from it.
    reach = params.vial_length / 2.0 - params.ball_radius
    position_axis.plot(time, window["x"].values * 1e3, color="tab:red", label="ball centre")
    contact_label = "ball centre at contact with an end face"
    position_axis.plot(drive_time, (vial - reach) * 1e3, color="0.4", lw=1, label=contact_label)
    position_axis.plot(drive_time, (vial + reach) * 1e3, color="0.4", lw=1)
    position_axis.set_ylabel("position (mm)")
    figure.suptitle("Ball motion in the first recorded window")
    # Above the axes: inside, it would hide the turning points at the end faces.
    position_axis.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=2, fontsize="small", frameon=False)
    momentum_axis.plot(time, window["p"].values, color="tab:purple")
    momentum_axis.set_ylabel("momentum (kg·m/s)")
    momentum_axis.set_xlabel("time (s)")
    for axis in (position_axis, momentum_axis):
        axis.grid(alpha=0.3)
    return figure


def heating_zoom_figure(run: RunLike, window: xr.Dataset, start: float) -> Figure:
    """Ball temperature in °C inside the window starting at ``start`` (s), impacts marked: the heating at each."""
    figure, (axis,) = _new_figure()
    time = window["time"].values
    axis.plot((time - start) * 1e3, to_celsius(window["theta_ball"].values), color="tab:red", lw=1.2)
    impact_times = run.impacts["time"].to_numpy()
    inside = impact_times[(impact_times >= start) & (impact_times <= time[-1])]
    for impact_time in inside:
        axis.axvline((impact_time - start) * 1e3, color="0.6", lw=0.6, ls=":")
    axis.ticklabel_format(axis="y", useOffset=False)
    axis.set_xlabel(f"time after t = {start:g} s (ms)")
    axis.set_ylabel("ball temperature (°C)")
    axis.set_title(f"Ball heating at each impact ({len(inside)} impacts, dotted)")
    axis.grid(alpha=0.3)
    return figure
