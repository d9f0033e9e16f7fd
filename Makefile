# shadowcam: `make demo` runs the default synthetic dataset end to end and builds the
# report; `make test` runs the test suite; `make lint` lints the workflow;
# `make bench` prints the speed benchmark (not part of the tests; ~10 min, renders
# its DNG input once into results/bench/dng and reuses it).
# Both install the package (editable, with test extras) into .venv first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SNAKEMAKE := $(BIN)/snakemake
DATASET ?= synthetic_lab

BENCH_ARGS ?=

.PHONY: demo test lint bench install clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

# Reinstall only when the package metadata changes.
$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(SNAKEMAKE) --profile profiles/local --config datasets=[$(DATASET)]
	PATH="$(CURDIR)/$(BIN):$$PATH" $(SNAKEMAKE) --profile profiles/local --config datasets=[$(DATASET)] --report results/report.html
	@echo
	@echo "Results of $(DATASET):  $(CURDIR)/results/$(DATASET)/"
	@echo "HTML report:           $(CURDIR)/results/report.html"

test: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/pytest -q

bench: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/shadowcam bench --dir results/bench/dng --json results/bench/figures.json $(BENCH_ARGS)

lint: $(STAMP)
	$(SNAKEMAKE) --lint

clean:
	rm -rf results logs benchmarks .snakemake
