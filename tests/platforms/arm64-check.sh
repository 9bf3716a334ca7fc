#!/usr/bin/env bash
# The arm64 build under qemu-user against the x86-64 build (`make test-arm64`; docs/platforms.md):
#   1. the kernel suites of ctest under SOFTDECA_CPU=portable (the NEON ones ran with the rest);
#   2. frames of a real take through the committed bundle, replayed by the x86-64 CLI and by the
#      arm64 library's C ABI (replay_check under qemu), compared vertex by vertex: SoftDECA and
#      SparseSoftDECA, static and dynamic, per precision (PRECISIONS, default half float int8).
#   usage: tests/platforms/arm64-check.sh X86_BUILD ARM64_BUILD AVATAR_DIR TAKE.sdrec FIRST FRAMES
set -euo pipefail
x86=$1 arm=$2 avatar=$3 take=$4 first=$5 frames=$6
out="$arm/replay-check"
mkdir -p "$out"
qemu=(qemu-aarch64 -cpu cortex-a76 -L .deps/arm64-qemu-prefix)  # plugin/platforms/linux-arm64/setup-cross.sh
suites='^(HyperTensor|SparseLdlt|DeformationTransfer|CpuFeatures|NeonKernels)\.'
echo "== kernel family portable on arm64 (SOFTDECA_CPU=portable)"
SOFTDECA_CPU=portable ctest --test-dir "$arm" --output-on-failure -R "$suites" | tail -n 3
# Tolerances (metres): 1e-3 mm for float, and the bounds docs/runtime.md gives the native runtime
# against its reference per storage, 1e-3 mm for half and 0.02 mm for int8. Both builds store the
# same values, so only ONNX Runtime's, Eigen's and the kernels' float rounding differs (measured
# figures: docs/platforms.md).
tolerance() { case $1 in float|half) echo 1e-6 ;; int8) echo 2e-5 ;; esac; }
for precision in ${PRECISIONS:-half float int8}; do
  for model in softdeca sparse; do
    for mode in static dynamic; do
      dir="$out/$precision-$model-$mode"
      flag=(); [ "$mode" = dynamic ] && flag=(--dynamics)
      "$x86/plugin/cli/softdeca" replay "$take" --bundle models/softdeca-default --avatar "$avatar" --models "$model" \
        --precision "$precision" --start "$first" --frames "$frames" "${flag[@]}" --out "$dir" > "$dir.log" 2>&1
      "${qemu[@]}" "$arm/tests/native/replay_check" models/softdeca-default "$avatar" "$take" "$first" \
        "$dir/$model.pc2" "$(tolerance "$precision")" "$precision" "$model" "$mode"
    done
  done
done
