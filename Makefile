# The two commands of the README: `make run` (the main job) and `make test` (the whole suite:
# ruff, mypy, pytest). Both create or reuse a local virtual environment in .venv with gaitopt
# (editable) and its test tools installed from PyPI; it is rebuilt when pyproject.toml changes.
# Needs only Python >= 3.11 with pip (and gcc for the generated C code). Use another Python
# with `make PYTHON=python3.12 test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
PYTEST_ARGS ?=

# BLAS on one thread in tests (tests/conftest.py says why).
SINGLE_THREAD := OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
# The OpenBLAS kernels `make test-kernels` runs the suite under: other CPUs' arithmetic.
KERNELS ?= Nehalem SkylakeX Prescott

# pytest exits 5 when it collects no test (e.g. a marker selects none): say so, don't fail.
define run_pytest
	$(SINGLE_THREAD) $(BIN)/python -m pytest $(1) $(PYTEST_ARGS); status=$$?; \
	if [ $$status -eq 5 ]; then echo 'pytest: no tests collected for: $(1)'; exit 0; fi; \
	exit $$status
endef

.PHONY: run costs walk-run test test-suite test-slow test-kernels lint docs bench clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' || { \
	  echo "gaitopt needs Python >= 3.11; '$(PYTHON)' is older: make PYTHON=python3.11 ..."; \
	  exit 1; }
	@# Without the venv module's pip (Debian's python3-venv missing), bootstrap pip from the
	@# interpreter's own pip.
	$(PYTHON) -m venv $(VENV) || { $(PYTHON) -m venv --clear --without-pip $(VENV) && \
	  $(PYTHON) -m pip --python $(BIN)/python install --quiet pip; }
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/gaitopt study -o out/study

# The cost study (docs/costs.md): a few minutes, so not part of `make run`.
costs: $(STAMP)
	$(BIN)/gaitopt study --costs -o out/costs

# The walk-run study (docs/running.md): the walks and runs of the five-link, seven-link and
# adult-point-feet bipeds at each speed under the paper's and the metabolic cost, and the
# walk-run transition (about 20 minutes on 2 cores).
walk-run: $(STAMP)
	$(BIN)/gaitopt study --walk-run -o out/walk-run

lint: $(STAMP)
	$(BIN)/ruff check
	$(BIN)/mypy

test: lint test-suite

# The suite under other CPUs' OpenBLAS kernels, one after the other: a test that depends on
# the last bits of a solver's output fails here (docs/testing.md). Run it before a release.
test-kernels: $(STAMP)
	@for k in $(KERNELS); do \
	  echo "== OPENBLAS_CORETYPE=$$k"; \
	  OPENBLAS_CORETYPE=$$k $(MAKE) --no-print-directory test-suite || exit 1; \
	done

test-suite: $(STAMP)
	$(call run_pytest,-n 2 -m "not slow")

test-slow: $(STAMP)
	$(call run_pytest,-n 2 -m slow)

# The documentation site (docs/index.md; the API and CLI reference generated from the code)
# into docs/_build/html; any Sphinx warning fails the build. CI runs it after `make test`.
docs: $(STAMP)
	$(BIN)/sphinx-build -W --keep-going -b html docs docs/_build/html

bench: $(STAMP)
	$(BIN)/python bench/dynamics.py

clean:
	rm -rf $(VENV) build docs/_build .pytest_cache .mypy_cache .ruff_cache .hypothesis
