#!/usr/bin/env bash
# Runs a command with every numerical library capped at one x86-64 kernel family, so that one
# machine runs the numerics another CPU would (docs/platforms.md, "Kernel families").
#   usage: tests/cpu/run-as.sh avx2|portable COMMAND [ARG...]
# avx2: what an x86-64 CPU with AVX2 and FMA but without AVX-512 runs (e.g. AMD Zen 2/3, Intel
#       before Skylake-SP). portable: the library's own loops without vector kernels (numpy, torch
#       and OpenBLAS at their SSE4.2/AVX2 floor, which no CPU the product supports lies below).
# The one table of these settings: the Makefile and the docs name this script, not the variables.
# ONNX Runtime has no such switch (its MLAS kernels follow cpuid): its float rounding differs by
# CPU in any mode, which the bounds of the runtime's tests allow for (their reasons say so).
set -euo pipefail
family=${1:-}
shift || true
case "$family" in
  avx2|portable) ;;
  *) echo "usage: $0 avx2|portable COMMAND [ARG...]" >&2; exit 2 ;;
esac
[ $# -gt 0 ] || { echo "usage: $0 avx2|portable COMMAND [ARG...]" >&2; exit 2; }
# The library's own kernels (plugin/src/core/cpu_features.h).
export SOFTDECA_CPU=$family
# numpy's dispatched loops: no AVX-512 groups (numpy 2.x names; unknown names only warn).
export NPY_DISABLE_CPU_FEATURES="X86_V4 AVX512_ICL AVX512_SPR"
# OpenBLAS (numpy's and scipy's): the Haswell kernels (AVX2 + FMA).
export OPENBLAS_CORETYPE=Haswell
# torch: ATen's dispatched kernels, MKL's BLAS and oneDNN at AVX2.
export ATEN_CPU_CAPABILITY=avx2
export MKL_ENABLE_INSTRUCTIONS=AVX2
export ONEDNN_MAX_CPU_ISA=AVX2
exec "$@"
