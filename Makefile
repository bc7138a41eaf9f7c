# rockyade: `make test` and `make run` each set up what they need (idempotent).
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
WORKERS ?= 2
OUT ?= reports/paper

.PHONY: setup system compiled test lint check run bench bench-all clean

# Python keeps its bytecode (__pycache__) even where the environment says otherwise: the suite
# starts hundreds of Pythons, and each would otherwise compile rockyade's modules again, and
# pytest rewrite every test module's asserts again in each worker.
unexport PYTHONDONTWRITEBYTECODE

setup: system $(STAMP) compiled

system:
	@tools/install-system-deps.sh

# The packages go in with uv (installed into the environment by its own pip first): it resolves
# and unpacks in parallel where pip works one wheel at a time (measured here, warm caches, loaded
# machine: pip 15.7 s against uv 6.2 s for the same versions), and it upgrades the environment's
# pip on the way (tests/test_wheel.py builds the wheel with it). uv reads no pip configuration
# (pip.conf, PIP_INDEX_URL): where it cannot install, pip does, as before. Its temporary folder is
# one in the environment, removed after (uv leaves an empty lock file there for each build of the
# package, which would pile up in /tmp). Then compileall on every core:
# the packages' bytecode, less their own test suites (no run imports them; Python would compile
# such a file when imported); a file compileall cannot compile is left to Python too, hence `|| true`
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -qq --root-user-action=ignore --disable-pip-version-check uv
	mkdir -p $(VENV)/tmp
	TMPDIR=$(abspath $(VENV))/tmp $(BIN)/uv pip install -q --python $(BIN)/python --upgrade-package pip pip -e '.[dev]' \
	  || $(BIN)/python -m pip install -qq --root-user-action=ignore --upgrade --no-compile pip -e '.[dev]'
	rm -rf $(VENV)/tmp
	$(BIN)/python -m compileall -q -j 0 -x '/(tests?|testing)/' $(VENV)/lib > /dev/null || true
	@touch $(STAMP)

# the solvers' numba code compiled into numba's cache once, here, so that no run and no test
# worker waits on it; every make looks (a second or two), as a change of a kernel's file stales it
compiled: $(STAMP)
	@$(BIN)/python -m rockyade.solvers.compile_cache --quiet --workers $(WORKERS)

# lint needs the tools, not the compiled solvers: `make test` runs it beside the compilation, at a
# lower priority (LINT_PRIORITY), so that the longest compilation (the reference DEM's general
# loop, most of a minute of CPU in one process) keeps a core and the lint takes what is left
LINT_PRIORITY ?=
lint: system $(STAMP)
	$(LINT_PRIORITY) $(BIN)/ruff check .
	$(LINT_PRIORITY) $(BIN)/ruff format --check .
	$(LINT_PRIORITY) $(BIN)/lint-imports
	$(LINT_PRIORITY) $(BIN)/mypy rockyade

# One thread per library in each test worker: pytest runs one worker per core already, and
# OpenBLAS's threads, waiting for work on a machine whose cores are all busy, cost CPU (on a
# part of the suite, measured on 2 cores: 6 % of its CPU); numba's threads are the tests' own
# (NUMBA_NUM_THREADS is left alone)
SINGLE_THREADED := OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1

# the inner loop: lint, then every test not marked slow, yade or siconos (pyproject's markers), in parallel
check: setup lint
	$(SINGLE_THREADED) $(BIN)/python -m pytest -n $(WORKERS) -q -m "not slow and not yade and not siconos"

# the compilation (one process per core) and lint side by side, then the suite
test: system $(STAMP)
	@$(MAKE) --no-print-directory -j $(WORKERS) --output-sync=target compiled lint LINT_PRIORITY='nice -n 10'
	$(SINGLE_THREADED) ROCKYADE_REQUIRE_YADE=1 ROCKYADE_REQUIRE_SICONOS=1 ROCKYADE_REQUIRE_CHROMIUM=1 $(BIN)/python -m pytest -n $(WORKERS) --durations=15

run: setup
	$(BIN)/rockyade paper --out $(OUT) --workers $(WORKERS)
	$(BIN)/rockyade verify --out reports/verify

bench: setup  # the targets of "Studies at scale", today's figures and the ratios
	$(BIN)/python benchmarks/bench_targets.py

bench-all: setup
	$(BIN)/python benchmarks/run_all.py

clean:
	rm -rf $(VENV) reports .pytest_cache .ruff_cache
