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

from shakermill.cli import fits, listing, plots, run, scans
from shakermill.cli.common import app

# The commands, in the order `shakermill --help` lists them, with the line it shows for each.
COMMANDS = (
    ("run", run.run, "Run one simulation and write its run folder."),
    ("compare-solvers", run.compare_solvers, "Run one configuration with the full and the averaged solver."),
    ("impact", run.impact, "One impact on its own: restitution, rebound, spin, dissipation."),
    ("presets", listing.presets, "List the presets, or one preset's values and sources."),
    ("materials", listing.materials_command, "List the materials library, or one material."),
    ("keys", listing.keys, "List the parameter keys with units, ranges and defaults."),
    ("plot", plots.plot, "Draw the figures of a run folder or a sweep folder."),
    ("report", plots.report, "Write the HTML report of a run folder."),
    ("sweep", scans.sweep, "Run one simulation per point of a grid or a list."),
    ("bifurcation", scans.bifurcation, "Scan one key: regimes, impact phases, attractors."),
    ("validate", fits.validate, "This model against the experiment and the paper."),
    ("calibrate", fits.calibrate, "Fit free keys to a measured curve or targets."),
)
for name, command, short_help in COMMANDS:
    app.command(name, short_help=short_help)(command)


def main() -> None:
    """Entry point of the ``shakermill`` console script."""
    try:
        app()
    finally:
        # Everything is written by now. Tearing down NumPy, SciPy, Numba and pandas at exit collects
        # every object they made, about 0.4 s of a short run; frozen objects are left to the OS instead.
        gc.freeze()
