# SoftDECA: top-level commands. `make demo` and `make test` are all a new machine needs;
# both run `make setup` first, which installs what is missing and is a no-op afterwards.
SHELL := /bin/bash
.DEFAULT_GOAL := help

ICT       ?= ../shared/ict-facekit
OUT       ?= out
JOBS      ?= $(shell nproc)
VENV      := .venv
PY        := $(VENV)/bin/python
BUILD     := build/release
ASAN      := build/asan
ORT_ROOT  := $(CURDIR)/.deps/onnxruntime
# training/ first: the shared .venv may hold an editable install of another checkout.
export PYTHONPATH := $(CURDIR)/$(BUILD)/python:$(CURDIR)/training
export SOFTDECA_ICT := $(abspath $(ICT))
export SOFTDECA_CACHE := $(CURDIR)/.cache
export VTK_DEFAULT_OPENGL_WINDOW := vtkEGLRenderWindow

.PHONY: help setup build build-asan test test-native test-python demo bench lint clean

help:
	@echo "make demo    render the template, its layers, sampled identities, landmarks -> $(OUT)/demo"
	@echo "make test    run every test (ctest release + ASan/UBSan, pytest)"
	@echo "make bench   run the benchmarks -> build/bench/<area>.json"
	@echo "make setup   install what is missing (apt, .venv, ONNX Runtime root); idempotent"
	@echo "variables:   ICT=<ICT-FaceKit checkout or archive folder> (default $(ICT)), OUT=$(OUT)"

setup:
	@.ci/setup

build: setup
	@mkdir -p build; cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DONNXRUNTIME_ROOT=$(ORT_ROOT) \
	  -DPython_EXECUTABLE=$(CURDIR)/$(PY) > $(BUILD).configure.log 2>&1 || { cat $(BUILD).configure.log; exit 1; }
	@cmake --build $(BUILD) -j $(JOBS)

build-asan: setup
	@mkdir -p build; cmake -S . -B $(ASAN) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSOFTDECA_SANITIZE=ON \
	  -DONNXRUNTIME_ROOT=$(ORT_ROOT) > $(ASAN).configure.log 2>&1 || { cat $(ASAN).configure.log; exit 1; }
	@cmake --build $(ASAN) -j $(JOBS)

test-native: build build-asan
	@echo "== native tests (release)";  ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)
	@echo "== native tests (ASan+UBSan)"; ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --test-dir $(ASAN) --output-on-failure -j $(JOBS)

test-python: build
	@echo "== Python tests"; $(PY) -m pytest -q tests/python

test: lint test-native test-python

demo: build
	@$(PY) -m softdeca_train demo --ict "$(SOFTDECA_ICT)" --out $(OUT)/demo

bench: build
	@mkdir -p build/bench
	@$(PY) -m softdeca_train bench --ict "$(SOFTDECA_ICT)" --out build/bench

lint: setup
	@$(VENV)/bin/ruff check training tests/python && $(VENV)/bin/ruff format --check training tests/python

clean:
	rm -rf build $(OUT)

# ---- Runtime (issue 6) -----------------------------------------------------------------------
# `make bench` also measures the native runtime (build/bench/runtime.json). `make replay-demo`
# replays a real take through both models with an UNTRAINED random bundle (the replay path that
# `make demo` will use once trained bundles exist) and prints where the results are.
REPLAY_TAKE ?= ../shared/recordings/livelinkface-alexdjulin/S07-001.csv
REPLAY_BUNDLE ?= build/bundles/random-untrained
.PHONY: bench-runtime replay-demo
bench: bench-runtime
bench-runtime: build
	@mkdir -p build/bench
	@$(PY) -m softdeca_train runtime-bench --ict "$(SOFTDECA_ICT)" --out build/bench

replay-demo: build
	@$(PY) -m softdeca_train runtime-bundle --ict "$(SOFTDECA_ICT)" --out $(REPLAY_BUNDLE)
	@SOFTDECA_PYTHON=$(CURDIR)/$(PY) $(BUILD)/plugin/cli/softdeca replay $(REPLAY_TAKE) \
	  --bundle $(REPLAY_BUNDLE) --seed 1 --out $(OUT)/replay --dynamics --preview \
	  --localised "w_skin_strain=100@0.05,-0.015,0.085,0.03"
	@echo "replay (UNTRAINED bundle): $(OUT)/replay/preview.png, $(OUT)/replay/*.pc2 over $(OUT)/replay/neutral.obj, $(OUT)/replay/replay.json"
