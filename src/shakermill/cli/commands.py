"""The ``shakermill`` commands, registered on the typer application of :mod:`shakermill.cli.common`."""

from __future__ import annotations

from shakermill.cli import ensembles, fits, listing, plots, run, scans, validating
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
    ("uncertainty", ensembles.uncertainty, "An answer over its assumed inputs: 5/50/95 %, Sobol' indices, regimes."),
    ("bifurcation", scans.bifurcation, "Scan one key: regimes, impact phases, attractors."),
    ("validate", validating.validate, "This model against the experiment and the paper."),
    ("calibrate", fits.calibrate, "Fit free keys to a measured curve or targets."),
)
for name, command, short_help in COMMANDS:
    app.command(name, short_help=short_help)(command)
