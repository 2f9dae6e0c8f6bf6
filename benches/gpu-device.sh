#!/bin/bash
# GPU frame times pass by pass on this machine's GPU, from a fresh checkout: builds xtask in
# release, runs `cargo xtask bench gpu` (every data scene, uploaded once, at 1280×720 and
# 1920×1080: warm-up frames, then the median of the timed frames, each pass's median), prints the
# Markdown table and says where the CSV is. Needs Rust and a Vulkan loader (libvulkan.so.1) with
# the GPU's driver; where the loader finds no driver, point it at the driver's ICD file, e.g.
#   VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/nvidia_icd.json bash benches/gpu-device.sh
# Refuses (exit 3) when the only adapter is a software one (lavapipe, SwiftShader): its times are
# the host CPU's, not a GPU's. Meant to take a few minutes on a hardware GPU, the build included
# (tried on lavapipe only: no hardware GPU was at hand).
#
#   bash benches/gpu-device.sh [--allow-software] [XTASK BENCH OPTIONS…]
#
# --allow-software  time a software adapter anyway (lavapipe at these settings: over an hour on
#                   2 cores; add --quick for 6–11 minutes: 1280x720, 1 warm-up + 3 timed frames)
# Other options go to `cargo xtask bench gpu` (defaults here: --warmup 3 --repeats 9, each left
# out where given), e.g. --sizes 1280x720,3840x2160, --scene csg --scene turboprop, --quick.
# Environment: WGPU_BACKEND (default vulkan), OUT (the output folder, default target/bench).
# Exit codes: 0 done; 3 only a software adapter; 2 no adapter or the bench failed; 1 the build.
set -euo pipefail
cd "$(dirname "$0")/.."

allow_software=0
extra=()
for arg in "$@"; do
  case $arg in
    --allow-software) allow_software=1 ;;
    -h | --help)
      sed -n '2,/^# Exit codes/p' "$0" | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    *) extra+=("$arg") ;;
  esac
done

export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
out=${OUT:-target/bench}
case $out in /*) ;; *) out=$PWD/$out ;; esac

# What the Vulkan loader will see, for the record and for the hints below.
icd_dirs=(/etc/vulkan/icd.d /usr/share/vulkan/icd.d /usr/local/share/vulkan/icd.d)
if [ "$(uname -s)" = Linux ] && command -v ldconfig >/dev/null &&
  ! ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1'; then
  echo "warning: no Vulkan loader (libvulkan.so.1) in the linker cache; install it (Debian/Ubuntu: libvulkan1) and the GPU's Vulkan driver" >&2
fi
if [ -n "${VK_ICD_FILENAMES:-}${VK_DRIVER_FILES:-}" ]; then
  echo "Vulkan drivers from the environment: ${VK_DRIVER_FILES:-$VK_ICD_FILENAMES}" >&2
else
  found=$(ls "${icd_dirs[@]}" 2>/dev/null | grep '\.json$' | tr '\n' ' ' || true)
  echo "Vulkan driver files (ICDs) in ${icd_dirs[*]}: ${found:-none}" >&2
fi

start=$(date +%s)
echo "building xtask (release)…" >&2
cargo build --release -p xtask || exit 1
built=$(date +%s)

# This script's defaults where the options do not say otherwise (`--quick` sets both).
flags=()
given=" ${extra[*]:-} "
case $given in *" --quick "*) given="$given --warmup --repeats " ;; esac
case $given in *" --warmup"[\ =]*) ;; *) flags+=(--warmup 3) ;; esac
case $given in *" --repeats"[\ =]*) ;; *) flags+=(--repeats 9) ;; esac
if [ "$allow_software" = 0 ]; then
  flags+=(--hardware-only)
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
set +e
# The Markdown on stdout; progress (the adapter first) on stderr, also kept for the summary.
{
  cargo run --release -q -p xtask -- bench gpu --out "$out" ${flags[@]+"${flags[@]}"} ${extra[@]+"${extra[@]}"} \
    2>&1 1>&3 3>&- | tee "$log" >&2 3>&-
} 3>&1
status=${PIPESTATUS[0]}
set -e
adapter=$(sed -n 's/^adapter: //p' "$log" | head -n 1)
case $status in
  0)
    echo
    echo "adapter: $adapter"
    echo "CSV: $out/gpu.csv (one row per scene × size × pass); Markdown: $out/gpu.md"
    echo "time: build $((built - start)) s, bench $(($(date +%s) - built)) s"
    ;;
  3)
    echo "refused: the only adapter is a software one — ${adapter:-unknown}. Its times are the host CPU's. Install or expose the GPU's Vulkan driver (VK_ICD_FILENAMES), or pass --allow-software." >&2
    exit 3
    ;;
  *)
    if [ -z "$adapter" ]; then
      echo "no GPU adapter was found through $WGPU_BACKEND. Check the Vulkan loader and driver: VK_ICD_FILENAMES=<dir>/<vendor>_icd.json (dirs: ${icd_dirs[*]}); 'vulkaninfo --summary' lists what the loader sees." >&2
    fi
    exit 2
    ;;
esac
