#!/usr/bin/env bash
# UNTESTED HERE (written for a Mac with Xcode's command line tools, CMake and Ninja; this
# repository's machines are Linux): softdeca.bundle for the Unity editor and macOS players,
# universal (arm64 + x86_64), against ONNX Runtime's macOS release archive
# (onnxruntime-osx-universal2-<version>.tgz from its GitHub releases: include/ and lib/).
# Eigen: `brew install eigen`. Usage: plugin/platforms/macos.sh ORT_ROOT [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
ort=${1:?usage: macos.sh ORT_ROOT [OUT_DIR]}
out=${2:-$root/build/macos}
cmake -S "$root" -B "$out" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_OSX_ARCHITECTURES="arm64;x86_64" \
  -DCMAKE_OSX_DEPLOYMENT_TARGET=11.0 -DONNXRUNTIME_ROOT="$ort" -DSOFTDECA_BUILD_PYTHON=OFF -DSOFTDECA_BUILD_TESTS=OFF \
  -DSOFTDECA_BUILD_TOOLS=OFF
cmake --build "$out" --target softdeca
# Unity loads macOS plugins as bundles or dylibs; a dylib renamed .bundle with its ORT beside it.
mkdir -p "$out/Plugins/macOS"
cp "$out/plugin/libsoftdeca.dylib" "$out/Plugins/macOS/softdeca.bundle"
cp "$ort"/lib/libonnxruntime*.dylib "$out/Plugins/macOS/"
install_name_tool -add_rpath @loader_path "$out/Plugins/macOS/softdeca.bundle"
echo "$out/Plugins/macOS: copy into the package's Plugins/macOS (tests/unity/package.py pack --binaries $out)"
