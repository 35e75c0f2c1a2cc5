"""The typer application of the ``shakermill`` command line and what its commands share: one ``error:`` line and
exit code 2 for bad input, tables on stdout, warnings and a progress bar on stderr, options declared once.

Only light modules are imported here and in the command modules: `shakermill --help` and the listing commands must
not wait for NumPy, Numba, pandas, xarray, SciPy or Matplotlib. Each command imports what it uses when it runs.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from datetime import datetime
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text
from typer.core import TyperGroup

from shakermill.engines.budget import BudgetExceeded
from shakermill.parameters.defaults import DEFAULT_PRESET, DEFAULT_SCHEDULER_TIMEOUT_S
from shakermill.parameters.errors import ParameterError
from shakermill.support.atomic import StorageError
from shakermill.support.version import __version__

if TYPE_CHECKING:
    from shakermill.parameters.keys import Parameters
    from shakermill.solvers.result import Result

EXIT_FAILED_RUN = 1


EXIT_USAGE = 2


EXIT_INTERRUPTED = 130


# A run's or a fit's progress bar appears once it has taken this long (s): quick ones end without a flicker.
PROGRESS_DELAY_S = 1.0


PIPED_TABLE_WIDTH = 160


DEFAULT_RESULTS_FOLDER = Path("results")


class OneLineUsageErrors(TyperGroup):
    """typer's command group, with its own usage errors (an unknown option or command, a value of the
    wrong type or outside an option's range) as one ``error:`` line and exit code 2, like every other
    bad input: typer draws them in a box over several lines, which scripts and logs read badly."""

    def main(
        self,
        args: Sequence[str] | None = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        windows_expand_args: bool = True,
        **extra: Any,
    ) -> Any:
        arguments = sys.argv[1:] if args is None else list(args)
        if not standalone_mode or not arguments:  # no arguments: typer shows the help, as it should
            return super().main(args, prog_name, complete_var, standalone_mode, windows_expand_args, **extra)
        try:
            outcome = super().main(arguments, prog_name, complete_var, False, windows_expand_args, **extra)
        except typer.Abort:
            # Outside Click's handling now: typer.Exit (what fail raises) would not be caught.
            echo_error("aborted")
            sys.exit(EXIT_FAILED_RUN)
        except Exception as exc:
            # Click's usage errors, told by what they carry: typer vendors Click and exports none of its classes.
            if getattr(exc, "exit_code", None) != EXIT_USAGE or not hasattr(exc, "format_message"):
                raise
            echo_error(exc.format_message())
            sys.exit(EXIT_USAGE)
        sys.exit(outcome if isinstance(outcome, int) else 0)

    # typer turns a Ctrl-C that no command caught into exit code 130 without a word, while it reads the command line
    # (which imports pydantic) as while a command runs.
    def make_context(self, *args: Any, **kwargs: Any) -> Any:
        with _interrupt_in_one_line():
            return super().make_context(*args, **kwargs)

    def invoke(self, ctx: Any) -> Any:
        with _interrupt_in_one_line():
            return super().invoke(ctx)


@contextmanager
def _interrupt_in_one_line() -> Iterator[None]:
    try:
        yield
    except KeyboardInterrupt:
        fail("interrupted by the user (Ctrl-C)", EXIT_INTERRUPTED)


app = typer.Typer(
    cls=OneLineUsageErrors,
    name="shakermill",
    help="Simulate a high-energy ball mill (SPEX 8000M-type shaker, mixer mills, planetary mills): ball motion, "
    "impacts, the heat they make and the temperatures of the balls, the vial and the air; `presets` lists the mills. "
    "Guides: docs/ (make docs).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # Plain help, as Click formats it: rich's panels import Markdown and take a third of `shakermill --help`.
    rich_markup_mode=None,
)


def _version(show: bool) -> None:
    if show:
        typer.echo(f"shakermill {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
) -> None:
    """Simulate a high-energy ball mill (SPEX 8000M-type shaker, mixer mills, planetary mills): ball motion, impacts,
    the heat they make and the temperatures of the balls, the vial and the air; `presets` lists the mills. Guides:
    docs/ (make docs)."""
    from shakermill.parameters.environment import check_environment

    with user_errors():
        check_environment()


def stdout_console() -> Console:
    # Piped into a file, tables are read later at any width; 80 columns would wrap every source citation.
    console = Console()
    return console if console.is_terminal else Console(width=PIPED_TABLE_WIDTH)


def add_plain_row(table: Table, *cells: str) -> None:
    # Plain text: values such as "[0, 1]" or "[start ≥ 0, ...]" would otherwise be parsed as rich markup.
    table.add_row(*(Text(cell) for cell in cells))


def echo_error(message: str) -> None:
    # typer.echo, not rich: rich would wrap a long message over several lines and read "[...]" as markup.
    typer.echo(f"error: {' '.join(message.splitlines())}", err=True)


def fail(message: str, code: int = EXIT_USAGE) -> NoReturn:
    echo_error(message)
    raise typer.Exit(code)


@contextmanager
def user_errors() -> Iterator[None]:
    """Turn bad input into one ``error:`` line and exit code 2."""
    try:
        yield
    except (ParameterError, StorageError) as exc:
        fail(str(exc))


@contextmanager
def nothing_written_when_interrupted(what: str) -> Iterator[None]:
    """Ctrl-C before anything was written: one line and exit code 130."""
    try:
        yield
    except KeyboardInterrupt:
        fail(f"interrupted; nothing was written ({what})", EXIT_INTERRUPTED)


@contextmanager
def writing(target: Path, what: str) -> Iterator[None]:
    """A write that fails (a full or read-only disk, a path under a file): one ``error:`` line and exit code 2."""
    try:
        yield
    except OSError as exc:
        fail(f"{target}: cannot write {what} ({exc.strerror or exc})")


@contextmanager
def nothing_written_when_a_run_is_stopped(what: str) -> Iterator[None]:
    """A run of a scan or fit used up its budget: one line and exit code 1, as a failed run."""
    try:
        yield
    except BudgetExceeded as exc:
        fail(f"{what} stopped, nothing was written: {exc}", EXIT_FAILED_RUN)


# Options shared by several commands, declared once.
ConfigArgument = Annotated[
    Path | None,
    typer.Argument(metavar="CONFIG", help="TOML file with canonical keys (and optionally preset = NAME)."),
]


PresetOption = Annotated[
    str | None, typer.Option("--preset", "-p", show_default=DEFAULT_PRESET, help="Preset to start from.")
]


SettingsOption = Annotated[
    list[str] | None,
    typer.Option("--set", "-s", metavar="KEY=VALUE", help="Override one key, units allowed: --set ball_radius='5 mm'."),
]


JsonOption = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout, nothing else.")]


OverwriteOption = Annotated[
    bool, typer.Option("--overwrite", help="Replace what --out holds (never a folder that shakermill did not write).")
]


SchedulerOption = Annotated[
    str | None,
    typer.Option("--scheduler", metavar="ADDRESS", help="Run on this Dask distributed scheduler (tcp://host:8786)."),
]


SchedulerTimeoutOption = Annotated[
    float | None,
    typer.Option(
        "--scheduler-timeout",
        min=0.1,
        max=86400.0,
        metavar="SECONDS",
        show_default=f"{DEFAULT_SCHEDULER_TIMEOUT_S:g}",
        help="With --scheduler: give up connecting to it, or waiting for a worker, after this long.",
    ),
]


def scheduler_timeout_of(scheduler: str | None, timeout: float | None) -> float:
    """The wait ``--scheduler-timeout`` allows (its default where not given); refused without a ``--scheduler``,
    where nothing would wait for it."""
    if timeout is not None and scheduler is None:
        raise ParameterError(
            "scheduler-timeout: bounds the waits for a Dask scheduler, and no --scheduler is given; allowed "
            "--scheduler-timeout with --scheduler"
        )
    return DEFAULT_SCHEDULER_TIMEOUT_S if timeout is None else timeout


FullResolutionOption = Annotated[
    bool, typer.Option("--full-resolution", help="Use the full-resolution solver (default: averaged).")
]


def echo_warnings(warnings: Sequence[str]) -> None:
    """One ``warning: ...`` line on stderr each (stdout stays clean for ``--json``)."""
    for warning in warnings:
        typer.echo(f"warning: {' '.join(warning.splitlines())}", err=True)


def echo_notes(notes: Sequence[str]) -> None:
    """One ``note: ...`` line on stderr each: what a user should know that is not a problem (how a solver was
    chosen)."""
    for note in notes:
        typer.echo(f"note: {' '.join(note.splitlines())}", err=True)


@contextmanager
def warnings_as_lines() -> Iterator[None]:
    """The library's warnings (an unreadable point file) as ``warning: ...`` lines, like a run's own."""
    import warnings

    with warnings.catch_warnings():
        warnings.showwarning = lambda message, *_: echo_warnings([str(message)])
        yield


def timestamped_folder(kind: str) -> Path:
    """``results/<kind>-<local timestamp>``, with a counter if one started in the same second."""
    stem = f"{kind}-{datetime.now():%Y%m%d-%H%M%S}"
    candidate = DEFAULT_RESULTS_FOLDER / stem
    counter = 1
    while candidate.exists():
        candidate = DEFAULT_RESULTS_FOLDER / f"{stem}-{counter}"
        counter += 1
    return candidate


def simulate_with_progress(params: Parameters) -> Result:
    """``simulate``, with a transient progress bar on stderr once the run takes a while, when stderr is a terminal.

    The bar counts the simulated seconds of each phase in turn: the averaged solver's mechanics (out of
    averaging_max_time, or the duration when shorter), the whole duration, then its attractor probe (all starts
    together). A fall-back to full resolution is announced on stderr in a ``note:`` line before it starts.
    """
    from shakermill.solvers.simulate import simulate

    counter = "{task.completed:.5g}/{task.total:.5g} s simulated"
    with progress_bar("simulating", counter, params.duration, delay_s=PROGRESS_DELAY_S) as update:
        return simulate(
            params,
            progress=lambda done, total: update(done, total=total),
            notice=lambda line: print(f"note: {line}", file=sys.stderr, flush=True),
        )


# Long work piped into a log says how far it is in a plain line at most this often (s), the first after as long: a
# bar redrawn many times a second would fill the log, and none would leave it silent for half an hour.
PIPED_INTERVAL_S = 30.0


@contextmanager
def progress_bar(
    verb: str, counter: str, total: float | None, delay_s: float = 0.0, lines_when_piped: bool = False, **fields: Any
) -> Iterator[Callable[..., None]]:
    """``update(completed, **fields)`` of a transient progress bar with an ETA on stderr.

    On a terminal the bar shows from the first update ``delay_s`` seconds after the start, or at once without a
    delay. Piped, stderr gets plain lines (:func:`piped_lines`) instead: one every :data:`PIPED_INTERVAL_S`, or each
    step of a study whose steps take minutes (``lines_when_piped``).
    """
    console = Console(stderr=True)
    if not console.is_terminal:
        yield piped_lines(verb, counter, 0.0 if lines_when_piped else PIPED_INTERVAL_S, total, **fields)
        return
    columns = (TextColumn(verb), BarColumn(), TextColumn(counter), TimeRemainingColumn())
    bar = Progress(*columns, console=console, transient=True)
    task = bar.add_task(verb, total=total, **fields)
    shown_from = time.monotonic() + delay_s

    def show_when_due() -> None:
        if not bar.live.is_started and time.monotonic() >= shown_from:
            bar.start()

    def update(completed: float, **updates: Any) -> None:
        bar.update(task, completed=completed, **updates)
        show_when_due()

    show_when_due()
    try:
        yield update
    finally:
        if bar.live.is_started:
            bar.stop()


def piped_lines(
    verb: str, counter: str, interval_s: float = 0.0, total: float | None = None, **fields: Any
) -> Callable[..., None]:
    """``update(completed, total=..., **fields)`` printing one plain line on stderr when ``completed`` has changed and
    ``interval_s`` has passed since the last line (or the start): the ``counter`` of a progress bar
    (``{task.completed}``, ``{task.total}``, ``{task.fields[NAME]}``) and the time elapsed."""
    started = time.monotonic()
    said: list[float] = []
    last = [started]
    known: dict[str, Any] = {"total": total, **fields}

    def update(completed: float, **updates: Any) -> None:
        known.update(updates)
        now = time.monotonic()
        if (said and said[-1] == completed) or now - last[0] < interval_s:
            return
        said.append(completed)
        last[0] = now
        task = SimpleNamespace(
            completed=completed, total=known["total"], fields={k: v for k, v in known.items() if k != "total"}
        )
        minutes, seconds = divmod(round(now - started), 60)
        typer.echo(f"{verb}: {counter.format(task=task)}, {minutes} min {seconds:02d} s", err=True)

    return update


def number(value: Any, spec: str) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    return format(value, spec)


def format_value(key: str, value: Any) -> str:
    """A preset value with its unit, e.g. '0.00635 m', 'true', '[0, 1], [600, 0.1] s'."""
    from shakermill.parameters.keys import field_unit

    unit = field_unit(key)
    if isinstance(value, bool):
        return str(value).lower()
    if key == "record_windows":
        pairs = ", ".join(f"[{start:g}, {length:g}]" for start, length in value)
        return f"{pairs} {unit}" if pairs else "none"
    if isinstance(value, (int, float)):
        return f"{value:g} {unit}".rstrip()
    return str(value)
