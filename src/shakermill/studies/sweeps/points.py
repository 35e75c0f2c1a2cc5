"""One point of a sweep: its run and its table row, or the row that says why it could not run."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from shakermill.io.runs import to_jsonable
from shakermill.parameters.errors import ParameterError
from shakermill.parameters.keys import Parameters
from shakermill.solvers.result import INTERRUPTED, Result
from shakermill.solvers.simulate import simulate

# A summary key that is also a swept key (only ``solver``: the averaged solver may fall back to
# full resolution) keeps the summary's value under this suffix; the swept value keeps the key.
USED_SUFFIX = "_used"


@dataclass(frozen=True)
class PointOutcome:
    """A point's table row, and its result when the run folder is to be kept."""

    row: dict[str, Any]
    result: Result | None = None


class PointInterrupted(Exception):
    """The user interrupted a point: it is not finished and must not be recorded as failed."""


def run_point(base: Parameters, values: Mapping[str, Any], keep_run: bool = False) -> PointOutcome:
    """Run one point and build its table row; a point that cannot run records why instead of raising."""
    # Both build on simulate; imported where they are used.
    from shakermill.analysis.regime import classify
    from shakermill.solvers.attractors import probed

    swept = dict(values)
    try:
        params = base.replace(**swept)
    except ParameterError as exc:
        return PointOutcome(failed_row(swept, str(exc)))
    try:
        result = simulate(params)
        if result.status == INTERRUPTED:
            # Not classified: a run cut short may be too short for it, and the point is not done anyway.
            raise PointInterrupted(result.message)
        regime, period = classify(result)
        # The averaged solver probed the other starts already; a full run has them probed here, unless
        # it stopped early: a probe would start a budget of its own after the run had spent the point's.
        # The probe settles one ball started on the axis: an engine whose runs do not start so has no such starts.
        if result.success and result.description.attractor_starts:
            probed(result)
    except PointInterrupted:
        raise
    except Exception as exc:  # noqa: BLE001 - one point's crash must not stop the sweep; its row says why
        if _caused_by_ctrl_c(exc):
            raise PointInterrupted(str(exc)) from None
        return PointOutcome(failed_row(swept, f"{type(exc).__name__}: {exc}"))
    # The summary's flat keys (solvers/summary.py) are the row's columns. A table cell holds one value: the warnings
    # and notes become one string each, or none (CSV cannot tell "" from missing).
    summary = result.summary
    told = {"warnings": "; ".join(summary.warnings) or None, "notes": " ".join(summary.notes) or None}
    columns = {**summary.flat(), **told}
    row = {
        **swept,
        "regime": regime,
        "period": period,
        "error": None if result.success else result.message,
        **{(f"{key}{USED_SUFFIX}" if key in swept else key): value for key, value in columns.items()},
        "output_dir": None,
    }
    return PointOutcome(to_jsonable(row), result if keep_run else None)


def _caused_by_ctrl_c(error: BaseException | None) -> bool:
    """Whether a ``KeyboardInterrupt`` is behind ``error``: one raised inside compiled code (Numba,
    SciPy) surfaces as another exception, a ``SystemError`` with the interrupt as its cause."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return True
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return False


def failed_row(values: Mapping[str, Any], error: str) -> dict[str, Any]:
    """The row of a point without a result: its values, why, and ``success`` false."""
    return to_jsonable({**values, "regime": None, "period": None, "error": error, "success": False})
