"""Figures of many runs: the maps or lines of a sweep folder (the summary's quantities against the swept keys,
with regimes and contour levels) and the bifurcation diagram of a scan with its coexisting attractors."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from shakermill.solvers.summary import SummaryKeyError, declared_names, unit_of
from shakermill.views.figures.common import add_context, new_figure
from shakermill.views.figures.impacts import _radian_ticks
from shakermill.views.notebook import rpm

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


# (column of the sweep table, quantity, unit) drawn by `shakermill plot SWEEP_DIR`.
SWEEP_QUANTITIES = (
    ("theta_inf_C", "ball θ∞ of the exponential fitted over the run", "°C"),
    ("tau_min", "time constant τ", "min"),
    ("impact_rate_hz", "impact rate", "1/s"),
    ("heat_power_W", "heat generated", "W"),
    ("mean_impact_speed_m_s", "mean impact speed", "m/s"),
    ("ball_steady_C", "ball steady state", "°C"),
    # The stress-energy spectrum (analysis/stress_energy.py): its middle and its upper tail.
    ("stress_energy_median_J", "median stress energy (dissipated per impact)", "J"),
    ("stress_energy_p90_J", "90th percentile of the stress energy", "J"),
)
# Columns of the sweep table that are summary keys: their names checked against the schema (solvers/summary.py).
declared_names(column for column, _, _ in SWEEP_QUANTITIES)


# Lengths read better in mm: a vial is a few centimetres long.
DISPLAY_UNITS = {"m": (1e3, "mm")}


CONTOUR_STYLE: dict[str, Any] = {"colors": "white", "linewidths": 2.0, "linestyles": "--"}


NOTE_STYLE: dict[str, Any] = {
    "fontsize": "small",
    "ha": "left",
    "va": "bottom",
    "bbox": {"facecolor": "white", "alpha": 0.85, "edgecolor": "0.6"},
}


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
    "stress_energy_median_J": "median stress energy",
    "stress_energy_p90_J": "stress energy p90",
}


# Units of the summary columns by the suffix of their names (theta_inf_C, tau_min, impact_rate_hz, ...).
SUFFIX_UNITS = (
    ("_C", "°C"),
    ("_K", "K"),
    ("_min", "min"),
    ("_hz", "1/s"),
    ("_W", "W"),
    ("_m_s", "m/s"),
    ("_J", "J"),
    ("_s", "s"),
)


MISSING_STYLE: dict[str, Any] = {"marker": "x", "color": "tab:red", "s": 40, "zorder": 3}


def contour_label(column: str, level: float) -> str:
    """``("theta_inf_C", 60)`` -> ``"ball θ∞ = 60 °C"``: the quantity's name and unit, not the column's."""
    return f"{SHORT_NAMES.get(column, column)} = {level:g} {column_unit(column)}".rstrip()


def column_unit(column: str) -> str:
    """The unit of a sweep table's column: a summary key's as its schema declares it, else by its name's suffix."""
    try:
        return unit_of(column)
    except SummaryKeyError:
        return next((unit for suffix, unit in SUFFIX_UNITS if column.endswith(suffix)), "")


def rpm_axis(axis: Axes, key: str, which: str = "x") -> None:
    """A second ω axis in rpm (drive cycles per minute, as mills are specified) when ``key`` is omega."""
    if key != "omega":
        return
    per_rad_s = rpm(1.0)
    functions = (lambda omega: omega * per_rad_s, lambda cycles: cycles / per_rad_s)
    if which == "x":
        secondary = axis.secondary_xaxis("top", functions=functions)
        secondary.set_xlabel("drive frequency (rpm)")
    else:
        secondary = axis.secondary_yaxis("left", functions=functions)
        secondary.set_ylabel("drive frequency (rpm)")
        # Outside the rad/s ticks of the same side, so that the two scales do not overlap.
        secondary.spines["left"].set_position(("outward", 45))


def sweep_context(manifest: Mapping[str, Any], keys: Sequence[str]) -> str:
    """ "spex8000m, 60 min, averaged solver" from a sweep's ``sweep.json``; the duration only when it is not swept."""
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
    from shakermill.parameters.keys import field_unit

    unit = DISPLAY_UNITS.get(field_unit(key), (1.0, field_unit(key)))[1]
    return f"{key} ({unit})" if unit else f"{key} (–)"


def display_values(key: str, values: np.ndarray) -> np.ndarray:
    from shakermill.parameters.keys import field_unit

    return np.asarray(values, dtype=float) * DISPLAY_UNITS.get(field_unit(key), (1.0, ""))[0]


@dataclass(frozen=True)
class KeyAxis:
    """Where each value of a swept key lies on an axis, and the tick labels when the values are names."""

    positions: np.ndarray
    names: tuple[str, ...] = ()

    def mark(self, axis: Axes, which: str = "x") -> None:
        """One tick per name (nothing for numbers, whose ticks matplotlib chooses)."""
        if self.names:
            set_ticks = axis.set_xticks if which == "x" else axis.set_yticks
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
    from shakermill.parameters.errors import ParameterError

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
    from shakermill.parameters.errors import ParameterError

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
                f"{column} = {level:g} not crossed: {column} is {values.min():.4g} to {values.max():.4g}, {side} it at "
                "every point"
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
    figure, (axis,) = new_figure(height=4.0)
    ordered = table.sort_values(key)
    key_values = key_axis(key, ordered[key].to_numpy())
    x = key_values.positions
    y = _numeric(ordered, column)
    axis.plot(*_broken_at_regime_changes(x, y, _regimes(ordered)), "o-", color="tab:blue", ms=4)
    missing = ~np.isfinite(y)
    if missing.any():
        # At the foot of the axis: a failed point has no value to place it at, but it must not vanish.
        axis.scatter(
            x[missing],
            np.zeros(missing.sum()),
            transform=axis.get_xaxis_transform(),
            clip_on=False,
            label=f"failed or no value ({missing.sum()})",
            **MISSING_STYLE,
        )
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
    figure, (axis,) = new_figure(height=5.0)
    x_key, y_key = keys
    x_values, y_values = key_axis(x_key, table[x_key].to_numpy()), key_axis(y_key, table[y_key].to_numpy())
    x_all, y_all = x_values.positions, y_values.positions
    gridded = _grid_of(x_all, y_all, _numeric(table, column)) if not table.empty else None
    if gridded is not None:
        x, y, values = gridded
        mesh = axis.pcolormesh(
            _cell_edges(x), _cell_edges(y), np.ma.masked_invalid(values), cmap="inferno", shading="flat"
        )
        for contour_column, level in contours:
            # On the quantity's points, so on its grid too.
            contour_grid = _grid_of(x_all, y_all, _numeric(table, contour_column))
            if contour_grid is not None and _straddled(contour_grid[2], level):
                lines = axis.contour(x, y, contour_grid[2], levels=[level], **CONTOUR_STYLE)
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


def _mark_missing(axis: Axes, x: np.ndarray, y: np.ndarray, values: np.ndarray) -> None:
    """A red x on each point without a value (failed, or NaN), so that a blank cell reads as a missing point."""
    missing = ~np.isfinite(values)
    if missing.any():
        axis.scatter(x[missing], y[missing], label=f"failed or no value ({missing.sum()})", **MISSING_STYLE)
        axis.legend(loc="upper left", bbox_to_anchor=(0.0, -0.12), fontsize="small", frameon=False)


def regime_figure(table: pd.DataFrame, keys: Sequence[str]) -> Figure:
    """The regime of each point (period-n, irregular, no impacts; failed points open) over the swept keys.

    The regime is the configured start's; points where other starts settle elsewhere are framed.
    """
    figure, (axis,) = new_figure(height=4.0 if len(keys) == 1 else 5.0)
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
        colour = (
            PERIOD_COLOURS[periods.index(label) % len(PERIOD_COLOURS)] if label in periods else REGIME_COLOURS[label]
        )
        axis.scatter(x[inside], y[inside], marker="s", s=70, color=colour, label=f"{label} ({inside.sum()})")
    if "n_attractors" in table:  # sweeps before attractors were probed have no such column
        several = _numeric(table, "n_attractors") > 1
        axis.scatter(
            x[several],
            y[several],
            marker="s",
            s=150,
            facecolors="none",
            edgecolors="black",
            lw=1.2,
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
    figure, (phase_axis, period_axis) = new_figure(rows=2, height=7.0)
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
        loc="lower left",
        bbox_to_anchor=(0.0, 1.0),
        ncols=4,
        fontsize="small",
        frameon=False,
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


def _attractor_periods(axis: Axes, attractors: pd.DataFrame, key: str) -> None:
    """Period of each attractor, irregular ones above the largest period; marker area ∝ basin fraction."""
    from matplotlib.ticker import MaxNLocator

    periods = pd.to_numeric(attractors["period"], errors="coerce").to_numpy(dtype=float)
    top = np.nanmax(periods, initial=1.0) + 1
    irregular = (attractors["regime"] == "irregular").to_numpy()
    shown = np.where(irregular, top, periods)
    x = display_values(key, attractors[key].to_numpy())
    colours = [PERIOD_COLOURS[label % len(PERIOD_COLOURS)] for label in attractors["attractor"]]
    # Open markers: two attractors of the same period at one value show as concentric rings.
    axis.scatter(
        x, shown, s=FULL_BASIN_AREA * attractors["basin_fraction"].to_numpy(), facecolors="none", edgecolors=colours
    )
    # Periods are whole numbers: half a period of room either way keeps the ticks on them.
    axis.set_ylim(0.5, np.nanmax(shown, initial=1.0) + 0.5)
    ticks = [tick for tick in MaxNLocator(integer=True, min_n_ticks=1).tick_values(1, top - 1) if 1 <= tick < top]
    labels = [f"{tick:g}" for tick in ticks]
    if irregular.any():
        # Irregular motion has no period: its row is named, not numbered, and ruled off from the periods.
        axis.axhline(top - 0.5, color="0.3", lw=1.0, ls="--")
        ticks, labels = [*ticks, top], [*labels, "irregular"]
    axis.set_yticks(ticks, labels)
    axis.set_ylabel("period n (drive periods)\nmarker area ∝ basin fraction")


def _attractor_handles(labels: Sequence[int]) -> list:
    from matplotlib.lines import Line2D

    return [
        Line2D(
            [],
            [],
            ls="",
            marker="s",
            color=PERIOD_COLOURS[label % len(PERIOD_COLOURS)],
            label="attractor 0 (configured start)" if label == 0 else f"attractor {label}",
        )
        for label in labels
    ]


def _wall_handles() -> list:
    from matplotlib.lines import Line2D

    return [Line2D([], [], ls="", marker=marker, color="0.3", label=name) for _, name, marker in WALL_MARKERS]
