# SoftDECA: top-level commands. `make demo` and `make test` are all a new machine needs;
# both run `make setup` first, which installs what is missing and is a no-op afterwards.
SHELL := /bin/bash
.DEFAULT_GOAL := help

DATA      ?= .cache/data
ICT       ?= $(DATA)/ict-facekit
TAKES     := $(DATA)/recordings/livelinkface-alexdjulin
OUT       ?= out
JOBS      ?= $(shell nproc)
VENV      := .venv
PY        := $(VENV)/bin/python
BUILD     := build/release
ASAN      := build/asan
ORT_ROOT  := $(CURDIR)/.deps/onnxruntime
# training/ first: the shared .venv may hold an editable install of another checkout.
export PYTHONPATH := $(CURDIR)/$(BUILD)/python:$(CURDIR)/training
export SOFTDECA_DATA := $(abspath $(DATA))
export SOFTDECA_ICT := $(abspath $(ICT))
export SOFTDECA_CACHE := $(CURDIR)/.cache
export VTK_DEFAULT_OPENGL_WINDOW := vtkEGLRenderWindow
# ccache (setup installs it) makes rebuilds and other checkouts of the same tree cheap; the build
# never needs it. Paths under the checkout are hashed relative to it, and the working directory
# is left out of the hash (it only names the debug info's compilation directory), so checkouts
# share hits.
LAUNCHER  := $(if $(shell command -v ccache),-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_NOHASHDIR := 1

.PHONY: help setup build build-asan test test-native test-python demo bench lint clean

# Every target is listed by `make help`: those with a `## description` on their rule line with
# it, any other under "more targets".
help: ## this list
	@echo "usage: make <target> [VARIABLE=value ...]"
	@awk -F':' '/^[a-zA-Z][a-zA-Z0-9_-]*:([^=]|$$)/ { t = $$1; d = ""; \
	    if (match($$0, /## .*/)) d = substr($$0, RSTART + 3); \
	    if (!(t in seen)) { seen[t] = 1; n++; name[n] = t }; if (d != "") desc[t] = d } \
	  END { for (i = 1; i <= n; i++) if (name[i] in desc) printf "  %-14s %s\n", name[i], desc[name[i]]; \
	        more = ""; for (i = 1; i <= n; i++) if (!(name[i] in desc)) more = more " " name[i]; \
	        if (more != "") print "  more targets:" more }' $(MAKEFILE_LIST)
	@echo "variables: DATA=<third-party data folder> (default $(DATA)), ICT=<ICT-FaceKit checkout,"
	@echo "  FaceXModel folder or archive> (default $(ICT)), OUT=$(OUT), BUNDLE=<model bundle folder or"
	@echo "  .tar> (default $(BUNDLE)), JOBS=$(JOBS); SOFTDECA_DATA_MIRROR=<mirror folder> (THIRD_PARTY.md)"

setup: ## install what is missing (apt, .venv, ONNX Runtime root, third-party data); idempotent
	@.ci/setup

build: setup ## release build in build/release
	@mkdir -p build; cmake -S . -B $(BUILD) -G Ninja $(LAUNCHER) -DCMAKE_BUILD_TYPE=Release -DONNXRUNTIME_ROOT=$(ORT_ROOT) \
	  -DPython_EXECUTABLE=$(CURDIR)/$(PY) > $(BUILD).configure.log 2>&1 || { cat $(BUILD).configure.log; exit 1; }
	@cmake --build $(BUILD) -j $(JOBS)

build-asan: setup ## ASan+UBSan build in build/asan
	@mkdir -p build; cmake -S . -B $(ASAN) -G Ninja $(LAUNCHER) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSOFTDECA_SANITIZE=ON \
	  -DONNXRUNTIME_ROOT=$(ORT_ROOT) > $(ASAN).configure.log 2>&1 || { cat $(ASAN).configure.log; exit 1; }
	@cmake --build $(ASAN) -j $(JOBS)

test-native: build build-asan ## ctest on both builds
	@echo "== native tests (release)";  ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)
	@echo "== native tests (ASan+UBSan)"; ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --test-dir $(ASAN) --output-on-failure -j $(JOBS)

test-python: build ## pytest (the numerical bounds' margins -> build/bounds/native.json)
	@echo "== Python tests"; SOFTDECA_BOUNDS_REPORT=$(CURDIR)/build/bounds/native.json $(PY) -m pytest -q tests/python

test: lint test-native test-fuzz test-python test-kernels test-swift test-unity ## every test: lint, ctest (release, ASan+UBSan), short fuzzing, pytest, other CPUs' kernels, Swift, Unity

# tests/python/test_hostile_avatars.py runs every hostile avatar through `softdeca fit` in
# test-python; the full form also replays each one and adds the FBX zlib bomb (docs/security.md).
.PHONY: test-hostile-full
test-hostile-full: build ## the hostile-avatar suite in full: every attack through fit and replay, and the zlib bomb
	@SOFTDECA_HOSTILE=full $(PY) -m pytest -q tests/python/test_hostile_avatars.py

# ---- Kernel families: the numerics another x86-64 CPU computes -----------------------------
# tests/cpu/run-as.sh caps every numerical library (this one, numpy, OpenBLAS, torch) at one
# kernel family (docs/platforms.md, "Kernel families"). test-kernels runs the native kernel and
# runtime suites and a replay check per precision under avx2 and portable, then the
# numerics-sensitive Python tests under avx2 (what a CPU without AVX-512 computes), reduced to
# those that run in minutes; test-kernels-full runs every Python test so.
KERNEL_PYTESTS := tests/python/test_lhm_eyes.py tests/python/test_lhm_mouth.py tests/python/test_lhm_conforming.py \
                  tests/python/test_sim_native.py tests/python/test_rest_physics.py tests/python/test_runtime_parity.py \
                  tests/python/test_residual_stage.py tests/python/test_linear_baseline.py
KCHECK := build/kernel-check
.PHONY: test-kernels test-kernels-full kernel-check-inputs
kernel-check-inputs: build ## the avatar and take of the kernel families' replay check -> build/kernel-check
	@mkdir -p $(KCHECK)
	@[ -f $(KCHECK)/avatar/neutral.obj ] || $(PY) -m softdeca_train avatar --seed 1 --out $(KCHECK)/avatar > /dev/null
	@[ -f $(KCHECK)/take.sdrec ] || $(BUILD)/plugin/cli/softdeca convert $(CHECK_TAKE) $(KCHECK)/take.sdrec > /dev/null

test-kernels: kernel-check-inputs ## the numerics again on other CPUs' kernel families (avx2, portable)
	@echo "== numerics on other kernel families (tests/cpu/run-as.sh)"
	@tests/cpu/check-kernels.sh $(BUILD) $(KCHECK)/avatar $(KCHECK)/take.sdrec $(CHECK_START)
	@echo "== numerics-sensitive Python tests, kernel family avx2"
	@SOFTDECA_BOUNDS_REPORT=$(CURDIR)/build/bounds/avx2.json tests/cpu/run-as.sh avx2 $(PY) -m pytest -q $(KERNEL_PYTESTS)

test-kernels-full: kernel-check-inputs ## test-kernels with every Python test under avx2
	@tests/cpu/check-kernels.sh $(BUILD) $(KCHECK)/avatar $(KCHECK)/take.sdrec $(CHECK_START)
	@SOFTDECA_BOUNDS_REPORT=$(CURDIR)/build/bounds/avx2-full.json tests/cpu/run-as.sh avx2 $(PY) -m pytest -q tests/python

# The demo's replay: frames DEMO_START.. of a real Live Link Face take through linear
# blendshapes, SoftDECA and SparseSoftDECA on the ICT identity of DEMO_SEED, default parameters,
# plus one localised change (fuller soft tissue, target_volume at the top of its range, in a
# 3 cm ball on the subject's left cheek), shown next to the physics under the same change.
BUNDLE         ?= models/softdeca-default
DEMO_TAKE      ?= $(TAKES)/S07-001.csv
DEMO_SEED      ?= 1
DEMO_START     ?= 360
DEMO_FRAMES    ?= 240
DEMO_LOCALISED ?= target_volume=max@0.05,-0.015,0.085,0.03

.PHONY: demo-bundle
demo-bundle: ## check that BUNDLE exists, else say how to make one
	@[ -f "$(BUNDLE)/manifest.json" ] || [ -f "$(BUNDLE)" ] || { \
	  echo "make demo: no model bundle at '$(BUNDLE)' (a folder with manifest.json, or a .tar; docs/bundle.md)."; \
	  echo "  The trained bundle is made by:  $(PY) -m softdeca_train train-bundle"; \
	  echo "  For an UNTRAINED stand-in:      $(PY) -m softdeca_train runtime-bundle --out build/bundles/random-untrained"; \
	  echo "                                  make demo BUNDLE=build/bundles/random-untrained"; exit 1; }

demo: demo-bundle build ## template, layers, identities, landmarks, then a real take replayed -> out/demo (OUT)
	@$(PY) -m softdeca_train demo --ict "$(SOFTDECA_ICT)" --out $(OUT)/demo
	@$(PY) -m softdeca_train avatar --ict "$(SOFTDECA_ICT)" --seed $(DEMO_SEED) --out $(OUT)/demo/replay/avatar
	@$(BUILD)/plugin/cli/softdeca replay $(DEMO_TAKE) --bundle $(BUNDLE) --avatar $(OUT)/demo/replay/avatar \
	  --start $(DEMO_START) --frames $(DEMO_FRAMES) --dynamics --localised "$(DEMO_LOCALISED)" --out $(OUT)/demo/replay
	@$(PY) -m softdeca_train replay-preview --replay $(OUT)/demo/replay --physics-seed $(DEMO_SEED) --ict "$(SOFTDECA_ICT)"
	@echo "demo replay ($(BUNDLE), identity seed $(DEMO_SEED), $(DEMO_FRAMES) frames of $(notdir $(DEMO_TAKE))):"
	@echo "  mesh sequence: $(OUT)/demo/replay/{linear,softdeca,sparse,softdeca_localised}.pc2 over $(OUT)/demo/replay/neutral.obj"
	@echo "                 (PC2 point caches: Blender Mesh Cache modifier; docs/runtime.md)"
	@echo "  preview:       $(OUT)/demo/replay/preview.png"
	@echo "  timings:       $(OUT)/demo/replay/replay.json"
	@echo "  lip openings:  $(OUT)/demo/replay/preview.json (linear, physics and the models on the shown frames;"
	@echo "                 the localised change's reach in the physics and in SoftDECA)"

bench: build bench-runtime bench-unity bench-stress ## every benchmark -> build/bench/<area>.json (docs/benchmarks.md)
	@mkdir -p build/bench
	@$(BUILD)/plugin/cli/softdeca bench-streaming --out build/bench/streaming.json
	@$(PY) -m softdeca_train runtime-test-data --out build/bench/runtime_test_data > /dev/null
	@rm -rf build/bench/hostile_avatars && $(PY) -m softdeca_train hostile-avatars --out build/bench/hostile_avatars > /dev/null
	@$(BUILD)/plugin/cli/softdeca bench-reliability --out build/bench/reliability.json --bundle build/bench/runtime_test_data/bundle \
	  --import-corpus build/bench/hostile_avatars \
	  --avatar build/bench/runtime_test_data/avatar --avatar-unit 1
	@$(BUILD)/plugin/bench/bench_physics --levels 3,4,5 --default 4 --frames 6 --repeats 2 --out build/bench/physics.json
	@$(PY) -m softdeca_train bench-physics --ict "$(SOFTDECA_ICT)" --out build/bench
	@$(PY) -m softdeca_train bench --ict "$(SOFTDECA_ICT)" --out build/bench
	@$(PY) -m softdeca_train bench-datagen --ict "$(SOFTDECA_ICT)" --out build/bench

lint: setup ## ruff check and format check of the Python code
	@$(VENV)/bin/ruff check training tests/python tests/unity && $(VENV)/bin/ruff format --check training tests/python tests/unity

clean: ## remove build/ and out/ (OUT)
	rm -rf build $(OUT)

# ---- Fuzzing the parsers of outside input -----------------------------------------------------
# libFuzzer targets of the streaming, recording, bundle, fit and avatar-file parsers (tests/fuzz),
# built by clang in build/fuzz.
# test-fuzz: a few seconds each on the committed corpus; fuzz-long: the long runs of
# docs/fuzzing.md, two at a time, niced, new inputs kept in build/fuzz-long/<target>/.
FUZZ         := build/fuzz
FUZZ_TARGETS := fit_file softdeca_packet livelinkface_packet ifacialmocap_packet livelinkface_csv recording_reader \
                bundle_tar bundle_folder manifest onnx_model onnx_graph obj shape_names avatar_folder fbx gltf draco
FUZZ_SECONDS ?= 620

.PHONY: fuzz-build test-fuzz fuzz-long

fuzz-build: setup ## build the libFuzzer targets (clang) in build/fuzz
	@mkdir -p build; CXX=clang++ cmake -S tests/fuzz -B $(FUZZ) -G Ninja $(LAUNCHER) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  > $(FUZZ).configure.log 2>&1 || { cat $(FUZZ).configure.log; exit 1; }
	@cmake --build $(FUZZ) -j $(JOBS)

test-fuzz: fuzz-build ## 3 s of fuzzing per target on the committed corpus
	@echo "== fuzzing (3 s per target on tests/fuzz/corpus)"
	@for t in $(FUZZ_TARGETS); do \
	  tmp=$$(mktemp -d); \
	  $(FUZZ)/fuzz_$$t -max_total_time=3 -rss_limit_mb=2048 -artifact_prefix=$$tmp/ $$tmp tests/fuzz/corpus/$$t \
	    > $$tmp/log 2>&1 || { tail -40 $$tmp/log; echo "fuzz_$$t failed: input in $$tmp"; exit 1; }; \
	  echo "fuzz_$$t: $$(grep -o 'Done [0-9]* runs' $$tmp/log), no crash"; rm -rf $$tmp; \
	done

fuzz-long: fuzz-build ## the long fuzzing runs of docs/fuzzing.md (FUZZ_SECONDS each)
	@mkdir -p build/fuzz-long
	@echo "$(FUZZ_TARGETS)" | tr ' ' '\n' | xargs -P 2 -I{} sh -c 'mkdir -p build/fuzz-long/{}/corpus && \
	  nice -n 10 $(FUZZ)/fuzz_{} -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 -rss_limit_mb=2048 \
	  -artifact_prefix=build/fuzz-long/{}/ build/fuzz-long/{}/corpus tests/fuzz/corpus/{} \
	  > build/fuzz-long/{}.log 2>&1; echo "fuzz_{}: exit $$?, $$(grep -o "Done [0-9]* runs in [0-9]* second(s)" build/fuzz-long/{}.log)"'

# ---- Runtime: benchmark and replay with an untrained bundle ----------------------------------
# `make bench` also measures the native runtime (build/bench/runtime.json). `make replay-demo`
# replays a whole real take through both models with an UNTRAINED random bundle (exported on the
# fly) and prints where the results are; `make demo` replays part of a take with $(BUNDLE).
REPLAY_TAKE ?= $(TAKES)/S07-001.csv
REPLAY_BUNDLE ?= build/bundles/random-untrained
.PHONY: bench-runtime replay-demo
bench-runtime: build ## the native runtime per frame -> build/bench/runtime.json
	@mkdir -p build/bench
	@$(PY) -m softdeca_train runtime-bench --ict "$(SOFTDECA_ICT)" --out build/bench

replay-demo: build ## a whole take through both models with an UNTRAINED bundle -> out/replay
	@$(PY) -m softdeca_train runtime-bundle --ict "$(SOFTDECA_ICT)" --out $(REPLAY_BUNDLE)
	@$(PY) -m softdeca_train avatar --ict "$(SOFTDECA_ICT)" --seed 1 --out $(OUT)/replay/avatar
	@$(BUILD)/plugin/cli/softdeca replay $(REPLAY_TAKE) --bundle $(REPLAY_BUNDLE) --avatar $(OUT)/replay/avatar \
	  --out $(OUT)/replay --dynamics --localised "w_skin_strain=100@0.05,-0.015,0.085,0.03"
	@$(PY) -m softdeca_train replay-preview --replay $(OUT)/replay
	@echo "replay (UNTRAINED bundle): $(OUT)/replay/preview.png, $(OUT)/replay/*.pc2 over $(OUT)/replay/neutral.obj, $(OUT)/replay/replay.json"

# ---- Physics ---------------------------------------------------------------------------------
# `make simulate-demo`: a few frames of a real take through the physics model (LHM level 3):
# point caches, OBJ sequence, side-by-side render and summary in $(OUT)/simulate.
SIMULATE_TAKE ?= $(TAKES)/alex_rom_3.csv
.PHONY: simulate-demo
simulate-demo: build ## a few frames of a real take through the physics model -> out/simulate
	@$(PY) -m softdeca_train simulate $(SIMULATE_TAKE) \
	  --out $(OUT)/simulate --level 3 --start 1300 --frames 6 --stride 100 --obj-every 1

# ---- iOS capture core (Swift package ios_capture/) --------------------------------------------
# `swift test` of the platform-independent core: golden encodings, loopback streams into
# `softdeca receive`, recorder takes through `softdeca replay`/`convert`/`info`. The toolchain
# is /opt/swift or `swift` on PATH; without one the tests are skipped, visibly.
SWIFT ?= $(firstword $(wildcard /opt/swift/usr/bin/swift) $(shell command -v swift 2>/dev/null))
.PHONY: test-swift
test-swift: build ## the iOS capture core: swift test (skipped without a Swift toolchain)
	@if [ -z "$(SWIFT)" ]; then \
	  echo "== Swift tests (ios_capture): SKIPPED, no Swift toolchain (/opt/swift/usr/bin/swift or swift on PATH)"; \
	else \
	  echo "== Swift tests (ios_capture, $$($(SWIFT) --version 2>/dev/null | head -n1))"; \
	  cd ios_capture && nice -n 5 $(SWIFT) build --build-tests -j $(JOBS) && \
	  SOFTDECA_CLI=$(CURDIR)/$(BUILD)/plugin/cli/softdeca SOFTDECA_PYTHON=$(CURDIR)/$(PY) \
	    $(SWIFT) test --skip-build; \
	fi
# ---- Unity package -------------------------------------------------------------------------
# test-unity: the C# core (unity_package/Runtime/Core) compiled by mono and tested with NUnit
# against this build's library (tests/unity/run); the Unity layer compiled against the
# declaration-only reference (tests/unity/compile-check); the package check (metas, GUIDs,
# asmdefs, package.json). bench-unity: the core's managed overhead per frame (build/bench/unity.json).
.PHONY: test-unity bench-unity
test-unity: build ## the Unity package: C# core on mono with NUnit, layer compile check, package check
	@echo "== Unity core (C# on mono, NUnit)"; PY=$(PY) tests/unity/run $(BUILD)
	@echo "== Unity layer and package"; tests/unity/compile-check && $(PY) tests/unity/package.py check
bench-unity: build ## managed call overhead of the C# core per frame -> build/bench/unity.json
	@PY=$(PY) tests/unity/bench $(BUILD)
# ---- Controls gallery (docs/controls.md): LHM level 3, static, 2 unseen identities x 3 expressions
.PHONY: controls
controls: build ## controls gallery: every material control on the physics and the bundle (BUNDLE) -> docs/controls
	@nice -n 5 $(PY) -m softdeca_train controls --bundle $(BUNDLE) --out docs/controls

# ---- Physics stress suite -------------------------------------------------------------------
# `make stress`: extreme expressions / identities / materials / gravity, levels 3 and 4, static
# and dynamic, plus every take in $(RECORDINGS) (every STRESS_TAKE_STRIDE-th frame, 3
# identities), judged by the sanity bounds (docs/physics.md) -> $(OUT)/stress/{stress.json,
# stress.md,stress_worst.png}. `make bench` runs it too and writes build/bench/physics_stress.json.
RECORDINGS         ?= $(DATA)/recordings
STRESS_TAKE_STRIDE ?= 10
.PHONY: stress bench-stress
stress: build ## the physics stress suite judged by the sanity bounds -> out/stress (report, contact sheet)
	@nice -n 5 $(PY) -m softdeca_train stress --ict "$(SOFTDECA_ICT)" --recordings "$(RECORDINGS)" \
	  --take-stride $(STRESS_TAKE_STRIDE) --workers $(JOBS) --out $(OUT)/stress
bench-stress: build ## the stress suite's figures -> build/bench/physics_stress.json
	@nice -n 5 $(PY) -m softdeca_train stress --ict "$(SOFTDECA_ICT)" --recordings "$(RECORDINGS)" \
	  --take-stride $(STRESS_TAKE_STRIDE) --workers $(JOBS) --out build/stress --bench-out build/bench --quiet

# ---- Native binaries per platform and the Unity package tarball (docs/platforms.md) -----------
# Linux x86_64 is build/release. Windows x64 is cross-built here with MinGW-w64 in build/windows;
# the cross compilers, wine and ONNX Runtime's Windows DLL are installed on first use by
# plugin/platforms/windows/setup-cross.sh, not by `make setup`. `make test-windows` runs the
# Windows build's tests under wine; `make test` does not (a second full build of the library), it
# checks the Linux staging of the package's binaries (tests/python/test_unity_binaries.py).
# macOS, iOS and Android: plugin/platforms/<platform>/build.sh, untested here; what they stage
# into UNITY_BINARIES on their machines, `make unity-package` packs too.
WINDOWS        := build/windows
WINDOWS_ORT    := $(CURDIR)/.deps/onnxruntime-win
WINDOWS_TESTS  := test_c_abi test_atomic_write test_stream test_bundle_folder abi_header_check_c abi_header_check_cpp replay_check
# The Windows tests that run under wine: the C ABI, the streaming and recording stack (UDP over
# loopback included), bundle folders (links, sizes, file kinds), the header checks against softdeca.dll, its export table.
WINDOWS_CTEST  := ^(AtomicWrite|BundleFolder|OnnxStaticSizes|CAbi|StreamCAbi|WireFormat|Golden|ArkitNames|IFacialMocap|LiveLinkFace|Rotation|JitterBuffer|NeutralAssembler|SequenceTracker|Interpolation|Player|Recording|Receiver|FrameRule|CsvNumbers|CsvLines)\.|^abi_header_check_|^dll_exports_only_c_abi$$
# The replay check: frames of a real take through models/softdeca-default on the identity of
# seed 1, by the Linux CLI and by the Windows DLL under wine, compared vertex by vertex.
CHECK          := build/platform-check
CHECK_TAKE     ?= $(TAKES)/S07-001.csv
CHECK_START    ?= 360
CHECK_FRAMES   ?= 12
CHECK_TOL      ?= 1e-4
UNITY_BINARIES ?= build/unity-binaries
UNITY_VERSION  := $(shell sed -n 's/.*"version": *"\([^"]*\)".*/\1/p' unity_package/package.json 2>/dev/null)
UNITY_TGZ      := build/unity-package/com.softdeca.facial-animation-$(UNITY_VERSION).tgz
.PHONY: windows test-windows unity-package
# A wine prefix of this checkout's own: another checkout's wine server cannot disturb the tests.
windows test-windows unity-package: export WINEPREFIX := $(CURDIR)/build/wineprefix
windows test-windows unity-package: export WINEDEBUG := -all

windows: setup ## Windows x64 cross-build (MinGW-w64) in build/windows; installs the cross tools on first use
	@plugin/platforms/windows/setup-cross.sh
	@mkdir -p build; cmake -S . -B $(WINDOWS) -G Ninja $(LAUNCHER) -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake \
	  -DCMAKE_BUILD_TYPE=Release -DONNXRUNTIME_ROOT=$(WINDOWS_ORT) -DSOFTDECA_BUILD_PYTHON=OFF \
	  > $(WINDOWS).configure.log 2>&1 || { cat $(WINDOWS).configure.log; exit 1; }
	@cmake --build $(WINDOWS) -j $(JOBS) --target softdeca $(WINDOWS_TESTS)

test-windows: windows build ## the Windows build's C ABI, streaming and replay tests under wine
	@echo "== Windows x64 tests under $$(wine --version)"
	@ctest --test-dir $(WINDOWS) --output-on-failure -j $(JOBS) -R '$(WINDOWS_CTEST)'
	@mkdir -p $(CHECK)
	@[ -f $(CHECK)/avatar/neutral.obj ] || $(PY) -m softdeca_train avatar --seed 1 --out $(CHECK)/avatar
	@$(BUILD)/plugin/cli/softdeca convert $(CHECK_TAKE) $(CHECK)/take.sdrec > /dev/null
	@$(BUILD)/plugin/cli/softdeca replay $(CHECK)/take.sdrec --bundle models/softdeca-default --avatar $(CHECK)/avatar \
	  --models softdeca --start $(CHECK_START) --frames $(CHECK_FRAMES) --out $(CHECK)/linux > $(CHECK)/linux.log
	@echo "== replay check: Linux libsoftdeca.so against the Linux CLI"
	@$(BUILD)/tests/native/replay_check models/softdeca-default $(CHECK)/avatar $(CHECK)/take.sdrec $(CHECK_START) \
	  $(CHECK)/linux/softdeca.pc2 $(CHECK_TOL)
	@echo "== replay check: Windows softdeca.dll (wine) against the Linux CLI"
	@wine $(WINDOWS)/bin/replay_check.exe models/softdeca-default $(CHECK)/avatar $(CHECK)/take.sdrec \
	  $(CHECK_START) $(CHECK)/linux/softdeca.pc2 $(CHECK_TOL)

# Linux arm64 (aarch64) is cross-built here with Debian's aarch64 compilers in build/arm64 and
# tested under qemu-user (plugin/platforms/linux-arm64/setup-cross.sh installs both and ONNX
# Runtime's aarch64 library on first use). `make test-arm64` runs the C ABI, runtime, bundle,
# streaming and recording suites and the kernel suites (NEON, then portable) under emulation, and
# replays real frames through the committed bundle by the arm64 library against the x86-64 CLI
# (tests/platforms/arm64-check.sh); `.ci/run` runs test-arm64-quick, its reduced form.
ARM64          := build/arm64
ARM64_ORT      := $(CURDIR)/.deps/onnxruntime-arm64
ARM64_TESTS    := test_c_abi test_stream test_bundle_folder test_runtime test_runtime_math test_cpu_features test_neon_kernels \
                  abi_header_check_c abi_header_check_cpp replay_check
ARM64_CTEST    := ^(BundleFolder|OnnxStaticSizes|CAbi|StreamCAbi|WireFormat|Golden|ArkitNames|IFacialMocap|LiveLinkFace|Rotation|JitterBuffer|NeutralAssembler|SequenceTracker|Interpolation|Player|Recording|Receiver|FrameRule|CsvNumbers|CsvLines|Runtime|Threads|Worker|HyperTensor|SparseLdlt|DeformationTransfer|CpuFeatures|NeonKernels|Half|Blendshapes|BundleFiles|Dynamics|Json|Normals|Rigid)\.|^abi_header_check_|^shared_library_exports
ARM64_FRAMES   ?= 8
.PHONY: arm64 test-arm64 test-arm64-quick arm64-check-inputs count-arm64

arm64: setup ## Linux arm64 cross-build (aarch64-linux-gnu) in build/arm64; installs the cross tools and qemu on first use
	@plugin/platforms/linux-arm64/setup-cross.sh
	@mkdir -p build; cmake -S . -B $(ARM64) -G Ninja $(LAUNCHER) -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/aarch64-linux-gnu.cmake \
	  -DCMAKE_BUILD_TYPE=Release -DONNXRUNTIME_ROOT=$(ARM64_ORT) -DSOFTDECA_BUILD_PYTHON=OFF \
	  -DSOFTDECA_PYTHON=$(CURDIR)/$(PY) -DSOFTDECA_QEMU_PREFIX=$(CURDIR)/.deps/arm64-qemu-prefix > $(ARM64).configure.log 2>&1 || { cat $(ARM64).configure.log; exit 1; }
	@cmake --build $(ARM64) -j $(JOBS) --target softdeca $(ARM64_TESTS)

arm64-check-inputs: build ## the avatar and take of the arm64 replay check -> build/platform-check
	@mkdir -p $(CHECK)
	@[ -f $(CHECK)/avatar/neutral.obj ] || $(PY) -m softdeca_train avatar --seed 1 --out $(CHECK)/avatar > /dev/null
	@[ -f $(CHECK)/take.sdrec ] || $(BUILD)/plugin/cli/softdeca convert $(CHECK_TAKE) $(CHECK)/take.sdrec > /dev/null

test-arm64: arm64 arm64-check-inputs ## the arm64 build's suites and a replay against x86-64 under qemu (minutes)
	@echo "== Linux arm64 tests under $$(qemu-aarch64 --version | head -n1), -cpu cortex-a76"
	@ctest --test-dir $(ARM64) --output-on-failure -j $(JOBS) -R '$(ARM64_CTEST)'
	@tests/platforms/arm64-check.sh $(BUILD) $(ARM64) $(CHECK)/avatar $(CHECK)/take.sdrec $(CHECK_START) $(ARM64_FRAMES)

# The reduced form builds only the suites it runs (a cold cross-build is most of its time).
test-arm64-quick: ARM64_TESTS := test_c_abi test_runtime_math test_cpu_features test_neon_kernels replay_check
test-arm64-quick: arm64 arm64-check-inputs ## test-arm64 reduced: the C ABI and kernel suites, static replays in float storage
	@ctest --test-dir $(ARM64) --output-on-failure -j $(JOBS) -R '^(CAbi|HyperTensor|SparseLdlt|CpuFeatures|NeonKernels)\.'
	@PRECISIONS=float MODES=static tests/platforms/arm64-check.sh $(BUILD) $(ARM64) $(CHECK)/avatar $(CHECK)/take.sdrec $(CHECK_START) 4

count-arm64: arm64 arm64-check-inputs ## per-frame instruction counts of the arm64 build, NEON and portable (qemu plugin)
	@tests/platforms/arm64-insn-count.sh $(BUILD) $(ARM64) $(CHECK)/avatar $(CHECK)/take.sdrec $(CHECK_START)

unity-package: build windows ## UPM tarball (Add package from tarball) with the Linux and Windows binaries -> build/unity-package/
	@plugin/platforms/stage-unity-binaries.sh linux $(BUILD) $(ORT_ROOT) $(UNITY_BINARIES)
	@plugin/platforms/stage-unity-binaries.sh windows $(WINDOWS) $(WINDOWS_ORT) $(UNITY_BINARIES)
	@$(PY) tests/unity/package.py pack --binaries $(UNITY_BINARIES) --out $(UNITY_TGZ)
	@echo "Unity: Window > Package Manager > + > Add package from tarball... > $(UNITY_TGZ)"
