"""The environment variables shakermill reads, checked like keys: a value it cannot use is refused in one line,
never ignored."""

from __future__ import annotations

import os

from shakermill.parameters.errors import ParameterError

# Caps the threads of one run's replicas (default: the cores this process may use). A sweep's workers set it to 1:
# the pool already gives every core a point.
THREADS_VARIABLE = "SHAKERMILL_THREADS"
MOST_THREADS = 1024


def threads_cap() -> int | None:
    """The whole number of threads THREADS_VARIABLE allows, or None where it is unset or empty."""
    setting = os.environ.get(THREADS_VARIABLE, "").strip()
    if not setting:
        return None
    try:
        cap = int(setting)
    except ValueError:
        cap = 0
    if not 1 <= cap <= MOST_THREADS:
        shown = setting if len(setting) <= 20 else setting[:20] + "…"
        raise ParameterError(
            f"{THREADS_VARIABLE}: {shown!r} is not a number of threads; allowed a whole number in [1, {MOST_THREADS}], "
            "or unset for one thread per core"
        )
    return cap


def check_environment() -> None:
    """Refuse, in one line, an environment variable of shakermill's set to a value it cannot use."""
    threads_cap()
