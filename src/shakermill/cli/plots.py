"""``shakermill plot`` and ``report``: the figures and the HTML report of a run folder (or a sweep's figures)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from shakermill.cli.common import fail, user_errors, writing
from shakermill.cli.run import FIGURES_FOLDER
from shakermill.parameters.defaults import (
    ANIMATION_FILE,
    ANIMATION_FRAMES,
    MOST_ANIMATION_FRAMES,
    PNG_DPI,
    REPORT_FILE,
)

if TYPE_CHECKING:
    from shakermill.io.runs import RunData


def load_run_or_fail(folder: Path) -> RunData:
    """The run folder at ``folder``, or one ``error:`` line and exit code 2."""
    from shakermill.io.runs import load_run

    with user_errors():
        return load_run(folder)


def plot(
    folder: Annotated[
        Path,
        typer.Argument(
            metavar="RUN_DIR|SWEEP_DIR", help="A run folder (`shakermill run`) or a sweep folder (`shakermill sweep`)."
        ),
    ],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", show_default="DIR/figures", help="Folder for the figures.")
    ] = None,
    impacts: Annotated[
        bool, typer.Option("--impacts", help="Run folder: only the impact statistics (speed, energy, rate, phase).")
    ] = False,
    contour: Annotated[
        list[str] | None,
        typer.Option(
            "--contour", metavar="COLUMN=VALUE", help="Sweep folder: draw this level on every map, e.g. theta_inf_C=60."
        ),
    ] = None,
    dpi: Annotated[int, typer.Option("--dpi", min=30, max=600, help="Resolution of the PNG files.")] = PNG_DPI,
    window: Annotated[
        int | None,
        typer.Option(
            "--window",
            min=0,
            show_default="0",
            help=(
                "Run folder: the record window (index in record_windows, from 0) of the ball's motion, the balls' "
                "paths and the animation."
            ),
        ),
    ] = None,
    animate: Annotated[
        bool,
        typer.Option(
            "--animate",
            help=(
                f"Run folder of the dem engine: also write {ANIMATION_FILE}, the balls over --window in the vial's "
                "side view."
            ),
        ),
    ] = False,
    frames: Annotated[
        int, typer.Option("--frames", min=2, max=MOST_ANIMATION_FRAMES, help="Frames of the animation (24 a second).")
    ] = ANIMATION_FRAMES,
) -> None:
    """Draw the figures of a run folder (paper Figs. 4, 5a, 5b, impact statistics; for the dem engine the balls'
    paths and heat by channel, and with --animate a GIF) or of a sweep folder (maps or lines)."""
    from shakermill.studies.sweeps.storage import is_sweep_folder
    from shakermill.views.figures.common import plot_figures

    target = out if out is not None else folder / FIGURES_FOLDER
    if is_sweep_folder(folder):
        for given, option in ((impacts, "--impacts"), (animate, "--animate"), (window is not None, "--window")):
            if given:
                fail(
                    f"{option}: a sweep folder has no impacts or motion of its own; plot one run (sweep --keep-runs "
                    "writes them)"
                )
        figures = _sweep_figures(folder, contour or [])
        with writing(target, "the figures"):
            paths = plot_figures(figures, target, dpi=dpi)
    else:
        if contour:
            fail("--contour: contours are drawn on the maps of a sweep folder, not on a run")
        paths = _plot_run_folder(
            folder, target, dpi, impacts=impacts, window=window, frames=frames if animate else None
        )
    typer.echo(f"{len(paths)} files written to {target}")


def _sweep_figures(folder: Path, contour: Sequence[str]) -> dict[str, Any]:
    """The maps or lines of a sweep folder, with the ``--contour`` levels; a note for each level never reached."""
    from shakermill.studies.sweeps.storage import load_sweep
    from shakermill.views.figures.sweeps import contour_notes, parse_contour, sweep_context, sweep_figures

    with user_errors():
        data = load_sweep(folder)
        numeric = list(data.table.select_dtypes("number").columns)
        levels = [parse_contour(spec, numeric) for spec in contour]
        figures = sweep_figures(data.table, data.keys, levels, context=sweep_context(data.manifest, data.keys))
    for note in contour_notes(data.table, levels):
        typer.echo(f"note: {note}; no contour drawn", err=True)
    return figures


def _plot_run_folder(
    folder: Path, target: Path, dpi: int, *, impacts: bool, window: int | None, frames: int | None
) -> list[Path]:
    """The figures of a run folder, and its animation of ``frames`` frames unless None; the files written."""
    from shakermill.views.figures.common import check_window, plot_figures, several_balls
    from shakermill.views.figures.impacts import impact_figures
    from shakermill.views.figures.run import run_figures, write_animation

    run_data = load_run_or_fail(folder)
    if frames is not None and not several_balls(run_data.params):
        fail(
            "--animate: the animation shows the balls of an engine that moves several in three dimensions (--set "
            f"engine=dem); this run's engine is {run_data.description.keys.title}"
        )
    with user_errors():
        if window is not None:
            check_window(run_data.params, window)
        written = []
        # First: a window without motion to animate is refused before any figure is written.
        if frames is not None:
            with writing(target, "the animation"):
                written.append(write_animation(run_data, target / ANIMATION_FILE, window=window or 0, frames=frames))
        figures = impact_figures(run_data) if impacts else run_figures(run_data, impacts=True, window=window or 0)
    with writing(target, "the figures"):
        return plot_figures(figures, target, dpi=dpi) + written


def report(
    run_dir: Annotated[Path, typer.Argument(metavar="RUN_DIR", help="A run folder written by `shakermill run`.")],
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", metavar="FILE", show_default=f"RUN_DIR/{REPORT_FILE}", help="HTML file to write."),
    ] = None,
    compare: Annotated[
        Path | None,
        typer.Option("--compare", metavar="OTHER_RUN_DIR", help="Add a side-by-side comparison with this run folder."),
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace the report file if it exists.")] = False,
) -> None:
    """Write one self-contained HTML report of a run folder (figures embedded, no external resources)."""
    from shakermill.views.report import save_report

    run_data = load_run_or_fail(run_dir)
    other = load_run_or_fail(compare) if compare is not None else None
    target = out if out is not None else run_dir / REPORT_FILE
    if target.is_file() and not overwrite:
        fail(f"{target}: exists; choose another --out, or add --overwrite to replace it")
    with writing(target, "the report"):
        save_report(run_data, target, other)
    typer.echo(f"report written to {target}")
