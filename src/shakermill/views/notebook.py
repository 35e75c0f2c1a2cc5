"""How a run reads in a notebook and at the top of a report: the answer in sentences, small HTML tables.

``Result._repr_html_`` and ``Parameters._repr_html_`` render through this module, and
``Result.plot()`` returns a :class:`FigureSet`, which a notebook shows as inline PNGs
without pyplot (the figures are drawn on the Agg canvas and never opened in a window).
Every piece of text that comes from a run goes through :func:`html.escape`.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from shakermill.support.presenters import register

if TYPE_CHECKING:
    from shakermill.parameters.keys import Parameters
    from shakermill.solvers.result import Result
    from shakermill.solvers.summary import Summary

# The experiment's ball temperature after the hour it lasted (Takacs & McHenry 2006 via Son 2025 Table 5).
EXPERIMENT_BALL_C = 48.0
# A prediction whose temperature rise is this much larger than the experiment's is "far above" it.
FAR_ABOVE_RATIO = 1.5
CALIBRATED_PRESET = "spex8000m-calibrated"
# The preset fitted to the experiment for each engine: a run is pointed to the one of its own engine.
CALIBRATED_PRESETS = {"1d": CALIBRATED_PRESET, "dem": "spex8000m-3d-calibrated"}
NOTEBOOK_PNG_DPI = 80

# (summary key, label, unit, format) of a run's answer, in the order the sentences give them.
ANSWER_KEYS = (
    ("ball_steady_C", "ball steady state", "°C", ".1f"),
    ("vial_steady_C", "vial steady state", "°C", ".1f"),
    ("air_steady_C", "air steady state", "°C", ".1f"),
    ("slowest_time_constant_min", "slowest time constant", "min", ".1f"),
    ("ball_C", "ball at the end of the run", "°C", ".1f"),
    ("vial_C", "vial at the end of the run", "°C", ".1f"),
    ("air_C", "air at the end of the run", "°C", ".1f"),
    ("heat_power_W", "heat generated", "W", ".3g"),
    ("impact_rate_hz", "impact rate", "1/s", ".3g"),
)
# (parameter, label, scale, unit, format) of the inputs a reader checks first.
KEY_INPUTS = (
    ("omega", "drive frequency ω", 1.0, "rad/s", ".4g"),
    ("amplitude", "amplitude", 1e3, "mm", ".4g"),
    ("ball_radius", "ball radius", 1e3, "mm", ".4g"),
    ("vial_length", "vial length", 1e3, "mm", ".4g"),
    ("duration", "duration", 1 / 60.0, "min", ".4g"),
    ("solver", "solver", None, "", ""),
    ("model", "thermal model", None, "", ""),
)

STYLE = (
    "<style>.shakermill-view table{border-collapse:collapse}"
    ".shakermill-view td,.shakermill-view th{border:1px solid #d0d7de;padding:2px 8px;text-align:left}"
    ".shakermill-view td.num{text-align:right}</style>"
)


def esc(value: Any) -> str:
    return html.escape(str(value), quote=True)


def number(value: Any, spec: str = ".4g") -> str:
    """``value`` formatted with ``spec``; "n/a" for missing or non-finite numbers (stored as null in JSON)."""
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (int, float)):
        return format(value, spec) if math.isfinite(value) else "n/a"
    return str(value)


def rpm(omega: float) -> float:
    """Revolutions (drive cycles) per minute of an angular frequency in rad/s."""
    return omega * 60.0 / (2.0 * math.pi)


def answer_sentences(summary: Summary, preset: str | None = None, fitted: bool = False) -> list[str]:
    """The run's answer in plain sentences: where it ends, where it would settle, how fast, driven by what.

    For a preset that nothing was fitted to (``fitted`` False), one more sentence compares the
    steady state with the experiment and points to the calibrated preset. The run's notes (advice that is not a
    problem, such as a run shorter than its time to steady state) end it.
    """
    v = {key: number(summary.value(key), spec) for key, _, _, spec in ANSWER_KEYS}
    minutes = number(_number(summary.simulated_s) / 60.0, ".3g")
    notes = list(summary.notes)
    charge = summary.charge
    if charge is not None and charge.n_balls == 0:
        return empty_mill_sentences(summary, v, minutes) + notes
    if charge is not None and charge.n_balls > 1:
        # The experiment had one ball: several balls are not compared with it.
        return several_ball_sentences(summary, v, minutes) + notes
    sentences = [
        f"After {minutes} min the ball is at {v['ball_C']} °C, the vial at {v['vial_C']} °C and the air at "
        f"{v['air_C']} °C.",
        f"Run on, the ball would settle at {v['ball_steady_C']} °C (vial {v['vial_steady_C']} °C, air "
        f"{v['air_steady_C']} °C); the slowest time constant of the thermal network is "
        f"{v['slowest_time_constant_min']} min.",
        f"The impacts generate {v['heat_power_W']} W of heat at {v['impact_rate_hz']} impacts per second"
        + _averaging_note(summary)
        + ".",
    ]
    if preset is not None and not fitted:
        comparison = experiment_comparison(summary, preset)
        if comparison:
            sentences.append(comparison)
    return sentences + notes


def empty_mill_sentences(summary: Summary, v: Mapping[str, str], minutes: str) -> list[str]:
    """The answer of a run with no balls (MODEL.md §13.4): the vial warmed by what does not depend on them."""
    drive = number(_number(summary.drive_heat_W), ".3g")
    return [
        f"An empty mill (no balls): after {minutes} min the vial is at {v['vial_C']} °C and the air at {v['air_C']} "
        "°C, "
        f"warmed by the drive's {drive} W alone.",
        f"Run on, the vial would settle at {v['vial_steady_C']} °C (air {v['air_steady_C']} °C); the slowest time "
        f"constant of the thermal network is {v['slowest_time_constant_min']} min.",
    ]


def several_ball_sentences(summary: Summary, v: Mapping[str, str], minutes: str) -> list[str]:
    """The answer of a 'dem' run with several balls: the range of their temperatures and their mean."""
    walls, between = _number(summary.impacts.on_walls), _number(summary.impacts.between_balls)
    share = walls / (walls + between) if walls + between > 0 else math.nan
    balls = summary.charge.n_balls if summary.charge is not None else None
    steady = summary.steady.each_ball_C if summary.steady is not None else None
    return [
        f"After {minutes} min the {balls} balls are at {_spread(summary.temperatures.each_ball_C)} °C "
        f"(mean {v['ball_C']} °C), the vial at {v['vial_C']} °C and the air at {v['air_C']} °C.",
        f"Run on, the balls would settle at {_spread(steady)} °C (mean {v['ball_steady_C']} °C; "
        f"vial {v['vial_steady_C']} °C, air {v['air_steady_C']} °C); the slowest time constant of the thermal "
        f"network is {v['slowest_time_constant_min']} min.",
        f"The impacts generate {v['heat_power_W']} W of heat at {v['impact_rate_hz']} impacts per second, "
        f"{number(share * 100.0, '.0f')} % of them on the walls" + _averaging_note(summary) + ".",
    ]


def _spread(values: Any) -> str:
    """ "20.5–20.8": the lowest and highest of a list of temperatures in °C (nulls left out), or "n/a"."""
    finite = [value for value in values or () if isinstance(value, (int, float)) and math.isfinite(value)]
    return f"{min(finite):.1f}–{max(finite):.1f}" if finite else "n/a"


def _number(value: Any) -> float:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else math.nan


def _averaging_note(summary: Summary) -> str:
    if summary.solver != "averaged":
        return ""
    window = number(summary.averaging.window_s if summary.averaging is not None else None, ".3g")
    return f" (impacts resolved over the {window} s averaging window, the rate holding for the whole run)"


def experiment_comparison(summary: Summary, preset: str) -> str:
    """A sentence on how the uncalibrated steady state stands to the experiment's 48 °C; empty without one."""
    steady = _number(summary.ball_steady_C)
    start = _number(summary.initial_temperature_C)
    if not (math.isfinite(steady) and math.isfinite(start)):
        return ""
    ratio = (steady - start) / (EXPERIMENT_BALL_C - start)
    if ratio < FAR_ABOVE_RATIO:
        return ""
    charge = summary.charge
    calibrated = CALIBRATED_PRESETS.get(charge.engine, CALIBRATED_PRESET) if charge is not None else CALIBRATED_PRESET
    return (
        f"With preset {preset}, which uses the published parameters and fits nothing, this is far above the "
        f"experiment: the ball's temperature rise is {ratio:.1f} times the experiment's, which approached "
        f"{EXPERIMENT_BALL_C:g} °C within the hour (Takacs & McHenry 2006). Preset "
        f"{calibrated} is fitted to that experiment; use it for predictions near it."
    )


def _rows(rows: list[tuple[str, str, str]]) -> str:
    return "".join(
        f'<tr><td>{esc(label)}</td><td class="num">{esc(value)}</td><td>{esc(unit)}</td></tr>'
        for label, value, unit in rows
    )


def _input_rows(params: Parameters) -> list[tuple[str, str, str]]:
    values = params.model_dump()
    rows = []
    for key, label, scale, unit, spec in KEY_INPUTS:
        if key not in values:
            continue
        shown = number(values[key] * scale, spec) if scale is not None else str(values[key])
        rows.append((label, shown, unit))
    # Researchers quote the mill in cycles per minute (1060 for the SPEX 8000M on 60 Hz mains).
    rows.insert(1, ("drive frequency", number(rpm(params.omega), ".4g"), "rpm"))
    return rows


def parameters_html(params: Parameters) -> str:
    """The key inputs in a small table, every key in a closed ``<details>`` below it."""
    everything = [(key, str(value), "") for key, value in params.model_dump().items()]
    return (
        f'<div class="shakermill-view">{STYLE}<strong>shakermill Parameters</strong>'
        f"<table>{_rows(_input_rows(params))}</table>"
        f"<details><summary>all {len(everything)} keys (SI units)</summary><table>{_rows(everything)}</table></details>"
        "</div>"
    )


def result_html(result: Result) -> str:
    """Status, the answer in sentences and a table, the key inputs and the warnings of ``result``."""
    summary = result.summary
    status = "completed" if result.success else f"stopped early (status {result.status})"
    answer = [(label, number(summary.value(key), spec), unit) for key, label, unit, spec in ANSWER_KEYS]
    warnings = "".join(f"<li>{esc(line)}</li>" for line in result.warnings)
    return (
        f'<div class="shakermill-view">{STYLE}'
        f"<strong>shakermill Result</strong>: {esc(status)}: {esc(result.message)}"
        f"<p>{esc(' '.join(answer_sentences(summary)))}</p>"
        f"<table><tr><th>result</th><th>value</th><th>unit</th></tr>{_rows(answer)}</table>"
        f"<table><tr><th>input</th><th>value</th><th>unit</th></tr>{_rows(_input_rows(result.params))}</table>"
        + (f"<p>Warnings:</p><ul>{warnings}</ul>" if warnings else "")
        + "</div>"
    )


class FigureSet(dict):
    """Figures by name; a notebook shows them, one inline PNG each, when this is a cell's value."""

    def _repr_html_(self) -> str:
        from shakermill.views.figures.common import png_bytes

        images = (
            f'<figure><img alt="{esc(name)}" src="data:image/png;base64,'
            f'{base64.b64encode(png_bytes(figure, NOTEBOOK_PNG_DPI)).decode("ascii")}"></figure>'
            for name, figure in self.items()
        )
        return '<div class="shakermill-figures">' + "".join(images) + "</div>"


def run_figure_set(result: Result, *, impacts: bool = False) -> FigureSet:
    from shakermill.views.figures.run import run_figures

    return FigureSet(run_figures(result, impacts=impacts))


def register_presenters() -> None:
    """Let parameters and results show themselves through this module (:mod:`shakermill.support.presenters`)."""
    register("parameters html", parameters_html)
    register("result html", result_html)
    register("result figures", run_figure_set)
