#!/bin/sh
# Daemon bench (make bench runs it after the frame bench): a 1920x1080
# G-buffer (nearest upscale of the bench scene, made here with
# exr_upscale, camera in the header) through obscurad over HTTP (EXR),
# the binary protocol over TCP and over a Unix socket (raw planes), against
# obs_run in process, medians in one run; then frames per second with 1,
# 2, 4 and 8 concurrent clients over the Unix socket.
#
#   BUILD=build bench/daemon_bench.sh [G-BUFFER.exr CAMERA.json]
#
# Loopback only; the daemon is killed on exit; every wait is bounded.
set -eu
BUILD=${BUILD:-build}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
FRAMES=${FRAMES:-7}
PER_CLIENT=${PER_CLIENT:-3}
if [ $# -ge 2 ]; then
    IN=$1 CAM=$2
elif [ -f "$SHARED/blender/room.exr" ]; then
    IN="$SHARED/blender/room.exr" CAM="$SHARED/blender/room.camera.json"
else
    echo "daemon bench: $SHARED/blender not found; using tests/data/room_small.exr" >&2
    IN=tests/data/room_small.exr CAM=tests/data/room_small.camera.json
fi
T=$(mktemp -d)
PID=""
cleanup() {
    [ -n "$PID" ] && kill -KILL "$PID" 2>/dev/null
    rm -rf "$T"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

"$BUILD/exr_upscale" "$IN" 1920x1080 "$T/big.exr" "$CAM"
SOCK="$T/obscurad.sock"
"$BUILD/obscurad" --http 127.0.0.1:0 --socket "$SOCK" --tcp 127.0.0.1:0 --queue 16 \
    2>"$T/d.log" &
PID=$!
i=0 HP="" TP=""
while [ $i -lt 300 ] && { [ -z "$HP" ] || [ -z "$TP" ] || [ ! -S "$SOCK" ]; }; do
    HP=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    TP=$(sed -n 's/.*binary protocol on tcp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    kill -0 "$PID" 2>/dev/null || break
    sleep 0.1
    i=$((i + 1))
done
if [ -z "$HP" ] || [ -z "$TP" ] || [ ! -S "$SOCK" ]; then
    echo "daemon bench: obscurad did not start" >&2; tail -5 "$T/d.log" >&2; exit 1
fi
echo "### daemon round trip: $(basename "$IN") upscaled to 1920x1080"
echo
echo "command: BUILD=$BUILD bench/daemon_bench.sh ($BUILD/daemon_bench --frames $FRAMES --per-client $PER_CLIENT" \
    "big.exr http://127.0.0.1:PORT tcp://127.0.0.1:PORT unix:SOCK)"
echo
"$BUILD/daemon_bench" --frames "$FRAMES" --per-client "$PER_CLIENT" "$T/big.exr" \
    "http://127.0.0.1:$HP" "tcp://127.0.0.1:$TP" "unix:$SOCK"
# where the daemon's time went (its log: one line per frame, warm-ups included)
echo
echo "Daemon's stages, median ms per frame (from its log):"
echo
echo "| protocol | frames | queue | decode | gl | encode | total in daemon |"
echo "|---|---|---|---|---|---|---|"
for p in "POST /v1/ao" "BINARY"; do
    grep "status=200" "$T/d.log" | grep "$p" | tr ' ' '\n' |
        awk -v p="$p" -F= '$1 ~ /^(queue|decode|gl|encode|total)$/ { v[$1, n[$1]++] = $2 }
            function med(k,   m, i, j, a, t) { m = n[k]; for (i = 0; i < m; i++) a[i] = v[k, i]
                for (i = 1; i < m; i++) { t = a[i]; for (j = i - 1; j >= 0 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
                return m ? a[int(m / 2)] : 0 }
            END { printf "| %s | %d | %.1f | %.1f | %.1f | %.1f | %.1f |\n", p, n["gl"], med("queue"), med("decode"), med("gl"), med("encode"), med("total") }'
done
kill -TERM "$PID"
k=0
while [ $k -lt 100 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
PID=""
