"""Post-processing of a temperature history (MODEL.md section 8; paper Eqs. 41–42)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.optimize import least_squares

from shakermill.analysis.sections import Celsius, CelsiusPerMinute, Kelvin, Minutes, Section


class FitSection(Section):
    """The summary's keys of the exponential fitted to the ball temperature (:meth:`ExponentialFit.as_summary`)."""

    theta_inf_C: Celsius
    """θ∞ of the exponential θ∞ − (θ∞ − θ₀)·exp(−t/τ) fitted to the ball temperature (the balls' mean) over the run
    (MODEL.md §8): a property of the run's window, not the steady state; NaN where the fit failed."""
    theta_inf_stderr_K: Kelvin
    """Standard error of ``theta_inf_C``."""
    tau_min: Minutes
    """τ of that fit."""
    tau_stderr_min: Minutes
    """Standard error of ``tau_min``."""
    rate0_C_per_min: CelsiusPerMinute
    """The fit's initial heating rate θ̇₀ = (θ∞ − θ₀)/τ."""
    fit_rms_residual_K: Kelvin
    """RMS residual of that fit."""
    exponential_fit_describes_run: bool
    """Whether the exponential is worth reading: fitted, over a run no shorter than the network's slowest time
    constant."""


@dataclass(frozen=True)
class ExponentialFit:
    """θ(t) = (θ_0 − θ_∞)·exp(−t/τ) + θ_∞ with θ_0 fixed; temperatures in K, times in s."""

    theta_0: float
    theta_inf: float
    tau: float
    theta_inf_stderr: float
    tau_stderr: float
    rms_residual: float
    success: bool
    message: str

    @property
    def initial_rate(self) -> float:
        """θ̇_0 = (θ_∞ − θ_0)/τ in K/s (paper Eq. 42)."""
        return (self.theta_inf - self.theta_0) / self.tau

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        return exponential_approach(t, self.theta_0, self.theta_inf, self.tau)

    def as_dict(self) -> dict[str, float | bool | str]:
        return {**asdict(self), "initial_rate": self.initial_rate}

    def as_summary(self, describes_run: bool) -> FitSection:
        """The summary's section of this fit, in °C and minutes; ``describes_run``: whether the run was no shorter than
        its network's slowest time constant, so that an exponential was to be expected."""
        return FitSection(
            theta_inf_C=self.theta_inf - 273.15,
            theta_inf_stderr_K=self.theta_inf_stderr,
            tau_min=self.tau / 60.0,
            tau_stderr_min=self.tau_stderr / 60.0,
            rate0_C_per_min=self.initial_rate * 60.0,
            fit_rms_residual_K=self.rms_residual,
            exponential_fit_describes_run=bool(self.success) and describes_run,
        )


def exponential_approach(t: np.ndarray, theta_0: float, theta_inf: float, tau: float) -> np.ndarray:
    """(θ_0 − θ_∞)·exp(−t/τ) + θ_∞ (paper Eq. 41)."""
    return (theta_0 - theta_inf) * np.exp(-np.asarray(t) / tau) + theta_inf


def fit_exponential(t: np.ndarray, theta: np.ndarray, theta_0: float) -> ExponentialFit:
    """Fit θ_∞ and τ by non-linear least squares over the whole record (MODEL.md §8).

    Returns a fit with ``success = False`` and NaNs when the record does not
    determine an exponential approach (too short, or no change).
    """
    t = np.asarray(t, dtype=float)
    theta = np.asarray(theta, dtype=float)
    keep = np.isfinite(t) & np.isfinite(theta)
    t, theta = t[keep], theta[keep]
    rise = theta[-1] - theta_0 if theta.size else 0.0
    if theta.size < 3 or t[-1] <= t[0] or abs(rise) < 1e-9:
        return _failed(theta_0, "too few points or no temperature change to fit")

    def residuals(v: np.ndarray) -> np.ndarray:
        return exponential_approach(t, theta_0, v[0], v[1]) - theta

    span = t[-1] - t[0]
    guess = np.array([theta_0 + 1.2 * rise, span / 3.0])
    solution = least_squares(residuals, guess, bounds=([-np.inf, 1e-9 * span], [np.inf, np.inf]), x_scale="jac")
    theta_inf, tau = solution.x
    dof = max(theta.size - 2, 1)
    variance = float(np.sum(solution.fun**2) / dof)
    try:
        covariance = np.linalg.inv(solution.jac.T @ solution.jac) * variance
        stderr = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    except np.linalg.LinAlgError:
        stderr = np.array([math.nan, math.nan])
    return ExponentialFit(
        theta_0=theta_0,
        theta_inf=float(theta_inf),
        tau=float(tau),
        theta_inf_stderr=float(stderr[0]),
        tau_stderr=float(stderr[1]),
        rms_residual=math.sqrt(variance),
        success=bool(solution.success),
        message=str(solution.message),
    )


def _failed(theta_0: float, message: str) -> ExponentialFit:
    return ExponentialFit(theta_0, math.nan, math.nan, math.nan, math.nan, math.nan, False, message)


def increment_ratio(theta_vial_end: float, theta_ball_end: float, theta_0: float) -> float:
    """(θ_v(t_end) − θ_0)/(θ_b(t_end) − θ_0): vial-to-ball temperature increment ratio (MODEL.md §8)."""
    ball_rise = theta_ball_end - theta_0
    return (theta_vial_end - theta_0) / ball_rise if ball_rise != 0.0 else math.nan
