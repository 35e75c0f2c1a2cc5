"""examples/quickstart.ipynb runs from top to bottom in a kernel of this environment and shows what it says."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

# Every test here reads a run made once for the module: make test-fast leaves them out.
pytestmark = pytest.mark.slow

NOTEBOOK = Path(__file__).resolve().parents[2] / "examples" / "quickstart.ipynb"
# The whole notebook takes a few seconds once the compiled functions are cached; the first run compiles them.
CELL_TIMEOUT_S = 300


@pytest.fixture(scope="module")
def executed(tmp_path_factory) -> list:
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    # "python3" is ipykernel's own kernel spec; jupyter_client starts it with this interpreter (sys.executable).
    client = NotebookClient(
        notebook,
        kernel_name="python3",
        timeout=CELL_TIMEOUT_S,
        resources={"metadata": {"path": str(tmp_path_factory.mktemp("notebook"))}},
    )
    client.execute()
    return [cell for cell in notebook.cells if cell.cell_type == "code"]


def outputs_of(cell, kind: str) -> list[str]:
    return [output["data"][kind] for output in cell.outputs if kind in output.get("data", {})]


def test_the_notebook_runs_without_errors(executed):
    assert all(output.output_type != "error" for cell in executed for output in cell.outputs)


def test_the_notebook_shows_the_html_views_and_the_steady_state(executed):
    parameters, result, printed = executed[0], executed[1], executed[2]
    assert '<td>drive frequency</td><td class="num">1060</td><td>rpm</td>' in outputs_of(parameters, "text/html")[0]
    text = "".join(output.get("text", "") for output in printed.outputs)
    steady = re.search(r"ball steady state: (\d+\.\d) °C", text)
    assert steady is not None, text
    # The printed number and the Result's own HTML view agree.
    assert f"the ball would settle at {steady.group(1)} °C" in outputs_of(result, "text/html")[0]


def test_the_notebook_draws_the_figures_and_the_celsius_series(executed):
    figures = outputs_of(executed[3], "text/html")[0]
    assert figures.count('src="data:image/png;base64,') == 2
    assert outputs_of(executed[4], "image/png"), "theta_ball_C.plot() drew nothing"


def test_the_notebook_sweep_has_a_row_per_frequency(executed):
    table = outputs_of(executed[5], "text/html")[0]
    assert table.count("</tr>") == 3  # the header and two points
    assert "ball_steady_C" in table and "1145.9" in table
