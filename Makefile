# spindle twin — the two commands a new machine needs are `make run` and `make test`.
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed
export PYVISTA_OFF_SCREEN := true

.PHONY: install run test test-fast bench lint model examples drift-example clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	# torch first and pinned: a bare `torch` would let pip pull the multi-GB CUDA build.
	$(BIN)/pip install --quiet torch==2.13.0
	$(BIN)/pip install --quiet -e ".[dev]"
	touch $(STAMP)

install: $(STAMP)

run: $(STAMP)
	$(BIN)/twin replay --out out/replay

test: $(STAMP)
	$(BIN)/python -m pytest -q

test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

bench: $(STAMP)
	$(BIN)/python -m bench.run --out bench/results.json

lint: $(STAMP)
	$(BIN)/ruff check .

model: $(STAMP)
	$(BIN)/python examples/make_model.py

examples: $(STAMP)
	$(BIN)/python examples/make_runs.py

# data-driven drift model on the bundled real step-test data (examples/real/, MIT)
DRIFT_DATA    := examples/real/train.csv
DRIFT_TARGETS := ch1_um,ch2_um,ch3_um,ch4_um,ch5_um
drift-example: $(STAMP)
	$(BIN)/twin drift select $(DRIFT_DATA) --target $(DRIFT_TARGETS) --out out/drift/sensors.json
	$(BIN)/twin drift fit $(DRIFT_DATA) --target $(DRIFT_TARGETS) --seed 0 --out out/drift/model.safetensors
	$(BIN)/twin drift predict out/drift/model.safetensors $(DRIFT_DATA) --out out/drift/pred.csv
	$(BIN)/twin drift report out/drift/model.safetensors $(DRIFT_DATA) --out out/drift/report

clean:
	rm -rf out bench/*.json .pytest_cache
