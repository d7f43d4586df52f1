#!/bin/sh
# End-to-end tests of obscurad's work and memory limits: --max-cost
# refuses a frame that asks for more samples than it allows (422
# too_costly, naming the option) before running it, over HTTP and the
# binary protocol, and lets a cheaper one through; --keep-memory bounds the
# texture memory the GL worker keeps for the next frame (the gauge
# obscurad_gl_kept_bytes of /metrics), which is released when the queue
# runs empty.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/limits.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
R=tests/data/room_small.exr
CAM=tests/data/room_small.camera.json
. tests/e2e/lib/common.sh

# metric PORT NAME: the value of a gauge
metric() { $CURL "http://127.0.0.1:$1/metrics" | sed -n "s/^$2 \([0-9.e+]*\)$/\1/p"; }
Q="fov_y=50&near=0.05&far=100"

echo "e2e limits: $OBSCURAD"
# room_small is 320x240: 76800 pixels x 16 samples = 1228800 samples
start C --max-cost 1m --socket "$T/c.sock"
st=$(post "$PORT_C" "$Q" "$R" "$T/c1.json")
check "--max-cost 1m: 320x240 x 16 samples (1228800) is 422 too_costly ($st)" \
    "[ '$st' = 422 ] && error_is '$T/c1.json' too_costly && grep -q 'max-cost' '$T/c1.json'"
st=$(post "$PORT_C" "$Q&samples=8" "$R" "$T/c2.out")
check "--max-cost 1m: 8 samples (614400) is answered ($st)" "[ '$st' = 200 ]"
st=$(post "$PORT_C" "$Q&method=hbao&hbao_directions=32&hbao_steps=32" "$R" "$T/c3.json")
check "--max-cost 1m: hbao 32 x 32 counts its 1024 samples per pixel: 422 ($st)" \
    "[ '$st' = 422 ] && error_is '$T/c3.json' too_costly"
"$OBSCURA" ao "$R" --camera "$CAM" -o "$T/c4.exr" --server "unix:$T/c.sock" -q 2>"$T/c4.err"
rc=$?
check "--max-cost over the binary protocol: the CLI exits 3 and shows why (rc $rc)" \
    "[ $rc -eq 3 ] && grep -q 'max-cost' '$T/c4.err'"
$CURL "http://127.0.0.1:$PORT_C/metrics" > "$T/c.metrics"
computed=$(sed -n 's/^obscurad_frames_total{[^}]*} \([0-9]*\)$/\1/p' "$T/c.metrics" | awk '{s += $1} END {print s + 0}')
check "the refused frames were not computed: one frame in obscurad_frames_total ($computed)" \
    "[ '$computed' = 1 ] && grep -q 'obscurad_requests_total{route=\"/v1/ao\",code=\"422\"} 2' '$T/c.metrics'"

# The kept targets of a 320x240 frame: 10449600 bytes (test_kept.c)
start K
st=$(post "$PORT_K" "$Q" "$R" "$T/k1.out")
kept=$(metric "$PORT_K" obscurad_gl_kept_bytes)
check "default --keep-memory: a frame's targets are kept for the next ($kept bytes)" \
    "[ '$st' = 200 ] && [ '$kept' = 10449600 ]"
start M --keep-memory 1m
st=$(post "$PORT_M" "$Q" "$R" "$T/m1.out")
kept=$(metric "$PORT_M" obscurad_gl_kept_bytes)
check "--keep-memory 1m: released once the queue ran empty ($kept bytes kept)" \
    "[ '$st' = 200 ] && [ '$kept' = 0 ]"
st=$(post "$PORT_M" "$Q" "$R" "$T/m2.out")
check "--keep-memory 1m: the next frame is the same ($st)" "[ '$st' = 200 ] && cmp -s '$T/m1.out' '$T/m2.out'"

echo "e2e limits: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
