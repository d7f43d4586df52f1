#!/bin/sh
# End-to-end test of obscurad's GL failure recovery: the daemon is started
# with --fail-gl-after 2, so that frame 2 is treated as a lost GL context.
# Frame 1 is 200, frame 2 is a 500 JSON error, the context is recreated,
# frame 3 is 200 with the same AO as frame 1, /metrics counts one
# recreation, /readyz is 200 again and SIGTERM exits 0.  On the CPU
# device (OBSCURA_BACKEND=cpu) there is no context: frame 2 fails as
# injected and nothing is recreated.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/recover.sh
#
# Loopback only; the daemon is killed on exit; every wait is bounded.
set -u
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
. tests/e2e/lib/common.sh

if ! command -v curl >/dev/null 2>&1; then
    echo "recover e2e: curl not found (make deps)"; exit 1
fi

CAM="fov_y=50&near=0.05&far=100"

echo "e2e recover: $OBSCURAD"
"$OBSCURAD" --help >"$T/help" 2>&1
check "--help lists --fail-gl-after" "grep -q -- '--fail-gl-after' '$T/help'"

start A --fail-gl-after 2 --queue 4 --threads 2
A=$PORT_A

c1=$(post $A "$CAM" "$R" "$T/f1.exr")
check "frame 1: 200" "[ '$c1' = 200 ]"
c2=$(post $A "$CAM" "$R" "$T/f2.json")
check "frame 2: 500 JSON gl_error naming the injected failure" "[ '$c2' = 500 ] && grep -qi 'Content-Type: application/json' $T/f2.json.h && error_is $T/f2.json gl_error && grep -q 'injected' $T/f2.json"
c3=$(post $A "$CAM" "$R" "$T/f3.exr")
check "frame 3: 200 after recovery" "[ '$c3' = 200 ]"
check "frame 3: same AO as frame 1" "cmp -s $T/f1.exr $T/f3.exr"

get $A /metrics "$T/m" >/dev/null
n=$(sed -n 's/^obscurad_gl_context_recreations_total //p' "$T/m")
if gl_only "the context's recreation (metrics and log)" "the CPU device has no context to lose"; then
    check "metrics: one GL context recreation (${n:-?})" "[ '${n:-}' = 1 ]"
    check "log: a warning names the recreation" "grep -qi 'recreat' $T/A.log"
else
    check "the CPU device: frame 3 ran with nothing recreated (${n:-?})" "[ '${n:-}' = 0 ] && ! grep -qi 'recreat' $T/A.log"
fi
check "metrics: GL up, one 500 on /v1/ao" "grep -q '^obscurad_gl_up 1' $T/m && grep -q 'route=\"/v1/ao\",code=\"500\"} 1' $T/m"
check "GET /readyz 200 after recovery" "[ \$(get $A /readyz $T/g) = 200 ]"
check "GET /healthz 200" "[ \$(get $A /healthz $T/g) = 200 ]"

kill -TERM "$PID_A"
k=0
while [ $k -lt 300 ] && kill -0 "$PID_A" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID_A"; rc=$?
check "SIGTERM: exit $rc (0)" "[ $rc -eq 0 ]"

# A second SIGINT during the drain exits at once (130) instead of
# finishing the frames still under way.
# 1920x1080 frames with the heaviest settings take seconds each on the GL
# worker, so the drain is still under way when the second signal comes.
"$BUILD/exr_upscale" "$R" 1920x1080 "$T/big.exr" 2>/dev/null
start B --queue 8 --threads 4
B=$PORT_B
i=0
while [ $i -lt 3 ]; do
    post $B "$CAM&samples=32&culling=off&blur_radius=16" "$T/big.exr" "$T/s$i.exr" >/dev/null &
    i=$((i + 1))
done
i=0
while [ $i -lt 200 ]; do
    get $B /metrics "$T/mb" >/dev/null
    f=$(sed -n 's/^obscurad_in_flight //p' "$T/mb")
    [ "${f:-0}" -ge 3 ] && break
    sleep 0.05
    i=$((i + 1))
done
kill -INT "$PID_B"
sleep 0.2
kill -INT "$PID_B"
k=0
while [ $k -lt 50 ] && kill -0 "$PID_B" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID_B"; rb=$?
check "second SIGINT during the drain ($f requests in flight): exit $rb (130) within 5 s" "[ $rb -eq 130 ] && grep -q 'second SIGINT' $T/B.log"
wait 2>/dev/null
if [ $failed -ne 0 ]; then
    echo "  --- log A (tail)"; tail -8 "$T/A.log" | sed 's/^/       /'
fi
echo "e2e recover: $pass passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
