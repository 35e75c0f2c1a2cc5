"""Coexisting attractors: the settled motions reached from several starts, and their basins.

One run settles on one motion, but this model can hold more than one at the same parameters
(period-1 from some starts and period-2 from others at a 23 mm stroke, a cycle beside irregular
motion). Which one a run reaches then depends on its start, and its regime and heat power hide the
others. So ``attractor_starts`` deterministic initial states, the configured start first, are each
integrated at full resolution (``solvers.attractors``), for the mechanics only: settled for
:data:`SETTLE_PERIODS` drive periods, then measured over :data:`MEASURE_PERIODS` (regime from the impact
phases, heat power and impact rate over whole cycles). Here they are grouped into attractors:

* a periodic start defines a cycle: the walls and drive phases ωt + φ (mod 2π) of its last full
  cycle; every start whose window ends on that cycle or on its mirror image (the vial's two ends
  are alike), up to a shift by whole drive periods, is on that attractor, whatever its own label,
* the remaining irregular starts are one attractor while their heat powers cannot be told apart
  (within their sampling errors, or 1 %), since a chaotic motion's mean over a finite window scatters,
* starts without impacts are one attractor.

The basin fraction of an attractor is the fraction of the starts that reach it. Attractors are
numbered in the order of their first start, so attractor 0 is the configured start's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

import numpy as np

from shakermill.analysis.regime import (
    MAX_PERIOD,
    MIN_REPEATS,
    NO_IMPACTS,
    PHASE_TOLERANCE,
    Signature,
    impact_phases,
    period_signatures,
    signatures_match,
)
from shakermill.analysis.sections import Key, Section, Watts
from shakermill.parameters.keys import Parameters

if TYPE_CHECKING:
    import pandas as pd

# Drive periods before the measurement. Over ω 90–130 rad/s and strokes of 23–28 mm, 250 periods
# already give the same basins as 400 (200 do not), but at rtol 1e-5 slow period doublings still
# change labels between 250 and 400.
SETTLE_PERIODS = 400
# Enough complete periods (two partial ones at the ends are dropped) for classify_impacts to
# recognise every period up to MAX_PERIOD with MIN_REPEATS repetitions.
MEASURE_PERIODS = (MIN_REPEATS + 1) * MAX_PERIOD + 2
# A start is on a cycle's attractor when each of its impacts is within this of the cycle's (rad): twice
# the classification's tolerance, because the integrator's error jitters both the cycle and the start.
MEMBERSHIP_TOLERANCE = 2.0 * PHASE_TOLERANCE
# Drive periods at the end of the window that must follow a cycle for a start to be on it: the longest
# cycle classified, and long enough that an irregular motion passing near a cycle is not taken for it.
TAIL_PERIODS = MAX_PERIOD
# A difference in heat power from the configured start's attractor worth a warning; irregular motions
# closer than this are one attractor even where their sampling errors are smaller.
HEAT_POWER_TOLERANCE = 0.01
# Irregular motions whose heat powers differ by less than this many combined standard errors are one
# attractor: over MEASURE_PERIODS the mean heat of one chaotic motion scatters by a few percent between starts.
SAMPLING_SPREAD = 3.0
# Drive periods per batch of the batch-means standard error of an irregular motion's heat power.
BATCH_PERIODS = 6
# Starts other than the configured one lie within this fraction of the free gap around the vial
# centre: a ball started touching an end face begins with a contact already under way.
POSITION_SPREAD = 0.8
# Positions k·g mod 1 for k = 1, 2, ...: any number of starts spreads evenly over the gap.
GOLDEN_FRACTION = (math.sqrt(5.0) - 1.0) / 2.0
# Start k moves at MOMENTUM_PATTERN[k mod 3] times the vial's peak speed A·ω: forwards, backwards, at rest.
MOMENTUM_PATTERN = (0.0, 1.0, -1.0)

FAILED = "failed"
ATTRACTOR_COLUMNS = ("attractor", "regime", "period", "basin_fraction", "impact_rate_hz", "heat_power_W", "starts")


@dataclass(frozen=True)
class SettledStart:
    """The motion one start settled on, measured over whole cycles of it (whole window otherwise)."""

    start: int
    ball_position: float  # m, relative to the vial centre at t = 0
    ball_momentum: float  # kg m/s
    regime: str  # "period-n", "irregular", "no impacts", or "failed" (the integrator stopped)
    period: int | None
    impact_rate_hz: float
    heat_power_W: float
    heat_power_stderr_W: float  # from batch means; what separates irregular motions
    impacts: dict[str, np.ndarray]  # the settled impacts' columns; "time" (s) and "wall" are used
    message: str = ""


@dataclass(frozen=True)
class Attractor:
    """One settled motion and the starts that reached it."""

    label: int
    regime: str
    period: int | None
    basin_fraction: float
    impact_rate_hz: float  # mean over its starts
    heat_power_W: float  # mean over its starts
    starts: tuple[int, ...]


class AttractorSection(Section):
    """The summary's section of the attractor probe (``summary.attractors``; ``solvers/attractors.py``)."""

    count: Annotated[int, Key("n_attractors")]
    """Settled motions reached from the probed starts."""
    heat_power_spread_W: Watts
    """Largest minus smallest heat power across those attractors."""
    heat_power_spread_relative: float
    """That spread over the configured start's heat power."""
    failed_starts: Annotated[int, Key("attractor_failed_starts")]
    """Probed starts that did not settle."""


@dataclass(frozen=True)
class AttractorScan:
    """All starts of one parameter set, and the attractors they reached (attractor 0: the configured start's)."""

    settled: tuple[SettledStart, ...]
    attractors: tuple[Attractor, ...]

    @property
    def configured(self) -> Attractor | None:
        """The attractor of the configured start (start 0), None when its integration failed."""
        return next((attractor for attractor in self.attractors if 0 in attractor.starts), None)

    @property
    def failed(self) -> tuple[SettledStart, ...]:
        return tuple(start for start in self.settled if start.regime == FAILED)

    @property
    def heat_power_spread_W(self) -> float:
        """Largest minus smallest heat power across the attractors (0 for one attractor)."""
        powers = [attractor.heat_power_W for attractor in self.attractors]
        return max(powers) - min(powers) if powers else math.nan

    def differing(self) -> list[Attractor]:
        """The attractors whose heat power differs from the configured start's by more than HEAT_POWER_TOLERANCE."""
        configured = self.configured
        if configured is None:
            return []
        return [
            attractor
            for attractor in self.attractors
            if _relative_difference(attractor.heat_power_W, configured.heat_power_W) > HEAT_POWER_TOLERANCE
        ]

    def as_summary(self) -> AttractorSection:
        configured = self.configured
        reference = configured.heat_power_W if configured is not None else math.nan
        return AttractorSection(
            count=len(self.attractors),
            heat_power_spread_W=self.heat_power_spread_W,
            heat_power_spread_relative=self.heat_power_spread_W / reference if reference > 0 else math.nan,
            failed_starts=len(self.failed),
        )

    def warnings(self) -> list[str]:
        """One line per other attractor with a different heat power, and one per failed start."""
        configured = self.configured
        # Without the configured start's attractor nothing differs from it (differing() is empty).
        lines = (
            []
            if configured is None
            else [_difference_warning(attractor, configured, len(self.settled)) for attractor in self.differing()]
        )
        # One line per reason: once a run's budget is spent, every start left fails for it.
        failed_for: dict[str, list[str]] = {}
        for start in self.failed:
            failed_for.setdefault(start.message, []).append(str(start.start))
        for message, starts in failed_for.items():
            lines.append(
                f"attractor probe: start{'s' if len(starts) > 1 else ''} {', '.join(starts)} did not settle ({message})"
            )
        return lines

    def table(self) -> pd.DataFrame:
        """One row per attractor: attractor, regime, period, basin_fraction, impact_rate_hz, heat_power_W, starts."""
        import pandas as pd

        rows = [
            {
                "attractor": attractor.label,
                "regime": attractor.regime,
                "period": attractor.period,
                "basin_fraction": attractor.basin_fraction,
                "impact_rate_hz": attractor.impact_rate_hz,
                "heat_power_W": attractor.heat_power_W,
                # One cell, readable in the CSV: the start indices, space-separated.
                "starts": " ".join(map(str, attractor.starts)),
            }
            for attractor in self.attractors
        ]
        table = pd.DataFrame(rows, columns=list(ATTRACTOR_COLUMNS))
        table["period"] = table["period"].astype("Int64")
        return table

    def phases(self, omega: float, phase: float) -> pd.DataFrame:
        """The drive phase of every settled impact of every start that settled: start, attractor, phase, wall."""
        import pandas as pd

        label_of = {start: attractor.label for attractor in self.attractors for start in attractor.starts}
        parts = []
        for settled in self.settled:
            if settled.start in label_of:
                angles = impact_phases(settled.impacts, omega, phase)
                parts.append(
                    pd.DataFrame(
                        {
                            "start": settled.start,
                            "attractor": label_of[settled.start],
                            "phase": angles.phase,
                            "wall": angles.wall,
                        }
                    )
                )
        columns = ["start", "attractor", "phase", "wall"]
        return pd.concat(parts, ignore_index=True)[columns] if parts else pd.DataFrame(columns=columns)


def _relative_difference(value: float, reference: float) -> float:
    if reference == 0.0:
        return 0.0 if value == 0.0 else math.inf
    return abs(value - reference) / abs(reference)


def _difference_warning(attractor: Attractor, configured: Attractor, starts: int) -> str:
    change = (
        f" ({100.0 * (attractor.heat_power_W / configured.heat_power_W - 1.0):+.1f} %)"
        if configured.heat_power_W > 0
        else ""
    )
    return (
        f"coexisting attractor: {len(attractor.starts)} of {starts} starts (basin fraction "
        f"{attractor.basin_fraction:.2f}) "
        f"settle on {attractor.regime} with heat power {attractor.heat_power_W:.4g} W{change}, the configured "
        f"start on {configured.regime} with {configured.heat_power_W:.4g} W; this run follows the configured start"
    )


# Starts -----------------------------------------------------------------------------------------


def initial_states(params: Parameters, count: int) -> list[tuple[float, float]]:
    """(ball_position, ball_momentum) of ``count`` starts: the configured one, then a fixed spread.

    Start k ≥ 1 sits at (2·frac(k·g) − 1)·POSITION_SPREAD of the free half-gap, g the golden
    fraction, and moves at MOMENTUM_PATTERN[k mod 3] times the vial's peak speed. Both scale with
    the geometry and the drive, so the starts mean the same at every point of a scan.
    """
    half_gap = params.vial_length / 2.0 - params.ball_radius
    speed = params.amplitude * params.omega
    states = [(params.ball_position, params.ball_momentum)]
    for k in range(1, count):
        fraction = (k * GOLDEN_FRACTION) % 1.0
        position = (2.0 * fraction - 1.0) * POSITION_SPREAD * half_gap
        states.append((position, params.ball_mass * speed * MOMENTUM_PATTERN[k % len(MOMENTUM_PATTERN)]))
    return states


def settle_span(params: Parameters) -> float:
    """Simulated seconds :func:`shakermill.solvers.attractors.settle` integrates: SETTLE_PERIODS and MEASURE_PERIODS
    drive periods."""
    return (SETTLE_PERIODS + MEASURE_PERIODS) * params.period


def group(settled: tuple[SettledStart, ...], omega: float, phase: float) -> tuple[Attractor, ...]:
    """The attractors of the starts that settled, numbered by their first start."""
    reached = [start for start in settled if start.regime != FAILED]
    groups, unmatched = _cycle_groups([start for start in reached if start.regime != NO_IMPACTS], omega, phase)
    groups += _heat_groups(unmatched)
    resting = [start for start in reached if start.regime == NO_IMPACTS]
    if resting:
        groups.append(resting)
    groups.sort(key=lambda members: members[0].start)
    return tuple(_attractor(label, members, len(settled)) for label, members in enumerate(groups))


def _cycle_groups(
    moving: list[SettledStart], omega: float, phase: float
) -> tuple[list[list[SettledStart]], list[SettledStart]]:
    """The starts that end on a periodic start's cycle, or its mirror image, grouped; and the others.

    A start is on a cycle when each of its last TAIL_PERIODS drive periods matches the cycle's within
    MEMBERSHIP_TOLERANCE, up to a shift by whole drive periods. The ends are compared because near a
    bifurcation the motion still drifts slowly towards its cycle; and there one start is called
    period-1 or irregular and another period-2 on the same motion, with the same heat power. The
    cycles are the last full cycles of the periodic starts, taken in start order.
    """
    cycles: list[tuple[list[Signature], list[SettledStart]]] = []
    unmatched = []
    for start in sorted(moving, key=lambda start: (start.period is None, start.start)):
        views = [_signatures(impacts, omega, phase) for impacts in (start.impacts, _mirrored(start.impacts, omega))]
        match = next((members for cycle, members in cycles if any(_ends_on(view, cycle) for view in views)), None)
        if match is not None:
            match.append(start)
        elif start.period is not None:
            cycles.append((views[0][-start.period :], [start]))
        else:
            unmatched.append(start)
    return [sorted(members, key=lambda start: start.start) for _, members in cycles], unmatched


def _signatures(impacts: dict[str, np.ndarray], omega: float, phase: float) -> list[Signature]:
    return period_signatures(impact_phases(impacts, omega, phase))


def _mirrored(impacts: dict[str, np.ndarray], omega: float) -> dict[str, np.ndarray]:
    """The same motion seen from the other end: x → −x is the drive half a period later, walls swapped.

    The vial's two ends are alike, so a motion and its mirror image are one attractor (the same heat,
    rate and regime), reached by mirror-image starts.
    """
    swapped = np.where(impacts["wall"] == "left", "right", "left")
    return {"time": impacts["time"] + math.pi / omega, "wall": swapped}


def _ends_on(window: list[Signature], cycle: list[Signature]) -> bool:
    """Whether each of the last TAIL_PERIODS periods of ``window`` matches the cycle's, for one shift."""
    tail = window[-TAIL_PERIODS:]
    return any(
        all(
            signatures_match(signature, cycle[(k + shift) % len(cycle)], MEMBERSHIP_TOLERANCE)
            for k, signature in enumerate(tail)
        )
        for shift in range(len(cycle))
    )


def _heat_groups(irregular: list[SettledStart]) -> list[list[SettledStart]]:
    """Irregular motions, sorted by heat power, split where two neighbours are told apart (:func:`_distinct_heat`)."""
    ordered = sorted(irregular, key=lambda start: start.heat_power_W)
    groups: list[list[SettledStart]] = []
    for start in ordered:
        if groups and not _distinct_heat(groups[-1][-1], start):
            groups[-1].append(start)
        else:
            groups.append([start])
    return [sorted(members, key=lambda start: start.start) for members in groups]


def _distinct_heat(a: SettledStart, b: SettledStart) -> bool:
    difference = abs(a.heat_power_W - b.heat_power_W)
    sampling = SAMPLING_SPREAD * math.hypot(a.heat_power_stderr_W, b.heat_power_stderr_W)
    return difference > max(sampling, HEAT_POWER_TOLERANCE * max(a.heat_power_W, b.heat_power_W))


def _attractor(label: int, members: list[SettledStart], starts: int) -> Attractor:
    # A group with a periodic start is that start's cycle (a jittered member may be called irregular).
    named = next((member for member in members if member.period is not None), members[0])
    return Attractor(
        label=label,
        regime=named.regime,
        period=named.period,
        basin_fraction=len(members) / starts,
        impact_rate_hz=float(np.mean([member.impact_rate_hz for member in members])),
        heat_power_W=float(np.mean([member.heat_power_W for member in members])),
        starts=tuple(member.start for member in members),
    )
