# Shared by plugin/platforms/<platform>/build.sh (sourced): the repository root, the ONNX Runtime
# version the Linux build pins, the staging folder, and the CMake options every platform build uses.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
say() { printf '\033[1m[%s]\033[0m %s\n' "$platform" "$*"; }
fail() { echo "$platform: $*" >&2; exit 1; }
# The ONNX Runtime version of training/requirements.lock (the one the bundles are tested with).
ort_version=${ORT_VERSION:-$(sed -n 's/^onnxruntime==//p' training/requirements.lock)}
[ -n "$ort_version" ] || fail "no onnxruntime== line in training/requirements.lock; set ORT_VERSION"
# Where the staged Plugins/<platform>/ folders go: `make unity-package` packs this folder.
out=${OUT:-$root/build/unity-binaries}
# Release build of the library alone: no tests, no Python extension, no METIS (a system library a
# player could not load), Eigen's CMake package from EIGEN3_DIR when the toolchain cannot find it.
cmake_common=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DSOFTDECA_BUILD_TESTS=OFF -DSOFTDECA_BUILD_PYTHON=OFF
              -DMETIS_INCLUDE_DIR=METIS_INCLUDE_DIR-NOTFOUND -DMETIS_LIBRARY=METIS_LIBRARY-NOTFOUND)
[ -z "${EIGEN3_DIR:-}" ] || cmake_common+=(-DEigen3_DIR="$EIGEN3_DIR")
fetch() {  # fetch URL FILE: download once
  [ -f "$2" ] || { say "downloading $1"; curl -fL --retry 3 -o "$2.part" "$1" && mv "$2.part" "$2"; }
}
# ort_package DIR URL UNPACK: ONNX Runtime's package for a platform, downloaded once into
# .deps/downloads and unpacked into DIR by the function UNPACK (ARCHIVE DIR), once per version.
ort_package() {
  local dir=$1 url=$2 unpack=$3
  local archive=.deps/downloads/${url##*/}
  [ ! -f "$dir/.stamp-$ort_version" ] || return 0
  mkdir -p .deps/downloads
  fetch "$url" "$archive"
  rm -rf "$dir" && mkdir -p "$dir"
  "$unpack" "$archive" "$dir"
  touch "$dir/.stamp-$ort_version"
}
