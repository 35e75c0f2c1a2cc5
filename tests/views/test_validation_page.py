"""The validation page (`validate --report`): the matrix's numbers, its figure, the structures and the verdict, from
hand-made study results."""

from __future__ import annotations

import math
import re

import pytest

from shakermill.studies.validation.matrix import (
    Experiment,
    MatrixRow,
    Point,
    Structure,
    StructureOutcome,
    ValidationMatrix,
)
from shakermill.studies.validation.report import ValidationReport
from shakermill.views import validation_page
from shakermill.views.validation_page import matrix_rows, render_validation_page, save_validation_page, structure_rows

FIVE = Experiment(
    "five",
    "Five balls",
    "a paper",
    "a calorimeter",
    False,
    {"n_balls": 5},
    (Point("ball", 3600.0, 46.0), Point("vial", 3600.0, 21.0)),
)
EMPTY = Experiment(
    "empty",
    "An empty mill",
    "none yet",
    "a thermocouple",
    False,
    {"n_balls": 0},
    (Point("vial", 3600.0, None),),
    falsifies="the drive's heat",
)
MATRIX = ValidationMatrix(
    (FIVE, EMPTY),
    (
        MatrixRow("a-preset", "mill-head", FIVE, FIVE.points[0], "held out", 105.0, 102.0, 106.0),
        MatrixRow("a-preset", "mill-head", FIVE, FIVE.points[1], "held out", 25.9, 20.0, 27.0),
        MatrixRow("a-preset", "mill-head", EMPTY, EMPTY.points[0], "prediction", 15.2, 14.0, 16.0),
        MatrixRow("b-preset", "paper", FIVE, FIVE.points[0], "held out", 225.0, math.nan, math.nan),
    ),
)
STRUCTURES = (
    StructureOutcome(
        Structure("physical", "spex8000m-3d-mill-head", ("drive_heat",)), {"drive_heat": 23.2}, 1.8, (), 60.0, 25.0
    ),
    StructureOutcome(
        Structure("on an edge", "spex8000m-3d-mill-head", ("drive_heat",)),
        {"drive_heat": 30.0},
        1.5,
        ("drive_heat",),
        92.0,
        14.0,
    ),
)
REPORT = ValidationReport("averaged", (), (), None, MATRIX, STRUCTURES)


def test_matrix_rows_give_the_error_and_whether_the_measurement_is_inside():
    rows = matrix_rows(MATRIX)
    ball, vial, empty, paper = rows
    assert ball[5:] == ("46", "105", "102 to 106", "+128 %", "no")
    assert vial[5:] == ("21", "25.9", "20 to 27", "+23 %", "yes")
    assert empty[4:] == ("prediction", "—", "15.2", "14 to 16", "—", "—")
    assert paper[7] == "—"  # no interval for an uncalibrated prediction


def test_structure_rows_say_which_meets_the_bar():
    physical, edge = structure_rows(STRUCTURES)
    assert physical[3:6] == ("none", "yes", "yes") and physical[6] == "60 (+30 %)"
    assert edge[3:6] == ("drive_heat", "yes", "no") and edge[7] == "14 (-33 %)"


def test_the_page_holds_the_matrix_its_figure_and_the_verdict(tmp_path):
    page = render_validation_page(REPORT)
    assert page.count("<img") == 1 and "data:image/png;base64," in page
    assert page.count("<tr>") == 2 + len(MATRIX.rows) + len(STRUCTURES)  # two header rows; no held-out table
    assert "+128 %" in page and "102 to 106" in page and "It falsifies: the drive&#x27;s heat" in page
    assert re.search(r"Met by: physical\.", page)
    target = save_validation_page(REPORT, tmp_path / "out" / "validation.html")
    assert target.read_text(encoding="utf-8") == page


def test_a_folder_is_refused_before_the_page_is_drawn(tmp_path, monkeypatch):
    monkeypatch.setattr(validation_page, "render_validation_page", lambda report: pytest.fail("the page was drawn"))
    with pytest.raises(IsADirectoryError):
        save_validation_page(REPORT, tmp_path)
