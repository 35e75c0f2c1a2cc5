"""The ``shakermill`` command line: parse, call the library, write files. No physics here.

Exit codes: 0 success; 1 the run ended with a failed status: the integrator stopped early, the run used up its
budget (``max_wall_time``, ``max_steps``) or its results cannot be trusted (the run folder is still written); 2 bad
input (one ``error: ...`` line on stderr, no traceback); 130 interrupted by the user (partial results are written).

A progress bar is drawn on stderr once a run has taken a second, and only when stderr is a terminal, so pipes and
logs stay clean. One module per command group holds its commands, registered on :data:`app` below; each imports the
libraries it uses inside its commands, so that ``shakermill --help`` loads none of them.
"""

from __future__ import annotations

import gc
import sys


def main() -> None:
    """Entry point of the ``shakermill`` console script.

    The commands are imported here, not when this package is: so Ctrl-C during start-up is one line too."""
    try:
        from shakermill.cli.commands import app

        app()
    except KeyboardInterrupt:
        print("error: interrupted by the user (Ctrl-C)", file=sys.stderr)
        sys.exit(130)
    finally:
        # Everything is written by now. Tearing down NumPy, SciPy, Numba and pandas at exit collects
        # every object they made, about 0.4 s of a short run; frozen objects are left to the OS instead.
        gc.freeze()


def __getattr__(name: str) -> object:
    # ``shakermill.cli.app``, the application with its commands, for those who drive it in-process (tests, notebooks).
    if name == "app":
        from shakermill.cli.commands import app

        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
