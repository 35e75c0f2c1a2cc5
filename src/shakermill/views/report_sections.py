"""The sections of a run's report about what happened in it: where the energy went, the impacts, the balls
of an engine of several, and the numerics."""

from __future__ import annotations

from collections.abc import Iterator

from shakermill.analysis.regime import classify_impacts, settled_run_impacts
from shakermill.analysis.stress_energy import StressSpectrum
from shakermill.io.runs import RunData
from shakermill.solvers.summary import unit_of
from shakermill.views.figures.common import several_balls
from shakermill.views.figures.impacts import TARGETS, impact_figures, run_stress_spectrum
from shakermill.views.figures.run import impact_span
from shakermill.views.html import figures_html, paragraph, section, table
from shakermill.views.notebook import number

FIGURE_CAPTIONS = {
    "ball_motion": (
        "Paper Fig. 4: ball centre position (mm) and momentum (kg·m/s) over the first recorded window. Grey: "
        "the ball centre at contact with either end face. Straight flights, momentum reversed at each impact."
    ),
    "temperatures": (
        "Paper Fig. 5a: ball, vial and inner-air temperatures (°C) over the run (min), with the exponential "
        "fitted to the ball temperature (MODEL.md §8)."
    ),
    "ball_heating_zoom": (
        "Paper Fig. 5b: the ball temperature in the record window nearest 10 min. It jumps at each impact "
        "(dotted) and falls by convection between impacts."
    ),
    "impact_speed_histogram": "Impact speed of the ball relative to the end face it hits, by end face.",
    "impact_energy_histogram": "Energy dissipated in each impact (mJ), by end face.",
    "stress_energy_spectrum": (
        "Stress-energy spectrum: impacts per second (left) and their power (right) at or above each stress energy, the "
        "energy an impact dissipates (Kwade; Burmeister & Kwade 2013). One ball on the axis hits head on: all normal."
    ),
    "impacts_per_second": "Impacts per second at each end face over the time the impacts were resolved.",
    "impact_phase_histogram": (
        "Drive phase ωt + φ (mod 2π) at the impacts of the settled motion, by end face: sharp lines for a "
        "periodic motion, a spread for an irregular one."
    ),
}


# A 'dem' run's figures (views/figures/run.py, SEVERAL_BALL_FIGURES) and its impact figures, where they differ.
SEVERAL_BALL_CAPTIONS = {
    "temperatures": (
        "Temperature (°C) of each ball, the vial and the inner air over the run (min), with the exponential "
        "fitted to the balls' mean temperature and the balls' mean steady state (cf. paper Fig. 5a)."
    ),
    "trajectories": (
        "The ball centres (mm) over the first record window in the vial's own frame (x along its axis, z up at "
        "rest), seen from above, from the side and along the axis, inside the vial's inner wall; discs: the "
        "balls to scale where the window ends."
    ),
    "heat_by_channel": (
        "Mean heat power (W) made in each dissipation channel (normal and tangential damping, sliding, rolling; "
        "MODEL.md §12.4), stacked by what was hit, and the heat received by each ball and the vial."
    ),
    "ball_heating_zoom": (
        "The temperature of each ball in the record window nearest 10 min: it jumps at the ball's impacts "
        "(dotted: every impact of any ball) and falls by convection between them (cf. paper Fig. 5b)."
    ),
    "impact_speed_histogram": (
        "Normal impact speed relative to what is hit: an end face, the side wall or another ball."
    ),
    "impact_energy_histogram": "Energy dissipated in each impact (mJ), by what was hit.",
    "stress_energy_spectrum": (
        "Stress-energy spectrum: impacts per second (left) and their power (right) at or above each stress energy, the "
        "energy an impact dissipates, in its normal part and its tangential part (damping, sliding, rolling), on the "
        "vial and between balls (Kwade; Burmeister & Kwade 2013); dash-dot lines: stress_energy_thresholds. Contacts "
        "that last over a millisecond roll or slide: their power is given apart."
    ),
    "impacts_per_second": "Impacts per second on each wall and between balls over the time the impacts were resolved.",
}


def captions_of(run: RunData) -> dict[str, str]:
    """The captions of ``run``'s figures: the paper's, or those of the 'dem' engine where they differ."""
    return {**FIGURE_CAPTIONS, **SEVERAL_BALL_CAPTIONS} if several_balls(run.params) else FIGURE_CAPTIONS


ENERGY_TERMS = (
    ("work_by_vial", "work done by the vial on the ball"),
    ("kinetic_energy_change", "change of the ball's kinetic energy"),
    ("elastic_energy_change", "change of the elastic contact energy"),
    ("dissipated", "dissipated in the contacts"),
    ("dissipated_normal", "of which by normal damping"),
    ("dissipated_tangential", "of which by tangential damping"),
    ("dissipated_sliding", "of which by sliding"),
    ("dissipated_rolling", "of which by rolling resistance"),
    ("work_by_gravity", "work done by gravity"),
    ("work_by_stiffening", "energy the tangential springs gain as they stiffen (Hertz–Mindlin)"),
    ("heat_generated", "irreversible heat generated (η × dissipated)"),
    ("not_converted_to_heat", "dissipated but not turned into heat"),
    ("drive_heat", "heat the drive put into the holder, whatever the balls did"),
    ("heat_lost_to_surroundings", "lost to the surroundings"),
    ("projection_correction", "total |ΔE_kin| applied by the energy projection (outside the balance)"),
    ("mechanical_residual", "mechanical residual: work − Δkinetic − Δelastic − dissipated"),
    ("thermal_residual", "thermal residual: heat − stored − lost"),
    ("residual", "total residual"),
)


RELATIVE_RESIDUAL_KEY = "relative_residual"


# The audit's terms of each node ("balls" together, then the vial, the air and whatever further nodes the network has:
# the holder, the powder), labelled from the node's name.
NODE_TERMS = (("heat_into_", "heat from the contacts into the {}"), ("stored_", "stored in the {}"))


def energy_label(key: str) -> str:
    """What the audit's ``key`` means: its fixed label, one made from its node's name, or the key itself (terms a
    newer audit may add are shown under their own names)."""
    for prefix, label in NODE_TERMS:
        if key.startswith(prefix):
            return label.format(key.removeprefix(prefix))
    return dict(ENERGY_TERMS).get(key, key)


def energy_section(run: RunData) -> str:
    energy = run.energy
    fixed = [key for key, _ in ENERGY_TERMS if key in energy]
    nodes = [key for prefix, _ in NODE_TERMS for key in energy if key.startswith(prefix)]
    others = [key for key in energy if key not in {*fixed, *nodes, RELATIVE_RESIDUAL_KEY}]
    keys = [*fixed[: fixed.index("not_converted_to_heat")], *nodes, *fixed[fixed.index("not_converted_to_heat") :]]
    rows = [(energy_label(key), key, number(energy[key], ".6g"), "J") for key in [*keys, *others]]
    if RELATIVE_RESIDUAL_KEY in energy:
        relative = ("relative residual: |residual| / largest flow", RELATIVE_RESIDUAL_KEY)
        rows.append((*relative, number(energy[RELATIVE_RESIDUAL_KEY], ".3e"), ""))
    supplied = "work by the vial + by gravity + stiffening" if several_balls(run.params) else "work by the vial"
    balances = (
        f"{supplied} = Δkinetic + Δelastic + dissipated; dissipated = heat generated + not converted to heat; "
        "heat generated (+ the drive's) = stored (in every node) + lost to the surroundings. The residuals are what "
        "is left "
        "of these balances."
    )
    return section(
        "Energy audit",
        paragraph(balances),
        table(("term", "key", "value", "unit"), rows, numeric=(2,)),
    )


def impact_statistics(run: RunData) -> list[tuple[str, str, str]]:
    """(quantity, value, unit) rows of the impact table, with the summary's count and rate."""
    impacts = run.impacts
    summary = run.summary
    rate = summary.impacts.rate_hz
    rows = [
        ("impacts in the run", number(summary.impacts.count, "d"), ""),
        ("impacts in the impact table", str(len(impacts)), ""),
        ("impact rate", number(rate, ".4g"), "Hz"),
    ]
    if impacts.empty:
        return rows
    rows += target_rows(run) if several_balls(run.params) else wall_rows(run)
    for column, label, scale, unit, spec in (
        ("impact_speed", "impact speed" if "wall" in impacts else "normal impact speed", 1.0, "m/s", ".4g"),
        ("rebound_speed", "rebound speed", 1.0, "m/s", ".4g"),
        ("tangential_speed", "tangential speed of the contact points at first touch", 1.0, "m/s", ".4g"),
        ("dissipated_energy", "dissipated energy per impact", 1e3, "mJ", ".4g"),
        ("heat_to_ball", "heat to the ball per impact", 1e3, "mJ", ".4g"),
        ("duration", "contact duration", 1e6, "µs", ".4g"),
        ("max_overlap", "maximum overlap", 1e6, "µm", ".4g"),
        ("peak_force", "peak contact force", 1.0, "N", ".5g"),
    ):
        if column in impacts:
            values = impacts[column].to_numpy() * scale
            stats = f"{values.mean():{spec}} / {values.min():{spec}} / {values.max():{spec}}"
            rows.append((f"{label}: mean / min / max", stats, unit))
    return rows


def wall_rows(run: RunData) -> list[tuple[str, str, str]]:
    """The regime of the settled motion and the impacts at each end face, of a 1-D run."""
    impacts, rate = run.impacts, run.summary.impacts.rate_hz
    regime, _ = classify_impacts(settled_run_impacts(run), run.params.omega, run.params.phase)
    rows = [("regime of the settled motion", regime, "")]
    for wall in ("left", "right"):
        count = int((impacts["wall"] == wall).sum())
        share = count / len(impacts)
        # The summary's rate covers the whole run (the averaged solver's table covers only its window).
        wall_rate = rate * share
        rows.append((f"impacts at the {wall} end face", f"{count} ({share:.1%})", ""))
        rows.append((f"impact rate at the {wall} end face", number(wall_rate, ".4g"), "Hz"))
    return rows


def target_rows(run: RunData) -> list[tuple[str, str, str]]:
    """The impacts on each wall and between balls, of a 'dem' run (whose several balls have no 1-D regime)."""
    impacts, rate = run.impacts, run.summary.impacts.rate_hz
    rows = []
    for target, label, _ in TARGETS:
        count = int((impacts["target"] == target).sum())
        share = count / len(impacts)
        target_rate = rate * share
        rows.append((f"impacts on {label}", f"{count} ({share:.1%})", ""))
        rows.append((f"impact rate on {label}", number(target_rate, ".4g"), "Hz"))
    return rows


def balls_section(run: RunData) -> str:
    """Each ball of a 'dem' run: radius, temperature at the end and steady state, impacts, heat received."""
    summary, impacts = run.summary, run.impacts
    at_end = summary.temperatures.each_ball_C or []
    steady = (summary.steady.each_ball_C if summary.steady is not None else None) or []
    series = run.timeseries
    seconds = float(series["time"].values[-1])
    heat = series["heat_into_balls"].transpose("time", "ball").values[-1] / seconds if seconds > 0 else None
    on_walls = impacts["target"] != "ball"
    rows = []
    for ball, radius in enumerate(run.params.ball_values("ball_radius")):
        mine = impacts["ball"] == ball
        rows.append(
            (
                str(ball),
                number(radius * 1e3, ".4g"),
                number(at_end[ball] if ball < len(at_end) else None, ".2f"),
                number(steady[ball] if ball < len(steady) else None, ".2f"),
                str(int((mine & on_walls).sum())),
                str(int((~on_walls & (mine | (impacts["other_ball"] == ball))).sum())),
                number(float(heat[ball]) if heat is not None else None, ".4g"),
            )
        )
    headers = (
        "ball",
        "radius (mm)",
        "at the end (°C)",
        "steady state (°C)",
        "impacts on the walls",
        "impacts with other balls",
        "heat received (W)",
    )
    note = (
        f"Balls are numbered as in the run's files, from 0. Impacts are those of the impact table "
        f"({number(impact_span(run), '.4g')} s of the run); the heat received is the mean over the whole run."
    )
    return section("Balls", table(headers, rows, numeric=range(1, len(headers))), paragraph(note, "note"))


def impacts_section(run: RunData, numbers: Iterator[int]) -> str:
    parts = [table(("quantity", "value", "unit"), impact_statistics(run), numeric=(1,))]
    if run.impacts.empty:
        parts.append(paragraph("No impacts were recorded.", "note"))
    elif run.summary.impacts.count != len(run.impacts):
        averaging = run.summary.averaging
        window = number(averaging.window_s if averaging is not None else None, ".3g")
        parts.append(
            paragraph(
                f"The averaged solver resolves impacts only while its averages converge ({window} s); the count for "
                "the whole run is the mean rate times the duration, and the statistics are over the impacts of the "
                "table.",
                "note",
            )
        )
    parts.append(figures_html(impact_figures(run), numbers, captions_of(run)))
    spectrum = run_stress_spectrum(run)
    if spectrum is not None and not run.impacts.empty:
        parts.append(stress_energy_table(spectrum))
    return section("Impacts", *parts)


def stress_energy_table(spectrum: StressSpectrum) -> str:
    """The stress-energy spectrum in numbers: events per second, median and 90th percentile of the total, of each
    part and on each target, then the power above each of the run's thresholds (analysis/stress_energy.py)."""
    parts = (("total", "all"), ("normal", "all"), ("tangential", "all"), ("total", "wall"), ("total", "ball"))
    rows = [
        (
            f"{component}, {target if target != 'all' else 'all targets'}",
            number(spectrum.events_per_second(0.0, component, target), ".4g"),
            number(spectrum.percentile(50, component, target), ".3g"),
            number(spectrum.percentile(90, component, target), ".3g"),
            number(spectrum.power(0.0, component, target), ".4g"),
        )
        for component, target in parts
    ]
    rows += [
        (
            f"total at or above {threshold:g} J",
            number(spectrum.events_per_second(threshold), ".4g"),
            "",
            "",
            number(spectrum.power(threshold), ".4g"),
        )
        for threshold in spectrum.thresholds
    ]
    lasting = number(spectrum.lasting_per_second(), ".4g")
    share = spectrum.lasting_share()
    rows.append(
        (
            f"lasting contacts (rolling, sliding: no stress events; {number(100 * share, '.3g')} % of the dissipation, "
            "left out of every row above)",
            lasting,
            "",
            "",
            number(spectrum.lasting_power(), ".4g"),
        )
    )
    rows.append(
        (
            "Kwade's stress energy ½·m*·v_n² at first touch (brought, not dissipated)",
            number(spectrum.events_per_second(0.0, "kinetic"), ".4g"),
            number(spectrum.percentile(50, "kinetic"), ".3g"),
            number(spectrum.percentile(90, "kinetic"), ".3g"),
            "",
        )
    )
    header = (
        "stress energy (J dissipated per impact)",
        "events per second (1/s)",
        "median (J)",
        "90th percentile (J)",
        "power (W)",
    )
    return table(header, rows, numeric=(1, 2, 3, 4))


def numerics_section(run: RunData) -> str:
    summary = run.summary
    params = run.params
    rows = [
        ("solver", summary.solver, ""),
        ("relative tolerance rtol", number(params.rtol, ".3g"), ""),
        ("accepted steps", number(summary.steps, "d"), ""),
        ("rejected steps", number(summary.rejected_steps, "d"), ""),
        ("right-hand-side evaluations", number(summary.rhs_evaluations, "d"), ""),
        ("wall time", number(summary.wall_time_s, ".3g"), "s"),
        ("energy projection", "on" if params.energy_projection else "off", ""),
        ("projection correction / dissipated energy", number(summary.energy_projection_relative, ".3e"), ""),
        ("energy audit relative residual", number(summary.energy_audit_residual, ".3e"), ""),
    ]
    # The averaged solver adds its statistics (averaged_*, averaging_*) to the summary, each with its unit.
    rows += [
        (key, number(value, ".4g"), unit_of(key)) for key, value in summary.flat().items() if key.startswith("averag")
    ]
    return section("Numerics", table(("quantity", "value", "unit"), rows, numeric=(1,)))
