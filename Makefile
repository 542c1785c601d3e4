# hybridgen: `make demo` sets everything up and runs the quickstart; `make test` sets up and runs the tests.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.hybridgen-installed
STAMP_TEST := $(VENV)/.hybridgen-test-installed
PIP    := $(BIN)/python -m pip --disable-pip-version-check

.PHONY: setup setup-test system demo test bench mutate clean bpy-venv

# `make demo` needs the core dependencies only; `make test` adds the test extras (pytest, Ray, BlenderProc,
# pycocotools, ... about 1.4 GB).
setup: system $(STAMP)

setup-test: system $(STAMP_TEST)

system:
	@bash tools/install_system_deps.sh

$(BIN)/python:
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "hybridgen needs Python >= 3.11"'
	$(PYTHON) -m venv $(VENV)

# Reinstall whenever the project's dependency list changes.
$(STAMP): pyproject.toml | $(BIN)/python
	$(PIP) install -q --upgrade pip
	$(PIP) install -q -e .
	@touch $(STAMP)

$(STAMP_TEST): pyproject.toml | $(BIN)/python
	$(PIP) install -q --upgrade pip
	$(PIP) install -q -e '.[test]'
	@touch $(STAMP) $(STAMP_TEST)

demo: setup
	$(BIN)/hybridgen run configs/quickstart.yaml output/quickstart
	$(BIN)/hybridgen vis output/quickstart/data.hdf5 --save output/quickstart/preview
	@echo "preview images: output/quickstart/preview/"

test: setup-test
	@bash tools/install_system_deps.sh --test
	$(BIN)/python -m pytest -q

bench: setup
	$(PIP) install -q -e '.[bench]'
	$(BIN)/python tools/bench_labels.py
	$(BIN)/python tools/bench_color.py

# Mutation testing (not part of `make test`: about an hour on 2 cores). cosmic-ray lives in its own venv;
# the tests run in .venv on a scratch copy of the committed tree. Report: tools/mutation/last_run.md.
# MUTATE_ARGS="--packages render io --sample 20" narrows it; see tools/mutation/README.md.
MUTVENV := .venv-mutation
mutate: setup-test
	@test -x $(MUTVENV)/bin/python || $(PYTHON) -m venv $(MUTVENV)
	$(MUTVENV)/bin/python -m pip --disable-pip-version-check install -q -r tools/mutation/requirements.txt
	nice -n 15 $(MUTVENV)/bin/python tools/mutation/run_mutation.py --python $(BIN)/python $(MUTATE_ARGS)

# .blend files (loader.BlendLoader, hybridgen.io.blend_loader) are read by Blender's bpy 4.2 in a venv of its own:
# it needs Python 3.11 and NumPy < 2 (about 1 GB; never a `make test` dependency). HYBRIDGEN_BPY_PYTHON names
# another Python that has bpy. Its color tables also give BlenderProc runs Blender's Filmic view
# (hybridgen/render/filmic_view.py).
BPY_PYTHON ?= python3.11
bpy-venv:
	$(BPY_PYTHON) -m venv .venv-bpy
	.venv-bpy/bin/python -m pip --disable-pip-version-check install -q bpy==4.2.0 'numpy<2'

clean:
	rm -rf output .pytest_cache
