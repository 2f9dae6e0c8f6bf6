#!/usr/bin/env bash
# Embree 3 on the mesh benchmark's own rays, on this machine (docs/mesh-bench.md): builds
# embree_bench.c, writes the rays with the `embree_rays` example, runs it. Needs Embree 3's
# headers and library (Debian 12: `apt-get install libembree-dev`).
set -euo pipefail
root=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
out=${TMPDIR:-/tmp}/fray-embree
mkdir -p "$out"
cc -O2 -Wall -o "$out/embree_bench" "$root/crates/mesh/benches/embree/embree_bench.c" \
    -lembree3 -lpthread -lm
(cd "$root" && cargo run --release -q -p fray-mesh --example embree_rays -- "$out/rays.bin")
"$out/embree_bench" "$root/data/meshes/bunny00.obj" "$out/rays.bin"
