"""What every study reads of a run it made: the summary of a concluded run. ``Result.summary`` is None only while a
run is being concluded (``solvers.result.conclude``); a run that ``simulate`` returns has one."""

from __future__ import annotations

from shakermill.solvers.result import Result
from shakermill.solvers.summary import Summary


def summary_of(result: Result) -> Summary:
    """``result``'s summary; a run returned unconcluded is a bug of the solver that returned it, said so."""
    if result.summary is None:
        raise RuntimeError(f"a run of {result.params.engine!r} was returned before it was concluded: no summary")
    return result.summary
