#!/bin/sh
# Daemon bench (make bench runs it after the frame bench): a 1920x1080
# G-buffer (nearest upscale of the bench scene, made here with
# exr_upscale, camera in the header) through obscurad over HTTP (EXR),
# the binary protocol over TCP and over a Unix socket (raw planes), against
# the decode + run in process, medians in one run; the EXR encode per
# compression and the decode per thread count; frames per second with 1,
# 2, 4 and 8 concurrent clients, on the GL backend, on the CPU device
# (a second daemon, --backend cpu) and with the chain on one core (a
# third, --render-threads 1: the decode beside the chain); each stage of a frame in the daemon
# (its log and /metrics); a one-shot `obscura ao` of the same file, and of
# BASELINE_OBSCURA (another build's obscura, e.g. main's) when set.
#
# With BASELINE_OBSCURAD (another build's obscurad), its HTTP concurrency
# and stages per client count against this build's, in turns.
#
#   BUILD=build [BASELINE_OBSCURA=PATH] [BASELINE_OBSCURAD=PATH] bench/daemon_bench.sh [G-BUFFER.exr CAMERA.json]
#
# Loopback only; the daemons are killed on exit; every wait is bounded.
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

# start_daemon LOG [FLAGS...]: sets PID, HP (HTTP port), TP (TCP port), SOCK
start_daemon() {
    log=$1
    shift
    SOCK="$T/obscurad.sock"
    rm -f "$SOCK"
    : >"$log" # before the daemon's shell opens it: the loop below reads it at once
    "${DAEMON_BIN:-$BUILD/obscurad}" --http 127.0.0.1:0 --socket "$SOCK" --tcp 127.0.0.1:0 --queue 16 "$@" 2>"$log" &
    PID=$!
    i=0 HP="" TP=""
    while [ $i -lt 300 ] && { [ -z "$HP" ] || [ -z "$TP" ] || [ ! -S "$SOCK" ]; }; do
        HP=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$log")
        TP=$(sed -n 's/.*binary protocol on tcp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$log")
        kill -0 "$PID" 2>/dev/null || break
        sleep 0.1
        i=$((i + 1))
    done
    if [ -z "$HP" ] || [ -z "$TP" ] || [ ! -S "$SOCK" ]; then
        echo "daemon bench: obscurad did not start" >&2; tail -5 "$log" >&2; exit 1
    fi
}

stop_daemon() {
    kill -TERM "$PID"
    k=0
    while [ $k -lt 100 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
    PID=""
}

# the median of the stages in the daemon's log lines (one per frame)
stage_table() {
    echo
    echo "Daemon's stages, median ms per 1080p frame (from its log: frames of over 1 MB, warm-ups and"
    echo "concurrent clients included; send: binary only, HTTP's is in /metrics):"
    echo
    echo "| protocol | frames | receive | decode | queue | gl | encode | send | total in daemon |"
    echo "|---|---|---|---|---|---|---|---|---|"
    for p in "POST /v1/ao" "BINARY"; do
        grep "status=200" "$1" | grep "$p" | grep -E ' in=[0-9]{7,} ' | tr ' ' '\n' |
            awk -v p="$p" -F= '$1 ~ /^(receive|queue|decode|gl|encode|send|total)$/ { v[$1, n[$1]++] = $2 }
                function med(k,   m, i, j, a, t) { m = n[k]; for (i = 0; i < m; i++) a[i] = v[k, i]
                    for (i = 1; i < m; i++) { t = a[i]; for (j = i - 1; j >= 0 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
                    return m ? a[int(m / 2)] : 0 }
                END { printf "| %s | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f |\n", p, n["gl"], med("receive"), med("decode"), med("queue"), med("gl"), med("encode"), med("send"), med("total") }'
    done
}

# ms of one command's wall time
wall_ms() {
    s=$(date +%s%N)
    "$@" >/dev/null 2>&1
    echo $(( ($(date +%s%N) - s) / 1000000 ))
}

# the median of the numbers on stdin
median() { sort -n | awk '{ v[n++] = $1 } END { print n % 2 ? v[int(n / 2)] : (v[n / 2 - 1] + v[n / 2]) / 2 }'; }

"$BUILD/exr_upscale" "$IN" 1920x1080 "$T/big.exr" "$CAM"
echo "### daemon round trip: $(basename "$IN") upscaled to 1920x1080"
echo
echo "command: BUILD=$BUILD bench/daemon_bench.sh ($BUILD/daemon_bench --frames $FRAMES --per-client $PER_CLIENT" \
    "big.exr http://127.0.0.1:PORT tcp://127.0.0.1:PORT unix:SOCK; then --cpu --concurrency-only against" \
    "obscurad --backend cpu)"
echo
# the daemon on the GL context the in-process frames run on (a daemon
# naming no backend takes the CPU device where there is no GPU)
GL_BACKEND=egl-surfaceless
"$BUILD/obscura" info --backend egl-device >/dev/null 2>&1 && GL_BACKEND=egl-device
start_daemon "$T/d.log" --backend "$GL_BACKEND"
"$BUILD/daemon_bench" --daemon-pid "$PID" --frames "$FRAMES" --per-client "$PER_CLIENT" "$T/big.exr" \
    "http://127.0.0.1:$HP" "tcp://127.0.0.1:$TP" "unix:$SOCK"
stage_table "$T/d.log"
stop_daemon

echo
echo "#### the same daemon on the CPU device (obscurad --backend cpu)"
start_daemon "$T/c.log" --backend cpu
"$BUILD/daemon_bench" --daemon-pid "$PID" --cpu --concurrency-only --max-clients 4 --per-client "$PER_CLIENT" "$T/big.exr" \
    "http://127.0.0.1:$HP"
stage_table "$T/c.log"
stop_daemon

# the chain held to one core: does the next frame's decode (an HTTP
# thread) run beside the current frame's chain (the worker)?
echo
echo "#### the chain held to one core (obscurad --render-threads 1): the decode beside the chain"
start_daemon "$T/r.log" --render-threads 1
"$BUILD/daemon_bench" --daemon-pid "$PID" --concurrency-only --max-clients 4 --per-client "$PER_CLIENT" "$T/big.exr" \
    "http://127.0.0.1:$HP"
stage_table "$T/r.log"
stop_daemon

# BASELINE_OBSCURAD (another build's obscurad, e.g. main's): its
# concurrency and stages per client count against this build's, the two
# daemons in turns, twice (a load from outside falls on both)
if [ -n "${BASELINE_OBSCURAD:-}" ]; then
    echo
    echo "#### this build's obscurad and BASELINE_OBSCURAD's, in turns (HTTP, 1, 2, 4 clients)"
    for round in 1 2; do
        for d in "$BUILD/obscurad" "$BASELINE_OBSCURAD"; do
            echo
            echo "##### $d (round $round, load $(cut -d' ' -f1-3 /proc/loadavg))"
            DAEMON_BIN=$d
            start_daemon "$T/b.log" --backend "$GL_BACKEND"
            DAEMON_BIN=""
            "$BUILD/daemon_bench" --daemon-pid "$PID" --concurrency-only --max-clients 4 --per-client "$PER_CLIENT" \
                "$T/big.exr" "http://127.0.0.1:$HP"
            stop_daemon
        done
    done
fi

# one-shot obscura ao: a whole process, read and write included; this
# build and the baseline in turns (a load from outside falls on both)
echo
echo "One-shot \`obscura ao big.exr -o out.exr\` (a whole process: EXR read, context, chain, EXR write),"
echo "median wall ms of 5, the builds in turns:"
echo
echo "| backend | $BUILD/obscura ms | ${BASELINE_OBSCURA:-(no BASELINE_OBSCURA)} ms | ratio |"
echo "|---|---|---|---|"
for b in auto cpu; do
    : >"$T/a" ; : >"$T/b"
    for k in 1 2 3 4 5; do
        wall_ms "$BUILD/obscura" ao "$T/big.exr" -o "$T/out.exr" --backend $b >>"$T/a"
        [ -n "${BASELINE_OBSCURA:-}" ] &&
            wall_ms "$BASELINE_OBSCURA" ao "$T/big.exr" -o "$T/out.exr" --backend $b >>"$T/b"
    done
    ma=$(median <"$T/a")
    mb=$([ -s "$T/b" ] && median <"$T/b" || echo "")
    echo "| $b | $ma | ${mb:--} | $([ -n "$mb" ] && awk "BEGIN { printf \"%.2f\", $ma / $mb }" || echo -) |"
done
