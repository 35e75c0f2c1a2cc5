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
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np

from .limits import MAX_BIFURCATION_VALUES
from .params import ParameterError, Parameters
from .simulate import Result
from .storage import FolderKind

if TYPE_CHECKING:
    import pandas as pd

# Impacts as columns: at least "time" (s) and "wall" ("left"/"right"); a dict of arrays or a DataFrame.
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
    time, wall = np.asarray(impacts["time"]), np.asarray(impacts["wall"])
    kept = np.full(time.shape, True) if solver == "averaged" else time >= 0.5 * end_time
    return {"time": time[kept], "wall": wall[kept]}


def settled_run_impacts(run: Any) -> dict[str, np.ndarray]:
    """:func:`settled_impacts` of a :class:`~shakermill.simulate.Result` or a stored run (from its summary)."""
    return settled_impacts(run.impacts, str(run.summary["solver"]), float(run.summary["simulated_s"]))


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
    return [
        (tuple(phases.wall[start:end]), phases.phase[start:end])
        for start, end in zip(bounds[:-1], bounds[1:])
    ]


def signatures_match(a: Signature, b: Signature, tolerance: float = PHASE_TOLERANCE) -> bool:
    """Same walls in the same order, each phase within ``tolerance`` (rad, on the circle)."""
    if a[0] != b[0]:
        return False
    difference = np.abs(a[1] - b[1])
    return bool(np.all(np.minimum(difference, 2 * math.pi - difference) <= tolerance))


def classify(result: Result) -> tuple[str, int | None]:
    """("period-n", n), ("irregular", None) or ("no impacts", None) for the settled motion of ``result``."""
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


@dataclass(frozen=True)
class Bifurcation:
    """Per value of the scanned key: the configured start's regime, every attractor, and their impact phases."""

    key: str
    regimes: pd.DataFrame  # <key>, regime, period, solver, message (the configured start's run), n_attractors
    attractors: pd.DataFrame  # <key>, attractor, regime, period, basin_fraction, impact_rate_hz, heat_power_W, starts
    phases: pd.DataFrame  # <key>, start, attractor, phase, wall: the settled impacts of every start


def bifurcation(
    base: Parameters,
    values: Sequence[float],
    key: str = "omega",
    progress: Callable[[int, int], None] | None = None,
) -> Bifurcation:
    """Settle the motion at each value of ``key`` from every start; record the attractors and their impact phases.

    The regime in ``regimes`` is that of a run from the configured start with ``base``'s solver (the
    averaged solver's mechanics phase, transient cut by MSER, or the second half of a full run).
    ``attractors`` and ``phases`` come from ``base.attractor_starts`` starts settled at full
    resolution (:mod:`shakermill.attractors`); the phase of an impact is ωt + φ (mod 2π) with the ω
    of that run. Ctrl-C during a run raises ``KeyboardInterrupt``, a run that uses up its budget
    :class:`~shakermill.budget.BudgetExceeded` naming the value.
    """
    import pandas as pd

    from .attractors import probed
    from .budget import BudgetExceeded
    from .simulate import simulate_whole

    if len(values) > MAX_BIFURCATION_VALUES:
        raise ParameterError(f"bifurcation: {len(values):,} values; allowed at most {MAX_BIFURCATION_VALUES:,}")
    regimes, attractors, phases = [], [], []
    for index, value in enumerate(values):
        try:
            result = simulate_whole(base.replace(**{key: float(value)}))
        except BudgetExceeded as exc:
            raise BudgetExceeded(f"at {key} = {float(value):g}: {exc}") from None
        scan = probed(result)
        label, period = classify(result)
        regimes.append(
            {key: float(value), "regime": label, "period": period, "solver": result.solver, "message": result.message,
             "n_attractors": len(scan.attractors)}
        )
        attractors.append(_keyed(scan.table(), key, value))
        phases.append(_keyed(scan.phases(result.params.omega, result.params.phase), key, value))
        if progress is not None:
            progress(index + 1, len(values))
    table = pd.DataFrame(regimes)
    table["period"] = table["period"].astype("Int64")
    return Bifurcation(key, table, pd.concat(attractors, ignore_index=True), pd.concat(phases, ignore_index=True))


def _keyed(table: pd.DataFrame, key: str, value: float) -> pd.DataFrame:
    """``table`` with the scanned value as its first column."""
    table.insert(0, key, float(value))
    return table


BIFURCATION_TABLES = ("bifurcation_regimes", "bifurcation_attractors", "bifurcation_phases")
BIFURCATION_FIGURE = "bifurcation"


def write_bifurcation(scan: Bifurcation, folder: Path) -> list[Path]:
    """``bifurcation_regimes``, ``bifurcation_attractors`` and ``bifurcation_phases`` tables (Parquet and CSV) in ``folder``."""
    from .sweep import write_table

    folder.mkdir(parents=True, exist_ok=True)
    tables = dict(zip(BIFURCATION_TABLES, (scan.regimes, scan.attractors, scan.phases)))
    return [path for stem, table in tables.items() for path in write_table(table, folder, stem)]


def is_bifurcation_folder(folder: Path) -> bool:
    """Whether ``folder`` holds only files that ``shakermill bifurcation`` writes, and so may be replaced."""
    from .plotting import FORMATS

    names = {f"{stem}.{suffix}" for stem in BIFURCATION_TABLES for suffix in ("parquet", "csv")}
    names |= {f"{BIFURCATION_FIGURE}.{suffix}" for suffix in FORMATS}
    return all(entry.name in names and entry.is_file() for entry in folder.iterdir())


BIFURCATION_FOLDER = FolderKind("bifurcation scan", is_bifurcation_folder)
