# hybridgen: `make demo` sets everything up and runs the quickstart; `make test` sets up and runs the tests.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.hybridgen-installed
PIP    := $(BIN)/python -m pip --disable-pip-version-check

.PHONY: setup system demo test bench clean

setup: system $(STAMP)

system:
	@bash tools/install_system_deps.sh

$(BIN)/python:
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "hybridgen needs Python >= 3.11"'
	$(PYTHON) -m venv $(VENV)

# Reinstall whenever the project's dependency list changes.
$(STAMP): pyproject.toml | $(BIN)/python
	$(PIP) install -q --upgrade pip
	$(PIP) install -q -e '.[test]'
	@touch $(STAMP)

demo: setup
	$(BIN)/hybridgen run configs/quickstart.yaml output/quickstart
	$(BIN)/hybridgen vis output/quickstart/data.hdf5 --save output/quickstart/preview
	@echo "preview images: output/quickstart/preview/"

test: setup
	@bash tools/install_system_deps.sh --test
	$(BIN)/python -m pytest -q

bench: setup
	$(PIP) install -q -e '.[bench]'
	$(BIN)/python tools/bench_labels.py
	$(BIN)/python tools/bench_color.py

clean:
	rm -rf output .pytest_cache
