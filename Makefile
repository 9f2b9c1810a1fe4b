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

REPORT_ARGS ?=
PYTEST_ARGS ?=

.PHONY: bootstrap report report-quick test lint bench clean-venv

bootstrap:
	@bash .ci/bootstrap

report: bootstrap
	$(PY) -m alte report $(REPORT_ARGS)

report-quick: bootstrap
	$(PY) -m alte report --quick $(REPORT_ARGS)

lint: bootstrap
	$(PY) -m ruff check alte tests bench
	$(PY) -m mypy

# mypy and the compilation of the mappers' numba kernels (`alte warmup`, cached for every
# later process) run side by side on the two cores, then the tests.
test: bootstrap
	$(PY) -m ruff check alte tests bench
	@$(PY) -m alte warmup & warm=$$!; $(PY) -m mypy; typed=$$?; wait $$warm && exit $$typed
	$(PY) -m pytest -n 2 --dist loadfile --no-loadscope-reorder tests notebooks --nbval-lax $(PYTEST_ARGS)

bench: bootstrap
	$(PY) -m alte bench

clean-venv:
	rm -rf $(VENV)
