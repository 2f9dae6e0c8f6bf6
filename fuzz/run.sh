#!/usr/bin/env bash
# Fuzzes fray's parsers one target at a time (docs/fuzzing.md): `fuzz/run.sh [SECONDS] [TARGET…]`,
# 300 s per target by default, every target unless named. One worker process (`-fork=1`) that
# goes on past a crash, a timeout or an out-of-memory, so one run finds all it can; findings land
# in fuzz/artifacts/<target>/, new inputs in $FRAY_FUZZ_WORK/<target>/ (not in the repository's
# seed corpus, which is only read), the log in $FRAY_FUZZ_WORK/<target>.log.
set -euo pipefail
cd "$(dirname "$0")"
seconds=${1:-300}
shift || true
targets=${*:-scene heightmap_png heightmap_exr heightmap_npy obj inr texture_png texture_exr}
work=${FRAY_FUZZ_WORK:-/tmp/fray-fuzz}
for target in $targets; do
  case $target in
    scene) dict=scene ;;
    *_png) dict=png ;;
    *_exr) dict=exr ;;
    *_npy) dict=npy ;;
    *) dict=$target ;;
  esac
  mkdir -p "$work/$target"
  cargo +nightly fuzz run "$target" --sanitizer none "$work/$target" "corpus/$target" -- \
    -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -dict="dict/$dict.dict" \
    -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 -print_final_stats=1 \
    2>&1 | tee "$work/$target.log" | grep -E "^#[0-9]+:|INFO: fuzzed|crash|timeout|oom|ERROR" || true
done
