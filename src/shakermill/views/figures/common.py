"""What every figure of shakermill shares: what a run must offer to be drawn (:class:`RunLike`), the figure
canvas (the Agg canvas directly, without pyplot: no display needed, and an interactive session's backend is left
alone), titles with the run's context, and writing figures as PNG and SVG atomically.

Matplotlib is imported inside the functions, so that importing :mod:`shakermill` stays fast.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import pandas as pd
import xarray as xr

from shakermill.analysis.fit import ExponentialFit
from shakermill.parameters.defaults import FIGURE_FORMATS, PNG_DPI
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.support.atomic import remove_abandoned_writes, write_files_atomically

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from shakermill.engines.interface import EngineDescription
    from shakermill.solvers.summary import Summary


KELVIN_OFFSET = 273.15


MIN_POINTS_TO_PLOT = 2


# Columns of a legend under a figure (one entry per ball, the vial and the air).
LEGEND_COLUMNS = 6


class RunLike(Protocol):
    """What the figures need: a :class:`shakermill.solvers.result.Result` or a :class:`shakermill.io.runs.RunData`."""

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
    def summary(self) -> Summary: ...

    @property
    def description(self) -> EngineDescription: ...


def several_balls(params: Parameters) -> bool:
    """Whether a run's engine moves several balls (the 'dem' engine, MODEL.md §12): its figures differ from the
    paper's."""
    return params.engine_keys.several_balls


def check_window(params: Parameters, window: int) -> None:
    """:class:`ParameterError` unless ``window`` is the index of one of the run's record windows."""
    count = len(params.record_windows)
    if not 0 <= window < count:
        allowed = f"0 to {count - 1}" if count else "none: the run has no record_windows"
        raise ParameterError(f"window {window}: not one of the run's record windows; allowed {allowed}")


def run_context(run: RunLike) -> str:
    """ "spex8000m, 60 min, averaged solver": what a figure of ``run`` shows, for its title.

    The preset is known for a stored run (:class:`shakermill.io.runs.RunData`), not for a bare Result.
    """
    minutes = run.summary.simulated_s / 60.0
    parts = [getattr(run, "preset", None), f"{minutes:.3g} min", f"{run.params.solver} solver"]
    return ", ".join(part for part in parts if part)


def averaging_window_note(run: RunLike) -> str:
    """For the averaged solver, which keeps the impacts of its averaging window only: that window; else empty."""
    averaging = run.summary.averaging
    if run.params.solver != "averaged" or averaging is None:
        return ""
    return f"impacts of the {averaging.window_s:.3g} s averaging window only"


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


def save_figure(figure: Figure, stem: Path, *, dpi: int = PNG_DPI) -> list[Path]:
    """Save ``figure`` as ``stem.png`` and ``stem.svg``, drawn in memory and written atomically."""
    files = {}
    for fmt in FIGURE_FORMATS:
        buffer = io.BytesIO()
        figure.savefig(buffer, format=fmt, dpi=dpi, bbox_inches="tight")
        files[stem.with_suffix(f".{fmt}")] = buffer.getbuffer()
    return write_files_atomically(files)


def new_figure(rows: int = 1, height: float = 4.5, columns: int = 1, width: float = 7.5) -> tuple[Figure, list]:
    """A figure of ``rows`` × ``columns`` axes, listed row by row; the rows of one column share their time axis."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(rows, columns, sharex=columns == 1, squeeze=False)
    return figure, list(axes.flat)


def to_celsius(kelvin: np.ndarray) -> np.ndarray:
    return np.asarray(kelvin) - KELVIN_OFFSET


def legend_below(figure: Figure, lines: Sequence[Any]) -> None:
    """A legend of ``lines`` under the figure: a line per ball would cover the curves inside the axes."""
    figure.legend(handles=lines, loc="outside lower center", ncols=min(len(lines), LEGEND_COLUMNS), fontsize="small")


def window_data(run: RunLike, index: int) -> xr.Dataset | None:
    """The points of record window ``index``, or None when it has too few to plot."""
    windows = run.params.record_windows
    if index >= len(windows):
        return None
    start, length = windows[index]
    times = run.windows["time"].values
    selected = run.windows.isel(time=np.flatnonzero((times >= start) & (times <= start + length)))
    return selected if selected.sizes["time"] >= MIN_POINTS_TO_PLOT else None


def png_bytes(figure: Figure, dpi: int = PNG_DPI) -> bytes:
    """``figure`` rendered as PNG, in memory (for embedding in a report)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    return buffer.getvalue()


def plot_figures(figures: dict[str, Figure], out_dir: Path | str, *, dpi: int = PNG_DPI) -> list[Path]:
    """Save each of ``figures`` as PNG and SVG in ``out_dir``; return the files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    remove_abandoned_writes(out)
    written: list[Path] = []
    for name, figure in figures.items():
        written.extend(save_figure(figure, out / name, dpi=dpi))
    return written
