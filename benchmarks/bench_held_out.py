"""Which network structure follows the one-ball curve with physical couplings, and what each predicts for five balls.

Each structure of ``studies.validation.matrix.STRUCTURES`` is fitted to the experiment's one-ball curve
(48 − 28·exp(−t/16.7 min) °C) from its uncalibrated preset, exactly as ``shakermill calibrate --preset P --free
...`` does; then five balls with the fitted values, nothing refitted, run the experiment's hour. The bar (issue 23,
point 7): the curve within 2 K RMS, every free key strictly inside its range, every computed path at its
correlation's value. The shipped ``spex8000m-3d-calibrated`` is the physical structure that comes closest; the
choice uses the one-ball curve and the ranges alone, never the five-ball numbers.

Then the validation matrix: each thermal model's calibrated preset against each experiment file, with 90 %
intervals. The mechanics are measured once for one ball and once for five (``solvers.simulate.thermal_variants``).
Run by hand (~10 min here); figures go into benchmarks/README.md and README.md.
"""

from __future__ import annotations

import time

from shakermill.studies.validation.matrix import structure_study, validation_matrix
from shakermill.views.validation_page import (
    MATRIX_HEADERS,
    matrix_rows,
    structure_headers,
    structure_rows,
    structure_verdict,
)


def markdown_table(headers: tuple[str, ...], rows: list[tuple[str, ...]]) -> str:
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def main() -> None:
    started = time.perf_counter()
    matrix = validation_matrix()
    print(f"validation matrix in {time.perf_counter() - started:.0f} s")
    print(markdown_table(MATRIX_HEADERS, matrix_rows(matrix)))
    started = time.perf_counter()
    outcomes = structure_study()
    print(f"\nstructure study in {time.perf_counter() - started:.0f} s")
    print(markdown_table(structure_headers(), structure_rows(outcomes)))
    print(structure_verdict(outcomes))


if __name__ == "__main__":
    main()
