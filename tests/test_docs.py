"""The documentation site (mkdocs.yml, docs/): it builds with warnings as errors, and what it says comes from its
sources (the docstrings, docs/MODEL.md, benchmarks/README.md, docs/figures) and agrees with the code."""

from __future__ import annotations

import ast
import html
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from shakermill.parameters.groups import GROUPS

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
# Paths the pages name in backticks, relative to the repository root.
REPOSITORY_PATH = re.compile(r"`((?:src|docs|benchmarks|examples|tests|scripts)/[^`\s]+)`")


def pages() -> list[Path]:
    """Every page written for the site; docs/MODEL.md is the shared specification, kept as it is, and docs/generated
    what a build of the examples wrote."""
    return sorted(
        path for path in DOCS.rglob("*.md") if path.name != "MODEL.md" and DOCS / "generated" not in path.parents
    )


def page_text(site: Path, page: str) -> str:
    """The text of a built page, tags dropped and white space collapsed."""
    text = html.unescape(re.sub(r"<[^>]+>", " ", (site / page).read_text(encoding="utf-8")))
    return " ".join(text.split())


def docstring_of(module: str, function: str) -> str:
    """The docstring of ``function`` in ``module`` (a path under src/), read without importing the package."""
    tree = ast.parse((ROOT / "src" / module).read_text(encoding="utf-8"))
    node = next(node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == function)
    return ast.get_docstring(node)


def test_the_paths_the_readme_and_the_pages_name_exist():
    for path in [ROOT / "README.md", *pages()]:
        for named in REPOSITORY_PATH.findall(path.read_text(encoding="utf-8")):
            if not re.search(r"[<*{]", named):
                assert (ROOT / named.rstrip(".,:;")).exists(), f"{path.relative_to(ROOT)} names {named}"


def test_every_figure_is_in_the_gallery():
    gallery = (DOCS / "gallery.md").read_text(encoding="utf-8")
    figures = [path for path in (DOCS / "figures").rglob("*") if path.suffix in {".png", ".gif", ".svg"}]
    assert figures
    for figure in figures:
        assert f"]({figure.relative_to(DOCS).as_posix()})" in gallery, figure


def test_the_documented_unit_warning_is_the_one_the_code_prints():
    from shakermill.parameters.guards import PLAUSIBLE_RANGES

    omega = PLAUSIBLE_RANGES["omega"]
    shown = f"({omega.low:g} to {omega.high:g} rad/s)"
    assert shown in (DOCS / "guide" / "configuration.md").read_text(encoding="utf-8")
    assert shown in (DOCS / "guide" / "troubleshooting.md").read_text(encoding="utf-8")


@pytest.mark.slow
def test_the_site_builds_strictly_from_its_sources(tmp_path):
    if importlib.util.find_spec("mkdocs") is None:
        pytest.fail(
            f"mkdocs is not installed in {sys.prefix}: `make test` and `make docs` install it "
            "(the docs extra: pip install -e '.[docs]')"
        )
    site = tmp_path / "site"
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "mkdocs",
            "build",
            "--strict",
            "--config-file",
            str(ROOT / "mkdocs.yml"),
            "--site-dir",
            str(site),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )
    assert completed.returncode == 0, completed.stderr[-4000:]
    assert "WARNING" not in completed.stderr, completed.stderr[-4000:]

    # The API reference is generated from the docstrings.
    simulate = docstring_of("shakermill/solvers/simulate.py", "simulate").replace("``", "")
    assert simulate.split("(")[0].strip() in page_text(site, "api.html")
    # The theory is docs/MODEL.md as it is, section 13 included.
    model = (DOCS / "MODEL.md").read_text(encoding="utf-8")
    section_13 = next(line for line in model.splitlines() if line.startswith("## 13."))
    assert section_13.removeprefix("## ") in page_text(site, "MODEL.html")
    # The keys page holds every key under its component's heading, generated from the key groups.
    keys_page = page_text(site, "guide/commands/keys.html")
    for group in GROUPS:
        assert group.title[1:] in keys_page, group
        for key in group.keys():
            assert f" {key} " in keys_page, key
    # The benchmarks page includes benchmarks/README.md, to its last section.
    benchmarks = page_text(site, "benchmarks.html")
    headings = [
        line
        for line in (ROOT / "benchmarks" / "README.md").read_text(encoding="utf-8").splitlines()
        if line.startswith("## ")
    ]
    assert len(headings) > 5
    for heading in headings:
        assert heading.removeprefix("## ").replace("`", "") in benchmarks, heading
    # The examples ran at the build: their pages hold what the scripts printed and drew, with no traceback.
    for example in ("plot_first_run", "plot_planetary"):
        page = page_text(site, f"generated/gallery/{example}.html")
        assert "<shakermill.Result: engine" in page and "success" in page and "Traceback" not in page, example
        assert (site / "generated" / "gallery" / "images" / f"mkd_glr_{example}_001.png").stat().st_size > 10_000
    # The gallery's images are copied beside it, and the site opens from the disk.
    assert (site / "figures" / "temperatures.png").is_file() and (
        site / "figures" / "dem" / "trajectories.gif"
    ).is_file()
    assert 'href="guide/install.html"' in (site / "index.html").read_text(encoding="utf-8")
