# shadowcam: `make demo` runs the default synthetic dataset end to end and builds the
# report; `make test` runs the test suite; `make lint` lints the workflow (snakemake --lint, snakefmt --check);
# `make bench-outdoor` reruns the outdoor pipeline on dev_ridge and prints per-stage
# wall time / peak memory and the arrival-time accuracy (ours and the naive baseline);
# `make bench-outdoor-size` the same stages at a camera's size (24 MP by default), extrapolated.
# `make bench` prints the speed benchmark: DNG -> shadow-time map against the pipeline's own
# mosaic reader and against rawpy, and CPU ns per pixel-frame of each stage (not part of the
# tests; ~10-15 min per compression, renders its DNG input once into
# results/bench/dng-<compression> and reuses it).
# `make shell` opens a shell inside .venv (`shadowcam`, `snakemake` on PATH; `exit` leaves it);
# `make shell CMD='...'` runs one command in it.
# Every target installs the package (editable, with test and SLURM-executor extras) into .venv first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SNAKEMAKE := $(BIN)/snakemake
# the embedded default: a rendered lab capture and a rendered sunset time-lapse (comma-separated)
DATASET ?= synthetic_lab,synthetic_ridge

OUTDOOR ?= dev_ridge
BENCH_ARGS ?=
# DNG compressions benchmarked: lossless JPEG (what cameras write), none (rawpy's cheapest decode)
BENCH_COMPRESSION ?= ljpeg none
# bench-outdoor-size: the camera's size (COLSxROWS, 24 MP), the columns of the full-height strip
# of it that is rendered at that resolution (the renderer's synthetic.outdoor.window; a whole
# 24 MP frame takes too long to render on 2 shared cores), render samples per pixel side,
# frames (the sweep is run at half, three quarters and all of them: the memory growth is the line
# through the three; the renderer drops 2 frames, which needs >= 10 each), frames per first-pass
# job, scratch dir
BENCH_SIZE ?= 6000x4000
BENCH_STRIP_COLS ?= 128
BENCH_SUPERSAMPLE ?= 1
BENCH_FRAMES ?= 24
# sun elevation at the first and last frame (deg): the whole sunset by default (intervals of
# minutes); a narrow range gives a photographer's cadence (8.0 -> 6.4 with 96 frames: ~5 s)
BENCH_START_ELEVATION ?= 20.0
BENCH_END_ELEVATION ?= 1.5
BENCH_PART ?= 8
BENCH_DIR ?= /tmp/shadowcam-bench-outdoor
# frames per chunk of the decoded store: one 24 MP frame is 288 MB of float32 RGB, and the
# streaming passes hold one chunk, so the default 16 would cost 4.6 GB per job
BENCH_CHUNK ?= 1
# column strips of the edge-tracking pass (outdoor.edge_strips): one job holds all the per-pixel
# state of a 24 MP frame (~600 B per pixel once the descent buffers of track_edges.descent_frames
# frames are full, ~15 GB); each strip job the state of its columns only (6 strips: ~2.5 GB)
BENCH_STRIPS ?= 6

CMD ?=

.PHONY: demo test lint install shell clean bench bench-outdoor bench-outdoor-size

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

# Reinstall only when the package metadata changes.
$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test,slurm]"
	touch $(STAMP)

install: $(STAMP)

shell: $(STAMP)
ifeq ($(strip $(CMD)),)
	@echo "In the shadowcam environment ($(CURDIR)/$(VENV)); 'exit' leaves it."
	@PATH="$(CURDIR)/$(BIN):$$PATH" VIRTUAL_ENV="$(CURDIR)/$(VENV)" $${SHELL:-/bin/sh} -i
else
	@PATH="$(CURDIR)/$(BIN):$$PATH" VIRTUAL_ENV="$(CURDIR)/$(VENV)" /bin/sh -c '$(CMD)'
endif

demo: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(SNAKEMAKE) --profile profiles/local --config datasets=[$(DATASET)]
	PATH="$(CURDIR)/$(BIN):$$PATH" $(SNAKEMAKE) --profile profiles/local --config datasets=[$(DATASET)] --report results/report.html
	@echo
	@for ds in $$(echo $(DATASET) | tr ',' ' '); do echo "Results of $$ds:  $(CURDIR)/results/$$ds/"; done
	@echo "HTML report:  $(CURDIR)/results/report.html"

test: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/pytest -q -n 2 --dist loadfile --durations=15

bench-outdoor: $(STAMP)
	rm -rf results/$(OUTDOOR) benchmarks/$(OUTDOOR)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(SNAKEMAKE) --profile profiles/local --cores 1 --config datasets=[$(OUTDOOR)] --quiet
	@echo "stage  wall_s  max_rss_MB  (one core; shared machines are noisy)"
	@for f in benchmarks/$(OUTDOOR)/*.tsv; do printf "%s  " "$$(basename $$f .tsv)"; tail -1 $$f | cut -f1,3; done
	@$(BIN)/python -c "import json; r = json.load(open('results/$(OUTDOOR)/outdoor/accuracy.json')); \
	[print(f\"{e:18s} {d:14s} median {s['median_abs']:.3f} p95 {s['p95_abs']:.3f} >5 {100*s['frac_over_5']:.2f}% \
	within1 {100*s['frac_within_1']:.1f}% coverage {100*s['coverage']:.2f}%\") for e, by in r['errors'].items() for d, s in by.items()]; \
	print('targets (' + r['condition'] + '):', 'met' if r['all_targets_pass'] else 'NOT met')"

bench: $(STAMP)
	for c in $(BENCH_COMPRESSION); do \
	  PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/shadowcam bench --compression $$c \
	    --json results/bench/figures-$$c.json $(BENCH_ARGS) || exit 1; \
	done

# The outdoor pipeline at a camera's size: BENCH_FRAMES and BENCH_FRAMES/2 frames of the ridge
# sunset rendered at BENCH_SIZE with the disc sun and the sensor model (every nuisance on, shake
# up to 2 px; 14-bit lossless-JPEG DNG with exact arrival ground truth), a full-height strip of
# BENCH_STRIP_COLS columns of the frame at its true resolution, run in a scratch copy of the
# workflow (2 cores, first pass in parts of BENCH_PART frames, edge tracking in BENCH_STRIPS
# column strips); prints the render time (apart), the arrival accuracy, per stage s/frame,
# frames/s, MP/s, peak RSS (and its growth from the half run), the 1000-frame extrapolation, and
# the scale targets side by side (store / RAW bytes, end-to-end and first pass / decode-only time
# of the same frames timed in this run, peak RSS per job and its 1000 / 100 frames ratio).
bench-outdoor-size: $(STAMP)
	rm -rf $(BENCH_DIR) && mkdir -p $(BENCH_DIR)/data_manifest
	cp -r Snakefile workflow config profiles $(BENCH_DIR)/
	printf 'decode: {chunk_frames: $(BENCH_CHUNK)}\noutdoor: {part_frames: $(BENCH_PART), edge_strips: $(BENCH_STRIPS)}\n' > $(BENCH_DIR)/bench.yaml
	cols=$$(echo $(BENCH_SIZE) | cut -dx -f1); rows=$$(echo $(BENCH_SIZE) | cut -dx -f2); \
	for n in $$(( $(BENCH_FRAMES) / 2 )) $$(( 3 * $(BENCH_FRAMES) / 4 )) $(BENCH_FRAMES); do \
	  printf '%s\n' "name: bench$$n" "kind: outdoor" "description: sunset time-lapse rendered at $(BENCH_SIZE), a full-height strip of $(BENCH_STRIP_COLS) columns, disc sun" \
	    "light: distant" "synthetic: {scene: ridge, seed: 3, height: $$rows, width: $$cols, frames: $$n, format: dng, bit_depth: 14, noise: true, supersample: $(BENCH_SUPERSAMPLE), exposure: 0.6," \
	    "  outdoor: {start_elevation_deg: $(BENCH_START_ELEVATION), end_elevation_deg: $(BENCH_END_ELEVATION), sun_diameter_deg: 0.53, shake_px: 2.0, dng_compression: ljpeg, window: [0, $$(( (cols - $(BENCH_STRIP_COLS)) / 2 )), $$rows, $(BENCH_STRIP_COLS)]}}" \
	    "provenance: rendered by shadowcam render (make bench-outdoor-size)" "licence: CC0-1.0" \
	    > $(BENCH_DIR)/data_manifest/bench$$n.yaml; \
	  (cd $(BENCH_DIR) && PATH="$(CURDIR)/$(BIN):$$PATH" $(CURDIR)/$(SNAKEMAKE) --profile profiles/local --cores 2 \
	    --configfile config/config.yaml bench.yaml --config datasets=[bench$$n] --quiet) || exit 1; \
	  mkdir -p $(BENCH_DIR)/render/bench$$n && mv $(BENCH_DIR)/benchmarks/bench$$n/render.tsv $(BENCH_DIR)/render/bench$$n/; \
	done
	$(BIN)/shadowcam bench-report --benchmarks $(BENCH_DIR)/benchmarks/bench$(BENCH_FRAMES) \
	  --frames $(BENCH_DIR)/results/bench$(BENCH_FRAMES)/frames/timelapse.zarr \
	  --compare $(BENCH_DIR)/benchmarks/bench$$(( $(BENCH_FRAMES) / 2 )) --compare-frames $$(( $(BENCH_FRAMES) / 2 )) \
	  --compare $(BENCH_DIR)/benchmarks/bench$$(( 3 * $(BENCH_FRAMES) / 4 )) --compare-frames $$(( 3 * $(BENCH_FRAMES) / 4 )) \
	  --raw $(BENCH_DIR)/results/bench$(BENCH_FRAMES)/capture/frames \
	  --accuracy $(BENCH_DIR)/results/bench$(BENCH_FRAMES)/outdoor/accuracy.json \
	  --render $(BENCH_DIR)/render/bench$(BENCH_FRAMES)

lint: $(STAMP)
	$(SNAKEMAKE) --lint
	$(BIN)/snakefmt --check Snakefile workflow

clean:
	rm -rf results logs benchmarks .snakemake
