"""CSV files users give (sweep points, measured curves): read whole or refused with one line saying why.

Spreadsheets save UTF-8 with a byte-order mark, editors without one; both are read. Any other
encoding, a malformed file, too many rows or an over-long cell gets one line naming the file.
"""

from __future__ import annotations

import csv
from pathlib import Path

from shakermill.parameters.errors import ParameterError
from shakermill.support.limits import MAX_VALUE_LENGTH


def read_csv_rows(path: Path, what: str, most_rows: int, delimiter: str = ",") -> list[list[str]]:
    """The rows of the CSV file at ``path``: its header and at most ``most_rows`` rows after it.

    ``what`` starts every error line ("points data.csv", "curve data.csv").
    """
    rows: list[list[str]] = []
    try:
        with path.open(newline="", encoding="utf-8-sig") as stream:
            reader = csv.reader(stream, delimiter=delimiter)
            for row in reader:
                _check_cells(row, what, reader.line_num)
                rows.append(row)
                if len(rows) > most_rows + 1:
                    raise ParameterError(
                        f"{what}: more than {most_rows:,} rows after the header; allowed at most {most_rows:,}"
                    )
    except UnicodeDecodeError:
        raise ParameterError(f"{what}: not UTF-8 text; save it as UTF-8 (with or without a byte-order mark)") from None
    except csv.Error as exc:
        raise ParameterError(f"{what}: malformed CSV at line {reader.line_num} ({exc})") from None
    except OSError as exc:
        raise ParameterError(f"{what}: cannot read the file ({exc.strerror or exc})") from None
    return rows


def _check_cells(row: list[str], what: str, line: int) -> None:
    for cell in row:
        if len(cell) > MAX_VALUE_LENGTH:
            raise ParameterError(
                f"{what} line {line}: a cell of {len(cell):,} characters; allowed at most {MAX_VALUE_LENGTH}"
            )


def check_rectangular(rows: list[list[str]], header: list[str], what: str) -> None:
    """Refuse a row of more or fewer cells than the header has columns, naming its line: a cell beyond the header
    would be dropped without a word, and "5,25,1" is most often a decimal comma (25,1 °C) split in two."""
    for line, row in enumerate(rows, start=2):
        if len(row) == len(header):
            continue
        hint = (
            "; a decimal comma splits a number in two: write 25.1, not 25,1 (or separate the columns with ';')"
            if len(row) > len(header)
            else ""
        )
        raise ParameterError(
            f"{what} line {line}: {len(row)} cell{'s' * (len(row) != 1)} for the {len(header)} columns of its header "
            f"({', '.join(header)}){hint}"
        )
