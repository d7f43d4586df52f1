#!/bin/sh
# End-to-end tests of obscurad: starts the real daemon on free loopback
# ports, talks HTTP to it with curl, checks answers, errors, limits, the
# full queue and the SIGTERM drain.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/daemon.sh
#
# Prints one line per check; exits 1 if any check failed.  Every daemon it
# starts is killed on exit, and every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
. tests/e2e/lib/common.sh

if ! command -v curl >/dev/null 2>&1; then
    echo "daemon e2e: curl not found (make deps)"; exit 1
fi

# The camera as query parameters: fov_y 50 and the JSON's world_to_camera.
W2C=$(tr -d ' \n' < "$DATA/room_small.camera.json" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
CAM="fov_y=50&near=0.05&far=100&world_to_camera=$W2C"
CAM_CLI="--fov-y 50 --near 0.05 --far 100 --world-to-camera $W2C"

echo "e2e: $OBSCURAD"
echo "-- options"
"$OBSCURAD" --help >"$T/help" 2>&1
check "--help lists every option" "grep -q -- '--max-body' '$T/help' && grep -q -- '--token-file' '$T/help' && grep -q -- '--log-level' '$T/help'"
"$OBSCURAD" --queue 0 >"$T/q0" 2>&1
check "--queue 0 refused with exit 2, naming it" "[ $? -eq 2 ] && grep -q 'queue' '$T/q0'"
"$OBSCURAD" --http '' >"$T/nolisten" 2>&1
check "no listener at all: exit 2" "[ $? -eq 2 ] && grep -q 'no listener' '$T/nolisten'"
printf 'queue 3\n# a comment\nlog_level debug\nbogus 1\n' > "$T/bad.conf"
"$OBSCURAD" --config "$T/bad.conf" >"$T/conf" 2>&1
check "config file error names file and line" "[ $? -eq 2 ] && grep -q 'bad.conf:4' '$T/conf'"

start A --queue 8 --threads 4
A=$PORT_A

echo "-- GET routes"
check "GET /healthz 200" "[ \$(get $A /healthz $T/g) = 200 ]"
check "GET /readyz 200" "[ \$(get $A /readyz $T/g) = 200 ]"
check "GET /v1/info 200 with backend and renderer" "[ \$(get $A /v1/info $T/g) = 200 ] && grep -q '\"backend\"' $T/g && grep -q 'gl_renderer' $T/g"
check "GET /v1/params lists the table" "[ \$(get $A /v1/params $T/g) = 200 ] && grep -q '\"radius\"' $T/g && grep -q '\"world_to_camera\"' $T/g && grep -q '\"output\"' $T/g"
check "GET /metrics 200" "[ \$(get $A /metrics $T/g) = 200 ] && grep -q 'obscurad_queue_depth' $T/g"
check "GET /nope 404 JSON" "[ \$(get $A /nope $T/g) = 404 ] && error_is $T/g not_found"
check "GET /v1/ao 405 with Allow" "[ \$(get $A /v1/ao $T/g) = 405 ] && error_is $T/g method_not_allowed && grep -qi '^Allow: POST' $T/g.h"
check "POST /healthz 405" "[ \$($CURL -o $T/g -w '%{http_code}' -X POST http://127.0.0.1:$A/healthz) = 405 ]"

echo "-- POST /v1/ao equals in-process"
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/local.exr" -q 2>"$T/local.err" || bad "in-process obscura ao failed"
code=$(post $A "$CAM" "$R" "$T/remote.exr")
check "POST room_small: 200 image/x-exr" "[ $code = 200 ] && grep -qi 'Content-Type: image/x-exr' $T/remote.exr.h"
check "Server-Timing has queue, decode, gl, encode" "grep -qi '^Server-Timing: queue;dur=.*decode;dur=.*gl;dur=.*encode;dur=' $T/remote.exr.h"
"$OBSCURA" compare "$T/local.exr" "$T/remote.exr" --mask none --json >"$T/cmp" 2>&1
mae=$(sed -n 's/.*"mae": \([-0-9.e+]*\).*/\1/p' "$T/cmp")
check "AO over HTTP = in-process (MAE ${mae:-?} < 1e-6)" "[ -n '$mae' ] && awk 'BEGIN { exit !($mae < 1e-6) }'"
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI --output both -o "$T/local_both.exr" -q 2>/dev/null
code=$(post $A "$CAM&output=both" "$R" "$T/both.exr")
"$OBSCURA" compare "$T/local_both.exr" "$T/both.exr" --channel-a R --channel-b R --mask none --json >"$T/cmp" 2>&1
mae=$(sed -n 's/.*"mae": \([-0-9.e+]*\).*/\1/p' "$T/cmp")
check "output=both: composite R = in-process (MAE ${mae:-?})" "[ $code = 200 ] && [ -n '$mae' ] && awk 'BEGIN { exit !($mae < 1e-6) }'"
code=$(post $A "$CAM&output=composite&format=png" "$R" "$T/c.png")
check "format=png composite: 200 image/png" "[ $code = 200 ] && grep -qi 'Content-Type: image/png' $T/c.png.h && head -c 4 $T/c.png | grep -q PNG"
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI --output ao -o "$T/local.png" -q 2>/dev/null
code=$(post $A "$CAM&format=png" "$R" "$T/ao.png")
check "format=png AO: same bytes as in-process" "[ $code = 200 ] && cmp -s $T/ao.png $T/local.png"
code=$(post $A "fov-y=50&depth-mode=planar&blur=off&samples=8" "$R" "$T/x.exr")
check "'-' names and a preset-free camera (fov only): 200" "[ $code = 200 ]"

echo "-- errors: a bad request never takes the daemon down"
code=$(post $A "$CAM&samples=64" "$R" "$T/e")
check "400 bad parameter names it and its range" "[ $code = 400 ] && error_is $T/e bad_parameter && grep -q 'samples' $T/e && grep -q '32' $T/e"
code=$(post $A "nope=1" "$R" "$T/e")
check "400 unknown parameter named" "[ $code = 400 ] && grep -q \"nope\" $T/e"
code=$(post $A "$CAM&format=png&output=both" "$R" "$T/e")
check "400 png + both says what to do" "[ $code = 400 ] && grep -q 'one output' $T/e"
code=$($CURL -o "$T/e" -w '%{http_code}' -H 'Content-Type: text/plain' --data-binary @"$R" "http://127.0.0.1:$A/v1/ao?$CAM")
check "415 wrong Content-Type" "[ $code = 415 ] && error_is $T/e unsupported_media_type"
# An EXR whose header asks for DWAA, which OpenEXR 3.1's C API cannot decode.
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/dwa.exr" -q 2>/dev/null
off=$(LC_ALL=C grep -obUaP 'compression\x00compression\x00' "$T/dwa.exr" | head -1 | cut -d: -f1)
printf '\010' | dd of="$T/dwa.exr" bs=1 seek=$((off + 28)) conv=notrunc 2>/dev/null
code=$(post $A "$CAM&depth=AO.Y" "$T/dwa.exr" "$T/e")
check "415 unsupported EXR feature (DWAA)" "[ $code = 415 ] && error_is $T/e unsupported && grep -q DWAA $T/e"
code=$(post $A "solve_camera=0" "$R" "$T/e")
check "422 no camera (its position pass not solved)" "[ $code = 422 ] && error_is $T/e no_camera"
code=$(post $A "$CAM&depth=Nope.Z" "$R" "$T/e")
check "422 missing channel named" "[ $code = 422 ] && error_is $T/e missing_channel && grep -q 'Nope.Z' $T/e"
code=$(post $A "$CAM" "$DATA/room_small.camera.json" "$T/e")
check "422 not an EXR (bad_file)" "[ $code = 422 ] && error_is $T/e bad_file"
n=0; n4=0; n415=0; n422=0; other=""
for f in "$DATA"/damaged/*; do
    case "$f" in *.rst) continue ;; esac
    n=$((n + 1))
    code=$(post $A "fov_y=50" "$f" "$T/e")
    case $code in
        415) n415=$((n415 + 1)); n4=$((n4 + 1)) ;;
        422) n422=$((n422 + 1)); n4=$((n4 + 1)) ;;
        4??|200) n4=$((n4 + 1)) ;;
        *) other="$other $(basename "$f"):$code" ;;
    esac
done
check "$n damaged EXRs: each a clear 4xx ($n415 x 415, $n422 x 422)${other:+, not:$other}" "[ $n4 -eq $n ] && [ $n422 -gt 0 ]"
code=$(post $A "$CAM" "$R" "$T/again.exr")
check "still serving after the errors: same AO" "[ $code = 200 ] && cmp -s $T/again.exr $T/remote.exr"
check "daemon A alive" "kill -0 $PID_A"

echo "-- limits and token"
echo "s3cret-token" > "$T/token"
start B --max-body 1m --max-pixels 10000 --token-file "$T/token"
B=$PORT_B
AUTH="Authorization: Bearer s3cret-token"
code=$(post $B "$CAM" "$R" "$T/e")
check "401 without the token" "[ $code = 401 ] && error_is $T/e unauthorized"
code=$(post $B "$CAM" "$R" "$T/e" -H 'Authorization: Bearer wrong')
check "401 with a wrong token" "[ $code = 401 ]"
check "GET /v1/info needs the token (401), with it 200" "[ \$(get $B /v1/info $T/g) = 401 ] && [ \$(get $B /v1/info $T/g -H '$AUTH') = 200 ]"
check "GET /healthz needs no token" "[ \$(get $B /healthz $T/g) = 200 ]"
code=$(post $B "$CAM" "$R" "$T/e" -H "$AUTH")
check "413 body over --max-body (Content-Length)" "[ $code = 413 ] && error_is $T/e body_too_large"
check "413 answered before the body was read (in=0)" "grep -q 'status=413 in=0 ' $T/B.log"
code=$(post $B "$CAM" "$R" "$T/e" -H "$AUTH" -H 'Transfer-Encoding: chunked')
check "chunked body over --max-body: 413, not stored" "[ $code = 413 ] && error_is $T/e body_too_large"
code=$(post $B "$CAM&depth=AO.Y" "$T/remote.exr" "$T/e" -H "$AUTH")
check "413 pixels over --max-pixels" "[ $code = 413 ] && error_is $T/e too_large"
check "daemon B alive" "kill -0 $PID_B"

echo "-- queue full: 503 with Retry-After"
start C --queue 1 --threads 8
C=$PORT_C
i=0; BG=""
while [ $i -lt 8 ]; do
    post $C "$CAM&samples=32&culling=off&blur_radius=16" "$R" "$T/q$i" > "$T/q$i.code" &
    BG="$BG $!"
    i=$((i + 1))
done
wait_bg() { for j in $BG; do wait "$j"; done; BG=""; }
wait_bg
n200=0; n503=0; i=0
while [ $i -lt 8 ]; do
    case $(cat "$T/q$i.code") in
        200) n200=$((n200 + 1)) ;;
        503) n503=$((n503 + 1)); grep -qi '^Retry-After: ' "$T/q$i.h" || n503=-100 ;;
    esac
    i=$((i + 1))
done
check "8 concurrent on --queue 1: $n200 x 200, $n503 x 503 with Retry-After, none lost" "[ $n200 -ge 1 ] && [ $n503 -ge 1 ] && [ $((n200 + n503)) -eq 8 ]"
code=$(post $C "$CAM" "$R" "$T/x")
check "after the burst: 200" "[ $code = 200 ]"

echo "-- metrics"
get $A /metrics "$T/m" >/dev/null
check "requests by route and status" "grep -q 'obscurad_requests_total{route=\"/v1/ao\",code=\"200\"}' $T/m && grep -q 'code=\"422\"' $T/m"
check "stage histograms (queue, decode, gl, encode)" "grep -q 'obscurad_stage_seconds_bucket{stage=\"gl\",le=\"+Inf\"}' $T/m && grep -q 'obscurad_stage_seconds_count{stage=\"encode\"}' $T/m"
check "bytes in/out, in-flight, queue depth" "grep -q '^obscurad_bytes_received_total [1-9]' $T/m && grep -q '^obscurad_bytes_sent_total [1-9]' $T/m && grep -q '^obscurad_in_flight' $T/m && grep -q '^obscurad_queue_depth 0' $T/m"

echo "-- SIGTERM with frames queued: all answered, exit 0"
i=0
while [ $i -lt 5 ]; do
    # heavy frames (HBAO with 32 x 32 steps, widest blur: ~0.2 s each)
    # keep the GL worker busy long enough for the others to wait in the
    # queue; lighter ones could all be answered before the last arrived
    post $A "$CAM&method=hbao&hbao_directions=32&hbao_steps=32&blur_radius=16" "$R" "$T/t$i.exr" > "$T/t$i.code" &
    BG="$BG $!"
    i=$((i + 1))
done
# wait (bounded) until the daemon holds all five (and this metrics
# request) and frames wait in the queue, then stop it
i=0
while [ $i -lt 200 ]; do
    get $A /metrics "$T/m2" >/dev/null
    q=$(sed -n 's/^obscurad_queue_depth //p' "$T/m2")
    f=$(sed -n 's/^obscurad_in_flight //p' "$T/m2")
    [ "${q:-0}" -ge 1 ] && [ "${f:-0}" -ge 6 ] && break
    sleep 0.02
    i=$((i + 1))
done
echo "       when signalled: ${q:-?} queued, ${f:-?} requests in flight"
kill -TERM "$PID_A"
k=0
while [ $k -lt 600 ] && kill -0 "$PID_A" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID_A"; rc=$?
wait_bg
n200=0; i=0
while [ $i -lt 5 ]; do
    [ "$(cat "$T/t$i.code")" = 200 ] && cmp -s "$T/t$i.exr" "$T/t0.exr" && n200=$((n200 + 1))
    i=$((i + 1))
done
check "SIGTERM: exit $rc (0), $n200 of 5 frames answered 200" "[ $rc -eq 0 ] && [ $n200 -eq 5 ] && [ ${q:-0} -ge 1 ]"
check "log: one line per request, 'stopped'" "grep -q 'req=[0-9]* peer=127.0.0.1:[0-9]* POST /v1/ao status=200 in=[0-9]* out=[0-9]* queue=' $T/A.log && grep -q 'stopped' $T/A.log"
kill -INT "$PID_B"; kill -INT "$PID_C"
k=0
while [ $k -lt 100 ] && { kill -0 "$PID_B" 2>/dev/null || kill -0 "$PID_C" 2>/dev/null; }; do sleep 0.1; k=$((k + 1)); done
wait "$PID_B"; rb=$?
wait "$PID_C"; rcc=$?
check "SIGINT: idle daemons exit 0 ($rb, $rcc)" "[ $rb -eq 0 ] && [ $rcc -eq 0 ]"
if [ $failed -ne 0 ]; then
    for n in A B C; do echo "  --- log $n (tail)"; tail -5 "$T/$n.log" | sed 's/^/       /'; done
fi
echo "e2e daemon: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
