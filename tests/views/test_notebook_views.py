"""Notebook views: the HTML reprs of Result and Parameters, Result.plot() and the °C variables."""

from __future__ import annotations

import base64
import copy
import re

import numpy as np
import pytest
from xarray.plot.utils import label_from_attrs

import shakermill as sm
from shakermill.io.runs import load_run, write_run
from shakermill.views.notebook import ANSWER_KEYS, CALIBRATED_PRESET, answer_sentences

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_result_html_repr_gives_status_answer_and_inputs_escaped(default_run_20s):
    result = copy.copy(default_run_20s)
    result.message = '<b onmouseover="x()">done</b>'
    document = result._repr_html_()
    assert "<b onmouseover" not in document and "&lt;b onmouseover=&quot;x()&quot;&gt;" in document
    summary = result.summary
    assert f'<td class="num">{summary.ball_steady_C:.1f}</td><td>°C</td>' in document
    assert f"After {summary.simulated_s / 60:.3g} min the ball is at {summary.ball_C:.1f} °C" in document
    assert '<td>drive frequency</td><td class="num">1060</td><td>rpm</td>' in document
    # Small: the key inputs only, not all the keys the plain repr prints.
    assert document.count("<tr>") < 25
    assert "<script" not in document


def test_parameters_html_repr_has_the_key_inputs_and_every_key_folded_away():
    params = sm.default_parameters(omega=100.0)
    document = params._repr_html_()
    assert '<td>drive frequency ω</td><td class="num">100</td><td>rad/s</td>' in document
    assert '<td>amplitude</td><td class="num">25</td><td>mm</td>' in document
    keys = params.model_dump()
    assert f"<summary>all {len(keys)} keys (SI units)</summary>" in document
    details = document[document.index("<details>") :]
    assert all(f"<td>{key}</td>" in details for key in keys)


@pytest.mark.slow
def test_temperatures_in_celsius_are_labelled_degc_and_stored_in_the_run_folder(default_run_20s, tmp_path):
    series = default_run_20s.timeseries
    for name in ("theta_ball", "theta_vial", "theta_air"):
        celsius = series[f"{name}_C"]
        np.testing.assert_allclose(celsius.values, series[name].values - 273.15)
        assert celsius.attrs["units"] == "degC"
    assert label_from_attrs(series["theta_ball_C"]) == "ball temperature [degC]"
    stored = load_run(write_run(default_run_20s, tmp_path / "run", preset="spex8000m"))
    for dataset in (stored.timeseries, stored.windows):
        assert dataset["theta_vial_C"].attrs["units"] == "degC"
    np.testing.assert_allclose(stored.timeseries["theta_air_C"].values, series["theta_air_C"].values)


@pytest.mark.slow
def test_result_plot_returns_the_paper_figures_shown_inline(default_run_20s):
    figures = default_run_20s.plot()
    assert list(figures) == ["temperatures", "ball_motion"]
    assert figures["temperatures"].axes[0].get_ylabel() == "temperature (°C)"
    images = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', figures._repr_html_())
    assert len(images) == 2
    assert all(base64.b64decode(image).startswith(PNG_SIGNATURE) for image in images)
    assert "impacts_per_second" in default_run_20s.plot(impacts=True)


@pytest.mark.parametrize("fitted", [False, True])
def test_the_answer_says_when_an_uncalibrated_steady_state_is_far_above_the_experiment(fitted, default_run_20s):
    summary = default_run_20s.summary.updated(
        ball_steady_C=124.6, initial_temperature_C=20.0, simulated_s=3600.0, ball_C=120.3
    )
    sentences = answer_sentences(summary, "spex8000m", fitted=fitted)
    assert sentences[0].startswith("After 60 min the ball is at 120.3 °C")
    far_above = [sentence for sentence in sentences if "far above the experiment" in sentence]
    if fitted:
        assert far_above == []
    else:
        assert len(far_above) == 1 and "3.7 times" in far_above[0] and CALIBRATED_PRESET in far_above[0]


def test_a_3d_run_far_above_the_experiment_is_pointed_to_the_3d_calibrated_preset(default_run_20s):
    # One ball of the 'dem' engine: its charge is a section of its own, whole.
    charge = {"engine": "dem", "n_balls": 1, "fill_fraction": 0.01, "work_gravity_J": 0.0, "work_stiffening_J": 0.0}
    summary = default_run_20s.summary.updated(ball_steady_C=124.6, initial_temperature_C=20.0, **charge)
    (far_above,) = (sentence for sentence in answer_sentences(summary, "spex8000m-3d") if "far above" in sentence)
    assert "Preset spex8000m-3d-calibrated is fitted to that experiment" in far_above


def test_the_answer_of_a_run_close_to_the_experiment_makes_no_comparison(default_run_20s):
    summary = default_run_20s.summary.updated(ball_steady_C=50.0, initial_temperature_C=20.0)
    assert not any("experiment" in sentence for sentence in answer_sentences(summary, "spex8000m"))
    # Numbers a run did not measure (NaN, null in summary.json) read "n/a".
    unmeasured = summary.updated(simulated_s=float("nan"), **{key: float("nan") for key, *_ in ANSWER_KEYS})
    assert "n/a" in answer_sentences(unmeasured, "spex8000m")[0]
