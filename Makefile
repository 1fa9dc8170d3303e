# The two README commands: `make run` and `make test`. Both create .venv on first use.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: run test test-slow bench docs clean pysph

$(STAMP): setup.py pyproject.toml $(wildcard sphgen/nnps/*.pyx) $(wildcard sphgen/nnps/*.h)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e .
	touch $(STAMP)

run: $(STAMP)
	$(VENV)/bin/sphgen run taylor_green --nx 50 --re 100 --tf 0.5 -d outputs/taylor_green --overwrite

# two test processes, a test file per process (module-scoped scenes are built once); most
# of a cold run is compiling generated modules, which this halves on two cores
test: $(STAMP)
	$(PY) -m pytest -q -n 2 --dist loadfile

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

bench: $(STAMP)
	$(PY) benchmarks/bench_taylor_green.py

# PySPH 1.0b2 in its own venv, for the benchmarks' same-case comparisons (not a dependency)
pysph:
	$(PYTHON) -m venv .pysph-venv
	.pysph-venv/bin/pip install --quiet pysph "numpy<2.4"

docs: $(STAMP)
	$(PY) -m pip install --quiet sphinx
	$(VENV)/bin/sphinx-build -q -b html docs docs/_build/html

clean:
	rm -rf $(VENV) build *.egg-info outputs
