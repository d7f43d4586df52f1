#!/bin/sh
# One render-farm task: the AO of a chunk of frames, with `obscura batch`.
# Any farm that hands a task its first and last frame can run it:
#
#   obscura-chunk.sh FIRST LAST [STEP]
#
#   OBSCURA_INPUT   G-buffer pattern, e.g. /show/shot010/gbuffer.####.exr
#   OBSCURA_OUTPUT  output pattern, e.g. /show/shot010/ao/ao.####.exr
#   OBSCURA_CAMERA  camera JSON (optional: else the EXR headers' camera)
#   OBSCURA_SERVER  obscurad URL or comma-separated list (optional: else
#                   in-process, one GL context per task)
#   OBSCURA_JOBS    frames in flight against the servers (default 4)
#   OBSCURA_ARGS    more `obscura ao` options, e.g. "--radius 0.4 --output both"
#   OBSCURA         the obscura binary (default: obscura on PATH)
#
# Examples with the farms' frame tokens:
#   Deadline (command line job):  obscura-chunk.sh <STARTFRAME> <ENDFRAME>
#   Tractor / Qube:               obscura-chunk.sh %f %l  (the farm's own start/end tokens)
#   OpenCue:                      obscura-chunk.sh #FRAME_START# #FRAME_END#   (opencue_job.xml)
#
# Exit codes are obscura batch's: 0 every frame written, 1 failure, 2 usage,
# 3 bad input: an input frame missing or damaged, the others written (do
# not retry until it is fixed), 4 server unreachable or busy (retry the
# task).  Gaps a shot accepts: OBSCURA_ARGS="--allow-missing" (a chunk that
# wrote nothing still fails).  OpenCue and Deadline read the
# "Progress: N%" lines on stdout.
set -eu
[ $# -ge 2 ] || { echo "usage: $0 FIRST LAST [STEP]" >&2; exit 2; }
: "${OBSCURA_INPUT:?set OBSCURA_INPUT to the G-buffer pattern (####)}"
: "${OBSCURA_OUTPUT:?set OBSCURA_OUTPUT to the output pattern (####)}"
frames="$1-$2"
[ $# -ge 3 ] && [ "$3" != 1 ] && frames="$frames"x"$3"
set -- batch "$OBSCURA_INPUT" --frames "$frames" -o "$OBSCURA_OUTPUT" --progress percent
[ -n "${OBSCURA_CAMERA:-}" ] && set -- "$@" --camera "$OBSCURA_CAMERA"
[ -n "${OBSCURA_SERVER:-}" ] && set -- "$@" --server "$OBSCURA_SERVER" --jobs "${OBSCURA_JOBS:-4}"
# shellcheck disable=SC2086
exec "${OBSCURA:-obscura}" "$@" ${OBSCURA_ARGS:-}
