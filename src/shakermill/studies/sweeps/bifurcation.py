"""Bifurcation scans: the settled motion and its attractors at each value of one key (issue 5), and
the folder a scan writes."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from shakermill.analysis.regime import classify
from shakermill.io.runs import FolderKind
from shakermill.parameters.defaults import FIGURE_FORMATS
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.support.limits import MAX_BIFURCATION_VALUES

if TYPE_CHECKING:
    import pandas as pd


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

    from shakermill.engines.budget import BudgetExceeded
    from shakermill.solvers.attractors import probed
    from shakermill.solvers.simulate import simulate_whole

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
            {
                key: float(value),
                "regime": label,
                "period": period,
                "solver": result.solver,
                "message": result.message,
                "n_attractors": len(scan.attractors),
            }
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
    """``bifurcation_regimes``, ``bifurcation_attractors`` and ``bifurcation_phases`` tables (Parquet and CSV) in
    ``folder``."""
    from shakermill.studies.sweeps.storage import write_table

    folder.mkdir(parents=True, exist_ok=True)
    tables = dict(zip(BIFURCATION_TABLES, (scan.regimes, scan.attractors, scan.phases)))
    return [path for stem, table in tables.items() for path in write_table(table, folder, stem)]


def is_bifurcation_folder(folder: Path) -> bool:
    """Whether ``folder`` holds only files that ``shakermill bifurcation`` writes, and so may be replaced."""
    names = {f"{stem}.{suffix}" for stem in BIFURCATION_TABLES for suffix in ("parquet", "csv")}
    names |= {f"{BIFURCATION_FIGURE}.{suffix}" for suffix in FIGURE_FORMATS}
    return all(entry.name in names and entry.is_file() for entry in folder.iterdir())


BIFURCATION_FOLDER = FolderKind("bifurcation scan", is_bifurcation_folder)
