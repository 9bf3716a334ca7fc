#!/usr/bin/env bash
# UNTESTED HERE (needs the Android NDK, which this repository's setup does not install):
# libsoftdeca.so for Android arm64-v8a against ONNX Runtime's Android package (the
# onnxruntime-android AAR from Maven Central: unzip it; headers/ and jni/arm64-v8a/libonnxruntime.so).
# Usage: plugin/platforms/android-arm64.sh NDK_DIR ORT_AAR_DIR [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
ndk=${1:?usage: android-arm64.sh NDK_DIR ORT_AAR_DIR [OUT_DIR]}
aar=${2:?usage: android-arm64.sh NDK_DIR ORT_AAR_DIR [OUT_DIR]}
out=${3:-$root/build/android-arm64}
ort="$out/onnxruntime"
mkdir -p "$ort/include" "$ort/lib"
cp "$aar"/headers/*.h "$ort/include/"
cp "$aar/jni/arm64-v8a/libonnxruntime.so" "$ort/lib/"
cmake -S "$root" -B "$out" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$ndk/build/cmake/android.toolchain.cmake" \
  -DANDROID_ABI=arm64-v8a -DANDROID_PLATFORM=android-26 -DANDROID_STL=c++_static -DCMAKE_BUILD_TYPE=Release \
  -DONNXRUNTIME_ROOT="$ort" -DSOFTDECA_BUILD_PYTHON=OFF -DSOFTDECA_BUILD_TESTS=OFF -DSOFTDECA_BUILD_TOOLS=OFF
cmake --build "$out" --target softdeca
mkdir -p "$out/Plugins/Android/arm64-v8a"
cp "$out/plugin/libsoftdeca.so" "$ort/lib/libonnxruntime.so" "$out/Plugins/Android/arm64-v8a/"
echo "$out/Plugins/Android/arm64-v8a (tests/unity/package.py pack --binaries $out)"
