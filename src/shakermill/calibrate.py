"""Calibration: fit free parameters to measured targets by bounded least squares.

What the paper did by hand (tuning β until θ∞ and τ matched Table 5), done by
``scipy.optimize.least_squares`` and reported honestly: which keys were free,
which quantities were targets, the residuals, the sensitivities, and whether a
parameter ended on a bound (a sign that the targets cannot be met with that
choice of free parameters).

Targets are the Table 5 quantities (``theta_inf_C``, ``tau_min``,
``rate0_C_per_min``, ``vial_ball_ratio``) and/or a measured ball-temperature
curve. Positive parameters are fitted in log space, so bounds are ratios and
steps are relative. The averaged solver is used unless asked otherwise: it
makes each evaluation a few hundredths of a second.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import tomli_w
from scipy.optimize import least_squares

from . import __version__
from .atomic import write_text_atomically
from .params import ParameterError, Parameters, check_known_keys
from .simulate import Result, simulate
from .validation import TARGET_KEYS

DEFAULT_FREE = ("beta", "vial_mass")
# A free parameter may move this factor either way from its starting value.
BOUND_FACTOR = 100.0
# Relative step of the finite-difference Jacobian in log space: large enough to rise above the
# averaged solver's statistical noise (relative standard error ~1e-4 to 1e-3 on mechanical inputs).
JACOBIAN_STEP = 1e-2
# A parameter within this relative distance of a bound is reported as stuck on it.
AT_BOUND = 1e-3
# A scalar target further off than this (relative) after the fit counts as not met.
TARGET_TOLERANCE = 5e-3
# Scalar targets are matched relatively; curve points in kelvin: one kelvin weighs like 1 % on a target.
CURVE_SCALE_K = 100.0


@dataclass(frozen=True)
class Curve:
    """A measured ball-temperature history: times in s, temperatures in °C."""

    times: np.ndarray
    ball_C: np.ndarray
    source: str = ""

    @classmethod
    def from_csv(cls, path: Path | str) -> Curve:
        """Read ``time_s`` or ``time_min`` and ``ball_C`` columns (header required)."""
        path = Path(path)
        try:
            with path.open(newline="") as handle:
                rows = list(csv.DictReader(handle))
        except OSError as exc:
            raise ParameterError(f"curve: cannot read {path} ({exc.strerror or exc})") from None
        if not rows:
            raise ParameterError(f"curve: {path} has no data rows")
        columns = set(rows[0])
        if "ball_C" not in columns or not columns & {"time_s", "time_min"}:
            raise ParameterError(f"curve: {path} needs columns time_s (or time_min) and ball_C, found {sorted(columns)}")
        scale, column = (1.0, "time_s") if "time_s" in columns else (60.0, "time_min")
        try:
            times = np.array([float(row[column]) * scale for row in rows])
            temperatures = np.array([float(row["ball_C"]) for row in rows])
        except (TypeError, ValueError):
            raise ParameterError(f"curve: {path} has a value that is not a number") from None
        return cls(times, temperatures, str(path))


@dataclass
class Calibration:
    """The outcome of :func:`calibrate`."""

    params: Parameters
    free: tuple[str, ...]
    fitted: dict[str, float]
    start: dict[str, float]
    targets: dict[str, float]
    achieved: dict[str, float]
    curve_rms_K: float | None
    parameter_stderr: dict[str, float]
    sensitivities: dict[str, dict[str, float]]  # target -> parameter -> d ln(target)/d ln(parameter)
    at_bounds: list[str]
    success: bool
    message: str
    evaluations: int
    solver: str
    result: Result | None = field(default=None, repr=False)

    @property
    def relative_residuals(self) -> dict[str, float]:
        return {key: (self.achieved[key] - value) / value for key, value in self.targets.items()}

    def as_dict(self) -> dict:
        return {
            "free": list(self.free),
            "fitted": self.fitted,
            "start": self.start,
            "targets": self.targets,
            "achieved": self.achieved,
            "relative_residuals": self.relative_residuals,
            "curve_rms_K": self.curve_rms_K,
            "parameter_stderr": self.parameter_stderr,
            "sensitivities": self.sensitivities,
            "at_bounds": self.at_bounds,
            "success": self.success,
            "message": self.message,
            "evaluations": self.evaluations,
            "solver": self.solver,
        }


def parse_targets(items: Sequence[str]) -> dict[str, float]:
    """``["theta_inf_C=48", ...]`` -> ``{"theta_inf_C": 48.0}`` with one-line errors."""
    targets: dict[str, float] = {}
    for item in items:
        name, separator, value = item.partition("=")
        name = name.strip()
        if not separator:
            raise ParameterError(f"target: expected NAME=VALUE, got {item!r}")
        if name not in TARGET_KEYS:
            raise ParameterError(f"target: unknown target {name!r}; allowed: {', '.join(TARGET_KEYS)}")
        try:
            targets[name] = float(value)
        except ValueError:
            raise ParameterError(f"target: {name} needs a number, got {value!r}") from None
    return targets


def parse_free(items: Sequence[str]) -> tuple[str, ...]:
    """``["beta,vial_mass", "eta"]`` -> ``("beta", "vial_mass", "eta")``; only positive float keys."""
    keys = tuple(key.strip() for item in items for key in item.split(",") if key.strip()) or DEFAULT_FREE
    check_known_keys(list(keys))
    for key in keys:
        if Parameters.model_fields[key].annotation is not float:
            raise ParameterError(f"free: {key} is not a numeric parameter and cannot be fitted")
    if len(set(keys)) != len(keys):
        raise ParameterError(f"free: a key is listed twice in {', '.join(keys)}")
    return keys


def _upper_limit(key: str) -> float:
    for constraint in Parameters.model_fields[key].metadata:
        for attribute in ("le", "lt"):
            if hasattr(constraint, attribute):
                return float(getattr(constraint, attribute))
    return math.inf


def calibrate(
    base: Parameters,
    free: Sequence[str] = DEFAULT_FREE,
    targets: Mapping[str, float] | None = None,
    curve: Curve | None = None,
    *,
    full_resolution: bool = False,
) -> Calibration:
    """Fit ``free`` keys of ``base`` to ``targets`` and/or ``curve``; see the module docstring."""
    targets = dict(targets or {})
    if not targets and curve is None:
        raise ParameterError("calibrate: give at least one --target or a --curve")
    free = tuple(free)
    for key in free:
        if getattr(base, key) <= 0:
            raise ParameterError(f"free: {key} must start positive to be fitted in log space, got {getattr(base, key)}")
    solver = "full" if full_resolution else "averaged"
    start = {key: float(getattr(base, key)) for key in free}
    x0 = np.log([start[key] for key in free])
    lower = x0 - math.log(BOUND_FACTOR)
    upper = np.array([min(x + math.log(BOUND_FACTOR), math.log(_upper_limit(key))) for x, key in zip(x0, free)])
    upper = np.maximum(upper, x0 + 1e-12)  # a start on the upper limit still needs an open interval
    if curve is not None and curve.times.max() > base.duration:
        base = base.replace(duration=float(curve.times.max()))
    cache: dict[tuple[float, ...], tuple[np.ndarray, Result]] = {}

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, Result]:
        key = tuple(np.round(x, 14))
        if key not in cache:
            params = base.replace(solver=solver, **{name: float(math.exp(v)) for name, v in zip(free, x)})
            result = simulate(params)
            cache[key] = (_residuals(result, targets, curve), result)
        return cache[key]

    solution = least_squares(
        lambda x: evaluate(x)[0], x0, bounds=(lower, upper), diff_step=JACOBIAN_STEP, x_scale=1.0, method="trf"
    )
    residuals, result = evaluate(solution.x)
    fitted = {key: float(math.exp(v)) for key, v in zip(free, solution.x)}
    achieved = {key: float(result.summary[key]) for key in targets}
    at_bounds = [
        key for key, x, lo, hi in zip(free, solution.x, lower, upper) if x - lo < AT_BOUND or hi - x < AT_BOUND
    ]
    missed = {key: (achieved[key] - value) / value for key, value in targets.items()}
    missed = {key: error for key, error in missed.items() if abs(error) > TARGET_TOLERANCE}
    message = str(solution.message)
    if missed or at_bounds:
        reasons = [f"{key} is off by {100 * error:+.2f} %" for key, error in missed.items()]
        reasons += [f"{key} ended on a bound" for key in at_bounds]
        message = (
            f"the targets cannot be met by moving {', '.join(free)} alone ({'; '.join(reasons)}); "
            "free another parameter or check the targets"
        )
    return Calibration(
        params=result.params.replace(solver=base.solver),
        free=free,
        fitted=fitted,
        start=start,
        targets=targets,
        achieved=achieved,
        curve_rms_K=_curve_rms(result, curve),
        parameter_stderr=_parameter_stderr(solution, free, fitted, residuals, curve),
        sensitivities=_sensitivities(solution.jac, free, targets),
        at_bounds=at_bounds,
        success=bool(solution.success) and not at_bounds and not missed and result.success,
        message=message,
        evaluations=len(cache),
        solver=solver,
        result=result,
    )


def _ball_curve_at(result: Result, times: np.ndarray) -> np.ndarray:
    series = result.timeseries
    return np.interp(times, series["time"].values, series["theta_ball"].values) - 273.15


def _residuals(result: Result, targets: Mapping[str, float], curve: Curve | None) -> np.ndarray:
    parts = [(float(result.summary[key]) - value) / value for key, value in targets.items()]
    if curve is not None:
        parts.extend((_ball_curve_at(result, curve.times) - curve.ball_C) / CURVE_SCALE_K)
    values = np.array(parts, dtype=float)
    # A failed or unfittable run must push the optimiser away, not stop it.
    return np.where(np.isfinite(values), values, 1e3)


def _curve_rms(result: Result, curve: Curve | None) -> float | None:
    if curve is None:
        return None
    return float(np.sqrt(np.mean((_ball_curve_at(result, curve.times) - curve.ball_C) ** 2)))


def _parameter_stderr(solution, free, fitted, residuals, curve) -> dict[str, float]:
    """Standard errors from the Jacobian; meaningful only for a curve with more points than parameters."""
    points = residuals.size
    if curve is None or points <= len(free):
        return {key: math.nan for key in free}
    variance = float(np.sum(residuals**2)) / (points - len(free))
    try:
        covariance = np.linalg.inv(solution.jac.T @ solution.jac) * variance
    except np.linalg.LinAlgError:
        return {key: math.nan for key in free}
    # In log space the standard error is relative; convert to the parameter's own units.
    return {key: float(fitted[key] * math.sqrt(max(covariance[i, i], 0.0))) for i, key in enumerate(free)}


def _sensitivities(jacobian: np.ndarray, free: Sequence[str], targets: Mapping[str, float]) -> dict[str, dict[str, float]]:
    """d ln(target)/d ln(parameter) from the least-squares Jacobian (rows of scalar targets only)."""
    return {
        target: {key: float(jacobian[row, column]) for column, key in enumerate(free)}
        for row, target in enumerate(targets)
    }


def write_preset(calibration: Calibration, path: Path | str, *, base_preset: str, command: str, description: str) -> Path:
    """Write a preset TOML usable with ``shakermill run FILE`` and as a shipped preset, with provenance."""
    path = Path(path)
    values = {key: calibration.fitted[key] for key in calibration.free}
    document = {
        "preset": base_preset,
        **values,
        "provenance": {
            "description": description,
            "command": command,
            "fitted": list(calibration.free),
            "targets": calibration.targets,
            "achieved": calibration.achieved,
            "relative_residuals": calibration.relative_residuals,
            "sensitivities": calibration.sensitivities,
            "start": calibration.start,
            "solver": calibration.solver,
            "evaluations": calibration.evaluations,
            "message": calibration.message,
            "shakermill_version": __version__,
            "date_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        },
    }
    if calibration.curve_rms_K is not None:
        document["provenance"]["curve_rms_K"] = calibration.curve_rms_K
    header = f"# shakermill preset fitted by calibration; keys not listed come from {base_preset!r}.\n"
    return write_text_atomically(path, header + tomli_w.dumps(document))


