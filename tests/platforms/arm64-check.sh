#!/usr/bin/env bash
# The arm64 build under qemu-user against the x86-64 build (`make test-arm64`; docs/platforms.md):
#   1. the NEON sources compiled by clang for aarch64; the kernel suites of ctest under
#      SOFTDECA_CPU=portable (the NEON ones ran with the rest);
#   2. frames of a real take through the committed bundle, replayed by the x86-64 CLI and by the
#      arm64 library's C ABI (replay_check under qemu), compared vertex by vertex: SoftDECA and
#      SparseSoftDECA, static and dynamic (MODES, default both), per precision (PRECISIONS,
#      default half float int8);
#      then the same through the runtime tests' small bundle, whose DT stage is not zero.
#   usage: tests/platforms/arm64-check.sh X86_BUILD ARM64_BUILD AVATAR_DIR TAKE.sdrec FIRST FRAMES
set -euo pipefail
x86=$1 arm=$2 avatar=$3 take=$4 first=$5 frames=$6
out="$arm/replay-check"
mkdir -p "$out"
qemu=(qemu-aarch64 -cpu cortex-a76 -L .deps/arm64-qemu-prefix)  # plugin/platforms/linux-arm64/setup-cross.sh
suites='^(HyperTensor|SparseLdlt|DeformationTransfer|CpuFeatures|NeonKernels)\.'
# The NEON sources under clang, the compiler of the Android NDK and of Xcode (neither installable
# here), for aarch64 against the cross sysroot: warnings are errors.
echo "== NEON sources under $(clang++ --version | head -n1), --target=aarch64-linux-gnu"
for source in plugin/src/kernels/hypertensor_neon.cpp tests/native/test_neon_kernels.cpp; do
  clang++ --target=aarch64-linux-gnu -std=c++17 -O2 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I plugin/src \
    -I plugin/include -isystem /usr/include/eigen3 -isystem /usr/src/googletest/googletest/include "$source"
done
echo "== kernel family portable on arm64 (SOFTDECA_CPU=portable)"
SOFTDECA_CPU=portable ctest --test-dir "$arm" --output-on-failure -R "$suites" > "$out/portable.log" || { cat "$out/portable.log"; exit 1; }
grep -E 'tests passed' "$out/portable.log"
# Tolerances (metres): 1e-3 mm for float, and the bounds docs/runtime.md gives the native runtime
# against its reference per storage, 1e-3 mm for half and 0.02 mm for int8. Both builds store the
# same values, so only ONNX Runtime's, Eigen's and the kernels' float rounding differs (measured
# figures: docs/platforms.md).
tolerance() { case $1 in float|half) echo 1e-6 ;; int8) echo 2e-5 ;; esac; }
# replay BUNDLE AVATAR TAKE FIRST FRAMES TAG: the x86-64 CLI's replay and replay_check's on arm64
# compared, per precision, model, static and dynamic.
replay() {
  local bundle=$1 avatar=$2 take=$3 first=$4 frames=$5 tag=$6
  for precision in ${PRECISIONS:-half float int8}; do
    for model in softdeca sparse; do
      for mode in ${MODES:-static dynamic}; do
        local dir="$out/$tag-$precision-$model-$mode" flag=()
        [ "$mode" = dynamic ] && flag=(--dynamics)
        "$x86/plugin/cli/softdeca" replay "$take" --bundle "$bundle" --avatar "$avatar" --models "$model" \
          --precision "$precision" --sparse-precision "$precision" --start "$first" --frames "$frames" "${flag[@]}" \
          --out "$dir" > "$dir.log" 2>&1
        "${qemu[@]}" "$arm/tests/native/replay_check" "$bundle" "$avatar" "$take" "$first" \
          "$dir/$model.pc2" "$(tolerance "$precision")" "$precision" "$model" "$mode"
      done
    done
  done
}
echo "== replay of $take through models/softdeca-default: x86-64 CLI against the arm64 library"
replay models/softdeca-default "$avatar" "$take" "$first" "$frames" default
# The committed bundle's deformation-transfer stage is zero (its frames skip the DT right-hand
# side and solve); the runtime tests' small random bundle has one, so its replay covers those.
data="$arm/runtime_test_data"
[ -f "$data/take.csv" ] || .venv/bin/python -m softdeca_train runtime-test-data --out "$data" > /dev/null
"$x86/plugin/cli/softdeca" convert "$data/take.csv" "$out/test-take.sdrec" > /dev/null
echo "== replay through the runtime tests' bundle (a deformation-transfer stage): x86-64 CLI against the arm64 library"
replay "$data/bundle" "$data/avatar" "$out/test-take.sdrec" 0 "$frames" test-bundle
