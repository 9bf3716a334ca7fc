#!/usr/bin/env bash
# macOS: softdeca.bundle, universal (arm64 + x86_64), for the Unity editor and macOS players.
#
# UNTESTED HERE: written for a Mac with Xcode's command-line tools, CMake, Ninja and Eigen
# (`brew install cmake ninja eigen`); the project's machines are Linux and never ran it.
#
# Steps: ONNX Runtime's universal2 release archive (GitHub releases, the version of
# training/requirements.lock) into .deps/onnxruntime-macos; a CMake build of the softdeca_bundle
# target in build/macos; the bundle staged as $OUT/Plugins/macOS/softdeca.bundle with
# libonnxruntime.<version>.dylib inside Contents/MacOS (the bundle's rpath is @loader_path), then
# signed ad hoc (Apple silicon loads no unsigned code).
# usage: plugin/platforms/macos/build.sh     (OUT=<staging folder>, default build/unity-binaries)
platform=macos
source "$(dirname "$0")/../common.sh"
[ "$(uname -s)" = Darwin ] || fail "run this on macOS"

ort=.deps/onnxruntime-macos
unpack() { tar -xzf "$1" -C "$2" --strip-components 1; }
ort_package "$ort" "https://github.com/microsoft/onnxruntime/releases/download/v$ort_version/onnxruntime-osx-universal2-$ort_version.tgz" unpack

cmake -S . -B build/macos "${cmake_common[@]}" -DCMAKE_OSX_ARCHITECTURES="arm64;x86_64" \
  -DCMAKE_OSX_DEPLOYMENT_TARGET=11.0 -DONNXRUNTIME_ROOT="$root/$ort"
cmake --build build/macos --target softdeca_bundle -j "$(sysctl -n hw.ncpu)"

dest="$out/Plugins/macOS"
rm -rf "$dest/softdeca.bundle" && mkdir -p "$dest"
cp -R build/macos/plugin/softdeca.bundle "$dest/"
cp "$ort/lib/libonnxruntime.$ort_version.dylib" "$dest/softdeca.bundle/Contents/MacOS/"
binary="$dest/softdeca.bundle/Contents/MacOS/softdeca"
lipo -archs "$binary" | grep -q arm64 && lipo -archs "$binary" | grep -q x86_64 || fail "$binary is not universal"
otool -L "$binary" | grep -q "@rpath/libonnxruntime" || fail "$binary does not load ONNX Runtime through its rpath"
codesign --force --deep --sign - "$dest/softdeca.bundle"
say "staged $dest/softdeca.bundle ($(lipo -archs "$binary"))"
