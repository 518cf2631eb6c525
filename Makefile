# Two commands set up a fresh machine (Python 3.11, make): `make build` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
PARAMS ?= swiftfin.toml
OUT ?= build

.PHONY: build test test-fast bench clean clean-cache

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e ".[test]"
	touch $(STAMP)

build: $(STAMP)
	$(BIN)/swiftfin build $(PARAMS) --out $(OUT)

# The suite on one worker per core (at most 4: each builds the session's shared parts), a test file per worker
# so a file's fixtures are built once; `make test PYTEST_ARGS=-n0` runs it in one process.
PYTEST_ARGS ?= -n auto --maxprocesses 4 --dist loadfile
test: $(STAMP)
	$(BIN)/python -m pytest $(PYTEST_ARGS)

test-fast: $(STAMP)
	$(BIN)/python -m pytest $(PYTEST_ARGS) -m "not slow"

bench: $(STAMP)
	$(BIN)/python bench/run_all.py

clean:
	rm -rf $(OUT) .pytest_cache

clean-cache:
	rm -rf .cache/swiftfin
