# shadowcam: `make demo` runs the default synthetic dataset end to end and builds the
# report; `make test` runs the test suite; `make lint` lints the workflow.
# Both install the package (editable, with test and SLURM-executor extras) into .venv first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SNAKEMAKE := $(BIN)/snakemake
DATASET ?= synthetic_lab

.PHONY: demo test lint install clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

# Reinstall only when the package metadata changes.
$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test,slurm]"
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

lint: $(STAMP)
	$(SNAKEMAKE) --lint

clean:
	rm -rf results logs benchmarks .snakemake
