"""The files a clone needs besides the code: the specification, the licence, how to cite, the changes."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
SHARED_MODEL = ROOT.parent / "shared" / "MODEL.md"


def pyproject() -> dict:
    with (ROOT / "pyproject.toml").open("rb") as handle:
        return tomllib.load(handle)


def version() -> str:
    """The version pyproject.toml reads from the package (one place for it, that start-up reads without metadata)."""
    assert "version" in pyproject()["project"]["dynamic"]
    assert pyproject()["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "shakermill.support.version.__version__"}
    text = (ROOT / "src" / "shakermill" / "support" / "version.py").read_text(encoding="utf-8")
    return re.search(r'^__version__ = "([^"]+)"$', text, re.M).group(1)


def test_the_specification_ships_with_the_repository():
    text = (ROOT / "docs" / "MODEL.md").read_text(encoding="utf-8")
    # The sections the code cites by number.
    for heading in ("## 2. Contact", "## 8. Post-processing", "## 9. Defaults", "## 11. Thermal steady state"):
        assert heading in text


def test_the_shipped_specification_is_kept_in_step_with_the_shared_one():
    if not SHARED_MODEL.is_file():
        pytest.skip("no ../shared beside this clone to compare the copy with")
    assert (ROOT / "docs" / "MODEL.md").read_bytes() == SHARED_MODEL.read_bytes()


def test_the_readme_points_at_the_specification_in_the_repository():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "../shared/MODEL.md" not in readme
    for target in re.findall(r"\]\(([^)#]+)\)", readme):
        if not target.startswith("http"):
            assert (ROOT / target).exists(), target


def test_licence_is_the_one_pyproject_declares():
    assert pyproject()["project"]["license"] == "MIT"
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License")


def test_citation_names_the_package_the_model_and_the_experiment():
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert citation["cff-version"] == "1.2.0" and citation["type"] == "software"
    assert citation["version"] == version()
    references = {(entry["authors"][0]["family-names"], entry["year"]) for entry in citation["references"]}
    assert references == {("Son", 2025), ("Takacs", 2006)}
    son = next(entry for entry in citation["references"] if entry["year"] == 2025)
    assert son["doi"] == "10.3390/math13030446"


def test_changelog_has_the_current_version_and_unreleased_changes():
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert "## [Unreleased]" in changelog
    assert f"## [{version()}]" in changelog


def test_the_readme_is_what_a_newcomer_needs_first():
    # Everything else lives in the documentation site (docs/, tests/test_docs.py builds it).
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(readme.splitlines()) <= 200
    for needed in ("make run", "make test", "make docs", "site/index.html", "make notebook", "10 minutes"):
        assert needed in readme, needed
