"""One self-contained HTML report of a run folder (``shakermill report``).

Everything is inline: the figures are base64 PNG data URIs and the style sheet
is in the page, so the file can be mailed, archived or opened offline, and it
needs no scripts. Every piece of text that comes from the run (messages, paths,
sources, values) goes through :func:`html.escape`.

The report states what was fitted and what was predicted (MODEL.md §10): the
Table 5 quantities a preset's calibration was fitted to are marked "fitted", the
others "predicted", with the relative error against the experiment either way.
"""

from __future__ import annotations

import itertools
import math
import tomllib
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from shakermill.io.runs import CONFIG_FILE, RunData, load_run
from shakermill.parameters.defaults import DEFAULT_PRESET, REPORT_FILE
from shakermill.parameters.keys import field_description, field_unit, material_sources
from shakermill.parameters.presets import PRESETS, Preset
from shakermill.studies.measured import EXPERIMENT, OPERATING_POINT_TOLERANCE, PAPER, fitted_quantities
from shakermill.studies.validation.table5 import ComparisonRow, compare, operating_point_mismatches
from shakermill.support.version import __version__
from shakermill.views.figures.common import several_balls
from shakermill.views.figures.run import comparison_temperature_figure, main_figure_names, model_of, paper_figures
from shakermill.views.html import (
    bullet_list,
    check_page_target,
    figure_html,
    figures_html,
    paragraph,
    percent,
    pretty_unit,
    section,
    table,
    write_page,
)
from shakermill.views.notebook import answer_sentences, esc, number
from shakermill.views.report_sections import (
    balls_section,
    captions_of,
    energy_section,
    impacts_section,
    numerics_section,
)

# Keys that change what is stored or reported, not what is simulated: a calibration still holds when they differ.
OUTPUT_ONLY_KEYS = frozenset({"record_windows", "output_interval", "attractor_starts"})


# MODEL.md §9: where this implementation departs from the printed paper, on purpose.
PAPER_DIFFERENCES = (
    "Hertz force (4/3)·E*·√R·ζ^(3/2); the printed text garbles it to a square root of the whole product.",
    "Damping exponent β_e = ln e / √(ln²e + π²), the standard form; the printed text drops the square root.",
    "Heat from the relative motion of ball and wall, η·c·ζ̇² (frame invariant), not η·|F_d·v| as printed; "
    'the printed form is available as heat_model = "paper".',
    "The end faces are at x_v ± l_v/2.",
    "The air mass m_a, the air heat capacity c_a, the drive frequency ω and the vial's thermal mass are not "
    "printed in the paper; they are stated assumptions (listed above with their values).",
)


RESULT_QUANTITIES = (
    ("ball_steady_C", "ball steady state (root of the averaged network, MODEL.md §11)", "°C", ".2f"),
    ("vial_steady_C", "vial steady state", "°C", ".2f"),
    ("air_steady_C", "air steady state", "°C", ".2f"),
    ("slowest_time_constant_min", "slowest time constant of the network", "min", ".1f"),
    ("theta_inf_C", "ball θ∞ of the exponential fitted over the whole run (not the steady state)", "°C", ".2f"),
    ("tau_min", "τ of that fit", "min", ".2f"),
    ("rate0_C_per_min", "initial heating rate θ̇₀ of that fit", "°C/min", ".3f"),
    ("ball_C", "ball at the end", "°C", ".2f"),
    ("vial_C", "vial at the end", "°C", ".2f"),
    ("air_C", "air at the end", "°C", ".2f"),
    ("vial_ball_ratio", "vial/ball temperature increment ratio", "", ".3f"),
    ("heat_power_W", "mean heat generation", "W", ".4g"),
    ("dissipated_power_W", "mean dissipated power", "W", ".4g"),
    ("impact_rate_hz", "impact rate", "Hz", ".4g"),
    ("mean_impact_speed_m_s", "mean impact speed", "m/s", ".4g"),
)

# The rows of the exponential fit, left out where it does not describe the run (summary
# "exponential_fit_describes_run").
FIT_KEYS = ("theta_inf_C", "tau_min", "rate0_C_per_min")

COMPARED_QUANTITIES = RESULT_QUANTITIES + (
    ("impacts", "impacts", "", "d"),
    ("mean_dissipated_per_impact_J", "mean dissipated energy per impact", "J", ".4g"),
    ("steps", "integrator steps", "", "d"),
    ("wall_time_s", "wall time", "s", ".3g"),
    ("energy_audit_residual", "energy audit relative residual", "", ".2e"),
)

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: #1d1d1f;
       max-width: 1150px; margin: 2em auto; padding: 0 1em; line-height: 1.45; }
h1 { font-size: 1.7em; margin-bottom: 0.2em; }
h2 { border-bottom: 2px solid #d0d7de; padding-bottom: 0.2em; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }
th, td { border: 1px solid #d0d7de; padding: 0.3em 0.6em; vertical-align: top; text-align: left; }
th { background: #f3f5f7; }
header td:first-child { white-space: nowrap; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.differs td { background: #fff4cc; }
tr.fitted td { background: #eaf2ff; }
.status { padding: 0.5em 0.8em; border-radius: 4px; font-weight: 600; }
.status.ok { background: #e6f4ea; color: #1e6b34; }
.status.failed { background: #fde7e9; color: #9b1c23; }
.note { color: #555; font-size: 0.9em; }
.statement { font-size: 1.05em; background: #f6f8fa; padding: 0.6em 0.8em; border-left: 4px solid #0969da; }
figure { margin: 1.2em 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #e5e7eb; }
figcaption { color: #444; font-size: 0.9em; margin-top: 0.3em; }
"""


def write_report(run_dir: Path | str, out: Path | str | None = None, compare_dir: Path | str | None = None) -> Path:
    """Write the HTML report of the run folder ``run_dir`` (default ``run_dir/report.html``); return its path.

    Raises :class:`shakermill.support.atomic.StorageError` when a folder is not a run folder.
    """
    run = load_run(run_dir)
    other = load_run(compare_dir) if compare_dir is not None else None
    return save_report(run, Path(out) if out is not None else Path(run_dir) / REPORT_FILE, other)


def save_report(run: RunData, target: Path, other: RunData | None = None) -> Path:
    """Write the report of ``run`` (compared with ``other``, if given) to ``target``; return ``target``."""
    check_page_target(target)
    return write_page(target, render_report(run, other))


def render_report(run: RunData, other: RunData | None = None) -> str:
    """The report as one HTML document: the answer first, then how it was obtained, then what to cite."""
    preset = PRESETS.get(run.preset)
    figure_numbers = itertools.count(1)
    sections = [
        header_section(run, preset),
        results_section(run),
        *([balls_section(run)] if several_balls(run.params) and run.params.n_balls else []),
        table5_section(run, preset),
        paper_figures_section(run, figure_numbers),
        configuration_section(run, preset),
        assumptions_section(run, preset),
        energy_section(run),
        impacts_section(run, figure_numbers),
        numerics_section(run),
    ]
    if other is not None:
        sections.append(comparison_section(run, other, figure_numbers))
    sections.append(citation_section())
    title = f"shakermill run report: {run_name(run)}"
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>{esc(title)}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
        + "\n".join(sections)
        + f'\n<p class="note">Report written by shakermill {esc(__version__)}.</p>\n</body>\n</html>\n'
    )


# ---------------------------------------------------------------- run facts


def model_name(run: RunData) -> str:
    return model_of(run.params)


def run_name(run: RunData) -> str:
    # Resolved, so that a run given as "." is still called by its folder's name.
    return run.path.resolve().name


def run_label(run: RunData) -> str:
    return f"{run_name(run)} ({model_name(run)}, {run.preset})"


def run_provenance(run: RunData) -> dict[str, Any]:
    """The ``[provenance]`` table of the run's ``config.toml``: version, creation time, command, overrides."""
    with (run.path / CONFIG_FILE).open("rb") as stream:
        return dict(tomllib.load(stream).get("provenance", {}))


def format_parameter(value: Any) -> str:
    """A parameter value without its unit: '0.00635', 'true', '[0, 1], [600, 0.1]', 'three_node', and the
    'dem' engine's lists: '0.005, 0.006' (ball_radii), '[x, 1, 0, 0.025], [yaw, 1, 0, 0.3]' (motion)."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (tuple, list)):
        items = (
            f"[{', '.join(format_parameter(part) for part in item)}]"
            if isinstance(item, (tuple, list))
            else format_parameter(item)
            for item in value
        )
        return ", ".join(items) or "none"
    return str(value)


def same_value(a: Any, b: Any) -> bool:
    # Values round-trip config.toml exactly; the tolerance only absorbs int/float spellings.
    numbers = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in (a, b))
    if numbers:
        return math.isclose(a, b, rel_tol=1e-12, abs_tol=0.0)
    return a == b


def keys_differing_from_preset(run: RunData, preset: Preset) -> list[str]:
    values = run.params.model_dump()
    return [
        key for key, value in values.items() if key in preset.values and not same_value(value, preset.values[key].value)
    ]


def fitted_targets(preset: Preset | None) -> tuple[str, ...]:
    """The Table 5 quantities (summary keys) a preset's calibration was fitted to.

    ``Preset.fitted`` names the *parameters* the calibration set (beta, vial_mass); the quantities they
    were fitted to come from its provenance, as in :func:`shakermill.studies.validation.table5.validate`.
    """
    if preset is None:
        return ()
    return fitted_quantities(preset.provenance)


# ---------------------------------------------------------------- sections


def header_section(run: RunData, preset: Preset | None) -> str:
    provenance = run_provenance(run)
    status_class = "ok" if run.success else "failed"
    if run.success:
        status = f"Run completed: {run.message}"
    else:
        status = f"Run stopped early (status {run.status}): {run.message}"
    facts = [
        ("run folder", str(run.path.resolve())),
        ("preset", f"{run.preset}: {preset.description}" if preset else f"{run.preset} (not known to this version)"),
        ("model", model_name(run)),
        ("solver", run.summary.solver),
        ("simulated time", f"{number(run.summary.simulated_s, '.6g')} s"),
        ("written by", f"shakermill {provenance.get('shakermill_version', 'n/a')}"),
        ("created (UTC)", str(provenance.get("created_utc", "n/a"))),
        ("command", str(provenance.get("command", "n/a"))),
        ("overrides (--set)", ", ".join(provenance.get("overrides", [])) or "none"),
    ]
    warnings = "".join(f'<p class="status failed">{esc("Warning: " + line)}</p>\n' for line in run.summary.warnings)
    return (
        f"<header>\n<h1>{esc('shakermill run report: ' + run_name(run))}</h1>\n"
        f'<p class="status {status_class}">{esc(status)}</p>\n{warnings}'
        + answer_html(run, preset)
        + table(None, facts)
        + "\n</header>"
    )


def answer_html(run: RunData, preset: Preset | None) -> str:
    """The run's answer in sentences, the first thing the report says."""
    fitted = preset is None or bool(preset.fitted)
    sentences = answer_sentences(run.summary, run.preset, fitted=fitted)
    caveat = preset.caveat_for(run.params.model_dump()) if preset is not None else None
    said = paragraph(" ".join(sentences), "statement answer") + "\n"
    return said + (paragraph(f"Caveat ({run.preset}): {caveat}", "status failed") + "\n" if caveat else "")


def results_section(run: RunData) -> str:
    summary = run.summary
    describes = summary.exponential_fit_describes_run
    rows = [
        (label, number(summary.value(key), spec), unit)
        for key, label, unit, spec in RESULT_QUANTITIES
        if key not in FIT_KEYS or describes
    ]
    uncertainty = (
        (
            f"Standard errors of the fit: θ∞ ± {number(summary.theta_inf_stderr_K, '.2g')} K, "
            f"τ ± {number(summary.tau_stderr_min, '.2g')} min; "
            f"RMS residual {number(summary.fit_rms_residual_K, '.2g')} K."
        )
        if describes
        else (
            "No exponential: the run is shorter than the network's slowest time constant, so one fitted to it "
            "describes "
            "the start of the heating, not where it goes; the steady state is the answer to read."
        )
    )
    return section("Results", table(("quantity", "value", "unit"), rows, numeric=(1,)), paragraph(uncertainty, "note"))


TABLE5_TITLE = "Table 5: experiment, the paper's model and this run"


def _or_zero(value: float) -> float:
    return value if math.isfinite(value) else 0.0


def table5_section(run: RunData, preset: Preset | None) -> str:
    vial = (preset or PRESETS[DEFAULT_PRESET]).values
    values = {**run.params.model_dump(), "duration": _or_zero(run.summary.simulated_s)}
    mismatches = operating_point_mismatches(values, {key: cited.value for key, cited in vial.items()})
    if run.params.n_balls != 1:
        mismatches.append(f"n_balls = {run.params.n_balls} (experiment: one ball)")
    if mismatches:
        reason = (
            "Left out: the experiment of Table 5 ran at ω = 111 rad/s (about 1060 rpm), 25 mm amplitude, one "
            "12.7 mm steel ball in the preset's vial, for 60 min; this run differs by more than "
            f"{OPERATING_POINT_TOLERANCE:.0%} in {'; '.join(mismatches)}. Its fitted exponential and temperatures "
            "are not comparable with the experiment's."
        )
        return section(TABLE5_TITLE, paragraph(reason, "statement"))
    rows = compare(run.summary, fitted_targets(preset))
    cells = []
    notes = []
    for row in rows:
        quantity = row.quantity
        marker = ""
        if quantity.experiment_note:
            notes.append(quantity.experiment_note)
            marker = " " + "*" * len(notes)
        cells.append(
            (
                quantity.label,
                quantity.unit,
                # The published numbers with all their digits; this run's to four significant digits.
                number(quantity.experiment, ".5g") + marker,
                number(quantity.paper_model, ".5g"),
                number(row.value, ".4g"),
                percent(row.error_vs_experiment),
                row.role,
            )
        )
    fitted_rows = {index: "fitted" for index, row in enumerate(rows) if row.fitted}
    headers = ("quantity", "unit", "experiment", "paper's model", "this run", "this run vs experiment", "role")
    footnotes = [f"{'*' * (index + 1)} {note}" for index, note in enumerate(notes)]
    sources = f"Experiment: {EXPERIMENT}. Paper's model: {PAPER}, Table 5."
    return section(
        TABLE5_TITLE,
        paragraph(fitted_statement(run, preset, rows), "statement"),
        table(headers, cells, numeric=(2, 3, 4, 5), row_classes=fitted_rows),
        *(paragraph(note, "note") for note in footnotes),
        paragraph(sources, "note"),
    )


def fitted_statement(run: RunData, preset: Preset | None, rows: Sequence[ComparisonRow]) -> str:
    """One plain sentence (two with a caveat) on what was fitted and what was predicted."""
    predicted = ", ".join(row.quantity.label for row in rows if not row.fitted)
    fitted = ", ".join(row.quantity.label for row in rows if row.fitted)
    if preset is None:
        return (
            f"The run's preset {run.preset!r} is not known to this version of shakermill, so what was fitted "
            f"cannot be told; every quantity is listed as predicted."
        )
    if not preset.fitted:
        return (
            f"Nothing was fitted: preset {preset.name} uses the published parameters and the stated assumptions, "
            f"so all four quantities ({predicted}) are predictions of the model."
        )
    if not fitted:
        statement = (
            f"Preset {preset.name} has fitted values ({', '.join(preset.fitted)}), but its provenance does not "
            f"name the quantities they were fitted to, so every quantity is listed as predicted."
        )
    else:
        through = (
            f"the experiment's curve ({preset.provenance['curve']}; RMS deviation "
            f"{preset.provenance.get('curve_rms_K', math.nan):.2f} K), which carries {fitted},"
            if "curve" in preset.provenance
            else f"make {fitted} match the experiment,"
        )
        statement = (
            f"{', '.join(preset.fitted)} were fitted (preset {preset.name}) to {through} "
            f"so agreement on these is by construction; predicted, not fitted: {predicted or 'nothing'}."
        )
    changed = [key for key in keys_differing_from_preset(run, preset) if key not in OUTPUT_ONLY_KEYS]
    if changed:
        statement += (
            f" This run changes {len(changed)} of the preset's values ({', '.join(changed)}), "
            f"so the fitted quantities need not match here."
        )
    return statement


def paper_figures_section(run: RunData, numbers: Iterator[int]) -> str:
    figures = paper_figures(run)
    missing = [name for name in main_figure_names(run.params) if name not in figures]
    parts = [figures_html(figures, numbers, captions_of(run))]
    if missing:
        parts.append(paragraph(f"Not drawn, no record window with enough points: {', '.join(missing)}.", "note"))
    if several_balls(run.params):
        return section("Figures of the balls: temperatures, paths and heat (cf. Son 2025, section 4)", *parts)
    return section("Figures of the paper (Son 2025, section 4)", *parts)


def configuration_section(run: RunData, preset: Preset | None) -> str:
    rows = []
    differs = {}
    everything = run.params.model_dump()
    from_materials = material_sources(everything)
    values = {key: value for key, value in everything.items() if key in run.params.engine_keys.reads}
    for index, (key, value) in enumerate(values.items()):
        cited = preset.values.get(key) if preset else None
        if cited is None:
            preset_value, source = "n/a", "no preset value"
        elif same_value(value, cited.value):
            preset_value, source = "same", cited.source
        else:
            preset_value, source = format_parameter(cited.value), cited.source
            differs[index] = "differs"
        material_value, material_source = from_materials.get(key, (None, None))
        if material_source is not None and same_value(value, material_value):
            source = material_source
        unit = pretty_unit(field_unit(key))
        rows.append((key, format_parameter(value), unit, preset_value, source, field_description(key)))
    changed = f"highlighted: the {len(differs)} keys whose value differs" if differs else "no key differs"
    unread = len(everything) - len(values)
    left_out = f" The {unread} keys the engine of this run does not read are left out." if unread else ""
    intro = (
        f"The resolved configuration of this run (SI units); {changed} from preset {run.preset}.{left_out} "
        "The source column cites the value's material where a material of the library gave it, else the preset's value."
    )
    headers = ("key", "value", "unit", "preset value", "source", "meaning")
    return section("Configuration", paragraph(intro), table(headers, rows, row_classes=differs))


def assumptions_section(run: RunData, preset: Preset | None) -> str:
    params = run.params.model_dump()
    if preset is None:
        assumed = paragraph(f"The run's preset {run.preset!r} is unknown here; its sources cannot be listed.", "note")
    else:
        items = [
            f"{key} = {format_parameter(cited.value)} {pretty_unit(field_unit(key))}".rstrip() + f": {cited.source}"
            for key, cited in preset.values.items()
            if cited.source.lower().startswith("assumption")
        ]
        assumed = paragraph(f"Values the paper does not print, as cited in preset {preset.name}:") + bullet_list(items)
    keys: tuple[str, ...] = ("model", "heat_model", "convection_velocity", "no_tension")
    if several_balls(run.params):
        keys += ("engine", "n_balls", "kinematics", "gravity", "friction", "rolling_friction")
    options = ", ".join(f"{key} = {format_parameter(params[key])}" for key in keys if key in params)
    return section(
        "Assumptions not in the paper",
        assumed,
        paragraph("Deliberate differences from the printed paper (MODEL.md §9):"),
        bullet_list(PAPER_DIFFERENCES, ordered=True),
        paragraph(f"Model options of this run: {options}.", "note"),
    )


def comparison_section(run: RunData, other: RunData, numbers: Iterator[int]) -> str:
    first, second = run_label(run), run_label(other)
    rows = [
        ("model", "", model_name(run), model_name(other), ""),
        ("preset", "", run.preset, other.preset, ""),
        ("solver", "", run.summary.solver, other.summary.solver, ""),
    ]
    for key, label, unit, spec in COMPARED_QUANTITIES:
        a, b = run.summary.value(key), other.summary.value(key)
        difference = b - a if isinstance(a, (int, float)) and isinstance(b, (int, float)) else None
        rows.append((label, unit, number(a, spec), number(b, spec), number(difference, "+.3g")))
    # Both runs were loaded into the same Parameters model, so they have the same keys.
    ours, theirs = run.params.model_dump(), other.params.model_dump()
    changed = [
        (key, format_parameter(value), format_parameter(theirs[key]), pretty_unit(field_unit(key)))
        for key, value in ours.items()
        if not same_value(value, theirs[key])
    ]
    if changed:
        parameters = table(("key", first, second, "unit"), changed)
    else:
        parameters = paragraph("The two runs have the same parameters.")
    # Two folders of the same name (in different places) still need two legend entries.
    names = (run_name(run), run_name(other)) if run_name(run) != run_name(other) else ("first run", "second run")
    figure = comparison_temperature_figure(dict(zip(names, (run, other))))
    caption = "Ball (solid) and vial (dashed) temperatures (°C) of both runs; a ball_only run has no vial reservoir."
    return section(
        f"Comparison: {run_name(run)} and {run_name(other)}",
        table(("quantity", "unit", first, second, "second − first"), rows, numeric=(2, 3, 4)),
        paragraph("Parameters that differ between the two runs:"),
        parameters,
        figure_html(figure, caption, next(numbers)),
    )


CITATIONS = (
    f"shakermill {__version__}: the simulator that produced this report (see CITATION.cff in its sources).",
    f"{PAPER}: the model, its parameters and the comparison of Table 5.",
    "Takacs & McHenry 2006, J. Mater. Sci. 41, 5246: the measured temperatures of Table 5.",
)


def citation_section() -> str:
    return section("What to cite", paragraph("Work that uses these results should cite:"), bullet_list(CITATIONS))
