"""What was measured, as the fits and the validation read it: the paper's Table 5 with its targets' ranges, the
experiment's curve as the paper summarises it, and measured curves read from CSV (``calibrate --curve``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from shakermill.parameters.csvinput import check_rectangular, read_csv_rows
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.fields import LONGEST_RUN_S
from shakermill.parameters.keys import Bounds
from shakermill.support.limits import MAX_CURVE_POINTS, quoted

if TYPE_CHECKING:
    import numpy as np


PAPER = "Son 2025, Mathematics 13, 446"
EXPERIMENT = "Takacs & McHenry 2006 (J. Mater. Sci. 41, 5246), one ball, SPEX 8000"


@dataclass(frozen=True)
class Quantity:
    key: str  # summary key
    label: str
    unit: str
    experiment: float
    paper_model: float
    experiment_note: str = ""


TABLE5: tuple[Quantity, ...] = (
    # The paper calls θ∞ the steady state; for this model it is the exponential fitted over the hour
    # (MODEL.md §8), which is the steady state only if the run lasts several slowest time constants (§11).
    Quantity("theta_inf_C", "ball θ∞ of the exponential fitted over 0–60 min", "°C", 48.0, 47.89),
    Quantity("tau_min", "τ of that fit", "min", 16.7, 16.70),
    Quantity("rate0_C_per_min", "initial heating rate θ̇₀ of that fit", "°C/min", 1.6766, 1.6702),
    Quantity(
        "vial_ball_ratio",
        "vial/ball temperature increment ratio after 1 h",
        "",
        0.46,
        0.44,
        experiment_note="five balls (vial +21 °C, ball +46 °C); the paper compares its one-ball model with it",
    ),
)

# The experiment's operating point (one 12.7 mm steel ball, SPEX 8000M at about 1060 rpm, 25 mm amplitude, one hour):
# Table 5 compares only runs at this point, each key within OPERATING_POINT_TOLERANCE of it. The vial's
# length and diameter are the preset's (see :func:`operating_point_mismatches`).
EXPERIMENT_OPERATING_POINT = {"omega": 111.0, "amplitude": 25e-3, "ball_radius": 6.35e-3, "duration": 3600.0}
VIAL_KEYS = ("vial_length", "vial_diameter")
# 2 %: ω = 111 ± 2.2 rad/s spans 1039–1081 rpm, the SPEX 8000M's speed on 50 and 60 Hz mains within its slip.
OPERATING_POINT_TOLERANCE = 0.02

TARGET_KEYS: tuple[str, ...] = tuple(quantity.key for quantity in TABLE5)
ABSOLUTE_ZERO_C = -273.15
# The experiment's curve is an exponential with these three numbers: a calibration to the curve fits them.
CURVE_QUANTITIES = ("theta_inf_C", "tau_min", "rate0_C_per_min")
# A model that follows the experiment's curve this closely (RMS over the hour) reproduces its shape.
# The measurement error of a curve's point where the curve states none (K), an assumption: a thermocouple read to
# 0.1 K scatters by a few tenths of a kelvin from run to run (its fixed offset, up to 1.1 K for type K, moves every
# point alike). Without it a fit of as many keys as points meets them exactly and calls its keys known.
ASSUMED_CURVE_SD_K = 0.5
CURVE_TOLERANCE_K = 1.0
# The experiment's curve as Son 2025 summarises Takacs & McHenry 2006 (Table 5): θ_0 = 20 °C,
# θ∞ = 48 °C, τ = 16.7 min, sampled every minute over the hour.
EXPERIMENT_CURVE_C = (20.0, 48.0, 16.7 * 60.0)
EXPERIMENT_CURVE_MINUTES = 60
# That curve is an exponential summary with no scatter, so a perfect fit would claim zero uncertainty;
# the fitted values' standard errors assume this error on each point instead (an assumption: the
# paper gives none).
EXPERIMENT_CURVE_SIGMA_K = 0.5


# Targets are matched relative to their values (calibrate.py), so none may be 0; each range spans what a
# mill can show: θ∞ above 0 °C (a mill at room temperature only heats) up to where steel melts, τ up to
# a week, heating rates up to 1000 °C/min, and a vial heated up to ten times as much as the ball.
TARGET_BOUNDS: dict[str, Bounds] = {
    "theta_inf_C": Bounds(0.0, 1400.0, low_open=True, high_open=False),
    "tau_min": Bounds(0.0, 1e4, low_open=True, high_open=False),
    "rate0_C_per_min": Bounds(0.0, 1000.0, low_open=True, high_open=False),
    "vial_ball_ratio": Bounds(0.0, 10.0, low_open=True, high_open=False),
}


def check_targets(targets: Mapping[str, float]) -> None:
    """Raise :class:`ParameterError` naming the first target that is unknown, not finite or out of its range."""
    for name, value in targets.items():
        if name not in TARGET_BOUNDS:
            raise ParameterError(f"target: unknown target {quoted(name)}; allowed: {', '.join(TARGET_KEYS)}")
        if not (math.isfinite(value) and TARGET_BOUNDS[name].contains(value)):
            raise ParameterError(f"target: {name} = {value:g} is not allowed; allowed {target_range(name)}")


def target_range(name: str) -> str:
    return f"{TARGET_BOUNDS[name]} {quantity(name).unit}".rstrip()


# The columns a curve file may measure, the node of the network each is of (the balls' mean, the vial) and the
# offset that turns its unit into °C.
NODE_COLUMNS = {
    "ball_C": ("ball", 0.0),
    "vial_C": ("vial", 0.0),
    "ball_K": ("ball", -273.15),
    "vial_K": ("vial", -273.15),
}
TIME_COLUMNS = {"time_s": 1.0, "time_min": 60.0}
NODE_VARIABLES = {"ball": "theta_ball", "vial": "theta_vial"}
# A mill starts at room temperature: °C values that never fall below this are kelvin (293 K is 20 °C), and kelvin
# values that never rise above it are °C.
KELVIN_FLOOR = 200.0


@dataclass(frozen=True)
class Curve:
    """A measured temperature history of a node (``ball``: the balls' mean, or ``vial``): times in s, temperatures
    in °C, and the settings of its run that differ from the calibrated parameters (``conditions``, "KEY=VALUE"
    with units, e.g. "n_balls=5").

    Checked on creation: finite times in [0, the longest run] that increase, finite temperatures above
    absolute zero, at most :data:`MAX_CURVE_POINTS` points; :class:`ParameterError` names the first point that is not,
    and the column it read (``column``).
    """

    times: np.ndarray
    temperature_C: np.ndarray
    source: str = ""
    # Measurement error of each point (K) where the curve itself has no scatter to estimate it from; a fit takes
    # ASSUMED_CURVE_SD_K for a curve that states none.
    sigma_K: float | None = None
    node: str = "ball"
    conditions: tuple[str, ...] = ()
    column: str = ""
    # What reading the file took on itself (a ';'-separated file's decimal commas), said where the curve is used.
    note: str = ""

    def __post_init__(self) -> None:
        what = f"curve {self.source}".rstrip()
        if not 1 <= self.times.size <= MAX_CURVE_POINTS or self.times.shape != self.temperature_C.shape:
            raise ParameterError(
                f"{what}: {self.times.size} times and {self.temperature_C.size} temperatures; allowed 1 to "
                f"{MAX_CURVE_POINTS:,} of each"
            )
        column = self.column or f"{self.node}_C"
        for index, (time, temperature) in enumerate(zip(self.times.tolist(), self.temperature_C.tolist())):
            _check_point(what, column, index, time, temperature, self.times[index - 1] if index else None)

    @classmethod
    def from_csv(cls, path: Path | str, conditions: tuple[str, ...] = ()) -> Curve:
        """Read ``time_s`` or ``time_min`` and one of ``ball_C``, ``vial_C``, ``ball_K`` or ``vial_K`` (header
        required; other columns ignored, every row as long as the header); ``conditions`` as the class says. A file
        whose header is separated by ';' is read so, its decimal commas as points, and says so in ``note``."""
        path = Path(path)
        what = f"curve {path}"
        rows, note = _curve_rows(path, what)
        header = [cell.strip() for cell in rows[0]]
        time_column, measured = _curve_columns(header, what)
        check_rectangular(rows[1:], header, what)
        times, temperatures = [], []
        for number, row in enumerate(rows[1:], start=2):
            cells = dict(zip(header, row))
            try:
                times.append(float(cells[time_column]) * TIME_COLUMNS[time_column])
                temperatures.append(float(cells[measured]))
            except ValueError:
                raise ParameterError(
                    f"{what} line {number}: needs a number in {time_column} and in {measured}"
                ) from None
        node, offset = NODE_COLUMNS[measured]
        _check_unit(what, measured, temperatures)
        import numpy as np

        return cls(
            np.array(times),
            np.array(temperatures) + offset,
            str(path),
            node=node,
            conditions=tuple(conditions),
            column=measured,
            note=note,
        )

    @property
    def variable(self) -> str:
        """The history variable (K) this curve measures."""
        return NODE_VARIABLES[self.node]

    def residuals_K(self, times: np.ndarray, theta_K: np.ndarray) -> np.ndarray:
        """A modelled temperature history of this curve's node (s, K) minus this curve at its times (K)."""
        import numpy as np

        return np.interp(self.times, times, theta_K) - 273.15 - self.temperature_C

    def rms_K(self, times: np.ndarray, theta_K: np.ndarray) -> float:
        residuals = self.residuals_K(times, theta_K)
        return math.sqrt(float((residuals**2).mean()))


def curve_from_option(item: str) -> Curve:
    """``calibrate --curve``'s value: ``FILE`` or ``FILE:KEY=VALUE,KEY=VALUE`` (the settings of the curve's run)."""
    path, separator, settings = item.rpartition(":")
    if not separator or "=" not in settings:
        return Curve.from_csv(item)
    return Curve.from_csv(path, tuple(setting.strip() for setting in settings.split(",") if setting.strip()))


def _curve_rows(path: Path, what: str) -> tuple[list[list[str]], str]:
    """The non-empty rows of a curve file, and a note where it was read as ';'-separated with decimal commas."""
    rows = [row for row in read_csv_rows(path, what, MAX_CURVE_POINTS) if any(cell.strip() for cell in row)]
    note = ""
    if rows and len(rows[0]) == 1 and ";" in rows[0][0]:
        rows = [
            row
            for row in read_csv_rows(path, what, MAX_CURVE_POINTS, delimiter=";")
            if any(cell.strip() for cell in row)
        ]
        rows = [[cell.replace(",", ".") for cell in row] for row in rows]
        note = f"{what}: read as ';'-separated columns, with decimal commas as points"
    if len(rows) < 2:
        raise ParameterError(f"{what}: has no data rows")
    return rows, note


def _curve_columns(header: list[str], what: str) -> tuple[str, str]:
    """The time column and the measured column of a curve file's header: one of each, each once."""
    repeated = sorted({name for name in header if name and header.count(name) > 1})
    if repeated:
        raise ParameterError(
            f"{what}: the column {repeated[0]} appears {header.count(repeated[0])} times; allowed once"
        )
    times = [name for name in TIME_COLUMNS if name in header]
    measured = [name for name in NODE_COLUMNS if name in header]
    if len(times) > 1:
        raise ParameterError(f"{what}: has both time_s and time_min, which need not agree; allowed one of them")
    if len(measured) != 1 or not times:
        raise ParameterError(
            f"{what}: needs columns time_s (or time_min) and one of {', '.join(NODE_COLUMNS)}, found {quoted(header)}"
        )
    return times[0], measured[0]


def _check_unit(what: str, column: str, temperatures: list[float]) -> None:
    """Refuse a curve whose values are plainly in the other unit than its column says (a mill starts near 20 °C)."""
    low, high = min(temperatures), max(temperatures)
    kelvin = column.endswith("_K")
    if not kelvin and low >= KELVIN_FLOOR:
        raise ParameterError(
            f"{what}: {column} holds {low:g} to {high:g}, which look like kelvin (a mill starts near 20 °C = 293 K); "
            f"allowed °C in {column}, or name the column {column[:-2]}_K to give kelvin"
        )
    if kelvin and high < KELVIN_FLOOR:
        raise ParameterError(
            f"{what}: {column} holds {low:g} to {high:g}, which look like °C (kelvin never falls below 0 and a mill "
            f"starts near 293 K); allowed kelvin in {column}, or name the column {column[:-2]}_C to give °C"
        )


def _check_point(what: str, column: str, index: int, time: float, temperature: float, previous: float | None) -> None:
    point = f"point {index + 1}"
    if not (math.isfinite(time) and 0.0 <= time <= LONGEST_RUN_S):
        raise ParameterError(f"{what}: {point} is at {time:g} s; allowed times in [0, {LONGEST_RUN_S:g}] s")
    if previous is not None and time <= previous:
        raise ParameterError(
            f"{what}: {point} at {time:g} s does not come after the one before ({previous:g} s); times must increase"
        )
    if not (math.isfinite(temperature) and temperature > ABSOLUTE_ZERO_C):
        raise ParameterError(
            f"{what}: {point} has {column} = {temperature:g} °C; allowed a finite temperature above "
            f"{ABSOLUTE_ZERO_C:g} °C"
        )


def experiment_curve() -> Curve:
    """θ(t) = 48 − 28·exp(−t/16.7 min) at every minute of the hour: the experiment as the paper gives it."""
    import numpy as np

    theta_0, theta_inf, tau = EXPERIMENT_CURVE_C
    times = np.arange(EXPERIMENT_CURVE_MINUTES + 1) * 60.0
    source = "experiment (Takacs & McHenry 2006 via Son 2025 Table 5): 48 - 28 exp(-t / 16.7 min), 0-60 min"
    return Curve(times, theta_inf + (theta_0 - theta_inf) * np.exp(-times / tau), source, EXPERIMENT_CURVE_SIGMA_K)


def fitted_quantities(provenance: Mapping[str, Any]) -> tuple[str, ...]:
    """The Table 5 quantities (summary keys) a calibration with this provenance was fitted to.

    The keys of its scalar ``targets``, and the three numbers of the exponential when it was fitted
    to the experiment's curve, which is nothing but those three numbers.
    """
    keys = list(provenance.get("targets", {}))
    if "curve" in provenance:
        keys += CURVE_QUANTITIES
    return tuple(dict.fromkeys(keys))


def quantity(key: str) -> Quantity:
    for entry in TABLE5:
        if entry.key == key:
            return entry
    raise KeyError(key)


def relative_error(value: float, reference: float) -> float:
    return (value - reference) / reference if reference else math.nan
