"""MkDocs hooks of the documentation site (mkdocs.yml, `hooks:`).

* The docstrings use Sphinx's cross-reference roles (:func:`~shakermill.solvers.full.simulate_full`), which
  mkdocstrings shows as written: the role is dropped and, for a ``~`` target, the module path too, so the API
  reference reads ``simulate_full``.
* ``<!-- summary-keys -->`` in a page becomes the table of every key of the run summary, with its unit and meaning,
  generated from its schema (``shakermill.solvers.summary``): the guide cannot fall behind the code.
* ``<!-- parameter-keys -->`` becomes the table of every parameter key, component by component, with its unit, allowed
  values, default and the source of that default, generated from the key groups (``shakermill.parameters.groups``).
* Some pages, docs/MODEL.md among them (kept byte-equal to the shared specification, so never edited here), start a
  list right under a paragraph, as GitHub allows; Python-Markdown would run it into the paragraph. A blank line is
  put before such a list when the page is read.
"""

from __future__ import annotations

import re

ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const):<code>(~?)([^<]*)</code>")
LIST_ITEM = re.compile(r"^(?:[-*+]|\d+\.) ")
SUMMARY_KEYS_MARKER = "<!-- summary-keys -->"
PARAMETER_KEYS_MARKER = "<!-- parameter-keys -->"
FENCE = re.compile(r"^\s*(```|~~~)")


def _shown(match: re.Match[str]) -> str:
    target = match.group(2)
    return f"<code>{target.rsplit('.', 1)[-1] if match.group(1) else target}</code>"


def _opens_list_under_paragraph(previous: str, line: str) -> bool:
    return (
        bool(LIST_ITEM.match(line))
        and bool(previous.strip())
        and not (LIST_ITEM.match(previous) or previous[:1].isspace() or previous.startswith(("#", "|", ">", "!!!")))
    )


def summary_keys_table() -> str:
    """Every declared key of the run summary as a Markdown table: key, unit, whether every run has it, meaning."""
    from shakermill.solvers.summary import summary_keys

    rows = [
        f"| `{key.name}` | {key.unit} | {'yes' if key.required else 'no'} | {key.meaning.replace('|', '&#124;')} |"
        for key in summary_keys()
    ]
    return "\n".join(["| key | unit | every run | meaning |", "|---|---|---|---|", *rows])


def _cell(text: str) -> str:
    return text.replace("|", "&#124;")


def parameter_keys_table() -> str:
    """Every parameter key under its component's heading: key, allowed values (SI), default, source, meaning."""
    from shakermill.cli.common import format_value
    from shakermill.parameters.groups import GROUPS
    from shakermill.parameters.keys import allowed_range, field_description, field_source
    from shakermill.parameters.presets import preset_values

    defaults = preset_values("spex8000m")
    parts = []
    for group in GROUPS:
        rows = [
            f"| `{key}` | {_cell(allowed_range(key))} | {_cell(format_value(key, defaults[key]))} | "
            f"{_cell(field_source(key))} | {_cell(field_description(key))} |"
            for key in group.keys()
        ]
        parts += [
            f"### {group.title[:1].upper()}{group.title[1:]}",
            "",
            _cell(" ".join((group.__doc__ or "").split())),
            "",
            "| key | allowed (SI) | default | its source | meaning |",
            "|---|---|---|---|---|",
            *rows,
            "",
        ]
    return "\n".join(parts)


def on_page_markdown(markdown: str, **_: object) -> str:
    if SUMMARY_KEYS_MARKER in markdown:
        markdown = markdown.replace(SUMMARY_KEYS_MARKER, summary_keys_table())
    if PARAMETER_KEYS_MARKER in markdown:
        markdown = markdown.replace(PARAMETER_KEYS_MARKER, parameter_keys_table())
    lines, fenced = [], False
    for line in markdown.split("\n"):
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced and lines and _opens_list_under_paragraph(lines[-1], line):
            lines.append("")
        lines.append(line)
    return "\n".join(lines)


def on_page_content(html: str, **_: object) -> str:
    return ROLE.sub(_shown, html)
