#!/bin/sh
# Concurrency test of obscurad: 16 concurrent `obscura batch --server`
# clients x 10 frames each (HTTP, Unix socket and TCP mixed), mixed sizes
# (tests/data/room_small.exr upscaled to 640x480, and one frame in 16 a
# 1920x1080 upscale, both made here with exr_upscale), against a daemon with a small --queue.
# Every frame must come back, byte-identical to the in-process output
# (else `obscura compare --mask none` MAE < 1e-6); the full queue must have
# been answered 503 and retried by the CLI.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad BUILD=build tests/e2e/load.sh
#
# Under ASan (BUILD containing "asan") the counts are scaled down, and the
# output says so.  Loopback only; the daemon and every client are killed on
# exit; every wait is bounded (DEADLINE: a hang guard in wall-clock
# seconds, about twice the longest run seen on a loaded 2-core machine).
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
BUILD=${BUILD:-build}
UPSCALE="$BUILD/exr_upscale"
DATA=tests/data
R="$(pwd)/$DATA/room_small.exr"
. tests/e2e/lib/common.sh
CPIDS=""
PID=""
CURL="curl -s --max-time 30"

CLIENTS=16 FRAMES=10 BIG_EVERY=16 QUEUE=3 DEADLINE=120
case "$BUILD" in
*asan*)
    CLIENTS=16 FRAMES=5 BIG_EVERY=16 QUEUE=2 DEADLINE=120
    echo "e2e load: ASan build ($BUILD): scaled down to $CLIENTS clients x $FRAMES frames" ;;
esac
NBIG=$(( CLIENTS * FRAMES / BIG_EVERY ))
echo "e2e load: $CLIENTS concurrent clients x $FRAMES frames ($NBIG frames 1920x1080, the rest 640x480), --queue $QUEUE"

W2C=$(tr -d ' \n' < "$DATA/room_small.camera.json" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
# 4 samples: the test is about the daemon, not the AO; it keeps the GL time down
CAM_CLI="--fov-y 50 --near 0.05 --far 100 --world-to-camera $W2C --samples 4"

# the inputs: frame.0001..N of each size (links), and their in-process AO
if ! "$UPSCALE" "$R" 1920x1080 "$T/big.exr" 2>"$T/err" ||
   ! "$UPSCALE" "$R" 640x480 "$T/mid.exr" 2>"$T/err"; then
    bad "exr_upscale 1920x1080 and 640x480"; cat "$T/err"; exit 1; fi
R="$T/mid.exr"
# client c's frame f (links) is 1920x1080 when (c * FRAMES + f) mod BIG_EVERY
# is 0, else 640x480: every client sees both sizes
c=0
while [ $c -lt "$CLIENTS" ]; do
    mkdir -p "$T/in$c"
    f=1
    while [ $f -le "$FRAMES" ]; do
        n=$(printf %04d $f)
        if [ $(( (c * FRAMES + f) % BIG_EVERY )) -eq 0 ]; then
            ln -s "$T/big.exr" "$T/in$c/frame.$n.exr"; echo big > "$T/in$c/size.$n"
        else
            ln -s "$R" "$T/in$c/frame.$n.exr"; echo small > "$T/in$c/size.$n"
        fi
        f=$((f + 1))
    done
    c=$((c + 1))
done
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/ref_small.exr" -q 2>/dev/null &&
    "$OBSCURA" ao "$T/big.exr" $CAM_CLI -o "$T/ref_big.exr" -q 2>/dev/null
check "in-process references (640x480 and 1920x1080)" "[ -s '$T/ref_small.exr' ] && [ -s '$T/ref_big.exr' ]"

SOCK="$T/obscurad.sock"
: > "$T/d.log"
"$OBSCURAD" --http 127.0.0.1:0 --socket "$SOCK" --tcp 127.0.0.1:0 --queue $QUEUE 2>"$T/d.log" &
PID=$!
i=0; HP=""; TP=""
while [ $i -lt 300 ] && { [ -z "$HP" ] || [ -z "$TP" ] || [ ! -S "$SOCK" ]; }; do
    HP=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    TP=$(sed -n 's/.*binary protocol on tcp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    kill -0 "$PID" 2>/dev/null || break
    sleep 0.1
    i=$((i + 1))
done
if [ -n "$HP" ] && [ -n "$TP" ] && [ -S "$SOCK" ]; then ok "obscurad --queue $QUEUE on http :$HP, tcp :$TP and unix:$SOCK"; else
    bad "obscurad did not start"; tail -5 "$T/d.log"; exit 1; fi

# the clients: client c talks HTTP, Unix socket or TCP (c mod 3)
start=$(date +%s)
c=0
while [ $c -lt "$CLIENTS" ]; do
    case $((c % 3)) in
    0) url="http://127.0.0.1:$HP" ;;
    1) url="unix:$SOCK" ;;
    *) url="tcp://127.0.0.1:$TP" ;;
    esac
    # shellcheck disable=SC2086
    OBSCURA_RETRIES=60 "$OBSCURA" batch "$T/in$c/frame.####.exr" --frames "1-$FRAMES" -o "$T/out$c/ao.####.exr" \
        $CAM_CLI --server "$url" 2>"$T/c$c.err" &
    CPIDS="$CPIDS $!"
    echo $! > "$T/c$c.pid"
    c=$((c + 1))
done

# wait for every client, at most DEADLINE seconds of wall clock in all
while :; do
    alive=0
    for p in $CPIDS; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ $alive -eq 0 ] && break
    [ $(( $(date +%s) - start )) -ge "$DEADLINE" ] && break
    sleep 0.1
done
for p in $CPIDS; do kill -KILL "$p" 2>/dev/null; done
elapsed=$(( $(date +%s) - start ))
check "every client finished within ${DEADLINE} s (took ${elapsed} s)" "[ $alive -eq 0 ]"

# every client exited 0 and wrote every frame, equal to the in-process output
mae() {
    "$OBSCURA" compare "$1" "$2" --mask none --json 2>/dev/null | sed -n 's/.*"mae": \([-0-9.e+]*\).*/\1/p'
}
same() { cmp -s "$1" "$2" && return 0; m=$(mae "$1" "$2"); [ -n "$m" ] && awk "BEGIN { exit !($m < 1e-6) }"; }
nok=0 nbad=0 nfail=0 retried=0
c=0
while [ $c -lt "$CLIENTS" ]; do
    wait "$(cat "$T/c$c.pid")" 2>/dev/null
    rc=$?
    [ $rc -eq 0 ] || { nfail=$((nfail + 1)); echo "       client $c: exit $rc"; sed 's/^/         /' "$T/c$c.err" | tail -3; }
    grep -q 'busy (503); retrying' "$T/c$c.err" && retried=$((retried + 1))
    f=1
    while [ $f -le "$FRAMES" ]; do
        n=$(printf %04d $f)
        o="$T/out$c/ao.$n.exr"
        size=$(cat "$T/in$c/size.$n")
        if [ -f "$o" ] && same "$T/ref_$size.exr" "$o"; then nok=$((nok + 1)); else
            nbad=$((nbad + 1)); echo "       client $c frame $f: missing or different"; fi
        f=$((f + 1))
    done
    c=$((c + 1))
done
CPIDS=""
total=$((CLIENTS * FRAMES))
check "every client exited 0 ($nfail did not)" "[ $nfail -eq 0 ]"
check "every frame answered and = in-process: $nok of $total ($nbad missing or different)" \
    "[ $nok -eq $total ] && [ $nbad -eq 0 ]"

# the daemon said 503 (queue full) and the CLI retried
$CURL "http://127.0.0.1:$HP/metrics" > "$T/metrics"
n503=$(awk '/^obscurad_requests_total\{route="(\/v1\/ao|binary)",code="503"\}/ { s += $2 } END { print s + 0 }' "$T/metrics")
n200=$(awk '/^obscurad_requests_total\{route="(\/v1\/ao|binary)",code="200"\}/ { s += $2 } END { print s + 0 }' "$T/metrics")
log503=$(grep -c 'status=503' "$T/d.log")
check "the full queue was answered 503: $n503 in /metrics, $log503 log lines" "[ $n503 -gt 0 ] && [ $log503 -gt 0 ]"
check "the CLI retried after 503 (in $retried of $CLIENTS clients)" "[ $retried -gt 0 ]"
check "/metrics: $n200 frames answered 200 = $total, none lost" "[ $n200 -eq $total ]"
check "the daemon is still alive and ready" "kill -0 $PID && [ \"\$($CURL -o /dev/null -w '%{http_code}' http://127.0.0.1:$HP/readyz)\" = 200 ]"

kill -TERM "$PID"
k=0
while [ $k -lt 100 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID"; rc=$?
PID=""
check "SIGTERM: exit $rc (0)" "[ $rc -eq 0 ]"
[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e load: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
