# Two commands on a fresh machine: `make run` and `make test`. `make docs` builds the documentation site,
# `make notebook` opens the example notebook in JupyterLab.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
NOTEBOOK_STAMP := $(VENV)/.installed-notebook
OUT ?= results/default

.PHONY: install run test test-fast bench docs notebook clean

install: $(STAMP)

# Reinstall only when the package metadata changes; the package itself is installed editable, with the extras
# the test suite needs: test, and docs (tests/test_docs.py builds the site).
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test,docs]"
	touch $(STAMP)

# JupyterLab only for `make notebook`: the suite runs the notebook without a front-end.
$(NOTEBOOK_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[notebook]"
	touch $(NOTEBOOK_STAMP)

run: install
	$(BIN)/shakermill run --overwrite --out $(OUT)

# First the formatter and the linter (ruff, pyproject.toml), then the static type check of the engine contract
# (mypy), then pytest. The report's browser test needs Chromium. scripts/ensure-browser installs it only when asked (BROWSER=1, as CI
# does; apt-get with --no-upgrade), so that a plain `make test` changes nothing outside this folder; otherwise, or
# when it cannot, it prints why and the test skips with that reason. One worker per core (pytest-xdist, at most 4):
# the suite is mostly engine runs on one thread each.
BROWSER ?=
test: install
	$(BIN)/ruff format --check --quiet .
	$(BIN)/ruff check --quiet .
	$(BIN)/mypy
	@reason="$$(BROWSER=$(BROWSER) scripts/ensure-browser)"; SHAKERMILL_BROWSER_UNAVAILABLE="$$reason" $(BIN)/python -m pytest -n auto --maxprocesses 4

# The unit tests alone: every test not marked slow (pyproject.toml), in under a minute.
test-fast: install
	$(BIN)/python -m pytest -m "not slow"

bench: install
	$(BIN)/python benchmarks/bench_full_run.py
	$(BIN)/python benchmarks/bench_averaged.py
	$(BIN)/python benchmarks/bench_sweep.py
	$(BIN)/python benchmarks/bench_startup.py

# The documentation site (mkdocs.yml) into site/; any warning fails the build. Open site/index.html.
docs: install
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict
	@echo "Open site/index.html"

# Opens examples/quickstart.ipynb in JupyterLab (Ctrl-C twice to stop it). Without a display (Linux, no DISPLAY
# or WAYLAND_DISPLAY) it adds --no-browser and says to open the printed URL; as root it adds --allow-root.
notebook: $(NOTEBOOK_STAMP)
	@flags=""; [ "$$(id -u)" = 0 ] && flags="--allow-root"; \
	if [ "$$(uname)" = Linux ] && [ -z "$$DISPLAY$$WAYLAND_DISPLAY" ]; then flags="$$flags --no-browser"; \
	  echo "No display: open the URL printed below (with its token) in a browser; from another machine run"; \
	  echo "ssh -L 8888:localhost:8888 THIS-HOST there first. (By hand: $(BIN)/jupyter lab --no-browser examples/quickstart.ipynb)"; fi; \
	set -x; $(BIN)/jupyter lab $$flags examples/quickstart.ipynb

clean:
	rm -rf $(VENV) results site
