#!/usr/bin/env bash
# Copies one build's native libraries into the Unity package's Plugins/ layout under OUT, with
# ONNX Runtime's library beside ours, and checks that they load from there:
#   linux:   OUT/Plugins/Linux/x86_64/libsoftdeca.so (RUNPATH $ORIGIN) + libonnxruntime.so.<major>
#   windows: OUT/Plugins/Windows/x86_64/softdeca.dll + onnxruntime.dll (no MinGW runtime DLLs)
# `make unity-package` then packs OUT (tests/unity/package.py pack --binaries OUT).
# usage: plugin/platforms/stage-unity-binaries.sh linux|windows BUILD_DIR ORT_ROOT OUT
set -euo pipefail
[ $# -eq 4 ] || { sed -n 2,8p "$0" >&2; exit 2; }
platform=$1 build=$2 ort=$3 out=$4
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --component plugin --prefix "$tmp" --strip > /dev/null
fail() { echo "stage-unity-binaries: $*" >&2; exit 1; }

case "$platform" in
  linux)
    dest="$out/Plugins/Linux/x86_64"; rm -rf "$dest"; mkdir -p "$dest"
    lib=$(find "$tmp/lib" -name 'libsoftdeca.so*' -type f | head -n1)
    [ -n "$lib" ] || fail "no libsoftdeca.so installed from $build"
    cp "$lib" "$dest/libsoftdeca.so"
    ort_lib=$(readlink -f "$ort/lib/libonnxruntime.so")
    ort_soname=$(readelf -d "$ort_lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
    [ -n "$ort_soname" ] || fail "$ort_lib has no SONAME"
    cp "$ort_lib" "$dest/$ort_soname"
    readelf -d "$dest/libsoftdeca.so" | grep -q 'R.*PATH.*\[\$ORIGIN\]' || fail "libsoftdeca.so lacks RUNPATH \$ORIGIN"
    readelf -d "$dest/libsoftdeca.so" | grep -q "(NEEDED).*\[$ort_soname\]" || fail "libsoftdeca.so does not need $ort_soname"
    ;;
  windows)
    dest="$out/Plugins/Windows/x86_64"; rm -rf "$dest"; mkdir -p "$dest"
    [ -f "$tmp/bin/softdeca.dll" ] || fail "no softdeca.dll installed from $build"
    cp "$tmp/bin/softdeca.dll" "$ort/lib/onnxruntime.dll" "$dest/"
    # Only Windows' own DLLs and ONNX Runtime's: the MinGW runtime is linked in statically.
    imports=$(x86_64-w64-mingw32-objdump -p "$dest/softdeca.dll" | sed -n 's/.*DLL Name: //p' | tr 'A-Z' 'a-z' | sort -u)
    foreign=$(echo "$imports" | grep -Ev '^(kernel32|msvcrt|ws2_32|user32|advapi32|onnxruntime|api-ms-win-.*)\.dll$' || true)
    [ -z "$foreign" ] || fail "softdeca.dll imports $(echo $foreign) (link the MinGW runtime statically)"
    ;;
  *) fail "unknown platform '$platform' (linux or windows; macOS, iOS and Android: plugin/platforms/<platform>/build.sh)" ;;
esac
echo "staged $platform: $(cd "$out" && find "Plugins/${dest#"$out/Plugins/"}" -type f | sort | tr '\n' ' ')"
