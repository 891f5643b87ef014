# spectrinsic: the front door. `make help` lists the targets.
PYTHON   ?= python3.11
VENV     := .venv
BIN      := $(VENV)/bin
PY       := $(BIN)/python -P
DEPS     := $(VENV)/.deps-installed
PKG      := $(VENV)/.pkg-installed
PACKAGES := spectrinsic
# Adding or removing a module changes its folder's mtime: strict editable installs only link
# the files present at install time, so the package is relinked then.
PKG_DIRS := $(shell find $(addprefix $(CURDIR)/,$(PACKAGES)) -type d -not -name __pycache__ 2>/dev/null)
# Optional: OUT, PRESET, DATASET, DATA_DIR (spectral data directory, default ../shared/data if present)
DATA_DIR ?= $(abspath $(firstword $(wildcard ../shared/data)))
export PYTHONSAFEPATH := 1
export SPECTRINSIC_DATA ?= $(DATA_DIR)

.DEFAULT_GOAL := help
.PHONY: help setup test test-torch test-properties test-fast test-unit study study-spectral dataset evaluate bench lint info clean

help: ## list the targets
	@awk 'BEGIN {FS = ":.*## "} /^[a-zA-Z_-]+:.*## / {printf "  make %-15s %s\n", $$1, $$2}' $(MAKEFILE_LIST)

$(DEPS): pyproject.toml constraints.txt scripts/setup-system.sh
	bash scripts/setup-system.sh
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -c constraints.txt -e ".[dev,blender,distributed]" --config-settings editable_mode=strict
	touch $@ $(PKG)

$(PKG): $(DEPS) $(PKG_DIRS)
	$(BIN)/pip install -q --no-deps -e . --config-settings editable_mode=strict
	touch $@

setup: $(PKG) ## create .venv, install the package (strict editable) and the system LLVM

test: $(PKG) ## run the test suite (tiny renders; < 15 min on 2 cores)
	$(PY) -m pytest -n 2 -q --durations=10

# torch is an optional extra: installed only for this step (the CPU build, pinned in the lock).
test-torch: $(PKG) ## install the CPU build of PyTorch, then run the torch adapter tests (CI runs it)
	$(BIN)/pip install -q -c constraints.txt torch
	SPECTRINSIC_REQUIRE_TORCH=1 $(PY) -m pytest -q -p no:xdist -m torch

test-properties: $(PKG) ## the property-based input tests with 2000 examples each (minutes)
	SPECTRINSIC_PROPERTY_EXAMPLES=2000 $(PY) -m pytest -p no:xdist -q tests/test_properties.py tests/scenes/test_mitsuba_properties.py

test-fast: $(PKG) ## the tests not marked slow (no dataset builds or converged renders)
	$(PY) -m pytest -n 2 -q --durations=10 -m "not slow"

test-unit: $(PKG) ## the tests that render nothing (no Mitsuba: spectra, scenes, layers, records, CLI checks); under a minute
	SPECTRINSIC_UNIT_TESTS=1 $(PY) -m pytest -n 2 -q --durations=5 -m "not render and not slow"

study: study-spectral ## all studies: Table 5.2, Table 4.4 and the rendered study (a few minutes)
	$(BIN)/spectrinsic study rendering

study-spectral: $(PKG) ## only the two spectral studies: Table 5.2 and Table 4.4 (seconds)
	$(BIN)/spectrinsic study reconstruction-error
	$(BIN)/spectrinsic study photometric

dataset: $(PKG) ## render the default dataset into OUT (default data/dataset); PRESET=preview|default|paper
	$(BIN)/spectrinsic dataset --out $(or $(OUT),data/dataset) --preset $(or $(PRESET),default)

evaluate: $(PKG) ## run the bundled decomposers on DATASET (default: data/dataset, else a preview set it builds)
	@set -e; dataset="$(DATASET)"; \
	if [ -z "$$dataset" ]; then \
	  dataset=data/dataset; \
	  if [ ! -f "$$dataset/manifest.json" ]; then \
	    dataset=data/preview; \
	    echo "no dataset in data/dataset (make dataset builds it): using the preview set in $$dataset"; \
	    $(BIN)/spectrinsic dataset --out "$$dataset" --preset preview; \
	  fi; \
	fi; \
	$(BIN)/spectrinsic evaluate --dataset "$$dataset" --out results/evaluation

bench: $(PKG) ## benchmarks, written as JSON under results/bench/
	$(PY) -m spectrinsic.bench --out results/bench

lint: $(PKG) ## ruff's rules and formatter check (the package folders and tests/) and mypy; .ci/run runs it before the tests
	$(BIN)/ruff check $(PACKAGES) tests
	$(BIN)/ruff format --check $(PACKAGES) tests
	$(BIN)/mypy -p spectrinsic

info: $(PKG) ## versions, usable Mitsuba variants, data directories
	$(BIN)/spectrinsic info

clean: ## remove the virtual environment and build outputs (not data/ or results/)
	rm -rf $(VENV) build *.egg-info .pytest_cache
