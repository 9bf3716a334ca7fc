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
	@$(BUILD)/plugin/bench_physics --levels 3,4,5 --default 4 --frames 6 --repeats 2 --out build/bench/physics.json
	@$(PY) -m softdeca_train bench --ict "$(SOFTDECA_ICT)" --out build/bench

lint: setup
	@$(VENV)/bin/ruff check training tests/python && $(VENV)/bin/ruff format --check training tests/python

clean:
	rm -rf build $(OUT)
