"""Regimes of the settled motion: period-n or irregular, from the impact phases (issue 5).

The drive is periodic, so a settled periodic motion repeats its impacts every n
drive periods: the same walls at the same drive phases ωt + φ (mod 2π). The
classification looks at the impacts of the settled motion (after the averaged
solver's transient, or the second half of a full run), groups them by drive
period and finds the smallest n for which every period matches the one n later.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .simulate import Result

# Longest period searched for; motions that repeat more slowly are called irregular.
MAX_PERIOD = 16
# Impact phases of matching periods may differ by this much (rad): the integrator's tolerance
# moves impact times by ~1e-5 of a period at rtol 1e-3.
PHASE_TOLERANCE = 1e-2
# A classification needs at least this many repetitions of the candidate period.
MIN_REPEATS = 3

NO_IMPACTS = "no impacts"
IRREGULAR = "irregular"


@dataclass(frozen=True)
class ImpactPhases:
    """Impacts of the settled motion: drive period index, phase in [0, 2π) and wall."""

    period_index: np.ndarray
    phase: np.ndarray
    wall: np.ndarray


def settled_impacts(result: Result) -> pd.DataFrame:
    """The impacts after the start-up transient (the averaged solver already cut it)."""
    impacts = result.impacts
    if result.solver == "averaged":
        return impacts
    return impacts[impacts["time"] >= 0.5 * result.t_end]


def impact_phases(impacts: pd.DataFrame, omega: float, phase: float) -> ImpactPhases:
    angle = omega * impacts["time"].to_numpy() + phase
    return ImpactPhases(
        period_index=np.floor(angle / (2 * math.pi)).astype(np.int64),
        phase=np.mod(angle, 2 * math.pi),
        wall=impacts["wall"].to_numpy(),
    )


def _signatures(phases: ImpactPhases) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """(walls, phases) of each complete drive period, first to last (the partial ends are dropped)."""
    first, last = phases.period_index.min() + 1, phases.period_index.max() - 1
    signatures = []
    for index in range(first, last + 1):
        inside = phases.period_index == index
        signatures.append((tuple(phases.wall[inside]), phases.phase[inside]))
    return signatures


def _matches(a: tuple[tuple[str, ...], np.ndarray], b: tuple[tuple[str, ...], np.ndarray]) -> bool:
    if a[0] != b[0]:
        return False
    difference = np.abs(a[1] - b[1])
    return bool(np.all(np.minimum(difference, 2 * math.pi - difference) <= PHASE_TOLERANCE))


def classify(result: Result, omega: float | None = None) -> tuple[str, int | None]:
    """("period-n", n), ("irregular", None) or ("no impacts", None) for the settled motion of ``result``."""
    omega = result.params.omega if omega is None else omega
    impacts = settled_impacts(result)
    if impacts.empty:
        return NO_IMPACTS, None
    signatures = _signatures(impact_phases(impacts, omega, result.params.phase))
    for period in range(1, MAX_PERIOD + 1):
        if len(signatures) < (MIN_REPEATS + 1) * period:
            break
        if all(_matches(signatures[k], signatures[k + period]) for k in range(len(signatures) - period)):
            return f"period-{period}", period
    return IRREGULAR, None


@dataclass(frozen=True)
class Bifurcation:
    """Per ω: the regime, and the phases of the settled impacts (long format)."""

    regimes: pd.DataFrame  # omega, regime, period, solver
    phases: pd.DataFrame  # omega, phase, wall


def bifurcation(base, omegas, progress=None) -> Bifurcation:
    """Settle the motion at each ω and record its impact phases and regime.

    Uses the averaged solver's mechanics phase (transient cut by MSER) unless ``base`` says
    otherwise; the thermal part does not matter here, so a short ``duration`` suffices.
    """
    from .simulate import simulate

    regimes, phases = [], []
    for index, omega in enumerate(omegas):
        result = simulate(base.replace(omega=float(omega)))
        label, period = classify(result)
        settled = impact_phases(settled_impacts(result), float(omega), result.params.phase)
        regimes.append({"omega": float(omega), "regime": label, "period": period, "solver": result.solver})
        phases.append(pd.DataFrame({"omega": float(omega), "phase": settled.phase, "wall": settled.wall}))
        if progress is not None:
            progress(index + 1, len(omegas))
    return Bifurcation(pd.DataFrame(regimes), pd.concat(phases, ignore_index=True))
