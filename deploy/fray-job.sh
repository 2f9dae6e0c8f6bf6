#!/bin/sh
# fray-job.sh — one job of a batch render: a range of frames or one tile of a still.
#
# The job's index comes from JOB_COMPLETION_INDEX, which a Kubernetes Indexed Job sets in each of
# its pods (0 … completions−1) and render-loop.sh sets for each process it starts. Everything
# else comes from the environment, the same under both:
#   FRAY_SCENE   the scene file
#   FRAY_OUT     the output folder (shared by the jobs: a volume, or a local folder)
#   FRAY_JOBS    how many jobs share the work (N)
#   FRAY_MODE    `frames` (job i renders its share of FRAY_FRAMES) or `tiles` (job i renders tile i/N)
#   FRAY_FRAMES  A..B, B excluded (frames mode)
#   FRAY_ARGS    more `fray render` options, e.g. "--width 1920 --threads 8" (optional)
#   FRAY         the fray binary (default: fray on the PATH)
# Frames are written as frame_NNNN.png, tiles as tile_NNNN.png; `fray assemble` stacks the tiles.
set -eu
i="${JOB_COMPLETION_INDEX:?the job index (set by an Indexed Job, or by render-loop.sh)}"
n="${FRAY_JOBS:?how many jobs}"
fray="${FRAY:-fray}"
mkdir -p "${FRAY_OUT:?the output folder}"
case "${FRAY_MODE:?frames or tiles}" in
  tiles)
    # shellcheck disable=SC2086 # FRAY_ARGS is a list of options
    exec "$fray" render "${FRAY_SCENE:?the scene}" --tile "$i/$n" --quiet \
      -o "$FRAY_OUT/tile_$(printf %04d "$i").png" ${FRAY_ARGS:-}
    ;;
  frames)
    range="${FRAY_FRAMES:?A..B}"
    a="${range%..*}"
    b="${range#*..}"
    # Job i takes frames [a + (b−a)·i/n, a + (b−a)·(i+1)/n): contiguous shares, none left over.
    start=$((a + (b - a) * i / n))
    end=$((a + (b - a) * (i + 1) / n))
    if [ "$start" -ge "$end" ]; then
      exit 0
    fi
    # shellcheck disable=SC2086
    exec "$fray" render "${FRAY_SCENE:?the scene}" --frames "$start..$end" --quiet \
      -o "$FRAY_OUT/frame_%04d.png" ${FRAY_ARGS:-}
    ;;
  *)
    echo "fray-job.sh: FRAY_MODE must be frames or tiles, got $FRAY_MODE" >&2
    exit 2
    ;;
esac
