"""The HTML of a report: escaped tables, sections, paragraphs, lists and embedded figures, no scripts."""

from __future__ import annotations

import base64
import errno
import math
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from shakermill.support.atomic import remove_abandoned_writes, write_text_atomically
from shakermill.views.figures.common import png_bytes
from shakermill.views.notebook import esc

if TYPE_CHECKING:
    from matplotlib.figure import Figure


# Screen resolution: sharp enough in a browser, and keeps a report of six figures well under a megabyte.
EMBED_DPI = 100


def percent(fraction: float) -> str:
    if not math.isfinite(fraction):
        return "n/a"
    # Adding 0.0 turns a -0.0 from rounding a tiny negative error into +0.0.
    return f"{round(fraction * 100, 1) + 0.0:+.1f} %"


def pretty_unit(unit: str) -> str:
    """'kg/m^3' -> 'kg/m³', 'J/(kg*K)' -> 'J/(kg·K)'."""
    return unit.replace("^3", "³").replace("^2", "²").replace("*", "·")


def table(
    headers: Sequence[str] | None,
    rows: Iterable[Sequence[str]],
    *,
    numeric: Sequence[int] = (),
    row_classes: Mapping[int, str] | None = None,
) -> str:
    """An HTML table of plain-text cells (escaped here); ``numeric`` columns are right-aligned.

    Without ``headers`` the table has no header row (a list of facts).
    """
    classes = row_classes or {}
    head = ""
    if headers:
        head = "<thead><tr>" + "".join(f"<th>{esc(header)}</th>" for header in headers) + "</tr></thead>\n"
    body = []
    for index, row in enumerate(rows):
        cells = "".join(
            f'<td class="num">{esc(cell)}</td>' if column in numeric else f"<td>{esc(cell)}</td>"
            for column, cell in enumerate(row)
        )
        css = f' class="{esc(classes[index])}"' if index in classes else ""
        body.append(f"<tr{css}>{cells}</tr>")
    return f"<table>\n{head}<tbody>\n" + "\n".join(body) + "\n</tbody>\n</table>"


def section(title: str, *parts: str) -> str:
    return f"<section>\n<h2>{esc(title)}</h2>\n" + "\n".join(parts) + "\n</section>"


def paragraph(text: str, css_class: str = "") -> str:
    css = f' class="{css_class}"' if css_class else ""
    return f"<p{css}>{esc(text)}</p>"


def bullet_list(items: Iterable[str], ordered: bool = False) -> str:
    tag = "ol" if ordered else "ul"
    return f"<{tag}>" + "".join(f"<li>{esc(item)}</li>" for item in items) + f"</{tag}>"


def figure_html(figure: Figure, caption: str, number: int) -> str:
    """``figure`` as an inline PNG (data URI) with its caption, numbered "Figure ``number``"."""
    encoded = base64.b64encode(png_bytes(figure, EMBED_DPI)).decode("ascii")
    caption = f"Figure {number}: {caption}"
    return (
        f'<figure><img src="data:image/png;base64,{encoded}" alt="{esc(caption)}">'
        f"<figcaption>{esc(caption)}</figcaption></figure>"
    )


def figures_html(figures: Mapping[str, Figure], numbers: Iterator[int], captions: Mapping[str, str]) -> str:
    """The figures in order, numbered on from ``numbers`` (one count for the whole report)."""
    return "\n".join(figure_html(figure, captions.get(name, name), next(numbers)) for name, figure in figures.items())


def check_page_target(target: Path) -> None:
    """Refuse a folder as a page's file before the page is drawn: the rename would fail only after it was written."""
    if target.is_dir():
        raise IsADirectoryError(errno.EISDIR, "a folder; give the report a file name", str(target))


def write_page(target: Path, text: str) -> Path:
    """Write an HTML page atomically (its folder made if needed); return ``target``."""
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_abandoned_writes(target.parent)
    write_text_atomically(target, text)
    return target
