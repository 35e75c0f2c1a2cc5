"""Regimes of the settled motion: period-n or irregular, from the impact phases (issue 5).

The drive is periodic, so a settled periodic motion repeats its impacts every n
drive periods: the same walls at the same drive phases ωt + φ (mod 2π). The
classification looks at the impacts of the settled motion (after the averaged
solver's transient, or the second half of a full run), groups them by drive
period and finds the smallest n for which every period matches the one n later.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

# Impacts as columns: at least "time" (s) and "wall" ("left"/"right"), or the 'dem' engine's "ball" and
# "target" (which ball hit what); a dict of arrays or a DataFrame.
ImpactColumns = Mapping[str, Any]

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


def settled_impacts(impacts: ImpactColumns, solver: str, end_time: float) -> dict[str, np.ndarray]:
    """Time and wall of the impacts after the start-up transient: the second half of a full run (the
    averaged solver already cut it)."""
    time, wall = np.asarray(impacts["time"]), _walls(impacts)
    kept = np.full(time.shape, True) if solver == "averaged" else time >= 0.5 * end_time
    return {"time": time[kept], "wall": wall[kept]}


def _walls(impacts: ImpactColumns) -> np.ndarray:
    """What was hit at each impact: the wall, or for several balls which ball hit what ("0:left", "1:ball")."""
    if "wall" in impacts:
        return np.asarray(impacts["wall"])
    return np.char.add(
        np.char.add(np.asarray(impacts["ball"]).astype(str), ":"), np.asarray(impacts["target"]).astype(str)
    )


def settled_run_impacts(run: Any) -> dict[str, np.ndarray]:
    """:func:`settled_impacts` of a :class:`~shakermill.simulate.Result` or a stored run (from its summary)."""
    return settled_impacts(run.impacts, run.summary.solver, run.summary.simulated_s)


def impact_phases(impacts: ImpactColumns, omega: float, phase: float) -> ImpactPhases:
    angle = omega * np.asarray(impacts["time"]) + phase
    return ImpactPhases(
        period_index=np.floor(angle / (2 * math.pi)).astype(np.int64),
        phase=np.mod(angle, 2 * math.pi),
        wall=np.asarray(impacts["wall"]),
    )


# The walls and the drive phases of the impacts of one drive period.
Signature = tuple[tuple[str, ...], np.ndarray]


def period_signatures(phases: ImpactPhases) -> list[Signature]:
    """(walls, phases) of each complete drive period, first to last (the partial ends are dropped).

    The impacts are in time order, so each period is one slice: linear in the number of impacts,
    which matters for the ~10^5 impacts of a settled full-resolution hour.
    """
    first, last = phases.period_index.min() + 1, phases.period_index.max() - 1
    bounds = np.searchsorted(phases.period_index, np.arange(first, last + 2))
    return [(tuple(phases.wall[start:end]), phases.phase[start:end]) for start, end in zip(bounds[:-1], bounds[1:])]


def signatures_match(a: Signature, b: Signature, tolerance: float = PHASE_TOLERANCE) -> bool:
    """Same walls in the same order, each phase within ``tolerance`` (rad, on the circle)."""
    if a[0] != b[0]:
        return False
    difference = np.abs(a[1] - b[1])
    return bool(np.all(np.minimum(difference, 2 * math.pi - difference) <= tolerance))


def classify(result: Any) -> tuple[str, int | None]:
    """("period-n", n), ("irregular", None) or ("no impacts", None) for the settled motion of ``result``
    (a :class:`~shakermill.solvers.result.Result`, or a run read back from its folder)."""
    settled = settled_impacts(result.impacts, result.solver, result.t_end)
    return classify_impacts(settled, result.params.omega, result.params.phase)


def classify_impacts(settled: ImpactColumns, omega: float, phase: float) -> tuple[str, int | None]:
    """The regime of a settled motion from its impacts (columns ``time`` and ``wall``), drive ω and φ."""
    if len(settled["time"]) == 0:
        return NO_IMPACTS, None
    signatures = period_signatures(impact_phases(settled, omega, phase))
    for period in range(1, MAX_PERIOD + 1):
        if len(signatures) < (MIN_REPEATS + 1) * period:
            break
        if all(signatures_match(signatures[k], signatures[k + period]) for k in range(len(signatures) - period)):
            return f"period-{period}", period
    return IRREGULAR, None


# A charge moves as a pack on the wall when its lasting contacts (over 1 ms: rolling, sliding, resting) take most of
# the dissipation and its balls hit at over 1 m/s less than once a turn each; otherwise it is active (MODEL.md §14.2:
# the regime named from the lasting contacts' share and the rate of impacts above 1 m/s).
PACK = "pack"
ACTIVE = "active"
PACK_SHARE = 0.5
PACK_FAST_IMPACTS_PER_BALL_AND_TURN = 1.0


def charge_regime(lasting_share: float, fast_impact_rate: float, n_balls: int, frequency: float) -> str:
    """:data:`PACK` or :data:`ACTIVE` from the lasting contacts' share of the dissipation, the impacts above 1 m/s a
    second, the balls and the drive's turns a second (Hz)."""
    rare = fast_impact_rate < PACK_FAST_IMPACTS_PER_BALL_AND_TURN * n_balls * frequency
    return PACK if lasting_share >= PACK_SHARE and rare else ACTIVE


# A charge whose batches change regime at least this often after its first (the start-up) switches back and forth: it
# is intermittent (MODEL.md §14.2), a regime of its own, averaged over batches that hold SWITCHES_PER_BATCH switches.
INTERMITTENT = "intermittent"
INTERMITTENT_SWITCHES = 2
SWITCHES_PER_BATCH = 3
# A regime holds for at least this many batches, or it is flicker: a batch of an active charge near the pack's
# thresholds named pack alone (pulverisette7 at friction 0.52: two such batches in 400 of 0.3 s) is no change of motion.
PERSISTENT_BATCHES = 3


@dataclass(frozen=True)
class Switching:
    """The regime of each batch of ``batch`` s of a settled motion, in order (:data:`PACK` or :data:`ACTIVE`)."""

    labels: tuple[str, ...]
    batch: float

    @cached_property
    def persistent(self) -> tuple[str, ...]:
        """The labels with every run shorter than PERSISTENT_BATCHES taken as the regime before it (the first run,
        as the first regime that persists): the regimes the motion held."""
        runs = [(label, len(list(run))) for label, run in itertools.groupby(self.labels)]
        held = [label for label, length in runs if length >= PERSISTENT_BATCHES]
        current = held[0] if held else (runs[0][0] if runs else "")
        smoothed: list[str] = []
        for label, length in runs:
            current = label if length >= PERSISTENT_BATCHES else current
            smoothed.extend([current] * length)
        return tuple(smoothed)

    @property
    def switches(self) -> int:
        held = self.persistent
        return sum(before != after for before, after in zip(held, held[1:]))

    @property
    def intermittent(self) -> bool:
        return self.switches >= INTERMITTENT_SWITCHES

    def share(self, regime: str) -> float:
        """The share of the batches (of the time) in ``regime``, flicker taken as the regime it interrupts; NaN without
        batches."""
        return self.persistent.count(regime) / len(self.labels) if self.labels else math.nan

    @property
    def switch_interval(self) -> float:
        """The mean time between switches (s); NaN without any."""
        return len(self.labels) * self.batch / self.switches if self.switches else math.nan

    def batches_holding_switches(self) -> int:
        """The fewest batches a group must hold for SWITCHES_PER_BATCH switches on average (1 without switches)."""
        if not self.switches:
            return 1
        return max(1, -(-SWITCHES_PER_BATCH * len(self.labels) // self.switches))
