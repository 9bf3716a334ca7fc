#!/usr/bin/env bash
# What the Linux arm64 (aarch64) cross-build needs on Debian x86-64, installed idempotently
# (called by `make arm64`; plain `make setup` does not install it):
#   1. Debian packages: the aarch64 cross compilers, whose own sysroot /usr/aarch64-linux-gnu
#      holds the target's libc and libstdc++, and qemu-user (qemu-aarch64 runs the tests, as set
#      by cmake/toolchains/aarch64-linux-gnu.cmake).
#   2. An ONNX Runtime root for arm64 in .deps/onnxruntime-arm64: libonnxruntime.so from the
#      manylinux aarch64 PyPI wheel of the version the x86-64 build uses
#      (.deps/onnxruntime/VERSION), and the headers of .deps/onnxruntime/include.
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
cd "$root"
say() { printf '\033[1m[arm64]\033[0m %s\n' "$*"; }

source "$root/plugin/platforms/cross-setup.sh"
apt_install g++-aarch64-linux-gnu gcc-aarch64-linux-gnu qemu-user

# unpack_arm64 WHEEL LIBDIR: the wheel's libonnxruntime.so.<version>, with the links the linker
# (libonnxruntime.so) and the loader (its SONAME) look for.
unpack_arm64() {
  unzip -q -j "$1" 'onnxruntime/capi/libonnxruntime.so.*' -d "$2"
  local lib soname
  lib=$(ls "$2"/libonnxruntime.so.* | head -n1)
  [ "${lib##*.so.}" = "$ver" ] || { echo "arm64: the wheel holds $(basename "$lib"), not ONNX Runtime $ver" >&2; exit 1; }
  ln -sf "$(basename "$lib")" "$2/libonnxruntime.so"
  soname=$(aarch64-linux-gnu-objdump -p "$lib" | awk '/SONAME/{print $2}')
  [ -z "$soname" ] || [ -e "$2/$soname" ] || ln -sf "$(basename "$lib")" "$2/$soname"
}
ort=.deps/onnxruntime-arm64
# Recent releases are tagged manylinux_2_28 (glibc 2.28; the cross sysroot has 2.36).
ort_wheel_root arm64 "$ort" unpack_arm64 manylinux_2_28_aarch64 manylinux_2_27_aarch64 manylinux2014_aarch64
# 3. qemu's library prefix (-L) in .deps/arm64-qemu-prefix: the sysroot's lib/, and a
#    /proc/cpuinfo of the CPU qemu emulates (-cpu cortex-a76). Debian 12's qemu-user (7.2) passes the
#    host's x86 /proc/cpuinfo through, and ONNX Runtime's CPU detection crashes on it (a null
#    pointer at its first session); qemu serves a guest's absolute paths from the prefix first.
prefix=.deps/arm64-qemu-prefix
mkdir -p "$prefix/proc"
ln -sfn /usr/aarch64-linux-gnu/lib "$prefix/lib"
for ((cpu = 0; cpu < $(getconf _NPROCESSORS_CONF); cpu++)); do
  printf 'processor\t: %d\nBogoMIPS\t: 50.00\nFeatures\t: %s\nCPU implementer\t: 0x41\nCPU architecture: 8\nCPU variant\t: 0x4\nCPU part\t: 0xd0b\nCPU revision\t: 1\n\n' \
    "$cpu" "fp asimd evtstrm aes pmull sha1 sha2 crc32 atomics fphp asimdhp cpuid asimdrdm lrcpc dcpop asimddp"
done > "$prefix/proc/cpuinfo"
say "ready: $(aarch64-linux-gnu-g++ --version | head -n1), $(qemu-aarch64 --version | head -n1), ONNX Runtime $ver ($ort), qemu prefix $prefix"
