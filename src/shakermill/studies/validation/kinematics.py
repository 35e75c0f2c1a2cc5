"""How the results depend on the assumed amplitudes of a named vial motion (MODEL.md §12.2: "where none
is found, state each as an assumption and show how the results depend on it").

Each assumed key of ``params.kinematics`` (``parameters.kinematic_models.KINEMATIC_MODELS[...].assumed``)
is scaled by each factor in turn, the others held, and a run measures the heat power, the rate and the mean
speed of hits (impacts of at least ``parameters.defaults.HIT_SPEED``, so that a resting ball's chatter does not
count) and any other summary key asked for, against the unscaled baseline. The 'dem' engine is
deterministic, so the same inputs give the same table.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from shakermill.parameters.keys import Parameters
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.solvers.simulate import simulate_whole
from shakermill.studies.measured import relative_error

if TYPE_CHECKING:
    import pandas as pd

MEASURES = ("heat_power_W", "hit_rate_hz", "mean_hit_speed_m_s")
DEFAULT_FACTORS = (0.5, 1.5)


@dataclass(frozen=True)
class SensitivityRow:
    """One key scaled by one factor: its value (SI), each measure and its change relative to the baseline."""

    key: str
    factor: float
    value: float
    measures: dict[str, float]
    relative_change: dict[str, float]


@dataclass(frozen=True)
class KinematicSensitivity:
    """The baseline's measures and one row per (key, factor), from runs of ``duration`` simulated seconds."""

    kinematics: str
    duration: float
    solver: str
    baseline: dict[str, float]
    rows: tuple[SensitivityRow, ...]

    def as_dict(self) -> dict:
        return {
            "kinematics": self.kinematics,
            "duration_s": self.duration,
            "solver": self.solver,
            "baseline": self.baseline,
            "rows": [row.__dict__ for row in self.rows],
        }

    def table(self) -> pd.DataFrame:
        """key, factor, value, the three measures and their relative changes (``<measure>_change``), baseline first."""
        import pandas as pd

        rows = (
            SensitivityRow("baseline", 1.0, math.nan, self.baseline, _relative(self.baseline, self.baseline)),
        ) + self.rows
        return pd.DataFrame.from_records(
            {
                "key": row.key,
                "factor": row.factor,
                "value": row.value,
                **row.measures,
                **{f"{name}_change": change for name, change in row.relative_change.items()},
            }
            for row in rows
        )


def kinematic_sensitivity(
    params: Parameters,
    keys: Sequence[str] | None = None,
    factors: Sequence[float] = DEFAULT_FACTORS,
    measures: Sequence[str] = MEASURES,
    progress: Callable[[int, int], None] | None = None,
) -> KinematicSensitivity:
    """Scale each of ``keys`` (default: the assumed keys of ``params.kinematics``) by each of ``factors``.

    Every run is ``params`` as given (its solver and duration) without record windows; a value that leaves a
    key's bounds raises :class:`~shakermill.parameters.errors.ParameterError`. ``progress(done, total)`` is
    called after each run.
    """
    chosen = tuple(KINEMATIC_MODELS[params.kinematics].assumed if keys is None else keys)
    base = params.replace(record_windows=())
    scaled = [(key, factor, base.replace(**{key: factor * getattr(base, key)})) for key in chosen for factor in factors]
    total = len(scaled) + 1
    baseline = measured(base, measures)
    if progress is not None:
        progress(1, total)
    rows = []
    for done, (key, factor, changed) in enumerate(scaled, start=2):
        values = measured(changed, measures)
        rows.append(SensitivityRow(key, factor, getattr(changed, key), values, _relative(values, baseline)))
        if progress is not None:
            progress(done, total)
    return KinematicSensitivity(params.kinematics, params.duration, params.solver, baseline, tuple(rows))


def measured(params: Parameters, measures: Sequence[str]) -> dict[str, float]:
    """The summary keys ``measures`` of a whole run of ``params``."""
    summary = simulate_whole(params).summary
    return {name: summary.number(name) for name in measures}


def _relative(values: dict[str, float], baseline: dict[str, float]) -> dict[str, float]:
    """(value − baseline)/baseline of each measure; NaN where the baseline is 0."""
    return {name: relative_error(values[name], baseline[name]) for name in values}
