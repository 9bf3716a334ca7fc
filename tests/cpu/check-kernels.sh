#!/usr/bin/env bash
# The native numerics on every kernel family this CPU can run, against the family it picks
# itself (`make test-kernels`; docs/platforms.md, "Kernel families"):
#   1. the kernel and runtime suites of ctest under each family (SOFTDECA_CPU);
#   2. a replay of real frames through the committed bundle, per precision, by the CLI on its
#      own kernels and by replay_check under each family, compared vertex by vertex.
#   usage: tests/cpu/check-kernels.sh BUILD_DIR AVATAR_DIR TAKE.sdrec [FIRST_FRAME [FRAMES]]
set -euo pipefail
build=$1 avatar=$2 take=$3 first=${4:-360} frames=${5:-8}
here=$(cd "$(dirname "$0")" && pwd)
out="$build/kernel-check"
mkdir -p "$out"
# The suites whose numbers depend on the kernels: hyper-tensor contraction and the DT solve
# (HyperTensor, SparseLdlt, DeformationTransfer), the runtime through its C ABI, the CPU cap.
suites='^(HyperTensor|SparseLdlt|DeformationTransfer|CpuFeatures|Runtime|Threads|Worker)\.'
# The same stored values on every family: only summation order and fused multiply-adds differ.
# Half and float: float32 rounding of millimetre offsets (measured 1.5e-8 m). Int8: the portable
# loop rounds each dequantised term in float while the vector kernels sum integers exactly, and
# the committed bundle's vertex stage has terms of metres that cancel to millimetres (collinear
# columns), so float rounding shows more (measured 6.7e-7 m).
tolerance() { [ "$1" = int8 ] && echo 2e-6 || echo 1e-6; }
for precision in half float int8; do
  "$build/plugin/cli/softdeca" replay "$take" --bundle models/softdeca-default --avatar "$avatar" --models softdeca \
    --precision "$precision" --sparse-precision "$precision" --start "$first" --frames "$frames" --out "$out/$precision" > "$out/$precision.log"
done
for family in avx2 portable; do
  echo "== kernel family $family (tests/cpu/run-as.sh $family)"
  "$here/run-as.sh" "$family" ctest --test-dir "$build" --output-on-failure -R "$suites" | tail -n 3
  for precision in half float int8; do
    "$here/run-as.sh" "$family" "$build/tests/native/replay_check" models/softdeca-default "$avatar" "$take" "$first" \
      "$out/$precision/softdeca.pc2" "$(tolerance "$precision")" "$precision"
  done
done
