"""Hard limits on the size of user input, each with the reason it is where it is (issue 12).

A value past one of these would not be a wrong answer but a hang, a multi-GiB allocation or a
line of error text as long as the input; they are checked before anything is parsed or allocated.
The limits of each parameter's value are its field's bounds in :mod:`shakermill.params`.

This module imports nothing, so that every reader of user input can use it without cost.
"""

from __future__ import annotations

# The longest number or quantity with its unit one value may be: "6.35e-3 m" or "1060 rpm" are ten
# characters, and any real number is written in 25 digits. A longer one is a paste gone wrong, and
# a number of 100 000 digits made the old parser take minutes.
MAX_VALUE_LENGTH = 100
# Stored samples of the time series (duration / output_interval): each holds ten state variables, so
# 1e6 samples are ~100 MB in memory and in timeseries.nc: a second's sampling for eleven days.
MAX_SAMPLES = 1_000_000
# Full-resolution windows: a run stores every integrator step inside them (~1000 per simulated second
# at the default drive), so ten minutes are ~6e5 rows, ~70 MB in windows.nc; the paper's two windows
# last 1.1 s. Longer stretches belong to the sampled time series.
MAX_RECORD_WINDOWS = 100
MAX_RECORDED_SECONDS = 600.0
# The full solver keeps every impact (72 bytes each, about three per drive period): 2e6 periods are
# ~31 hours at the default drive and ~450 MB of impacts; longer runs are the averaged solver's.
MAX_FULL_RESOLUTION_PERIODS = 2_000_000
# A sweep lists every point in sweep.json and runs each for ~0.03-3 s: 1e5 points are ~20 MB of
# manifest and a day of a 16-core machine's time even with the averaged solver.
MAX_SWEEP_POINTS = 100_000
# A bifurcation scan settles every start at each value: 1e4 values are hours, and more than a
# diagram's few thousand pixels across can show.
MAX_BIFURCATION_VALUES = 10_000
# A measured temperature curve: a point a second for a day is 86 400.
MAX_CURVE_POINTS = 100_000
# The most balls a run moves: the 'dem' engine's contact search (a neighbour list, engines/dem/neighbours.py) and
# its memory grow linearly with them; a run's preflight refuses what the machine cannot hold or finish.
MAX_BALLS = 2000
# A configuration file holds about sixty keys, a few kilobytes.
MAX_CONFIG_BYTES = 1_000_000
# How much of an over-long or odd input an error line quotes.
QUOTED_LENGTH = 40


def quoted(value: object) -> str:
    """``repr(value)``, shortened to :data:`QUOTED_LENGTH` characters so that an error stays one readable line."""
    text = repr(value)
    return text if len(text) <= QUOTED_LENGTH else f"{text[: QUOTED_LENGTH - 5]}...{text[-2:]} ({len(text)} characters)"


def in_one_line(error: BaseException) -> str:
    """An exception's message on one line (its type's name where it has none)."""
    return " ".join(str(error).split()) or type(error).__name__
