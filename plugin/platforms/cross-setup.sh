# Sourced by the cross-build setups (plugin/platforms/<target>/setup-cross.sh), which define say().
# apt_install PACKAGE...: installs those of the Debian packages that are missing (sudo when not
# root); nothing when all are installed.
apt_install() {
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -gt 0 ] || return 0
  say "installing Debian packages: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# ort_wheel_root TARGET DIR UNPACK PLATFORM...: an ONNX Runtime root for TARGET in DIR, assembled
# once per version (sets ver to it): the library of the onnxruntime PyPI wheel of the version the
# Linux build uses (.deps/onnxruntime/VERSION) for the first of pip's PLATFORM tags that has one,
# taken out of the wheel into a lib/ folder by the function UNPACK (WHEEL LIBDIR), and the headers
# of .deps/onnxruntime/include: the wheels hold none, and the same version's C API serves every
# target.
ort_wheel_root() {
  local target=$1 dir=$2 unpack=$3 linux_ort=.deps/onnxruntime tags=() p
  shift 3
  [ -f "$linux_ort/VERSION" ] || { echo "${target,,}: no $linux_ort/VERSION; run \`make setup\` first" >&2; exit 1; }
  ver=$(cat "$linux_ort/VERSION")
  [ ! -f "$dir/.stamp-$ver" ] || return 0
  say "assembling the ONNX Runtime $ver root for $target in $dir"
  # Expanded now: the trap runs at the script's exit, where this function's locals are gone.
  local tmp; tmp=$(mktemp -d); trap "rm -rf '$tmp'" EXIT
  for p in "$@"; do tags+=(--platform "$p"); done
  .venv/bin/python -m pip download -q --no-deps --only-binary=:all: "${tags[@]}" \
    --python-version 3.11 "onnxruntime==$ver" -d "$tmp"
  "$unpack" "$(ls "$tmp"/onnxruntime-"$ver"-*.whl | head -n1)" "$tmp/lib"
  rm -rf "$dir"; mkdir -p "$dir/include"
  cp "$linux_ort"/include/*.h "$dir/include/"
  cp -P -r "$tmp/lib" "$dir/lib"
  echo "$ver" > "$dir/VERSION"
  touch "$dir/.stamp-$ver"
}
