"""``repr(result)`` is a few lines, as xarray and pandas objects print (issue 37, point 7: it was 428,278 characters,
every array)."""

from __future__ import annotations

import shakermill as sm


def test_a_results_repr_says_what_ran_its_headlines_and_the_sizes_of_its_data_in_a_few_lines():
    result = sm.simulate(sm.default_parameters(duration=60, solver="averaged"))
    text = repr(result)
    lines = text.splitlines()
    assert len(lines) <= 6 and len(text) < 1000
    assert lines[0].startswith("<shakermill.Result: engine '1d', solver 'averaged', success, 60 s simulated")
    assert lines[1].strip() == result.message
    assert (
        f"ball °C {result.summary.ball_C:.4g}" in lines[2] and f"heat W {result.summary.heat_power_W:.4g}" in lines[2]
    )
    assert (
        f"{result.history.times.size} samples of {len(result.history.variables)} series, {len(result.impacts)} "
        "contact records"
    ) in lines[3]
    assert str(result) == text


def test_a_long_message_is_cut_and_the_warnings_are_counted():
    result = sm.simulate(sm.default_parameters(duration=60, solver="averaged"))
    result.message = "x" * 500
    result.warnings = ["one", "two"]
    lines = repr(result).splitlines()
    assert len(lines[1].strip()) == 160 and lines[1].endswith("…")
    assert lines[-1].strip() == "2 warnings (.warnings)"
