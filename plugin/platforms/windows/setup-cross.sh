#!/usr/bin/env bash
# What the Windows x64 cross-build needs on Debian, installed idempotently (called by
# `make windows`; plain `make setup` does not install it):
#   1. Debian packages: the MinGW-w64 compilers with the posix thread model (the win32 model has
#      no std::thread), mingw-w64-tools, and wine (runs the Windows tests; `wine64` alone puts
#      no `wine` on PATH).
#   2. An ONNX Runtime root for Windows in .deps/onnxruntime-win: onnxruntime.dll from the
#      win_amd64 PyPI wheel of the version the Linux build uses (.deps/onnxruntime/VERSION), and
#      the headers of .deps/onnxruntime/include (the wheel has neither headers nor an import
#      library; GNU ld links against the DLL itself, C API only).
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
cd "$root"
say() { printf '\033[1m[windows]\033[0m %s\n' "$*"; }

source "$root/plugin/platforms/cross-setup.sh"
apt_install g++-mingw-w64-x86-64-posix gcc-mingw-w64-x86-64-posix mingw-w64-tools wine wine64

unpack_windows() {  # unpack_windows WHEEL LIBDIR
  unzip -q -j "$1" 'onnxruntime/capi/onnxruntime.dll' -d "$2"
}
ort=.deps/onnxruntime-win
ort_wheel_root Windows "$ort" unpack_windows win_amd64
say "ready: $(x86_64-w64-mingw32-g++-posix --version | head -n1), $(wine --version), ONNX Runtime $ver ($ort)"
