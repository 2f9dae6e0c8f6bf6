#!/bin/sh
# render-loop.sh — a batch render on one machine (or over ssh, by editing the loop): starts
# FRAY_JOBS processes of fray-job.sh, one per index, waits for all, and in tiles mode stacks the
# tiles into FRAY_OUT/image.png. The same environment as fray-job.sh; nothing else to install.
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
n="${FRAY_JOBS:?how many jobs}"
pids=""
i=0
while [ "$i" -lt "$n" ]; do
  JOB_COMPLETION_INDEX=$i "$here/fray-job.sh" &
  pids="$pids $!"
  i=$((i + 1))
done
failed=0
for pid in $pids; do
  wait "$pid" || failed=1
done
if [ "$failed" -ne 0 ]; then
  echo "render-loop.sh: a job failed" >&2
  exit 1
fi
if [ "$FRAY_MODE" = tiles ]; then
  # The tiles in index order (their names sort so).
  # shellcheck disable=SC2046
  "${FRAY:-fray}" assemble -o "$FRAY_OUT/image.png" $(ls "$FRAY_OUT"/tile_*.png | sort)
fi
