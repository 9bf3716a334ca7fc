#!/usr/bin/env bash
# iOS: libsoftdeca.a (arm64, device) and ONNX Runtime's static onnxruntime.framework, for Unity
# iOS players (the C# bindings call the library as "__Internal"; Xcode links both into the app).
#
# UNTESTED HERE: written for a Mac with Xcode, CMake, Ninja and Eigen (`brew install cmake ninja
# eigen`); the project's machines are Linux and never ran it.
#
# Steps: ONNX Runtime's iOS package (the onnxruntime-c CocoaPod's archive, holding
# onnxruntime.xcframework, the version of training/requirements.lock) into .deps/onnxruntime-ios;
# a CMake build of the static library (target softdeca_core: every object of the library) for
# the iOS device SDK in build/ios; staged as $OUT/Plugins/iOS/libsoftdeca.a and
# $OUT/Plugins/iOS/onnxruntime.framework (the xcframework's ios-arm64 slice).
# usage: plugin/platforms/ios/build.sh     (OUT=<staging folder>, default build/unity-binaries;
#        IOS_DEPLOYMENT_TARGET, default 15.1, at least ONNX Runtime's own minimum)
platform=ios
source "$(dirname "$0")/../common.sh"
[ "$(uname -s)" = Darwin ] || fail "run this on macOS with Xcode"

ort=.deps/onnxruntime-ios
unpack() { unzip -q "$1" -d "$2"; }
ort_package "$ort" "https://download.onnxruntime.ai/pod-archive-onnxruntime-c-$ort_version.zip" unpack
framework=$(find "$ort" -path '*onnxruntime.xcframework/ios-arm64/onnxruntime.framework' -type d | head -n1)
[ -n "$framework" ] || fail "no ios-arm64/onnxruntime.framework in $ort"

# The framework's headers and binary are handed to FindOnnxRuntime directly (its cache variables).
cmake -S . -B build/ios "${cmake_common[@]}" -DCMAKE_SYSTEM_NAME=iOS -DCMAKE_OSX_ARCHITECTURES=arm64 \
  -DCMAKE_OSX_DEPLOYMENT_TARGET="${IOS_DEPLOYMENT_TARGET:-15.1}" \
  -DONNXRUNTIME_INCLUDE_DIR="$root/$framework/Headers" -DONNXRUNTIME_LIBRARY="$root/$framework/onnxruntime"
cmake --build build/ios --target softdeca_core -j "$(sysctl -n hw.ncpu)"

dest="$out/Plugins/iOS"
rm -rf "$dest" && mkdir -p "$dest"
cp build/ios/plugin/libsoftdeca_core.a "$dest/libsoftdeca.a"
cp -R "$framework" "$dest/"
nm -gU "$dest/libsoftdeca.a" 2>/dev/null | grep -q ' _softdeca_version$' || fail "libsoftdeca.a lacks the C ABI"
say "staged $dest: libsoftdeca.a, onnxruntime.framework"
