#!/bin/bash
# A/B frame times of two `fray` builds on the CPU, run alternately on one machine in one sitting
# (this machine is shared and noisy: only ratios within one run mean anything). Prints the
# median of RUNS frame times per build, their ratio, and whether the last PNGs were identical.
#
#   bash benches/ab_frames.sh BASE_FRAY NEW_FRAY "FLAGS" SCENE...
#
# e.g. the previous main built in a worktree:
#   git worktree add ../base <commit> && (cd ../base && cargo build --release)
#   bash benches/ab_frames.sh ../base/target/release/fray target/release/fray \
#       "--width 1024 --threads 1" data/scenes/mesh_bunny_freeform.ron
set -euo pipefail
base=$1 new=$2 flags=$3
shift 3
runs=${RUNS:-5}
out=$(mktemp -d)
ms() { # the frame time of the summary line, in ms
  sed -nE 's/.* in ([0-9.]+) (ms|s) \(.*/\1 \2/p' | awk '{ print ($2 == "s") ? $1 * 1000 : $1 }'
}
median() { sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
for scene in "$@"; do
  : >"$out/base" && : >"$out/new"
  for _ in $(seq "$runs"); do
    # shellcheck disable=SC2086
    "$base" render "$scene" $flags --backend cpu -o "$out/base.png" 2>&1 | ms >>"$out/base"
    # shellcheck disable=SC2086
    "$new" render "$scene" $flags --backend cpu -o "$out/new.png" 2>&1 | ms >>"$out/new"
  done
  b=$(median <"$out/base") n=$(median <"$out/new")
  same=$(cmp -s "$out/base.png" "$out/new.png" && echo "identical PNGs" || echo "PNGs DIFFER")
  echo "$scene [$flags]: base $b ms, new $n ms, new/base $(awk -v n="$n" -v b="$b" 'BEGIN { printf "%.3f", n / b }'), $same"
done
rm -r "$out"
