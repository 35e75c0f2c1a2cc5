"""The HTML report: content, self-containment, escaping, the command line, and rendering in headless Chromium."""

from __future__ import annotations

import base64
import dataclasses
import html
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import shakermill as sm
from shakermill import cli
from shakermill.analysis.regime import classify_impacts, settled_run_impacts
from shakermill.io.runs import RunData, load_run, write_run
from shakermill.parameters.defaults import DEFAULT_PRESET
from shakermill.parameters.engine_keys import reads
from shakermill.parameters.keys import FIELD_NAMES
from shakermill.parameters.presets import PRESETS
from shakermill.studies.measured import TABLE5
from shakermill.views.report import REPORT_FILE, fitted_targets, number, render_report, write_report

# Every test here reads a run made once for the module: make test-fast leaves them out.
pytestmark = pytest.mark.slow

CALIBRATED_PRESET = "spex8000m-calibrated"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
DATA_URI_IMAGE = re.compile(r'<img[^>]*\ssrc="data:image/png;base64,([A-Za-z0-9+/=]+)"')
# Any attribute that would make the browser fetch something: an absolute or protocol-relative URL.
EXTERNAL_REFERENCE = re.compile(r"""(?:src|href)\s*=\s*["']?\s*(?:[a-z][a-z0-9+.-]*:)?//""", re.IGNORECASE)
BROWSER_TIMEOUT_S = 120
CHROMIUM_NAMES = ("chromium", "chromium-browser")
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
)
SCREENSHOT_SIZE = (1200, 3000)

runner = CliRunner()


def short_run(folder: Path, preset: str = DEFAULT_PRESET, **overrides) -> Path:
    """30 simulated seconds with the paper's two windows moved inside them (Fig. 4 and a Fig. 5b-like zoom)."""
    params = sm.default_parameters(preset, duration=30.0, record_windows=((0.0, 1.0), (20.0, 0.1)), **overrides)
    return write_run(sm.simulate(params), folder, preset=preset)


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory) -> Path:
    return short_run(tmp_path_factory.mktemp("report") / "three_node")


@pytest.fixture(scope="module")
def ball_only_folder(tmp_path_factory) -> Path:
    return short_run(tmp_path_factory.mktemp("report") / "ball_only", model="ball_only")


@pytest.fixture(scope="module")
def report_html(run_folder) -> str:
    return render_report(load_run(run_folder))


def rows_of_table_after(document: str, heading: str) -> list[str]:
    """The ``<tr>`` elements of the first table after the ``<h2>`` that starts with ``heading``."""
    section = document[document.index(f"<h2>{html.escape(heading)}") :]
    table = section[section.index("<table>") : section.index("</table>")]
    return re.findall(r"<tr[^>]*>.*?</tr>", table, flags=re.DOTALL)


def test_report_lists_every_configuration_key_its_engine_reads_with_its_source(report_html):
    rows = rows_of_table_after(report_html, "Configuration")
    listed = [re.search(r"<td>(\w+)</td>", row).group(1) for row in rows[1:]]
    assert listed == [key for key in FIELD_NAMES if reads("1d", key)]
    assert (
        "friction" not in listed and "n_balls" not in listed and "omega" in listed
    )  # the 'dem' engine's keys are left out
    assert (
        f"The {len(FIELD_NAMES) - len(listed)} keys the engine of this run does not read are left out." in report_html
    )
    assert html.escape(PRESETS[DEFAULT_PRESET].values["omega"].source) in report_html
    # duration and record_windows were changed for this short run: marked as differing from the preset.
    marked = [row for row in rows_of_table_after(report_html, "Configuration") if 'class="differs"' in row]
    assert sorted(re.search(r"<td>(\w+)</td>", row).group(1) for row in marked) == ["duration", "record_windows"]


def test_report_names_the_assumptions_and_the_deliberate_differences(report_html):
    assumptions = report_html[report_html.index("<h2>Assumptions not in the paper") :]
    assumed = [key for key, cited in PRESETS[DEFAULT_PRESET].values.items() if cited.source.startswith("assumption")]
    assert "vial_mass" in assumed and "omega" in assumed
    for key in assumed:
        assert f"<li>{key} = " in assumptions, key
    assert assumptions.count("<li>Hertz force") == 1
    assert "MODEL.md §9" in assumptions


def at_the_experiments_operating_point(run: RunData, **changes) -> RunData:
    """``run`` as if it had lasted the experiment's hour (with ``changes``): Table 5 compares only such runs."""
    params = run.params.replace(duration=3600.0, **changes)
    return dataclasses.replace(run, params=params, summary=run.summary.updated(simulated_s=3600.0))


def test_the_report_of_a_preset_whose_validation_failed_says_what_it_found(run_folder):
    preset = PRESETS["spex8000m-calibrated"]
    assert preset.caveat and "+70 %" in preset.caveat  # its held-out ratio, as stored with the preset
    shipped = dataclasses.replace(load_run(run_folder), preset=preset.name, params=sm.default_parameters(preset.name))
    caveats = re.compile(r'<p class="status failed">Caveat \(spex8000m-calibrated\): (.*?)</p>')
    report_html = render_report(shipped)
    said = caveats.search(report_html)
    assert said is not None and said.group(1) == html.escape(preset.caveat)
    assert said.start() > report_html.index('<p class="statement answer">')
    # A run that changes what the calibration fitted gets the finding of the preset as shipped, and is told so.
    changed = render_report(dataclasses.replace(shipped, params=shipped.params.replace(beta=1.0)))
    assert "This run changes beta, which the calibration fitted" in caveats.search(changed).group(1)
    # The paper's preset has nothing to confess beyond its comparison with the experiment.
    assert "Caveat (" not in render_report(load_run(run_folder))


def test_table5_of_the_published_preset_is_all_predicted(run_folder):
    report_html = render_report(at_the_experiments_operating_point(load_run(run_folder)))
    rows = rows_of_table_after(report_html, "Table 5")
    assert len(rows) == 1 + len(TABLE5)
    for quantity, row in zip(TABLE5, rows[1:]):
        assert html.escape(quantity.label) in row
        assert row.endswith("<td>predicted</td></tr>")
    assert "Nothing was fitted" in report_html


def test_table5_of_a_calibrated_run_marks_the_calibration_targets_fitted(tmp_path):
    folder = short_run(tmp_path / "calibrated", preset=CALIBRATED_PRESET)
    # 1 % off the experiment's ω: inside the operating point's tolerance, so Table 5 is shown.
    document = render_report(at_the_experiments_operating_point(load_run(folder), omega=112.1))
    rows = rows_of_table_after(document, "Table 5")[1:]
    roles = {quantity.key: re.findall(r"<td>(fitted|predicted)</td>", row)[0] for quantity, row in zip(TABLE5, rows)}
    assert roles == {
        "theta_inf_C": "fitted",
        "tau_min": "fitted",
        "rate0_C_per_min": "fitted",
        "vial_ball_ratio": "predicted",
    }
    assert "beta, vial_mass, h_outer, lam were fitted" in document
    # Any change of a calibrated value, however small: the report says the fit need not hold for this run.
    assert "This run changes 1 of the preset&#x27;s values (omega)" in document
    assert "far above the experiment" not in document


def test_fitted_targets_are_the_calibration_quantities_not_the_fitted_parameters():
    assert fitted_targets(PRESETS[CALIBRATED_PRESET]) == ("theta_inf_C", "tau_min", "rate0_C_per_min")
    assert fitted_targets(PRESETS[DEFAULT_PRESET]) == ()
    assert fitted_targets(None) == ()


def test_report_shows_the_energy_audit_with_its_residual(run_folder, report_html):
    energy = load_run(run_folder).energy
    rows = rows_of_table_after(report_html, "Energy audit")
    text = "\n".join(rows)
    for key in ("work_by_vial", "dissipated", "heat_generated", "stored_balls", "residual", "relative_residual"):
        assert f"<td>{key}</td>" in text, key
    assert number(energy["relative_residual"], ".3e") in text
    assert number(energy["work_by_vial"], ".6g") in text


def test_report_shows_impact_statistics_and_numerics(run_folder, report_html):
    run = load_run(run_folder)
    impacts = "\n".join(rows_of_table_after(report_html, "Impacts"))
    assert f">{run.summary.impacts.count}<" in impacts
    for wall in ("left", "right"):
        count = int((run.impacts["wall"] == wall).sum())
        assert f'impacts at the {wall} end face</td><td class="num">{count} (' in impacts
    assert "contact duration: mean / min / max" in impacts and "µs" in impacts
    regime, _ = classify_impacts(settled_run_impacts(run), run.params.omega, run.params.phase)
    assert f'regime of the settled motion</td><td class="num">{regime}<' in impacts
    assert "Drive phase ωt + φ (mod 2π) at the impacts of the settled motion" in report_html
    numerics = "\n".join(rows_of_table_after(report_html, "Numerics"))
    for label in ("accepted steps", "rejected steps", "right-hand-side evaluations", "wall time"):
        assert label in numerics
    assert f">{run.summary.steps}<" in numerics


def test_report_is_self_contained_with_embedded_png_figures(report_html):
    images = DATA_URI_IMAGE.findall(report_html)
    assert len(images) >= 4  # Figs. 4, 5a, 5b and the impact figures
    assert len(images) == report_html.count("<img")
    for encoded in images:
        assert base64.b64decode(encoded).startswith(PNG_SIGNATURE)
    assert EXTERNAL_REFERENCE.search(report_html) is None
    assert "http://" not in report_html and "https://" not in report_html
    assert "<script" not in report_html.lower()
    assert "<link" not in report_html.lower()


def test_text_from_the_run_is_escaped(run_folder):
    run = dataclasses.replace(load_run(run_folder), message='<b onmouseover="x()">stopped</b> & more')
    document = render_report(run)
    assert "<b onmouseover" not in document
    assert "&lt;b onmouseover=&quot;x()&quot;&gt;stopped&lt;/b&gt; &amp; more" in document


def test_unknown_preset_and_missing_numbers_still_render(run_folder):
    run = at_the_experiments_operating_point(load_run(run_folder))
    summary = run.summary.updated(theta_inf_C=float("nan"), tau_min=float("nan"))  # null in summary.json
    document = render_report(dataclasses.replace(run, preset="no-such-preset", summary=summary))
    assert "is not known to this version of shakermill" in document
    assert "fitted</td>" not in document
    assert "no preset value" in document
    assert "n/a" in document


def test_write_report_defaults_into_the_run_folder_and_leaves_no_temporary_file(run_folder):
    before = {entry.name for entry in run_folder.iterdir()}
    path = write_report(run_folder)
    assert path == run_folder / REPORT_FILE
    assert {entry.name for entry in run_folder.iterdir()} == before | {REPORT_FILE}
    assert path.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_report_command_writes_the_file_and_compare_adds_the_side_by_side_table(run_folder, ball_only_folder, tmp_path):
    alone, compared = tmp_path / "alone.html", tmp_path / "sub" / "compared.html"
    result = runner.invoke(cli.app, ["report", str(run_folder), "--out", str(alone)])
    assert result.exit_code == 0, result.stderr
    assert str(alone) in result.stdout
    assert "<h2>Comparison" not in alone.read_text(encoding="utf-8")
    args = ["report", str(run_folder), "--out", str(compared), "--compare", str(ball_only_folder)]
    result = runner.invoke(cli.app, args)
    assert result.exit_code == 0, result.stderr
    document = compared.read_text(encoding="utf-8")
    assert "<h2>Comparison: three_node and ball_only</h2>" in document
    rows = rows_of_table_after(document, "Comparison")
    assert "three_node (three_node, spex8000m)" in rows[0] and "ball_only (ball_only, spex8000m)" in rows[0]
    assert any("<td>model</td>" in row and "ball_only" in row for row in rows)
    assert any("ball θ∞" in row for row in rows)
    assert len(DATA_URI_IMAGE.findall(document)) == len(DATA_URI_IMAGE.findall(alone.read_text(encoding="utf-8"))) + 1


@pytest.mark.parametrize("make_folder", ["missing", "empty", "other"])
def test_report_command_refuses_a_folder_that_is_not_a_run(tmp_path, make_folder):
    folder = tmp_path / "not_a_run"
    if make_folder != "missing":
        folder.mkdir()
    if make_folder == "other":
        (folder / "notes.txt").write_text("hello", encoding="utf-8")
    result = runner.invoke(cli.app, ["report", str(folder)])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    expected = "no such folder" if make_folder == "missing" else "not a shakermill run folder (no summary.json)"
    assert len(lines) == 1 and lines[0].startswith("error: ") and expected in lines[0]
    assert not (folder / REPORT_FILE).exists()


def test_report_command_refuses_a_compare_folder_that_is_not_a_run(run_folder, tmp_path):
    args = ["report", str(run_folder), "--compare", str(tmp_path), "--out", str(tmp_path / "r.html")]
    result = runner.invoke(cli.app, args)
    assert result.exit_code == 2
    assert result.stderr.startswith("error: ")
    assert not (tmp_path / "r.html").exists()


def test_report_command_refuses_a_folder_as_output_file(run_folder, tmp_path):
    result = runner.invoke(cli.app, ["report", str(run_folder), "--out", str(tmp_path)])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "cannot write the report (a folder" in lines[0]
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- the report in a real browser


def chromium() -> str:
    """The Chromium binary; the test fails without one unless SHAKERMILL_SKIP_BROWSER=1 says to skip it, or
    ``make test`` (scripts/ensure-browser) could not install it and says why in SHAKERMILL_BROWSER_UNAVAILABLE."""
    if os.environ.get("SHAKERMILL_SKIP_BROWSER") == "1":
        pytest.skip("SHAKERMILL_SKIP_BROWSER=1")
    if os.environ.get("SHAKERMILL_BROWSER_UNAVAILABLE"):
        pytest.skip(os.environ["SHAKERMILL_BROWSER_UNAVAILABLE"])
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    pytest.fail(
        "chromium is not installed: `apt-get install chromium` (`make test BROWSER=1` does it), "
        "or set SHAKERMILL_SKIP_BROWSER=1 to skip the browser test"
    )


def run_chromium(profile: Path, *args: str) -> subprocess.CompletedProcess:
    command = [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=BROWSER_TIMEOUT_S, check=False)


def test_report_renders_in_headless_chromium(run_folder, tmp_path):
    import matplotlib.image

    report = write_report(run_folder, tmp_path / "report.html")
    url = report.absolute().as_uri()
    width, height = SCREENSHOT_SIZE
    shot = tmp_path / "shot.png"
    completed = run_chromium(tmp_path / "profile", f"--screenshot={shot}", f"--window-size={width},{height}", url)
    assert shot.is_file(), completed.stderr[-2000:]
    assert shot.stat().st_size > 100_000
    pixels = matplotlib.image.imread(shot)
    assert pixels.shape[:2] == (height, width)
    # A page with tables and figures: many colours and a real spread, not a blank or single-colour image.
    assert len(np.unique(pixels[..., :3].reshape(-1, 3), axis=0)) > 100
    assert pixels[..., :3].std() > 0.05

    dom = run_chromium(tmp_path / "profile", "--dump-dom", url)
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert "<h2>Table 5: experiment, the paper's model and this run</h2>" in dom.stdout
    images = re.findall(r"<img[^>]*>", dom.stdout)
    assert len(images) >= 4
    assert all('src="data:image/png;base64,' in image for image in images)


def test_report_shows_the_runs_warnings_and_its_steady_state(run_folder, report_html):
    summary = load_run(run_folder).summary
    # 30 s is far shorter than the slowest time constant: the run says so in its answer, not as a warning.
    assert any("slowest time constant" in line for line in summary.notes)
    assert not any("slowest time constant" in line for line in summary.warnings)
    answer = re.search(r'<p class="statement answer">(.*?)</p>', report_html).group(1)
    assert all(html.escape(note) in answer for note in summary.notes)
    for line in summary.warnings:
        assert html.escape("Warning: " + line) in report_html
    results = "".join(rows_of_table_after(report_html, "Results"))
    assert "ball steady state" in results and number(summary.ball_steady_C, ".2f") in results


def test_table5_is_left_out_off_the_experiments_operating_point_and_the_report_says_why(run_folder, report_html):
    table5 = report_html[report_html.index("<h2>Table 5") :].split("</section>")[0]
    assert "<table>" not in table5
    assert "Left out" in table5 and "duration = 30 s (experiment: 3600 s)" in table5
    faster = render_report(at_the_experiments_operating_point(load_run(run_folder), omega=115.0))
    table5 = faster[faster.index("<h2>Table 5") :].split("</section>")[0]
    assert "<table>" not in table5 and "omega = 115 rad/s (experiment: 111 rad/s)" in table5
    assert "duration" not in table5


def test_report_opens_with_the_answer_and_points_the_default_preset_to_the_calibrated_one(run_folder, report_html):
    summary = load_run(run_folder).summary
    answer = re.search(r'<p class="statement answer">(.*?)</p>', report_html).group(1)
    # Before every table: the answer is the first thing read.
    assert report_html.index(answer) < report_html.index("<table>")
    assert f"the ball would settle at {summary.ball_steady_C:.1f} °C" in answer
    assert f"slowest time constant of the thermal network is {summary.slowest_time_constant_min:.1f} min" in answer
    assert f"{summary.heat_power_W:.3g} W of heat at {summary.impacts.rate_hz:.3g} impacts per second" in answer
    assert "far above the experiment" in answer and CALIBRATED_PRESET in answer


def test_report_numbers_its_figures_in_order(report_html, run_folder, ball_only_folder):
    numbers = [int(n) for n in re.findall(r"<figcaption>Figure (\d+): ", report_html)]
    assert numbers == list(range(1, report_html.count("<figure>") + 1)) and len(numbers) >= 4
    compared = render_report(load_run(run_folder), load_run(ball_only_folder))
    assert f"<figcaption>Figure {len(numbers) + 1}: Ball (solid)" in compared


def test_report_ends_with_what_to_cite(report_html):
    last = report_html[report_html.rindex("<section>") :]
    assert "<h2>What to cite</h2>" in last
    for source in (
        "shakermill ",
        "Son 2025, Mathematics 13, 446",
        "Takacs &amp; McHenry 2006, J. Mater. Sci. 41, 5246",
    ):
        assert source in last, source
