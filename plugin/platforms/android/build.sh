#!/usr/bin/env bash
# Android arm64-v8a: libsoftdeca.so and ONNX Runtime's libonnxruntime.so, for Unity Android players.
#
# UNTESTED HERE: written for a Linux or macOS machine with the Android NDK (r26 or newer; set
# ANDROID_NDK_HOME), CMake, Ninja, curl, unzip and Eigen (Debian: libeigen3-dev); the project's
# machines never ran it.
#
# Steps: ONNX Runtime's Android AAR (Maven Central com.microsoft.onnxruntime:onnxruntime-android,
# the version of training/requirements.lock) into .deps/onnxruntime-android as an ONNX Runtime
# root (headers/ -> include/, jni/arm64-v8a/ -> lib/); a CMake build of the softdeca target with
# the NDK's toolchain (API level ANDROID_PLATFORM, default android-24; the C++ runtime linked
# statically) in build/android-arm64; staged as $OUT/Plugins/Android/arm64-v8a/libsoftdeca.so and
# libonnxruntime.so (Android loads both from the app's native library folder).
# usage: ANDROID_NDK_HOME=<ndk> plugin/platforms/android/build.sh     (OUT=<staging folder>)
platform=android
source "$(dirname "$0")/../common.sh"
ndk=${ANDROID_NDK_HOME:-${ANDROID_NDK_ROOT:-}}
[ -n "$ndk" ] && [ -f "$ndk/build/cmake/android.toolchain.cmake" ] || fail "set ANDROID_NDK_HOME to an Android NDK"
eigen_dir=${EIGEN3_DIR:-/usr/share/eigen3/cmake}
[ -f "$eigen_dir/Eigen3Config.cmake" ] || fail "no Eigen3Config.cmake in $eigen_dir; set EIGEN3_DIR"

ort=.deps/onnxruntime-android
unpack() {  # the AAR's headers/ and jni/arm64-v8a/ as an ONNX Runtime root's include/ and lib/
  unzip -q "$1" 'headers/*' 'jni/arm64-v8a/*' -d "$2/aar"
  mv "$2/aar/headers" "$2/include" && mv "$2/aar/jni/arm64-v8a" "$2/lib" && rm -rf "$2/aar"
}
ort_package "$ort" "https://repo1.maven.org/maven2/com/microsoft/onnxruntime/onnxruntime-android/$ort_version/onnxruntime-android-$ort_version.aar" unpack

# The NDK's toolchain searches its sysroot only: Eigen's package and ONNX Runtime are named directly.
cmake -S . -B build/android-arm64 "${cmake_common[@]}" -DCMAKE_TOOLCHAIN_FILE="$ndk/build/cmake/android.toolchain.cmake" \
  -DANDROID_ABI=arm64-v8a -DANDROID_PLATFORM="${ANDROID_PLATFORM:-android-24}" -DANDROID_STL=c++_static \
  -DEigen3_DIR="$eigen_dir" -DONNXRUNTIME_INCLUDE_DIR="$root/$ort/include" \
  -DONNXRUNTIME_LIBRARY="$root/$ort/lib/libonnxruntime.so"
cmake --build build/android-arm64 --target softdeca -j "$(nproc 2>/dev/null || sysctl -n hw.ncpu)"

dest="$out/Plugins/Android/arm64-v8a"
rm -rf "$dest" && mkdir -p "$dest"
lib=$(find build/android-arm64/plugin -maxdepth 1 -name 'libsoftdeca.so*' -type f | head -n1)
[ -n "$lib" ] || fail "no libsoftdeca.so in build/android-arm64/plugin"
cp "$lib" "$dest/libsoftdeca.so"
cp "$ort/lib/libonnxruntime.so" "$dest/"
strip=$(find "$ndk/toolchains/llvm/prebuilt" -name llvm-strip | head -n1)
[ -z "$strip" ] || "$strip" --strip-unneeded "$dest/libsoftdeca.so"
say "staged $dest: libsoftdeca.so, libonnxruntime.so"
