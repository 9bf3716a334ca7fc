#!/usr/bin/env bash
# Per-frame instruction counts of the arm64 build, with the NEON kernels and with the portable
# ones (SOFTDECA_CPU=portable), for SoftDECA and SparseSoftDECA (`make count-arm64`;
# docs/platforms.md). qemu-user runs replay_check with a plugin that counts the guest
# instructions executed (tests/platforms/qemu_insn_count.c); a run of FEW frames is subtracted
# from one of MANY, which leaves the frames alone (loading, preparing and exiting cancel), divided
# by the frame difference. One thread, static; half storage and both models unless PRECISION or
# MODELS say otherwise.
# These are counts of instructions, not times: qemu's speed says nothing of a device's.
#   usage: tests/platforms/arm64-insn-count.sh X86_BUILD ARM64_BUILD AVATAR_DIR TAKE.sdrec FIRST
set -euo pipefail
x86=$1 arm=$2 avatar=$3 take=$4 first=$5
few=2 many=${MANY:-10} precision=${PRECISION:-half}
out="$arm/insn-count"
mkdir -p "$out"

# Debian ships qemu's plugin support but no plugin and no header: the header comes from the
# Debian source package of the installed qemu-user (cached per version in .deps/qemu-plugin).
src_version=$(dpkg-query -W -f='${source:Version}' qemu-user)
header_dir=.deps/qemu-plugin/$src_version
if [ ! -f "$header_dir/qemu-plugin.h" ]; then
  tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
  uri=$(grep -rhoE '^URIs:\s*\S+' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}' | grep -v security | head -n1 || true)
  [ -n "$uri" ] || uri=$(grep -hoE '^deb\s+(\[[^]]*\]\s+)?\S+' /etc/apt/sources.list 2>/dev/null | awk '{print $NF}' | head -n1)
  codename=$(. /etc/os-release && echo "$VERSION_CODENAME")
  mkdir -p "$tmp/lists/partial"
  echo "deb-src [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $uri $codename main" > "$tmp/src.list"
  O=(-o Dir::Etc::SourceList="$tmp/src.list" -o Dir::Etc::SourceParts=/dev/null -o Dir::State::Lists="$tmp/lists"
     -o Debug::NoLocking=1 -o APT::Sandbox::User=root)
  apt-get "${O[@]}" update -qq
  (cd "$tmp" && apt-get "${O[@]}" source --download-only -qq "qemu=$src_version" > /dev/null)
  tar -xJf "$tmp"/qemu_*.orig.tar.xz -C "$tmp" --wildcards '*/include/qemu/qemu-plugin.h'
  mkdir -p "$header_dir"
  cp "$tmp"/qemu-*/include/qemu/qemu-plugin.h "$header_dir/"
fi
plugin="$out/libinsncount.so"
cc -O2 -Wall -Wextra -shared -fPIC -I "$header_dir" tests/platforms/qemu_insn_count.c -o "$plugin"

count() {  # count FAMILY MODEL FRAMES: the instructions of one replay_check run
  local dir="$out/$2-$3"
  [ -f "$dir/$2.pc2" ] || "$x86/plugin/cli/softdeca" replay "$take" --bundle models/softdeca-default --avatar "$avatar" \
    --models "$2" --precision "$precision" --sparse-precision "$precision" --start "$first" --frames "$3" --out "$dir" > "$dir.log" 2>&1
  SOFTDECA_CPU=$1 qemu-aarch64 -cpu cortex-a76 -L .deps/arm64-qemu-prefix -plugin "$plugin" -d plugin -D "$out/$1-$2-$3.txt" \
    "$arm/tests/native/replay_check" models/softdeca-default "$avatar" "$take" "$first" "$dir/$2.pc2" 1e-5 "$precision" "$2" > /dev/null
  awk '/^instructions/ {print $2}' "$out/$1-$2-$3.txt"
}
echo "per-frame instructions (arm64, $precision storage, one thread; frames $((first + few))-$((first + many - 1)) of the take)"
for model in ${MODELS:-softdeca sparse}; do
  for family in neon portable; do
    a=$(count "$family" "$model" "$few") b=$(count "$family" "$model" "$many")
    awk -v m="$model" -v f="$family" -v a="$a" -v b="$b" -v n=$((many - few)) 'BEGIN { printf "%-9s %-9s %12.0f\n", m, f, (b - a) / n }'
  done
done
