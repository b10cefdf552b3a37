# Quick start: `make demo` (sets up ./.venv, then runs the demo), `make test`.
VENV ?= .venv
BIN := $(VENV)/bin
PYTEST_ARGS ?=

.PHONY: setup demo test test-all lint docs bench lock clean

setup:  ## create ./.venv with everything installed (idempotent; seconds when up to date)
	bash scripts/setup.sh

demo: setup  ## the main job on the embedded defaults
	$(BIN)/ara demo

test: setup  ## the default (fast) test suite; prints its 15 slowest tests
	$(BIN)/pytest -m "not slow and not gpu" --durations=15 $(PYTEST_ARGS)

test-all: setup  ## every test, slow ones included; prints its 15 slowest tests
	$(BIN)/pytest --durations=15 $(PYTEST_ARGS)

lint: setup
	$(BIN)/ruff check ara grammars data eval training coordination tests bench scripts

docs: setup  ## regenerate docs/cli.md from the commands' --help (the tests check it is current)
	$(BIN)/python scripts/cli_reference.py

bench: setup  ## measurements, printed as tables; not part of the tests
	$(BIN)/python bench/spot_bounds.py
	$(BIN)/python bench/coord_planners.py
	$(BIN)/python bench/translate_latency.py
	$(BIN)/python bench/help_request_wordings.py
	$(BIN)/python bench/self_consistency.py

lock: setup  ## write the venv's versions to scripts/constraints.txt (after upgrading and testing)
	{ sed -n '/^#/p' scripts/constraints.txt; $(BIN)/pip freeze --exclude-editable | grep -v '^torch=='; } > scripts/constraints.tmp
	mv scripts/constraints.tmp scripts/constraints.txt

clean:
	rm -rf data/prepared .pytest_cache
