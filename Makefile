# Two commands on a fresh machine: `make run` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT ?= results/default

.PHONY: install run test test-fast bench clean

install: $(STAMP)

# Reinstall only when the package metadata changes; the package itself is installed editable.
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

run: install
	$(BIN)/shakermill run --overwrite --out $(OUT)

# scripts/ensure-browser installs Chromium for the report's browser test, or prints why it cannot
# (the test then skips with that reason). One worker per core (pytest-xdist, at most 4): the suite is
# mostly engine runs on one thread each.
test: install
	@reason="$$(scripts/ensure-browser)"; SHAKERMILL_BROWSER_UNAVAILABLE="$$reason" $(BIN)/python -m pytest -n auto --maxprocesses 4

# The unit tests alone: every test not marked slow (pyproject.toml), in under a minute.
test-fast: install
	$(BIN)/python -m pytest -m "not slow"

bench: install
	$(BIN)/python benchmarks/bench_full_run.py
	$(BIN)/python benchmarks/bench_averaged.py
	$(BIN)/python benchmarks/bench_sweep.py
	$(BIN)/python benchmarks/bench_startup.py

clean:
	rm -rf $(VENV) results
