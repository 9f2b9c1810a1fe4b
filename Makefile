# The two commands of the README: `make report` and `make test`. Both bootstrap
# what is missing (.ci/bootstrap: Debian libraries, .venv, pinned packages) first.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
# Headless rendering everywhere make runs things: matplotlib Agg, pyvista/VTK off-screen.
export MPLBACKEND := Agg
export PYVISTA_OFF_SCREEN := true
export ALTE_RENDER := static
export PATH := $(CURDIR)/$(VENV)/bin:$(PATH)
# Every target starts many Python processes (notebook kernels, Dask and pytest workers,
# CLI runs). With PYTHONDONTWRITEBYTECODE set in the caller's environment each of them
# compiled numpy, pandas, matplotlib, alte ... from source again (about 4 of its 6 CPU
# seconds of imports; uv installs no bytecode), so make writes the bytecode caches
# (__pycache__, git-ignored) whatever the caller says.
export PYTHONDONTWRITEBYTECODE :=

REPORT_ARGS ?=
PYTEST_ARGS ?=
# Notebooks executed side by side: chapter 5 (the longest, its grid and sensor study on
# two Dask workers) starts first and the other chapters fill the second core meanwhile.
REPORT_JOBS ?= 2

.PHONY: bootstrap report report-full report-quick test check-full lint docs bench reference mutants clean-venv

bootstrap:
	@bash .ci/bootstrap

report: bootstrap
	$(PY) -m alte report --jobs $(REPORT_JOBS) $(REPORT_ARGS)

# The report with the sensor study over every seed (SENSOR_SEEDS_ALL of
# alte/lab/studies/sensor/report.py: seeds 0-2, its worst-seed columns; about 10 more
# minutes than `make report`).
report-full: bootstrap
	$(PY) -m alte report --jobs $(REPORT_JOBS) --param "SENSOR_SEEDS=[0, 1, 2]" $(REPORT_ARGS)

report-quick: bootstrap
	$(PY) -m alte report --quick --jobs $(REPORT_JOBS) $(REPORT_ARGS)

lint: bootstrap
	$(PY) -m ruff check alte tests bench docs plugins
	$(PY) -m mypy

# Lint, types and the fast tests (.ci/test): ruff; then `alte warmup` (numba's kernels
# compiled into the package cache once, for every later process), mypy and the docs site's
# tests side by side on the two cores; the other tests on two pytest workers as soon as
# the kernels are cached (mypy and the docs tests finishing beside them).
# The long end-to-end checks (marker `full`: the whole quick bench, the 10-million-point
# memory runs, chapters 5 and 6 headless, ...; tests/README.md says which smaller test
# proves each one's parts) run in `make check-full`, which CI runs after `make test`.
PYTEST := $(PY) -m pytest -n 2 --dist loadfile --no-loadscope-reorder tests plugins/alte-elevation/tests notebooks --nbval-lax
test: bootstrap
	@bash .ci/test $(PYTEST_ARGS)

check-full: bootstrap
	@$(PY) -m alte warmup
	$(PYTEST) -m full $(PYTEST_ARGS)

# Rewrite the checked-in reference results (tests/reference) from a fresh quick chapter 5
# run, after a deliberate change; `git diff tests/reference` shows what moved.
reference: bootstrap
	$(PY) -m pytest tests/reference -p no:cacheprovider --update-reference -q

# Mutation testing of the verdict logic and the metrics (tests/README.md): mutmut, one
# module at a time with its own tests (tests/mutation_run.py); results in mutants/<name>/,
# a rerun retests only what changed; MODULES='checks truth' picks modules,
# MUTANTS='alte.lab.studies.analysis.evidence.x__outcome*' narrows them; rm -rf mutants starts afresh.
MUTANTS ?=
MODULES ?=
mutants: bootstrap
	$(PY) tests/mutation_run.py $(MODULES) --max-children 2 $(if $(MUTANTS),--mutants='$(MUTANTS)')
	$(PY) tests/mutation_score.py

# The documentation site (docs/): Sphinx with myst-nb, the tutorials executed on small
# inputs, warnings as errors; open docs/_build/html/index.html. DOCS_ARGS=-E rebuilds all.
# ALTE_DOCS_EXECUTE=cache re-runs only the notebooks whose code changed;
# ALTE_DOCS_TUTORIALS=skip shows the tutorials unexecuted (what make test builds; make
# check-full builds the site with them executed).
DOCS_ARGS ?=
docs: bootstrap
	$(PY) -m sphinx -W --keep-going -b html -j 2 $(DOCS_ARGS) docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

bench: bootstrap
	$(PY) -m alte bench

clean-venv:
	rm -rf $(VENV)
