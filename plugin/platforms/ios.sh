#!/usr/bin/env bash
# UNTESTED HERE (written for a Mac with Xcode and CMake; this repository's machines are Linux):
# the static library libsoftdeca.a for iOS devices (arm64), which Unity links into the app (the
# C# binding imports "__Internal" there), against ONNX Runtime's iOS package (the onnxruntime-c
# pod, or onnxruntime.xcframework from its release archive: pass its headers folder; link the
# framework in the Xcode project Unity generates). Eigen: `brew install eigen`.
# Usage: plugin/platforms/ios.sh ORT_HEADERS_DIR [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
headers=${1:?usage: ios.sh ORT_HEADERS_DIR [OUT_DIR]}
out=${2:-$root/build/ios}
# FindOnnxRuntime wants a root with include/ and lib/: the static library links nothing itself.
mkdir -p "$out/onnxruntime/include" "$out/onnxruntime/lib"
cp "$headers"/*.h "$out/onnxruntime/include/"
touch "$out/onnxruntime/lib/libonnxruntime.a"
cmake -S "$root" -B "$out" -G Xcode -DCMAKE_SYSTEM_NAME=iOS -DCMAKE_OSX_ARCHITECTURES=arm64 \
  -DCMAKE_OSX_DEPLOYMENT_TARGET=14.0 -DONNXRUNTIME_ROOT="$out/onnxruntime" -DSOFTDECA_BUILD_PYTHON=OFF \
  -DSOFTDECA_BUILD_TESTS=OFF -DSOFTDECA_BUILD_TOOLS=OFF
cmake --build "$out" --config Release --target softdeca_core
mkdir -p "$out/Plugins/iOS"
cp "$(find "$out" -name libsoftdeca_core.a | head -n1)" "$out/Plugins/iOS/libsoftdeca.a"
echo "$out/Plugins/iOS/libsoftdeca.a (tests/unity/package.py pack --binaries $out; link ONNX Runtime's iOS package in Xcode)"
