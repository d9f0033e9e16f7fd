# shadowcam: `make demo` runs the default synthetic dataset end to end and builds the
# report; `make test` runs the test suite; `make lint` lints the workflow;
# `make bench-outdoor` reruns the outdoor pipeline on dev_ridge and prints per-stage
# wall time / peak memory and the arrival-time accuracy (ours and the naive baseline).
# Both install the package (editable, with test and SLURM-executor extras) into .venv first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SNAKEMAKE := $(BIN)/snakemake
DATASET ?= synthetic_lab

OUTDOOR ?= dev_ridge

.PHONY: demo test lint install clean bench-outdoor

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

bench-outdoor: $(STAMP)
	rm -rf results/$(OUTDOOR) benchmarks/$(OUTDOOR)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(SNAKEMAKE) --profile profiles/local --cores 1 --config datasets=[$(OUTDOOR)] --quiet
	@echo "stage  wall_s  max_rss_MB  (one core; shared machines are noisy)"
	@for f in benchmarks/$(OUTDOOR)/*.tsv; do printf "%s  " "$$(basename $$f .tsv)"; tail -1 $$f | cut -f1,3; done
	@$(BIN)/python -c "import json; r = json.load(open('results/$(OUTDOOR)/outdoor/accuracy.json')); \
	[print(f\"{e:18s} {d:14s} median {s['median_abs']:.3f} p95 {s['p95_abs']:.3f} >5 {100*s['frac_over_5']:.2f}% \
	within1 {100*s['frac_within_1']:.1f}% coverage {100*s['coverage']:.2f}%\") for e, by in r['errors'].items() for d, s in by.items()]; \
	print('targets (' + r['condition'] + '):', 'met' if r['all_targets_pass'] else 'NOT met')"

lint: $(STAMP)
	$(SNAKEMAKE) --lint

clean:
	rm -rf results logs benchmarks .snakemake
