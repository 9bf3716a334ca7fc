#!/usr/bin/env bash
# softdeca.dll for Windows x64, cross-built on Linux with MinGW-w64 (Debian's -posix compilers)
# against ONNX Runtime's Windows library from its PyPI wheel (onnxruntime.dll; GNU ld links the
# DLL directly, the C API headers are the ones .deps/onnxruntime already has). libgcc,
# libstdc++ and winpthread are linked statically: the DLL needs only onnxruntime.dll beside it.
# Then, under wine: the header check and a replay through the DLL compared with the Linux
# build's replay (tests/unity/fixture).
# Usage: plugin/platforms/windows-x64.sh [OUT_DIR]   (default build/windows-x64)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
out=${1:-build/windows-x64}
py=${PY:-.venv/bin/python}
ort_version=$(cat .deps/onnxruntime/VERSION)
wheels=.cache/onnxruntime-win
mkdir -p "$wheels" "$out/onnxruntime/lib"

# 1. ONNX Runtime's Windows DLL from the win_amd64 wheel (downloaded once into the cache).
wheel=$(ls "$wheels"/onnxruntime-"$ort_version"-*win_amd64.whl 2>/dev/null | head -n1 || true)
if [ -z "$wheel" ]; then
  "$py" -m pip download -q "onnxruntime==$ort_version" --platform win_amd64 --python-version 311 \
    --only-binary=:all: --no-deps -d "$wheels"
  wheel=$(ls "$wheels"/onnxruntime-"$ort_version"-*win_amd64.whl | head -n1)
fi
"$py" - "$wheel" "$out/onnxruntime/lib" <<'PY'
import sys, zipfile
with zipfile.ZipFile(sys.argv[1]) as z:
    for name in z.namelist():
        if name.endswith("capi/onnxruntime.dll"):
            open(sys.argv[2] + "/onnxruntime.dll", "wb").write(z.read(name))
            break
    else:
        raise SystemExit(f"{sys.argv[1]} holds no onnxruntime.dll")
PY
rm -rf "$out/onnxruntime/include"
cp -r .deps/onnxruntime/include "$out/onnxruntime/include"

# 2. Configure and build: the library and the C-ABI test programs (no CLI, Python or GoogleTest).
cmake -S . -B "$out" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/mingw-w64-x86_64.cmake" \
  -DCMAKE_BUILD_TYPE=Release -DONNXRUNTIME_ROOT="$root/$out/onnxruntime" -DSOFTDECA_BUILD_PYTHON=OFF \
  -DSOFTDECA_BUILD_TOOLS=OFF -DCMAKE_RUNTIME_OUTPUT_DIRECTORY="$root/$out/bin" \
  -DSOFTDECA_SMOKE_REPLAY="$root/build/unity/replay" > "$out.configure.log" 2>&1 || { cat "$out.configure.log"; exit 1; }
cmake --build "$out" -j "${JOBS:-2}" --target softdeca abi_header_check_c abi_header_check_cpp replay_smoke
cp "$out/onnxruntime/lib/onnxruntime.dll" "$out/bin/"
echo "DLLs softdeca.dll needs: $(x86_64-w64-mingw32-objdump -p "$out/bin/softdeca.dll" | awk '/DLL Name/{print $3}' | sort | tr '\n' ' ')"

# 3. Run them under wine (its own prefix inside the build folder).
export WINEPREFIX="$root/$out/wineprefix" WINEDEBUG=-all
[ -f build/unity/replay/softdeca.pc2 ] || PY="$py" tests/unity/fixture
ctest --test-dir "$out" --output-on-failure
