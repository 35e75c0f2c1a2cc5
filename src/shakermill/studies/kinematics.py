"""How the results depend on the assumed amplitudes of a named vial motion (MODEL.md §12.2: "where none
is found, state each as an assumption and show how the results depend on it").

Each assumed key of ``params.kinematics`` (``parameters.kinematic_models.KINEMATIC_MODELS[...].assumed``)
is scaled by each factor in turn, the others held, and a short full-resolution mechanics run measures the
heat power, the impact rate and the mean impact speed against the unscaled baseline. The 'dem' engine is
deterministic, so the same inputs give the same table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Sequence

from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.parameters.schema import Parameters
from shakermill.solvers.result import summarize
from shakermill.solvers.simulate import simulate_whole

if TYPE_CHECKING:
    import pandas as pd

MEASURES = ("heat_power_W", "impact_rate_hz", "mean_impact_speed_m_s")
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
    baseline: dict[str, float]
    rows: tuple[SensitivityRow, ...]

    def table(self) -> pd.DataFrame:
        """key, factor, value, the three measures and their relative changes (``<measure>_change``), baseline first."""
        import pandas as pd

        rows = (SensitivityRow("baseline", 1.0, math.nan, self.baseline, _relative(self.baseline, self.baseline)),) + self.rows
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
    duration: float = 10.0,
    progress: Callable[[int, int], None] | None = None,
) -> KinematicSensitivity:
    """Scale each of ``keys`` (default: the assumed keys of ``params.kinematics``) by each of ``factors``.

    Every run is ``params`` with ``duration`` (s), the full solver and no record windows; a value that
    leaves a key's bounds raises :class:`~shakermill.parameters.schema.ParameterError`. ``progress(done,
    total)`` is called after each run.
    """
    chosen = tuple(KINEMATIC_MODELS[params.kinematics].assumed if keys is None else keys)
    short = params.replace(duration=duration, solver="full", record_windows=())
    scaled = [(key, factor, short.replace(**{key: factor * getattr(short, key)})) for key in chosen for factor in factors]
    total = len(scaled) + 1
    baseline = _measure(short)
    if progress is not None:
        progress(1, total)
    rows = []
    for done, (key, factor, changed) in enumerate(scaled, start=2):
        measures = _measure(changed)
        rows.append(SensitivityRow(key, factor, getattr(changed, key), measures, _relative(measures, baseline)))
        if progress is not None:
            progress(done, total)
    return KinematicSensitivity(params.kinematics, duration, baseline, tuple(rows))


def _measure(params: Parameters) -> dict[str, float]:
    summary = summarize(simulate_whole(params))
    return {name: float(summary[name]) for name in MEASURES}  # type: ignore[arg-type]


def _relative(measures: dict[str, float], baseline: dict[str, float]) -> dict[str, float]:
    """(value − baseline)/baseline of each measure; NaN where the baseline is 0 or undefined."""
    return {name: (measures[name] - baseline[name]) / baseline[name] if baseline[name] else math.nan for name in MEASURES}
